//! Grid scans of a built-in object for the studies: the evaluator of a hand on an object over
//! some trial parameters, a scan over the whole trial space, and its best point.

use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{Object, ParamKind, TrialSpace};
use graspopt_trial::Evaluator;
use graspopt_trial::scan::{ScanPoint, grid_axes, scan_grid};

use crate::error::ExperimentError;

/// A grid scan: the axes' values and the points (the last axis fastest).
#[derive(Debug, Clone, PartialEq)]
pub struct Scan {
    pub axes: Vec<Vec<f64>>,
    pub points: Vec<ScanPoint>,
}

impl Scan {
    /// The best-scoring point (the first of equals); None for an empty scan.
    pub fn argmax(&self) -> Option<&ScanPoint> {
        argmax(&self.points)
    }

    /// Points where the grasp is force closure.
    pub fn force_closure(&self) -> usize {
        self.points
            .iter()
            .filter(|p| p.score.metrics.is_some_and(|m| m.force_closure()))
            .count()
    }
}

/// `hand` (a built-in name or a URDF file) on the built-in `object`, over `kinds` (each with
/// its full default bounds), with the default scoring settings.
pub fn evaluator(
    hand: &str,
    object: &str,
    kinds: &[ParamKind],
) -> Result<Evaluator, ExperimentError> {
    let object = Object::by_name(object)?;
    let space = TrialSpace::with_params(&object, kinds)?;
    let hand = hand_by_name(hand).map_err(|source| ExperimentError::Hand {
        name: hand.to_string(),
        source,
    })?;
    Ok(Evaluator::new(object, hand, space))
}

/// A grid scan over the whole trial space of `ev` with `steps[k]` points on axis `k`, on
/// `threads` workers (0: all cores).
pub fn scan(ev: &Evaluator, steps: &[usize], threads: usize) -> Result<Scan, ExperimentError> {
    let axes = grid_axes(&ev.space.bounds(), steps);
    let points = scan_grid(ev, &axes, threads, &|_| {})?;
    Ok(Scan { axes, points })
}

/// The best-scoring point of a scan (the first of equals); None when empty.
pub fn argmax(points: &[ScanPoint]) -> Option<&ScanPoint> {
    let mut best = points.first()?;
    for p in points {
        if p.score.score > best.score.score {
            best = p;
        }
    }
    Some(best)
}

/// Width of the parameter range of a 1D scan on `xs` where `pred` holds (grid spacing
/// counted per point).
pub fn span(xs: &[f64], points: &[ScanPoint], pred: impl Fn(&ScanPoint) -> bool) -> f64 {
    let step = if xs.len() > 1 { xs[1] - xs[0] } else { 0.0 };
    points.iter().filter(|p| pred(p)).count() as f64 * step
}
