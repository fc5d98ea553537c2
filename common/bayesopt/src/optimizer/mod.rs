//! The ask/tell Bayesian optimisation engine (thesis section 3.4, plus batch proposals).
//!
//! Convention: the optimizer **maximises** (grasp quality) unless [`Settings::minimize`] is set,
//! in which case observations are negated internally and [`Optimizer::best`] reports the
//! minimum. Inputs are scaled to the unit cube and outputs standardised at every iteration;
//! hyperparameters are refitted (MAP, warm-started) on every proposal round, with random
//! restarts every [`Settings::full_refit_every`] rounds. The acquisition (log-EI by default) is
//! maximised by DIRECT on the unit cube and polished by L-BFGS from the best few rectangles.
//! Batches (`q > 1`, or points still pending from earlier calls) use the kriging believer, a
//! constant liar or sequential-greedy qEI ([`crate::qei`]). The whole state serialises with
//! serde, including the generator state, so a restored optimizer proposes exactly what the
//! original would have (serde_json needs its `float_roundtrip` feature for bit-exact floats).
//!
//! **Large-n mode** ([`Settings::model_cap`], on in [`Settings::for_grasps`] at
//! [`GRASP_MODEL_CAP`] observations). The exact GP costs O(n^3) per fit evaluation and
//! O(n^2) per prediction: a round of 32 proposals at 2,000 observations would take tens of
//! seconds. Past the cap, a round models a subset of the epoch's observations: the
//! incumbent's nearest neighbours (the local model a trust region would give), the best of
//! the others by value (other basins), and a greedy farthest-point spread of the rest (so EI
//! far from the incumbent still sees where the search has been). The hyperparameters are
//! then only warm-started from the last fit (no restarts). A point proposed while others
//! are pending or already proposed in the round (the kriging believer's batch path, one
//! rank-one extension of the Cholesky factor per point) gets a smaller DIRECT budget
//! ([`ModelCap::batch_evals_per_dim`]) and one polish start. Measured (docs/benchmarks.md,
//! "Planner at thousands of observations"): with the cap the planner's round of 32 at
//! 2,000 observations fits in the 250 ms of issue 19 on one core in 2D and 6D, and with the
//! cap forced down to 30 observations the simulator objects are reached in as few trials
//! as with the exact model; what was tried and dropped is listed there.

use std::collections::HashMap;

use serde::{Deserialize, Serialize};

use crate::acquisition::{
    self, AcquisitionKind, LOG_EI_FLOOR, XiRule, expected_improvement, log_expected_improvement,
};
use crate::baseline::AskTell;
use crate::direct::{self, DirectSettings, same_point};
use crate::error::{BoError, Result};
use crate::fit::{FitSettings, Hyperparameters, fit_map};
use crate::gp::Gp;
use crate::kernel::KernelKind;
use crate::qei::QeiContext;
use crate::rng::Rng;

mod propose;
mod settings;
#[cfg(test)]
mod tests;
mod warp;

use warp::{RankWarp, TailWarp, Warp};

/// L-BFGS iterations of the polish of a qEI batch point (finite-difference gradients, so each
/// costs 2 d + 1 evaluations of the gain). Measured on Hartmann6 seeds 0-49 at q = 4: without
/// the polish 27 of 50 seeds reach 0.1% regret (DIRECT alone does not resolve the last digits),
/// with 10 iterations 36, with 30 no more (35) for twice the extra time.
const QEI_POLISH_ITERS: usize = 10;

/// Most base samples a [`BatchStrategy::Qei`] may ask for (the cost of a point grows with them).
pub const MAX_QEI_SAMPLES: usize = 65_536;

pub use settings::{
    BatchStrategy, GRASP_MODEL_CAP, InitialDesign, MIN_MODEL_CAP, ModelCap, RestartRule, Settings,
    StopReason, StopRule,
};

/// The model at one point: see [`Optimizer::model_at`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModelPoint {
    /// Posterior mean of the objective (raw units, the user's sign convention).
    pub mean: f64,
    /// Posterior standard deviation (raw units; linearised through the output transform).
    pub sd: f64,
    /// Expected improvement (the model's standardised units).
    pub ei: f64,
}

/// Diagnostics of the last proposal round.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct RoundInfo {
    /// EI (standardised units) at the first model-based proposal of the round. With
    /// [`BatchStrategy::Qei`] and points pending, that proposal is a qEI point and this is its
    /// qEI gain: the improvement it adds beyond the pending points, at most its EI. The
    /// small-EI stop rule then reads "nothing left to gain beyond the trials in flight".
    pub best_ei: Option<f64>,
    /// The same divided by the range of the modelled outputs (the observed range of y of
    /// the current epoch, after the output transform if any).
    pub relative_ei: Option<f64>,
    /// xi used (standardised units).
    pub xi: Option<f64>,
    /// Number of random (initial-design) points in the round.
    pub random_points: usize,
    /// Number of exploration steps (see [`Settings::explore_below_ei`]) in the round.
    pub exploration_points: usize,
}

/// The ask/tell optimizer. See the module documentation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Optimizer {
    lower: Vec<f64>,
    upper: Vec<f64>,
    settings: Settings,
    seed: u64,
    rng: Rng,
    xs: Vec<Vec<f64>>,
    ys: Vec<f64>,
    pending: Vec<Vec<f64>>,
    hyper: Option<Hyperparameters>,
    rounds: usize,
    low_ei_streak: usize,
    last_round: RoundInfo,
    /// First observation of the current epoch (see [`RestartRule`]).
    #[serde(default)]
    epoch_start: usize,
    /// Incumbents (unit cube) of earlier epochs.
    #[serde(default)]
    tabu: Vec<Vec<f64>>,
    /// The first epoch's initial design (unit cube), drawn whole when first needed.
    #[serde(default)]
    design: Vec<Vec<f64>>,
    /// Index in `design` of the next point to consider.
    #[serde(default)]
    design_next: usize,
}

#[derive(Clone)]
struct Standardised {
    x: Vec<Vec<f64>>,
    y: Vec<f64>,
    mean: f64,
    std: f64,
    warp: Option<Warp>,
}

/// The Latin hypercube of `n` points in `[0, 1]^d` with the largest smallest pairwise distance
/// among `candidates` random ones (each point uniform inside its cell).
fn maximin_latin_hypercube(rng: &mut Rng, n: usize, d: usize, candidates: usize) -> Vec<Vec<f64>> {
    let mut best: Vec<Vec<f64>> = Vec::new();
    let mut best_gap = f64::NEG_INFINITY;
    for _ in 0..candidates.max(1) {
        let mut pts = vec![vec![0.0; d]; n];
        for j in 0..d {
            let mut cells: Vec<usize> = (0..n).collect();
            for i in (1..n).rev() {
                let k = (rng.uniform() * (i + 1) as f64) as usize;
                cells.swap(i, k.min(i));
            }
            for (p, c) in pts.iter_mut().zip(&cells) {
                p[j] = (*c as f64 + rng.uniform()) / n as f64;
            }
        }
        let mut gap = f64::INFINITY;
        for a in 0..n {
            for b in a + 1..n {
                let d2: f64 = pts[a]
                    .iter()
                    .zip(&pts[b])
                    .map(|(x, y)| (x - y) * (x - y))
                    .sum();
                gap = gap.min(d2);
            }
        }
        if gap > best_gap {
            best_gap = gap;
            best = pts;
        }
    }
    best
}

/// Monotone output transform applied (to the maximisation-direction values) before
/// standardising.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum OutputTransform {
    /// Values as observed.
    #[default]
    None,
    /// Compress the bad tail logarithmically: values below the median `m` map to
    /// `m - s ln(1 + (m - z) / s)` (`s` = best minus median), the good half stays linear, so a
    /// few huge bad values do not flatten the model where the optimum is.
    TailLog,
    /// Replace values by their rank scores `(rank + 1/2) / n` (ties averaged): a copula-style
    /// transform that makes mediocre differences visible next to a deep basin.
    Rank,
}

impl Optimizer {
    /// New optimizer on the box given by `bounds` (one `(lower, upper)` per dimension).
    pub fn new(bounds: &[(f64, f64)], settings: Settings, seed: u64) -> Result<Self> {
        let lower: Vec<f64> = bounds.iter().map(|b| b.0).collect();
        let upper: Vec<f64> = bounds.iter().map(|b| b.1).collect();
        direct::check_bounds(&lower, &upper)?;
        settings.validate()?;
        Ok(Optimizer {
            lower,
            upper,
            settings,
            seed,
            rng: Rng::new(seed),
            xs: Vec::new(),
            ys: Vec::new(),
            pending: Vec::new(),
            hyper: None,
            rounds: 0,
            low_ei_streak: 0,
            last_round: RoundInfo::default(),
            epoch_start: 0,
            tabu: Vec::new(),
            design: Vec::new(),
            design_next: 0,
        })
    }

    /// Input dimension.
    pub fn dim(&self) -> usize {
        self.lower.len()
    }

    /// The box: one `(lower, upper)` per dimension.
    pub fn bounds(&self) -> Vec<(f64, f64)> {
        self.lower
            .iter()
            .copied()
            .zip(self.upper.iter().copied())
            .collect()
    }

    /// Checks the data of a state that did not come from [`Optimizer::new`] and its methods
    /// (a deserialised one, which serde checks for shape only) against its bounds and
    /// settings: valid bounds and settings ranges, every point of the bounds' dimension and
    /// finite, design and earlier incumbents in the unit cube, a design of the configured
    /// size, one finite value per observation, positive finite hyperparameters, positions
    /// within their lists. The settings' sizes (design size, DIRECT budget, restart window)
    /// are not judged: a caller that takes a state from outside compares its settings with
    /// its own.
    pub fn check_state(&self) -> Result<()> {
        direct::check_bounds(&self.lower, &self.upper)?;
        self.settings.validate()?;
        let d = self.dim();
        let points = |what: &'static str, list: &[Vec<f64>]| -> Result<()> {
            for p in list {
                if p.len() != d {
                    return Err(BoError::DimensionMismatch {
                        expected: d,
                        got: p.len(),
                    });
                }
                if p.iter().any(|v| !v.is_finite()) {
                    return Err(BoError::NonFinite { what });
                }
            }
            Ok(())
        };
        points("observations", &self.xs)?;
        points("pending points", &self.pending)?;
        points("initial design", &self.design)?;
        points("earlier incumbents", &self.tabu)?;
        if self.ys.len() != self.xs.len() {
            return Err(BoError::InvalidSetting(format!(
                "{} observed values for {} observed points",
                self.ys.len(),
                self.xs.len()
            )));
        }
        if self.ys.iter().any(|y| !y.is_finite()) {
            return Err(BoError::NonFinite {
                what: "observed values",
            });
        }
        if let Some(h) = &self.hyper {
            let positive = |v: f64| v.is_finite() && v > 0.0;
            if h.length_scales.len() != d
                || !h.length_scales.iter().all(|&l| positive(l))
                || !positive(h.signal_variance)
                || !positive(h.noise)
            {
                return Err(BoError::InvalidSetting(
                    "hyperparameters must be d positive length scales, a positive signal \
                     variance and a positive noise"
                        .into(),
                ));
            }
        }
        let unit = |list: &[Vec<f64>]| list.iter().flatten().all(|v| (0.0..=1.0).contains(v));
        if !unit(&self.design) || !unit(&self.tabu) {
            return Err(BoError::InvalidSetting(
                "initial design or earlier incumbents outside the unit cube".into(),
            ));
        }
        if !self.design.is_empty() && self.design.len() != self.n_init().max(2) {
            return Err(BoError::InvalidSetting(format!(
                "an initial design of {} points, not {}",
                self.design.len(),
                self.n_init().max(2)
            )));
        }
        if self.epoch_start > self.xs.len() || self.design_next > self.design.len() {
            return Err(BoError::InvalidSetting(
                "epoch start or design position beyond its list".into(),
            ));
        }
        Ok(())
    }

    /// The settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The seed given at construction.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Observations `(x, y)` so far, in the order told.
    pub fn observations(&self) -> impl Iterator<Item = (&[f64], f64)> {
        self.xs
            .iter()
            .map(|x| x.as_slice())
            .zip(self.ys.iter().copied())
    }

    /// Number of observations.
    pub fn len(&self) -> usize {
        self.xs.len()
    }

    /// True before the first observation.
    pub fn is_empty(&self) -> bool {
        self.xs.is_empty()
    }

    /// Points suggested and not yet observed.
    pub fn pending(&self) -> &[Vec<f64>] {
        &self.pending
    }

    /// Forget all pending points (e.g. trials that were abandoned).
    pub fn clear_pending(&mut self) {
        self.pending.clear();
    }

    /// Replace the pending points by `pending` (the trials a coordinator has issued and not
    /// yet observed, e.g. after a restart). Nothing changes on an invalid point.
    pub fn set_pending(&mut self, pending: Vec<Vec<f64>>) -> Result<()> {
        for p in &pending {
            self.check_point(p)?;
        }
        self.pending = pending;
        Ok(())
    }

    /// Hyperparameters of the last fit (unit-cube inputs, standardised outputs).
    pub fn hyperparameters(&self) -> Option<&Hyperparameters> {
        self.hyper.as_ref()
    }

    /// Number of restarts so far (see [`RestartRule`]); the model uses the observations
    /// from index [`Optimizer::epoch_start`] on.
    pub fn restarts(&self) -> usize {
        self.tabu.len()
    }

    /// First observation of the current epoch (0 before any restart).
    pub fn epoch_start(&self) -> usize {
        self.epoch_start
    }

    /// Diagnostics of the last proposal round.
    pub fn last_round(&self) -> &RoundInfo {
        &self.last_round
    }

    /// Best observation (maximum, or minimum with `minimize`).
    pub fn best(&self) -> Option<(Vec<f64>, f64)> {
        let mut best: Option<usize> = None;
        for (i, y) in self.ys.iter().enumerate() {
            let better = match best {
                None => true,
                Some(b) => {
                    if self.settings.minimize {
                        *y < self.ys[b]
                    } else {
                        *y > self.ys[b]
                    }
                }
            };
            if better {
                best = Some(i);
            }
        }
        best.map(|i| (self.xs[i].clone(), self.ys[i]))
    }

    /// Whether the current epoch stagnates under `rule` (after its initial design): no
    /// significant improvement over the window and, with [`RestartRule::max_relative_ei`], a
    /// last round whose relative EI is below it.
    fn epoch_stagnates(&self, rule: &RestartRule) -> bool {
        let from = self.epoch_start.min(self.ys.len());
        let ys = &self.ys[from..];
        let init = if from > 0 {
            rule.init.max(2)
        } else {
            self.n_init()
        };
        let w = rule.window.max(1);
        if ys.len() < init + w {
            return false;
        }
        let sign = if self.settings.minimize { -1.0 } else { 1.0 };
        let best_of = |v: &[f64]| v.iter().map(|y| sign * y).fold(f64::NEG_INFINITY, f64::max);
        let now = best_of(ys);
        let before = best_of(&ys[..ys.len() - w]);
        let lo = ys.iter().map(|y| sign * y).fold(f64::INFINITY, f64::min);
        let model_expects_more = match (rule.max_relative_ei, self.last_round.relative_ei) {
            (Some(th), Some(r)) => r.is_finite() && r >= th,
            _ => false,
        };
        now - before <= rule.tol * (now - lo) && !model_expects_more
    }

    fn n_init(&self) -> usize {
        self.settings
            .n_init
            .unwrap_or_else(|| Settings::default_n_init(self.dim()))
    }

    fn to_unit(&self, x: &[f64]) -> Vec<f64> {
        x.iter()
            .zip(self.lower.iter().zip(&self.upper))
            .map(|(v, (l, u))| ((v - l) / (u - l)).clamp(0.0, 1.0))
            .collect()
    }

    fn unit_to_box(&self, u: &[f64]) -> Vec<f64> {
        u.iter()
            .zip(self.lower.iter().zip(&self.upper))
            .map(|(v, (l, h))| (l + v * (h - l)).clamp(*l, *h))
            .collect()
    }

    fn check_point(&self, x: &[f64]) -> Result<()> {
        if x.len() != self.dim() {
            return Err(BoError::DimensionMismatch {
                expected: self.dim(),
                got: x.len(),
            });
        }
        for (i, v) in x.iter().enumerate() {
            if !v.is_finite() {
                return Err(BoError::NonFinite { what: "point" });
            }
            let (l, u) = (self.lower[i], self.upper[i]);
            let tol = 1e-9 * (u - l);
            if *v < l - tol || *v > u + tol {
                return Err(BoError::OutOfBounds {
                    dim: i,
                    value: *v,
                    lower: l,
                    upper: u,
                });
            }
        }
        Ok(())
    }

    /// Tell the result `y` of evaluating `x`. Removes `x` from the pending points if it is
    /// one of them. Errors on a dimension mismatch, a point outside the bounds or a
    /// non-finite value (nothing is recorded then).
    pub fn observe(&mut self, x: &[f64], y: f64) -> Result<()> {
        self.check_point(x)?;
        if !y.is_finite() {
            return Err(BoError::NonFinite {
                what: "observation",
            });
        }
        if let Some(i) = self.pending.iter().position(|p| {
            p.iter()
                .zip(x)
                .all(|(a, b)| (a - b).abs() <= 1e-12 * (1.0 + a.abs()))
        }) {
            self.pending.remove(i);
        }
        self.xs.push(x.to_vec());
        self.ys.push(y);
        Ok(())
    }

    /// Why to stop now, if so.
    pub fn stop_reason(&self) -> Option<StopReason> {
        if let Some(b) = self.settings.stop.budget
            && self.xs.len() >= b
        {
            return Some(StopReason::Budget);
        }
        let min_evals = self.settings.stop.min_evals.unwrap_or(10 * self.dim());
        if self.xs.len() >= min_evals && self.low_ei_streak >= self.settings.stop.patience.max(1) {
            return Some(StopReason::SmallExpectedImprovement);
        }
        None
    }

    fn standardised(&self) -> Standardised {
        let sign = if self.settings.minimize { -1.0 } else { 1.0 };
        let from = self.epoch_start.min(self.ys.len());
        let mut y: Vec<f64> = self.ys[from..].iter().map(|v| sign * v).collect();
        let warp = match self.settings.output_transform {
            OutputTransform::None => None,
            OutputTransform::TailLog => TailWarp::fit(&y).map(Warp::Tail),
            OutputTransform::Rank => RankWarp::fit(&y).map(Warp::Rank),
        };
        if let Some(w) = &warp {
            y.iter_mut().for_each(|v| *v = w.forward(*v));
        }
        let n = y.len().max(1) as f64;
        let avg = y.iter().sum::<f64>() / n;
        let var = y.iter().map(|v| (v - avg) * (v - avg)).sum::<f64>() / n;
        let mean = match self.settings.prior_mean_quantile {
            Some(qt) if !y.is_empty() => {
                let mut sorted = y.clone();
                sorted.sort_by(|a, b| a.total_cmp(b));
                let k = ((qt.clamp(0.0, 1.0) * (sorted.len() - 1) as f64).round()) as usize;
                sorted[k.min(sorted.len() - 1)]
            }
            _ => avg,
        };
        let std = if var.sqrt() > 1e-12 * mean.abs().max(1e-300) && var > 0.0 {
            var.sqrt()
        } else {
            1.0
        };
        Standardised {
            x: self.xs[from..].iter().map(|p| self.to_unit(p)).collect(),
            y: y.iter().map(|v| (v - mean) / std).collect(),
            mean,
            std,
            warp,
        }
    }

    /// The observations the model of a round conditions on: `data` itself, or with a
    /// [`Settings::model_cap`] that `data` exceeds, the subset that [`ModelCap`] describes
    /// (in the order observed). Deterministic: it draws nothing.
    fn model_data<'a>(&self, data: &'a Standardised) -> std::borrow::Cow<'a, Standardised> {
        use std::borrow::Cow;
        let n = data.y.len();
        let Some(cap) = self.settings.model_cap.filter(|c| n > c.size) else {
            return Cow::Borrowed(data);
        };
        let d = self.dim();
        let inv_ls: Vec<f64> = match &self.hyper {
            Some(h) if h.length_scales.len() == d => {
                h.length_scales.iter().map(|l| 1.0 / l).collect()
            }
            _ => vec![1.0; d],
        };
        let dist2 = |a: &[f64], b: &[f64]| -> f64 {
            a.iter()
                .zip(b)
                .zip(&inv_ls)
                .map(|((p, q), w)| (p - q) * (p - q) * w * w)
                .sum()
        };
        let Some(top) = (0..n).max_by(|&a, &b| data.y[a].total_cmp(&data.y[b]).then(b.cmp(&a)))
        else {
            return Cow::Borrowed(data);
        };
        let share = |f: f64| (cap.size as f64 * f).round() as usize;
        let n_near = share(cap.near).clamp(1, cap.size);
        let n_best = share(cap.best).min(cap.size - n_near);
        let mut chosen = vec![false; n];
        let mut near: Vec<(f64, usize)> = (0..n)
            .map(|i| (dist2(&data.x[i], &data.x[top]), i))
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for &(_, i) in near.iter().take(n_near) {
            chosen[i] = true;
        }
        let mut rest: Vec<usize> = (0..n).filter(|&i| !chosen[i]).collect();
        rest.sort_by(|&a, &b| data.y[b].total_cmp(&data.y[a]).then(a.cmp(&b)));
        for &i in rest.iter().take(n_best) {
            chosen[i] = true;
        }
        // Greedy farthest point: each next point is the one farthest from all chosen.
        let picked: Vec<usize> = (0..n).filter(|&i| chosen[i]).collect();
        let mut gap: Vec<f64> = (0..n)
            .map(|i| {
                if chosen[i] {
                    f64::NEG_INFINITY
                } else {
                    picked
                        .iter()
                        .map(|&j| dist2(&data.x[i], &data.x[j]))
                        .fold(f64::INFINITY, f64::min)
                }
            })
            .collect();
        for _ in n_near + n_best..cap.size {
            let Some(far) = (0..n)
                .filter(|&i| !chosen[i])
                .max_by(|&a, &b| gap[a].total_cmp(&gap[b]).then(b.cmp(&a)))
            else {
                break;
            };
            chosen[far] = true;
            gap[far] = f64::NEG_INFINITY;
            for i in 0..n {
                if !chosen[i] {
                    gap[i] = gap[i].min(dist2(&data.x[i], &data.x[far]));
                }
            }
        }
        let keep: Vec<usize> = (0..n).filter(|&i| chosen[i]).collect();
        Cow::Owned(Standardised {
            x: keep.iter().map(|&i| data.x[i].clone()).collect(),
            y: keep.iter().map(|&i| data.y[i]).collect(),
            mean: data.mean,
            std: data.std,
            warp: data.warp.clone(),
        })
    }

    /// Refit the hyperparameters (MAP, warm-started) and build the GP on the observations
    /// (on [`Optimizer::model_data`]'s subset when capped: then warm-started only, once a
    /// fit exists).
    fn fit_model(&mut self, data: &Standardised, full: bool) -> Result<Gp> {
        let capped = self
            .settings
            .model_cap
            .is_some_and(|c| data.y.len() > c.size);
        let model = self.model_data(data);
        let data: &Standardised = &model;
        let restarts = if (full && !capped) || self.hyper.is_none() {
            self.settings.fit.restarts
        } else {
            0
        };
        let (h, _) = fit_map(
            self.settings.kernel,
            &self.settings.fit,
            &data.x,
            &data.y,
            self.hyper.as_ref(),
            restarts,
            &mut self.rng,
        )?;
        let gp = Gp::new(
            data.x.clone(),
            data.y.clone(),
            h.kernel(self.settings.kernel),
            h.noise,
        )?;
        self.hyper = Some(h);
        Ok(gp)
    }

    /// The current model at each of `points`: posterior mean and standard deviation of the
    /// objective (raw units, the user's sign convention) and the expected improvement.
    /// The model is the current epoch's observations, standardised (and transformed), with
    /// the last fit's hyperparameters (the prior's before the first fit); EI uses `xi` from
    /// the settings against the best observation, in the model's standardised units, and
    /// ignores pending points. Called right after a one-point [`Optimizer::suggest`] (before
    /// its point is observed), the EI is the acquisition that round maximised, without
    /// restart penalties or diversification. One model for all points. Needs at least one
    /// observation.
    pub fn model_at(&self, points: &[Vec<f64>]) -> Result<Vec<ModelPoint>> {
        for x in points {
            self.check_point(x)?;
        }
        if self.xs.is_empty() {
            return Err(BoError::NotEnoughData("no observation yet".into()));
        }
        let full = self.standardised();
        let mut data = self.model_data(&full).into_owned();
        let h = self.hyper.clone().unwrap_or_else(|| {
            Hyperparameters::from_theta(&self.settings.fit.prior_mean(self.dim()))
        });
        let x = std::mem::take(&mut data.x);
        let gp = Gp::new(x, data.y.clone(), h.kernel(self.settings.kernel), h.noise)?;
        let best = data.y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let xi = self.settings.xi.xi(gp.kernel().signal_variance);
        let sign = if self.settings.minimize { -1.0 } else { 1.0 };
        Ok(points
            .iter()
            .map(|x| {
                let (m, v) = gp.predict(&self.to_unit(x));
                let w = data.mean + data.std * m;
                let sd = data.std * v.sqrt();
                let (mean, sd) = match &data.warp {
                    Some(t) => (sign * t.inverse(w), sd / t.slope_at_image(w)),
                    None => (sign * w, sd),
                };
                ModelPoint {
                    mean,
                    sd,
                    ei: crate::acquisition::expected_improvement(m, v, best, xi),
                }
            })
            .collect())
    }

    /// The model at one point ([`Optimizer::model_at`]).
    fn model_at_point(&self, x: &[f64]) -> Result<ModelPoint> {
        let mut one = self.model_at(&[x.to_vec()])?;
        one.pop()
            .ok_or_else(|| BoError::NotEnoughData("no model point".into()))
    }

    /// Posterior mean and standard deviation of the objective at `x` (raw units, the user's
    /// sign convention), with the hyperparameters of the last fit (prior ones before the
    /// first). Needs at least one observation.
    pub fn predict(&self, x: &[f64]) -> Result<(f64, f64)> {
        let p = self.model_at_point(x)?;
        Ok((p.mean, p.sd))
    }

    /// Expected improvement at `x` under the current model (see [`Optimizer::model_at`]).
    pub fn expected_improvement(&self, x: &[f64]) -> Result<f64> {
        Ok(self.model_at_point(x)?.ei)
    }
}

impl AskTell for Optimizer {
    fn suggest(&mut self, q: usize) -> Result<Vec<Vec<f64>>> {
        Optimizer::suggest(self, q)
    }
    fn observe(&mut self, x: &[f64], y: f64) -> Result<()> {
        Optimizer::observe(self, x, y)
    }
    fn best(&self) -> Option<(Vec<f64>, f64)> {
        Optimizer::best(self)
    }
}
