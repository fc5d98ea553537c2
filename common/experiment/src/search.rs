//! One seeded run of a method on a simulated grasp: the engine (with the benchmark or the
//! thesis settings) or uniform random search, maximising the score, one trial at a time or
//! with several in flight (asynchronous workers).

use std::collections::VecDeque;

use graspopt_bayesopt::{AskTell, Method, Optimizer, RandomSearch, Settings, StopReason};
use graspopt_trial::Evaluator;
use serde::{Deserialize, Serialize};

use crate::error::ExperimentError;

/// How a run goes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SearchSettings {
    /// Which method: [`Method::Random`] or an engine run (the engine settings come from
    /// `engine`, or from the method's preset).
    pub method: Method,
    /// Trials at most.
    pub budget: usize,
    /// Size of the engine's initial design (None: the engine's default, 5 in 2D).
    pub n_init: Option<usize>,
    /// Stop before the budget once the engine says the expected improvement has vanished
    /// (thesis 3.4); otherwise the run goes on and [`Trace::ei_stop_at`] records when the
    /// engine would have stopped. Random search always uses the whole budget.
    pub stop_on_small_ei: bool,
    /// The engine's settings, replacing the method's preset; ignored by random search;
    /// `minimize` is forced off.
    #[serde(default)]
    pub engine: Option<Settings>,
    /// Trials in flight (>= 1): W workers run asynchronously. Each proposal is made while
    /// the other W - 1 trials are pending; the oldest trial is scored, observed and
    /// replaced. Trials count in completion order. 1 is the sequential run.
    #[serde(default = "one_worker")]
    pub workers: usize,
}

fn one_worker() -> usize {
    1
}

/// The trials of one run, in order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trace {
    pub method: Method,
    pub seed: u64,
    /// Parameters of each trial (the trial space's units).
    pub params: Vec<Vec<f64>>,
    /// Score of each trial.
    pub scores: Vec<f64>,
    /// Trials after which the engine first said the expected improvement had vanished
    /// (its stopping rule, thesis 3.4), if it did.
    pub ei_stop_at: Option<usize>,
}

impl Trace {
    /// The best score after each trial.
    pub fn best_so_far(&self) -> Vec<f64> {
        let mut best = f64::NEG_INFINITY;
        self.scores
            .iter()
            .map(|s| {
                best = best.max(*s);
                best
            })
            .collect()
    }

    /// The best trial: its index and score.
    pub fn best(&self) -> Option<(usize, f64)> {
        self.scores
            .iter()
            .copied()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }
}

enum Searcher {
    Engine(Box<Optimizer>),
    Random(RandomSearch),
}

impl Searcher {
    fn ask_tell(&mut self) -> &mut dyn AskTell {
        match self {
            Searcher::Engine(o) => o.as_mut(),
            Searcher::Random(r) => r,
        }
    }
}

/// Scores `params`, refusing a score that is not finite.
pub(crate) fn score(ev: &Evaluator, params: &[f64]) -> Result<f64, ExperimentError> {
    let score = ev.score(params).map_err(|error| ExperimentError::Trial {
        params: params.to_vec(),
        error,
    })?;
    if !score.is_finite() {
        return Err(ExperimentError::NonFinite {
            params: params.to_vec(),
            score,
        });
    }
    Ok(score)
}

/// Runs `settings.method` on `ev` with `seed`.
pub fn run(ev: &Evaluator, settings: &SearchSettings, seed: u64) -> Result<Trace, ExperimentError> {
    run_observed(ev, settings, seed, &mut |_, _, _| Ok(()))
}

/// Called after each proposal round of an engine run with the engine, the trials so far and
/// the points proposed.
pub(crate) type OnProposal<'a> =
    dyn FnMut(&Optimizer, &Trace, &[Vec<f64>]) -> Result<(), ExperimentError> + 'a;

/// [`run`], calling `proposed(engine, trace, points)` after every proposal round of an
/// engine run, before its points are scored and observed.
pub(crate) fn run_observed(
    ev: &Evaluator,
    settings: &SearchSettings,
    seed: u64,
    proposed: &mut OnProposal,
) -> Result<Trace, ExperimentError> {
    if settings.budget == 0 {
        return Err(ExperimentError::Settings(
            "the budget must be at least one trial".into(),
        ));
    }
    if settings.workers == 0 {
        return Err(ExperimentError::Settings(
            "a run needs at least one worker".into(),
        ));
    }
    let bounds = ev.space.bounds();
    let engine = match (&settings.engine, settings.method) {
        (_, Method::Random) => None,
        (Some(custom), _) => Some(Settings {
            minimize: false,
            ..custom.clone()
        }),
        (None, Method::Bo(preset)) => Some(Settings {
            minimize: false,
            ..preset.settings()
        }),
    };
    let mut searcher = match engine {
        Some(mut s) => {
            s.n_init = settings.n_init.or(s.n_init);
            Searcher::Engine(Box::new(Optimizer::new(&bounds, s, seed)?))
        }
        None => Searcher::Random(RandomSearch::new(&bounds, false, seed)?),
    };
    let mut trace = Trace {
        method: settings.method,
        seed,
        params: Vec::with_capacity(settings.budget),
        scores: Vec::with_capacity(settings.budget),
        ei_stop_at: None,
    };
    let mut in_flight: VecDeque<Vec<f64>> = VecDeque::new();
    while trace.scores.len() < settings.budget {
        while in_flight.len() < settings.workers
            && trace.scores.len() + in_flight.len() < settings.budget
        {
            let next = searcher.ask_tell().suggest(1)?;
            if let Searcher::Engine(opt) = &searcher {
                proposed(opt, &trace, &next)?;
            }
            in_flight.extend(next);
        }
        let Some(p) = in_flight.pop_front() else {
            break;
        };
        let y = score(ev, &p)?;
        searcher.ask_tell().observe(&p, y)?;
        trace.params.push(p);
        trace.scores.push(y);
        if let Searcher::Engine(opt) = &searcher
            && trace.ei_stop_at.is_none()
            && opt.stop_reason() == Some(StopReason::SmallExpectedImprovement)
        {
            trace.ei_stop_at = Some(trace.scores.len());
            if settings.stop_on_small_ei {
                break;
            }
        }
    }
    Ok(trace)
}
