//! Grid scans: the score at every point of a grid over the trial space, computed in
//! parallel on all cores (scoped threads pulling indices from a shared counter), with a
//! progress callback. Points come back in grid order (the last axis fastest).

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use serde::{Deserialize, Serialize};

use crate::error::TrialError;
use crate::evaluator::Evaluator;
use crate::score::TrialScore;

/// One grid point of a scan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScanPoint {
    pub params: Vec<f64>,
    pub score: TrialScore,
}

/// The most points a grid (steps multiplied over the axes) may hold.
pub const MAX_GRID_POINTS: usize = 10_000_000;

/// A grid of trials: the evaluator, the parameters, points per axis and the axes' values.
pub struct Grid {
    pub ev: Evaluator,
    pub kinds: Vec<graspopt_sim::ParamKind>,
    pub steps: Vec<usize>,
    pub axes: Vec<Vec<f64>>,
}

impl Grid {
    /// The grid over the whole of `ev`'s trial space with `steps[k]` points on axis `k`
    /// (`kinds` names the space's parameters, in order).
    pub fn new(ev: Evaluator, kinds: Vec<graspopt_sim::ParamKind>, steps: Vec<usize>) -> Grid {
        let axes = grid_axes(&ev.space.bounds(), &steps);
        Grid {
            ev,
            kinds,
            steps,
            axes,
        }
    }

    /// Points in the grid.
    pub fn points(&self) -> usize {
        self.steps.iter().product()
    }
}

/// Points per axis from the text of `--steps` (comma separated whole numbers >= 1; one value
/// applies to every one of the `axes` axes), checked against [`MAX_GRID_POINTS`].
pub fn grid_steps(text: &str, axes: usize) -> Result<Vec<usize>, TrialError> {
    let steps: Vec<usize> = text
        .split(',')
        .map(|s| {
            s.trim()
                .parse::<usize>()
                .ok()
                .filter(|&n| n >= 1)
                .ok_or_else(|| {
                    TrialError::Settings(format!("--steps: expected whole numbers >= 1, got {s:?}"))
                })
        })
        .collect::<Result<_, _>>()?;
    let steps = match steps.len() {
        1 => vec![steps[0]; axes],
        n if n == axes => steps,
        n => {
            return Err(TrialError::Settings(format!(
                "--steps has {n} values for {axes} axes"
            )));
        }
    };
    let total = grid_points(&steps)?;
    if total > MAX_GRID_POINTS {
        return Err(TrialError::Settings(format!(
            "--steps {}: a grid of {total} points is more than the {MAX_GRID_POINTS} allowed; \
             use fewer steps or axes",
            text.trim()
        )));
    }
    Ok(steps)
}

/// Points of a grid with `steps[k]` points on axis `k`; errors (naming `--steps`) when the
/// The grid point of flat index `index` (the first axis varies slowest), as [`scan_grid`]
/// visits them. `index` must be below the product of the axes' lengths.
pub fn grid_point(axes: &[Vec<f64>], mut index: usize) -> Vec<f64> {
    let mut params = vec![0.0; axes.len()];
    for (k, axis) in axes.iter().enumerate().rev() {
        params[k] = axis[index % axis.len()];
        index /= axis.len();
    }
    params
}

/// product does not fit in a `usize`.
pub fn grid_points(steps: &[usize]) -> Result<usize, TrialError> {
    steps
        .iter()
        .try_fold(1usize, |acc, &n| acc.checked_mul(n))
        .ok_or_else(|| {
            let list: Vec<String> = steps.iter().map(usize::to_string).collect();
            TrialError::Settings(format!(
                "--steps {}: the grid has more points than can be counted (at most {MAX_GRID_POINTS} allowed)",
                list.join(",")
            ))
        })
}

/// Evenly spaced values from `lower` to `upper` inclusive (`n >= 2`; one value, the
/// midpoint, for `n == 1`).
pub fn linspace(lower: f64, upper: f64, n: usize) -> Vec<f64> {
    match n {
        0 => Vec::new(),
        1 => vec![0.5 * (lower + upper)],
        _ => (0..n)
            .map(|i| lower + (upper - lower) * i as f64 / (n - 1) as f64)
            .collect(),
    }
}

/// The axes of a grid over a box: `steps[k]` evenly spaced values (see [`linspace`]) from
/// `bounds[k].0` to `bounds[k].1`.
pub fn grid_axes(bounds: &[(f64, f64)], steps: &[usize]) -> Vec<Vec<f64>> {
    bounds
        .iter()
        .zip(steps)
        .map(|(&(lower, upper), &n)| linspace(lower, upper, n))
        .collect()
}

/// The workers a scan of `points` points uses when `requested` are asked for (0: one per
/// core), never more than there are points, at least one.
pub fn worker_count(requested: usize, points: usize) -> usize {
    let n = if requested == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        requested
    };
    n.min(points).max(1)
}

/// Scores the grid `axes[0] x axes[1] x ...` with `threads` workers (0: all cores),
/// calling `progress(done)` after each point. The first failing point stops the scan and
/// its error is returned with its parameters.
pub fn scan_grid(
    evaluator: &Evaluator,
    axes: &[Vec<f64>],
    threads: usize,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<Vec<ScanPoint>, TrialError> {
    if axes.is_empty() || axes.iter().any(Vec::is_empty) {
        return Err(TrialError::Settings(
            "a scan needs at least one value per axis".into(),
        ));
    }
    if axes.len() != evaluator.space.dim() {
        return Err(TrialError::Settings(format!(
            "the scan has {} axes but the trial space has {} parameters",
            axes.len(),
            evaluator.space.dim()
        )));
    }
    let total: usize = axes.iter().map(Vec::len).product();
    let point = |index: usize| grid_point(axes, index);
    let threads = worker_count(threads, total);
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let failed: Mutex<Option<TrialError>> = Mutex::new(None);
    let results: Mutex<Vec<Option<ScanPoint>>> = Mutex::new(vec![None; total]);
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= total || failed.lock().map_or(true, |f| f.is_some()) {
                        break;
                    }
                    let params = point(i);
                    match evaluator.evaluate(&params) {
                        Ok(e) => {
                            if let Ok(mut r) = results.lock() {
                                r[i] = Some(ScanPoint {
                                    params,
                                    score: e.score,
                                });
                            }
                            progress(done.fetch_add(1, Ordering::Relaxed) + 1);
                        }
                        Err(err) => {
                            if let Ok(mut f) = failed.lock() {
                                f.get_or_insert(TrialError::Settings(format!(
                                    "trial at {params:?} failed: {err}"
                                )));
                            }
                            break;
                        }
                    }
                }
            });
        }
    });
    if let Some(err) = failed.into_inner().ok().flatten() {
        return Err(err);
    }
    let results = results
        .into_inner()
        .map_err(|_| TrialError::Settings("a scan worker panicked".into()))?;
    results
        .into_iter()
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| TrialError::Settings("a scan point was not computed".into()))
}
