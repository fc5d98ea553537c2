//! A 1D run with the model at every step (thesis figures 4.16-4.17): before each trial from
//! the third on, the model that chose it (GP posterior mean and standard deviation and the
//! expected improvement along the whole parameter range) and the trial it chose.

use graspopt_trial::Evaluator;
use graspopt_trial::scan::linspace;
use serde::{Deserialize, Serialize};

use crate::error::ExperimentError;
use crate::search::{SearchSettings, Trace, run_observed};

/// The model of a 1D run after some trials, as it chose the next trial.
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
    /// Expected improvement as the engine sees it (`Optimizer::model_at`: its standardised,
    /// transformed units, with its `xi`).
    pub ei: Vec<f64>,
    /// The trial it chose next.
    pub next: f64,
    /// The expected improvement there (the maximum the engine found; it can lie between
    /// grid values, above every value of `ei`).
    pub next_ei: f64,
}

/// Runs an engine method on a one-parameter `ev` and returns the run and, on a grid of
/// `points` values, a snapshot of the model that chose each trial from the third on (a model
/// needs two observations).
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
    let mut take = |opt: &graspopt_bayesopt::Optimizer, trace: &Trace, next: &[Vec<f64>]| {
        let Some(next) = next.first().and_then(|p| p.first()).copied() else {
            return Ok(());
        };
        if trace.scores.len() < 2 {
            return Ok(());
        }
        // One model for the grid and the chosen trial (the last point).
        let at: Vec<Vec<f64>> = grid.iter().chain([&next]).map(|&x| vec![x]).collect();
        let mut model = opt.model_at(&at)?;
        let chosen = model.pop().map_or(0.0, |p| p.ei);
        let snap = Snapshot {
            trials: trace.scores.len(),
            grid: grid.clone(),
            mean: model.iter().map(|p| p.mean).collect(),
            sd: model.iter().map(|p| p.sd).collect(),
            ei: model.iter().map(|p| p.ei).collect(),
            next,
            next_ei: chosen,
        };
        snaps.push(snap);
        Ok(())
    };
    if settings.method == graspopt_bayesopt::Method::Random {
        return Err(ExperimentError::Settings(
            "snapshots show the engine's model: random search has none".into(),
        ));
    }
    let trace = run_observed(ev, settings, seed, &mut take)?;
    Ok((trace, snaps))
}
