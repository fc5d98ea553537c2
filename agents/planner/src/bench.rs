//! `graspopt bench planner`: the time of a proposal round at thousands of observations,
//! through the planner's own path ([`Planner::answer`]: the engine told the new
//! observations, the pending points set, the round proposed and the engine state encoded).
//!
//! The run's history is synthetic but shaped like a long BO run: a quarter of the points
//! uniform in the box, the rest clustered around the test function's optima at three
//! spreads (10%, 3% and 1% of each axis), as a search that has converged leaves them. The
//! objective is Branin in 2D and Hartmann6 in 6D, negated (the planner maximises). The first
//! round rebuilds the engine from the history (a planner that was restarted, or has no
//! usable state); the timed rounds after it continue a pipeline of `pending` workers: the
//! points pending in one round are observed before the next, whose request carries the
//! previous reply's engine state, as the coordinator sends it.

use std::fmt;
use std::time::Instant;

use graspopt_bayesopt::TestFunction;
use graspopt_bayesopt::rng::Rng;
use graspopt_protocol::{Observation, PlannerMethod, RunId, SuggestRequest};

use crate::{Planner, PlannerError};

/// The most observations, pending points or proposals of one bench round.
pub const MAX_BENCH_POINTS: usize = 100_000;

/// What to time.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannerBenchSettings {
    /// Input dimensions: 2 (Branin) and/or 6 (Hartmann6).
    pub dims: Vec<usize>,
    /// Observations in the history before the first round.
    pub observations: usize,
    /// Points pending in every round, and proposed by it.
    pub pending: usize,
    /// Timed rounds after the first.
    pub rounds: usize,
    /// Seed of the synthetic history and of the engine.
    pub seed: u64,
}

impl Default for PlannerBenchSettings {
    fn default() -> Self {
        PlannerBenchSettings {
            dims: vec![2, 6],
            observations: 2000,
            pending: 32,
            rounds: 9,
            seed: 1,
        }
    }
}

/// The figures of one dimension.
#[derive(Debug, Clone, PartialEq)]
pub struct DimFigures {
    pub dim: usize,
    pub function: &'static str,
    /// The first round (engine rebuilt from the history), milliseconds.
    pub first_ms: f64,
    /// Each timed round, milliseconds.
    pub rounds_ms: Vec<f64>,
    /// Observations of the first and the last timed round.
    pub observations: (usize, usize),
}

impl DimFigures {
    /// Median of the timed rounds (ms).
    pub fn median_ms(&self) -> f64 {
        graspopt_bayesopt::benchmark::median(&self.rounds_ms).unwrap_or(f64::NAN)
    }

    /// Slowest timed round (ms).
    pub fn max_ms(&self) -> f64 {
        self.rounds_ms
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// The figures of a bench run.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannerBenchReport {
    pub settings: PlannerBenchSettings,
    pub dims: Vec<DimFigures>,
}

impl fmt::Display for PlannerBenchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = &self.settings;
        writeln!(
            f,
            "planner round of {p} proposals with {p} pending, from {n} observations \
             (engine grasp, one thread)",
            p = s.pending,
            n = s.observations
        )?;
        writeln!(
            f,
            "| dim | function | observations | first round, rebuilt (ms) | median round (ms) | slowest round (ms) | rounds (ms) |"
        )?;
        writeln!(f, "|---|---|---|---|---|---|---|")?;
        for d in &self.dims {
            let rounds: Vec<String> = d.rounds_ms.iter().map(|v| format!("{v:.1}")).collect();
            writeln!(
                f,
                "| {} | {} | {}-{} | {:.1} | {:.1} | {:.1} | {} |",
                d.dim,
                d.function,
                d.observations.0,
                d.observations.1,
                d.first_ms,
                d.median_ms(),
                d.max_ms(),
                rounds.join(", ")
            )?;
        }
        Ok(())
    }
}

/// Where the test function of dimension `d` is minimal (the clusters of the history).
fn function_of(d: usize) -> Result<(TestFunction, Vec<Vec<f64>>), PlannerError> {
    match d {
        2 => Ok((
            TestFunction::Branin,
            vec![
                vec![-std::f64::consts::PI, 12.275],
                vec![std::f64::consts::PI, 2.275],
                vec![9.424_78, 2.475],
            ],
        )),
        6 => Ok((
            TestFunction::Hartmann6,
            vec![vec![
                0.201_69, 0.150_011, 0.476_874, 0.275_332, 0.311_652, 0.657_3,
            ]],
        )),
        _ => Err(PlannerError::State(format!(
            "the planner bench runs in 2 or 6 dimensions, not {d}"
        ))),
    }
}

/// A point of the synthetic history (see the module documentation).
fn history_point(rng: &mut Rng, lo: &[f64], hi: &[f64], optima: &[Vec<f64>]) -> Vec<f64> {
    let u = rng.uniform();
    if u < 0.25 {
        return lo
            .iter()
            .zip(hi)
            .map(|(l, h)| l + rng.uniform() * (h - l))
            .collect();
    }
    let spread = if u < 0.5 {
        0.1
    } else if u < 0.75 {
        0.03
    } else {
        0.01
    };
    let k = ((rng.uniform() * optima.len() as f64) as usize).min(optima.len() - 1);
    optima[k]
        .iter()
        .zip(lo.iter().zip(hi))
        .map(|(c, (l, h))| (c + spread * (h - l) * rng.normal()).clamp(*l, *h))
        .collect()
}

/// Times the planner's rounds as [`PlannerBenchSettings`] says.
pub fn planner_bench(s: &PlannerBenchSettings) -> Result<PlannerBenchReport, PlannerError> {
    let too_many = |what: &str, v: usize| {
        PlannerError::State(format!(
            "{what} must be between 1 and {MAX_BENCH_POINTS}, got {v}"
        ))
    };
    if !(1..=MAX_BENCH_POINTS).contains(&s.observations) {
        return Err(too_many("the observations", s.observations));
    }
    if !(1..=MAX_BENCH_POINTS).contains(&s.pending) {
        return Err(too_many("the pending points", s.pending));
    }
    if !(1..=1000).contains(&s.rounds) {
        return Err(PlannerError::State(format!(
            "the rounds must be between 1 and 1000, got {}",
            s.rounds
        )));
    }
    let mut dims = Vec::new();
    for &d in &s.dims {
        dims.push(one_dim(s, d)?);
    }
    Ok(PlannerBenchReport {
        settings: s.clone(),
        dims,
    })
}

fn one_dim(s: &PlannerBenchSettings, d: usize) -> Result<DimFigures, PlannerError> {
    let (function, optima) = function_of(d)?;
    let (lo, hi) = function.bounds();
    let mut rng = Rng::new(s.seed);
    let observe = |x: Vec<f64>| Observation {
        y: -function.eval(&x),
        x,
    };
    // The first (untimed) round is one batch earlier, so the first timed one has
    // `observations`.
    let mut history: Vec<Observation> = (0..s.observations.saturating_sub(s.pending))
        .map(|_| observe(history_point(&mut rng, &lo, &hi, &optima)))
        .collect();
    let mut pending: Vec<Vec<f64>> = (0..s.pending)
        .map(|_| history_point(&mut rng, &lo, &hi, &optima))
        .collect();
    let run_id = RunId::new("bench-planner").map_err(|e| PlannerError::State(e.to_string()))?;
    let mut planner = Planner::default();
    let mut state = None;
    let mut first_ms = 0.0;
    let mut rounds_ms = Vec::with_capacity(s.rounds);
    let mut first_n = 0;
    let mut last_n = 0;
    for round in 0..=s.rounds {
        let req = SuggestRequest {
            run_id: run_id.clone(),
            request_id: round as u64 + 1,
            method: PlannerMethod::Bo,
            bounds: lo.iter().zip(&hi).map(|(l, h)| [*l, *h]).collect(),
            seed: s.seed,
            initial: None,
            observations: history.clone(),
            pending: pending.clone(),
            count: u32::try_from(s.pending).map_err(|_| PlannerError::State("pending".into()))?,
            engine_state: state.take(),
        };
        last_n = history.len();
        let start = Instant::now();
        let reply = planner.answer(&run_id, &req)?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        if let Some(e) = reply.error {
            return Err(PlannerError::State(format!("the planner failed: {e}")));
        }
        if round == 0 {
            first_ms = ms;
        } else {
            if round == 1 {
                first_n = last_n;
            }
            rounds_ms.push(ms);
        }
        state = reply.engine_state;
        // The pending trials complete; the proposals are the next round's pending ones.
        history.extend(pending.drain(..).map(observe));
        pending = reply.points;
    }
    Ok(DimFigures {
        dim: d,
        function: function.name(),
        first_ms,
        rounds_ms,
        observations: (first_n, last_n),
    })
}
