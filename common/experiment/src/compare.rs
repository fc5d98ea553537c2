//! Several methods over many seeds on one evaluator (thesis 4.8, Table 4.1): every run in
//! parallel, then per method the trials each seed needed to get within 5/10/20% of a
//! reference value, their medians, and the best-so-far curve's mean and spread.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use graspopt_bayesopt::Method;
use graspopt_trial::Evaluator;
use graspopt_trial::scan::worker_count;
use serde::{Deserialize, Serialize};

use crate::error::ExperimentError;
use crate::search::{SearchSettings, Trace, run};
use crate::target::{TARGET_FRACTIONS, median, trials_to_within};

/// One method's runs, summarised.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodSummary {
    pub method: Method,
    /// One run per seed, in seed order.
    pub traces: Vec<Trace>,
    /// Per seed, trials to within each of [`TARGET_FRACTIONS`] of the reference.
    pub trials_to: Vec<[Option<usize>; 3]>,
    /// Seeds that got within each fraction.
    pub reached: [usize; 3],
    /// Median trials to each fraction, a seed that never got there counted as budget + 1;
    /// None unless more than half the seeds got there (so the median is a trial count).
    pub median_trials_to: [Option<f64>; 3],
    /// Mean over seeds of the best score after each trial (a run that stopped early keeps
    /// its last best).
    pub mean_best: Vec<f64>,
    /// Standard deviation over seeds of the same.
    pub std_best: Vec<f64>,
    /// Lowest and highest over seeds of the same.
    pub min_best: Vec<f64>,
    pub max_best: Vec<f64>,
}

/// Every method's summary against one reference.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// The value the fractions are taken of (the grid maximum, or the best any run found).
    pub reference: f64,
    /// Trials per run at most.
    pub budget: usize,
    pub methods: Vec<MethodSummary>,
}

/// Runs every method in `methods` once per seed on `ev` (`threads` workers, 0: one per core)
/// and summarises them against `reference`, or against the best score of all runs when
/// `reference` is None. `template.method` is replaced by each method in turn.
pub fn compare(
    ev: &Evaluator,
    methods: &[Method],
    seeds: &[u64],
    template: &SearchSettings,
    reference: Option<f64>,
    threads: usize,
) -> Result<Comparison, ExperimentError> {
    if methods.is_empty() || seeds.is_empty() {
        return Err(ExperimentError::Settings(
            "a comparison needs at least one method and one seed".into(),
        ));
    }
    let jobs: Vec<(usize, u64)> = (0..methods.len())
        .flat_map(|m| seeds.iter().map(move |s| (m, *s)))
        .collect();
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Result<Trace, ExperimentError>>>> =
        Mutex::new((0..jobs.len()).map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..worker_count(threads, jobs.len()) {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&(m, seed)) = jobs.get(i) else { break };
                    let settings = SearchSettings {
                        method: methods[m],
                        ..template.clone()
                    };
                    let trace = run(ev, &settings, seed);
                    if let Ok(mut r) = results.lock() {
                        r[i] = Some(trace);
                    }
                }
            });
        }
    });
    // A worker's panic is re-raised by the scope, so a poisoned lock cannot be seen here.
    let results = results.into_inner().unwrap_or_else(|e| e.into_inner());
    let mut traces = Vec::with_capacity(jobs.len());
    for r in results {
        traces.push(
            r.ok_or_else(|| ExperimentError::Settings("a comparison run was not done".into()))??,
        );
    }
    let reference = match reference {
        Some(r) => r,
        None => traces
            .iter()
            .filter_map(|t| t.best().map(|b| b.1))
            .fold(f64::NEG_INFINITY, f64::max),
    };
    let mut summaries = Vec::with_capacity(methods.len());
    let mut traces = traces.into_iter();
    for &method in methods {
        let runs: Vec<Trace> = traces.by_ref().take(seeds.len()).collect();
        summaries.push(summarise(method, runs, reference, template.budget));
    }
    Ok(Comparison {
        reference,
        budget: template.budget,
        methods: summaries,
    })
}

/// Summarises one method's runs against `reference` (`budget`: the trials per run).
pub fn summarise(
    method: Method,
    traces: Vec<Trace>,
    reference: f64,
    budget: usize,
) -> MethodSummary {
    let curves: Vec<Vec<f64>> = traces.iter().map(Trace::best_so_far).collect();
    let trials_to: Vec<[Option<usize>; 3]> = curves
        .iter()
        .map(|c| TARGET_FRACTIONS.map(|f| trials_to_within(c, reference, f)))
        .collect();
    let mut reached = [0; 3];
    let mut median_trials_to = [None; 3];
    for k in 0..3 {
        reached[k] = trials_to.iter().filter(|t| t[k].is_some()).count();
        let counts: Vec<f64> = trials_to
            .iter()
            .map(|t| t[k].map_or(budget as f64 + 1.0, |n| n as f64))
            .collect();
        if 2 * reached[k] > traces.len() {
            median_trials_to[k] = median(&counts);
        }
    }
    let len = curves.iter().map(Vec::len).max().unwrap_or(0);
    let at = |c: &Vec<f64>, i: usize| c.get(i).or(c.last()).copied().unwrap_or(f64::NAN);
    let n = curves.len().max(1) as f64;
    let mut mean_best = Vec::with_capacity(len);
    let mut std_best = Vec::with_capacity(len);
    let mut min_best = Vec::with_capacity(len);
    let mut max_best = Vec::with_capacity(len);
    for i in 0..len {
        let v: Vec<f64> = curves.iter().map(|c| at(c, i)).collect();
        let mean = v.iter().sum::<f64>() / n;
        mean_best.push(mean);
        std_best.push((v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt());
        min_best.push(v.iter().copied().fold(f64::INFINITY, f64::min));
        max_best.push(v.iter().copied().fold(f64::NEG_INFINITY, f64::max));
    }
    MethodSummary {
        method,
        traces,
        trials_to,
        reached,
        median_trials_to,
        mean_best,
        std_best,
        min_best,
        max_best,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trace(scores: &[f64]) -> Trace {
        Trace {
            method: Method::Random,
            seed: 0,
            params: scores.iter().map(|_| vec![0.0]).collect(),
            scores: scores.to_vec(),
            ei_stop_at: None,
        }
    }

    /// Four seeds against the reference 1.0, `reaching` of them within 5% (from 0.95).
    fn runs(reaching: usize) -> Vec<Trace> {
        let good = [
            trace(&[0.0, 0.96, 0.96, 0.96]),
            trace(&[0.0, 0.5, 0.97, 0.97]),
            trace(&[0.0, 0.5, 0.97, 0.97]),
        ];
        (0..4)
            .map(|i| {
                if i < reaching {
                    good[i].clone()
                } else {
                    trace(&[0.0, 0.5, 0.6, 0.7])
                }
            })
            .collect()
    }

    #[test]
    fn medians_are_trial_counts_only_when_most_seeds_got_there() {
        // Two of four: no median (it would average 3 and the 'never' count, 5).
        let half = summarise(Method::Random, runs(2), 1.0, 4);
        assert_eq!(half.reached[0], 2);
        assert_eq!(half.median_trials_to[0], None);
        // Three of four: the median of 2, 3, 3 and 5 is 3.
        let most = summarise(Method::Random, runs(3), 1.0, 4);
        assert_eq!(
            most.trials_to.iter().map(|t| t[0]).collect::<Vec<_>>(),
            vec![Some(2), Some(3), Some(3), None]
        );
        assert_eq!(most.median_trials_to[0], Some(3.0));
        // Within 20% (from 0.8): the same three seeds.
        assert_eq!(most.reached[2], 3);
        // The curves, per trial over the four seeds.
        assert_eq!(most.mean_best[1], (0.96 + 0.5 + 0.5 + 0.5) / 4.0);
        assert_eq!(most.max_best[3], 0.97);
        assert_eq!(most.min_best[3], 0.7);
    }
}
