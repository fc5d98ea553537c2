//! A 1D run with the model at every step (thesis figures 4.16-4.17): after each trial, the
//! GP posterior mean and standard deviation and the expected improvement along the whole
//! parameter range, with the samples so far and the trial proposed next.

use graspopt_trial::Evaluator;
use graspopt_trial::scan::linspace;
use serde::{Deserialize, Serialize};

use crate::error::ExperimentError;
use crate::search::{SearchSettings, Trace, run_observed};

/// The model after some trials of a 1D run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Trials observed.
    pub trials: usize,
    /// The parameter values the curves are given at.
    pub grid: Vec<f64>,
    /// Posterior mean of the score (raw units).
    pub mean: Vec<f64>,
    /// Posterior standard deviation.
    pub sd: Vec<f64>,
    /// Expected improvement as the engine sees it (`Optimizer::expected_improvement`: its
    /// standardised, transformed units, with its `xi`).
    pub ei: Vec<f64>,
    /// The trial proposed next, if the run went on.
    pub next: Option<f64>,
}

/// Runs an engine method on a one-parameter `ev` and returns the run and a snapshot after
/// every trial from the second on, on a grid of `points` values.
pub fn run_with_snapshots(
    ev: &Evaluator,
    settings: &SearchSettings,
    seed: u64,
    points: usize,
) -> Result<(Trace, Vec<Snapshot>), ExperimentError> {
    if ev.space.dim() != 1 {
        return Err(ExperimentError::Settings(format!(
            "snapshots need a one-parameter trial space, this one has {}",
            ev.space.dim()
        )));
    }
    if points < 2 {
        return Err(ExperimentError::Settings(
            "snapshots need at least 2 grid points".into(),
        ));
    }
    let (lo, hi) = ev.space.bounds()[0];
    let grid = linspace(lo, hi, points);
    let mut snaps: Vec<Snapshot> = Vec::new();
    let mut take = |opt: &graspopt_bayesopt::Optimizer, trace: &Trace| {
        if trace.scores.len() < 2 {
            return Ok(());
        }
        let mut snap = Snapshot {
            trials: trace.scores.len(),
            grid: grid.clone(),
            mean: Vec::with_capacity(points),
            sd: Vec::with_capacity(points),
            ei: Vec::with_capacity(points),
            next: None,
        };
        for &x in &grid {
            let (m, s) = opt.predict(&[x])?;
            snap.mean.push(m);
            snap.sd.push(s);
            snap.ei.push(opt.expected_improvement(&[x])?);
        }
        snaps.push(snap);
        Ok(())
    };
    if settings.method == graspopt_bayesopt::Method::Random {
        return Err(ExperimentError::Settings(
            "snapshots show the engine's model: random search has none".into(),
        ));
    }
    let trace = run_observed(ev, settings, seed, &mut take)?;
    for s in &mut snaps {
        s.next = trace.params.get(s.trials).map(|p| p[0]);
    }
    Ok((trace, snaps))
}
