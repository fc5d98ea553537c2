//! `graspopt experiment`: regenerate the thesis's chapter-4 figures in the simulator, into a
//! folder of CSV and SVG (and PNG) files with a short markdown report.
//!
//! - [`metrics`]: the metric figures 4.3-4.15;
//! - [`bo`]: the Bayesian-optimisation figures 4.16-4.27 and Table 4.1, and the same in 6D.

mod bo;
mod metrics;

use std::path::Path;

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{Object, ParamKind};
use graspopt_trial::Evaluator;
use graspopt_trial::scan::{ScanPoint, grid_axes, scan_grid};

use super::setup::space_for;

#[derive(Args, Debug)]
pub struct ExperimentArgs {
    #[command(subcommand)]
    pub which: Experiment,
}

#[derive(Subcommand, Debug)]
pub enum Experiment {
    /// The metric figures of thesis chapter 4 (4.3-4.15).
    Metrics(metrics::MetricsArgs),
    /// The Bayesian-optimisation figures of thesis chapter 4 (4.16-4.27, Table 4.1), BO
    /// versus random search over seeds on all seven objects, in 2D and 6D.
    Bo(bo::BoArgs),
}

pub fn run(args: &ExperimentArgs) -> Result<std::process::ExitCode> {
    match &args.which {
        Experiment::Metrics(m) => metrics::metrics(m)?,
        Experiment::Bo(b) => bo::bo(b)?,
    }
    Ok(std::process::ExitCode::SUCCESS)
}

/// `hand` (a built-in name or a URDF file) on a built-in object, over the given parameters.
fn evaluator(hand: &str, object: &str, kinds: &[ParamKind]) -> Result<Evaluator> {
    let object = Object::by_name(object)?;
    let space = space_for(&object, kinds)?;
    let hand = hand_by_name(hand).with_context(|| format!("cannot load the hand {hand:?}"))?;
    Ok(Evaluator::new(object, hand, space))
}

/// A grid scan over the whole trial space with `steps[k]` points on axis `k`.
fn scan(
    ev: &Evaluator,
    steps: &[usize],
    threads: usize,
) -> Result<(Vec<Vec<f64>>, Vec<ScanPoint>)> {
    let axes = grid_axes(&ev.space.bounds(), steps);
    let points = scan_grid(ev, &axes, threads, &|_| {})?;
    Ok((axes, points))
}

/// Writes `text` to `dir/name`; returns `name` for the report.
fn write(dir: &Path, name: &str, text: &str) -> Result<String> {
    let path = dir.join(name);
    std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(name.to_string())
}

/// The scores of a 2D scan as `z[i][j]` (axis 0 index `i`, axis 1 index `j`), NaN where the
/// hand touched nothing (drawn grey), for the heatmaps.
fn touched_grid(axes: &[Vec<f64>], points: &[ScanPoint]) -> Vec<Vec<f64>> {
    let ny = axes.get(1).map_or(1, Vec::len);
    points
        .chunks(ny)
        .map(|column| {
            column
                .iter()
                .map(crate::commands::scan::touched_score)
                .collect()
        })
        .collect()
}

/// The best-scoring point of a (non-empty) scan.
fn argmax(points: &[ScanPoint]) -> &ScanPoint {
    let mut best = &points[0];
    for p in points {
        if p.score.score > best.score.score {
            best = p;
        }
    }
    best
}
