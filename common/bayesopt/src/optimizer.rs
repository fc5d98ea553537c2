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

/// L-BFGS iterations of the polish of a qEI batch point (finite-difference gradients, so each
/// costs 2 d + 1 evaluations of the gain). Measured on Hartmann6 seeds 0-49 at q = 4: without
/// the polish 27 of 50 seeds reach 0.1% regret (DIRECT alone does not resolve the last digits),
/// with 10 iterations 36, with 30 no more (35) for twice the extra time.
const QEI_POLISH_ITERS: usize = 10;

/// Most base samples a [`BatchStrategy::Qei`] may ask for (the cost of a point grows with them).
pub const MAX_QEI_SAMPLES: usize = 65_536;

/// Value assumed for pending points when proposing a batch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum BatchStrategy {
    /// Kriging believer: the posterior mean at the pending point.
    #[default]
    KrigingBeliever,
    /// Constant liar with the worst observed value (pessimistic, spreads points most).
    ConstantLiarMin,
    /// Constant liar with the mean of the observations.
    ConstantLiarMean,
    /// Constant liar with the best observed value (optimistic).
    ConstantLiarMax,
    /// Sequential-greedy q-Expected-Improvement (see [`crate::qei`]): each point of a round
    /// after the first (every point when others are pending) maximises the joint qEI of the
    /// pending points, the round's earlier points and itself under the GP's joint posterior,
    /// estimated with `samples` fixed base samples of the others and the candidate's own
    /// value integrated exactly, maximised by DIRECT and a short finite-difference polish. No
    /// fantasy values; rounds of more than one point (or with points pending) are not
    /// diversified (see [`Settings::diversify_every`]): measured on Hartmann6, qEI with the
    /// diversification rounds was no better than the kriging believer. The qEI points are
    /// chosen by (q)EI whatever [`Settings::acquisition`] says (it picks the round's first
    /// point), and [`Settings::explore_below_ei`] does not apply to them.
    Qei {
        /// Base samples per maximisation (1 to [`MAX_QEI_SAMPLES`]).
        samples: usize,
    },
}

/// How the points of the initial design are placed (the first epoch's; a restarted epoch's
/// points are always uniform).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum InitialDesign {
    /// Independent uniform points (the thesis's random initial design).
    #[default]
    Random,
    /// A Latin hypercube (one point in each of `n` equal slices of every axis), the one with
    /// the largest smallest pairwise distance among `candidates` random ones, so a small design
    /// leaves no large region unsampled.
    MaximinLatinHypercube {
        /// Random Latin hypercubes compared (>= 1).
        candidates: usize,
    },
}

/// When to stop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StopRule {
    /// Stop once this many observations are in (None: no budget).
    pub budget: Option<usize>,
    /// Stop on small EI only after this many observations (None: 10 x d).
    pub min_evals: Option<usize>,
    /// Threshold on the best EI divided by the observed range of y (of the current epoch,
    /// after the output transform if any; see [`RoundInfo::relative_ei`]).
    pub relative_ei_threshold: f64,
    /// Number of consecutive proposal rounds below the threshold needed to stop.
    pub patience: usize,
}

impl Default for StopRule {
    fn default() -> Self {
        StopRule {
            budget: None,
            min_evals: None,
            relative_ei_threshold: 1e-6,
            patience: 3,
        }
    }
}

/// Restart of a stagnating search (trust-region-style): once the best value of the current
/// epoch has not improved by more than `tol` times the epoch's observed range over its last
/// `window` observations, a new epoch starts with `init` random points and a model of the new
/// epoch's observations only, and the acquisition is penalised inside a ball of radius
/// `tabu_radius * sqrt(d)` (unit cube) around the incumbent of every earlier epoch, so the
/// search looks for another basin instead of polishing the old one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RestartRule {
    /// Observations without significant improvement before restarting (>= 1).
    pub window: usize,
    /// Significant improvement, as a fraction of the epoch's observed range of y.
    pub tol: f64,
    /// Random points at the start of each new epoch (>= 2).
    pub init: usize,
    /// Radius of the balls around earlier incumbents, as a fraction of `sqrt(d)`.
    pub tabu_radius: f64,
}

/// Why the optimizer says to stop.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum StopReason {
    /// The evaluation budget is used up.
    Budget,
    /// The best EI stayed below the threshold for `patience` rounds after `min_evals`.
    SmallExpectedImprovement,
}

/// Engine settings. Defaults follow the thesis (Matern 3/2, EI with xi = sigma_f^2/100,
/// DIRECT) plus the robustness measures listed in the module doc.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// Minimise instead of maximise.
    pub minimize: bool,
    /// Kernel family.
    pub kernel: KernelKind,
    /// Size of the initial design (None: `max(5, ceil(5 d / 3))`, i.e. 5 in 2D, 10 in 6D).
    pub n_init: Option<usize>,
    /// Placement of the initial design.
    #[serde(default)]
    pub initial_design: InitialDesign,
    /// Acquisition function.
    pub acquisition: AcquisitionKind,
    /// EI exploration margin rule (thesis default `sigma_f^2 / 100`).
    pub xi: XiRule,
    /// Hyperparameter priors, bounds and effort.
    pub fit: FitSettings,
    /// Random restarts of the fit every this many proposal rounds (1 = always; others are
    /// warm-started only).
    pub full_refit_every: usize,
    /// DIRECT budget per input dimension for the acquisition maximisation.
    pub direct_evals_per_dim: usize,
    /// Local polish starts (best DIRECT centres); 0 disables the polish.
    pub polish_starts: usize,
    /// L-BFGS iterations per polish start.
    pub polish_iters: usize,
    /// Batch strategy for pending points.
    pub batch: BatchStrategy,
    /// When the best EI (standardised units) falls below this, propose instead the most
    /// uncertain of 100 d random candidates (a space-filling exploration step that helps leave
    /// a local optimum in higher dimensions). None disables it.
    pub explore_below_ei: Option<f64>,
    /// GP prior mean at this quantile of the (transformed) observations instead of their
    /// mean (None: the mean). Low quantiles are pessimistic away from data.
    pub prior_mean_quantile: Option<f64>,
    /// Every this many proposal rounds (0 = never), the first point of the round is the
    /// second point of a pessimistic constant-liar batch: the EI maximiser is assumed to be as
    /// bad as the worst observation and the next EI maximiser is proposed instead, which
    /// moves the search away from an exhausted local optimum. With [`BatchStrategy::Qei`],
    /// only rounds of one point with nothing pending are diversified.
    pub diversify_every: usize,
    /// How many pessimistic fantasies a diversification round stacks (>= 1).
    pub diversify_depth: usize,
    /// Monotone transform of the outputs applied before standardising.
    pub output_transform: OutputTransform,
    /// Restart of a stagnating search (None: off). See [`RestartRule`].
    #[serde(default)]
    pub restart: Option<RestartRule>,
    /// Stopping rule.
    pub stop: StopRule,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            minimize: false,
            kernel: KernelKind::Matern32,
            n_init: None,
            initial_design: InitialDesign::Random,
            acquisition: AcquisitionKind::ExpectedImprovement,
            xi: XiRule::ThesisSignalVariance,
            fit: FitSettings::default(),
            full_refit_every: 10,
            direct_evals_per_dim: 150,
            polish_starts: 3,
            polish_iters: 30,
            batch: BatchStrategy::KrigingBeliever,
            output_transform: OutputTransform::None,
            prior_mean_quantile: None,
            diversify_every: 0,
            diversify_depth: 1,
            explore_below_ei: None,
            restart: None,
            stop: StopRule::default(),
        }
    }
}

impl Settings {
    /// Settings for grasp scores: the thesis's (the defaults) with the bad tail of the
    /// outputs compressed ([`OutputTransform::TailLog`]) and a space-filling initial design
    /// ([`InitialDesign::MaximinLatinHypercube`] of 50 candidates). A trial that misses the
    /// object scores far below every grasp; without the compression those few values set the
    /// model's scale. The best of the settings measured on the simulator's seven objects
    /// (`graspopt experiment bo`, docs/benchmarks.md); maximising.
    pub fn for_grasps() -> Self {
        Settings {
            output_transform: OutputTransform::TailLog,
            initial_design: InitialDesign::MaximinLatinHypercube { candidates: 50 },
            ..Settings::default()
        }
    }

    /// Default initial-design size for dimension `d`.
    pub fn default_n_init(d: usize) -> usize {
        (5 * d).div_ceil(3).max(5)
    }

    fn validate(&self) -> Result<()> {
        self.fit.validate()?;
        if self.direct_evals_per_dim == 0 || self.full_refit_every == 0 {
            return Err(BoError::InvalidSetting(
                "direct_evals_per_dim and full_refit_every must be >= 1".into(),
            ));
        }
        match self.xi {
            XiRule::Fixed(v) | XiRule::SignalVarianceTimes(v) if !(v >= 0.0 && v.is_finite()) => {
                return Err(BoError::InvalidSetting(format!("xi must be >= 0, got {v}")));
            }
            _ => {}
        }
        if let AcquisitionKind::Ucb { beta } = self.acquisition
            && !(beta > 0.0 && beta.is_finite())
        {
            return Err(BoError::InvalidSetting(format!(
                "UCB beta must be > 0, got {beta}"
            )));
        }
        if let Some(r) = self.restart
            && !(r.tol >= 0.0
                && r.tol.is_finite()
                && r.tabu_radius >= 0.0
                && r.tabu_radius.is_finite())
        {
            return Err(BoError::InvalidSetting(
                "restart tol and tabu_radius must be finite and >= 0".into(),
            ));
        }
        if let BatchStrategy::Qei { samples } = self.batch
            && !(1..=MAX_QEI_SAMPLES).contains(&samples)
        {
            return Err(BoError::InvalidSetting(format!(
                "a qEI batch strategy needs 1 to {MAX_QEI_SAMPLES} samples, got {samples}"
            )));
        }
        if let InitialDesign::MaximinLatinHypercube { candidates: 0 } = self.initial_design {
            return Err(BoError::InvalidSetting(
                "a Latin hypercube design needs candidates >= 1".into(),
            ));
        }
        if self.stop.relative_ei_threshold.is_nan() || self.stop.relative_ei_threshold < 0.0 {
            return Err(BoError::InvalidSetting(
                "relative_ei_threshold must be >= 0".into(),
            ));
        }
        Ok(())
    }
}

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

#[derive(Debug, Clone, PartialEq)]
enum Warp {
    Tail(TailWarp),
    Rank(RankWarp),
}

impl Warp {
    fn forward(&self, z: f64) -> f64 {
        match self {
            Warp::Tail(t) => t.forward(z),
            Warp::Rank(r) => r.forward(z),
        }
    }
    fn inverse(&self, w: f64) -> f64 {
        match self {
            Warp::Tail(t) => t.inverse(w),
            Warp::Rank(r) => r.inverse(w),
        }
    }
    fn slope_at_image(&self, w: f64) -> f64 {
        match self {
            Warp::Tail(t) => t.slope_at_image(w),
            Warp::Rank(r) => {
                let h = 1e-3;
                let dz = r.inverse(w + h) - r.inverse(w - h);
                if dz > 0.0 { 2.0 * h / dz } else { 1.0 }
            }
        }
    }
}

/// Piecewise-linear rank transform through the sorted distinct observations.
#[derive(Debug, Clone, PartialEq)]
struct RankWarp {
    /// Sorted distinct values and their scores.
    z: Vec<f64>,
    w: Vec<f64>,
}

impl RankWarp {
    fn fit(z: &[f64]) -> Option<Self> {
        let n = z.len();
        if n < 3 {
            return None;
        }
        let mut v = z.to_vec();
        v.sort_by(|a, b| a.total_cmp(b));
        let mut zs = Vec::new();
        let mut ws = Vec::new();
        let mut i = 0;
        while i < n {
            let mut j = i;
            while j + 1 < n && v[j + 1] == v[i] {
                j += 1;
            }
            zs.push(v[i]);
            ws.push(((i + j) as f64 / 2.0 + 0.5) / n as f64);
            i = j + 1;
        }
        if zs.len() < 2 {
            return None;
        }
        Some(RankWarp { z: zs, w: ws })
    }

    fn interp(xs: &[f64], ys: &[f64], x: f64) -> f64 {
        let n = xs.len();
        if x <= xs[0] {
            let slope = (ys[1] - ys[0]) / (xs[1] - xs[0]);
            return ys[0] + slope * (x - xs[0]);
        }
        if x >= xs[n - 1] {
            let slope = (ys[n - 1] - ys[n - 2]) / (xs[n - 1] - xs[n - 2]);
            return ys[n - 1] + slope * (x - xs[n - 1]);
        }
        let k = xs.partition_point(|v| *v <= x).clamp(1, n - 1);
        let t = (x - xs[k - 1]) / (xs[k] - xs[k - 1]);
        ys[k - 1] + t * (ys[k] - ys[k - 1])
    }

    fn forward(&self, z: f64) -> f64 {
        Self::interp(&self.z, &self.w, z)
    }

    fn inverse(&self, w: f64) -> f64 {
        Self::interp(&self.w, &self.z, w)
    }
}

/// Monotone output warp that compresses the bad tail logarithmically (values below the
/// median `m` map to `m - s ln(1 + (m - z) / s)`), leaving the good half linear, so a few
/// huge bad values do not flatten the model where the optimum is.
#[derive(Debug, Clone, Copy, PartialEq)]
struct TailWarp {
    m: f64,
    s: f64,
}

impl TailWarp {
    fn fit(z: &[f64]) -> Option<Self> {
        if z.len() < 3 {
            return None;
        }
        let mut v = z.to_vec();
        v.sort_by(|a, b| a.total_cmp(b));
        let m = v[v.len() / 2];
        let top = v[v.len() - 1] - m;
        let mut dev: Vec<f64> = v.iter().map(|x| (x - m).abs()).collect();
        dev.sort_by(|a, b| a.total_cmp(b));
        let mad = dev[dev.len() / 2];
        let s = top.max(mad);
        if s > 0.0 && s.is_finite() {
            Some(TailWarp { m, s })
        } else {
            None
        }
    }

    fn forward(&self, z: f64) -> f64 {
        if z >= self.m {
            z
        } else {
            self.m - self.s * ((self.m - z) / self.s).ln_1p()
        }
    }

    fn inverse(&self, w: f64) -> f64 {
        if w >= self.m {
            w
        } else {
            self.m - self.s * ((self.m - w) / self.s).exp_m1()
        }
    }

    /// d forward / dz at the pre-image of `w`.
    fn slope_at_image(&self, w: f64) -> f64 {
        if w >= self.m {
            1.0
        } else {
            (-(self.m - w) / self.s).exp()
        }
    }
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

    /// Whether the current epoch stagnates under `rule` (after its initial design).
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
        now - before <= rule.tol * (now - lo)
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

    /// Refit the hyperparameters (MAP, warm-started) and build the GP on the observations.
    fn fit_model(&mut self, data: &Standardised, full: bool) -> Result<Gp> {
        let restarts = if full || self.hyper.is_none() {
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
        let mut data = self.standardised();
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

    /// Propose `q` new points (distinct from each other, from the observations and from the
    /// pending points), taking into account the points still pending. The points are added
    /// to the pending list until observed.
    pub fn suggest(&mut self, q: usize) -> Result<Vec<Vec<f64>>> {
        if q == 0 {
            return Err(BoError::InvalidSetting("q must be >= 1".into()));
        }
        let mut out: Vec<Vec<f64>> = Vec::with_capacity(q);
        let mut info = RoundInfo::default();
        self.restart_if_stagnant();
        self.initial_points(q, &mut out, &mut info);
        if out.len() < q {
            self.model_points(q, &mut out, &mut info)?;
        }
        self.pending.extend(out.iter().cloned());
        self.last_round = info;
        Ok(out)
    }

    /// A new epoch when the restart rule says this one stagnates: its best point becomes a
    /// tabu centre.
    fn restart_if_stagnant(&mut self) {
        if let Some(rule) = self.settings.restart
            && self.epoch_stagnates(&rule)
        {
            let sign = if self.settings.minimize { -1.0 } else { 1.0 };
            let from = self.epoch_start;
            if let Some(i) = (from..self.ys.len())
                .max_by(|a, b| (sign * self.ys[*a]).total_cmp(&(sign * self.ys[*b])))
            {
                self.tabu.push(self.to_unit(&self.xs[i]));
            }
            self.epoch_start = self.ys.len();
        }
    }

    /// Adds to `out` (up to `q` points) the epoch's initial design (and random points while
    /// fewer than 2 observations exist).
    fn initial_points(&mut self, q: usize, out: &mut Vec<Vec<f64>>, info: &mut RoundInfo) {
        let epoch_init = match self.settings.restart {
            Some(rule) if self.epoch_start > 0 => rule.init.max(2),
            _ => self.n_init(),
        };
        let epoch_len = self.xs.len() - self.epoch_start.min(self.xs.len());
        while out.len() < q
            && (epoch_len + self.pending.len() + out.len() < epoch_init || epoch_len < 2)
        {
            let u = if self.epoch_start == 0 {
                self.next_design_point(epoch_init, out)
            } else {
                self.rng.unit_point(self.dim())
            };
            out.push(self.unit_to_box(&u));
            info.random_points += 1;
        }
    }

    /// The next point (unit cube) of the first epoch's design. The design is drawn whole when
    /// first needed and handed out in order, skipping its points already observed, pending or
    /// in `out`: an engine rebuilt from a run's history continues the same design, and a
    /// design point whose trial failed (dropped from both) is not followed by a point still
    /// pending. Past its end: a random point.
    fn next_design_point(&mut self, epoch_init: usize, out: &[Vec<f64>]) -> Vec<f64> {
        let d = self.dim();
        if self.design.is_empty() {
            let n = epoch_init.max(2);
            self.design = match self.settings.initial_design {
                InitialDesign::Random => (0..n).map(|_| self.rng.unit_point(d)).collect(),
                InitialDesign::MaximinLatinHypercube { candidates } => {
                    maximin_latin_hypercube(&mut self.rng, n, d, candidates)
                }
            };
        }
        let next = (self.design_next..self.design.len()).find(|&i| {
            let x = self.unit_to_box(&self.design[i]);
            !self
                .xs
                .iter()
                .chain(&self.pending)
                .chain(out)
                .any(|p| same_point(p, &x, &self.lower, &self.upper))
        });
        match next {
            Some(i) => {
                self.design_next = i + 1;
                self.design[i].clone()
            }
            None => self.rng.unit_point(d),
        }
    }

    /// Fills `out` up to `q` points from the model: EI maximisers (or qEI points), each
    /// conditioning the next through a lie or the joint posterior.
    fn model_points(
        &mut self,
        q: usize,
        out: &mut Vec<Vec<f64>>,
        info: &mut RoundInfo,
    ) -> Result<()> {
        let data = self.standardised();
        let full = self.rounds.is_multiple_of(self.settings.full_refit_every);
        let gp = self.fit_model(&data, full)?;
        let xi = self.settings.xi.xi(gp.kernel().signal_variance);
        info.xi = Some(xi);
        let mut round = self.open_round(gp, &data, xi, out)?;
        while out.len() < q {
            let qei_point = round.qei.is_some() && !round.chosen.is_empty();
            let (u, ei) = self.propose_one(&mut round, qei_point, q, out.is_empty())?;
            let u = self.settle_point(&round, u, ei, qei_point, info);
            if info.best_ei.is_none() {
                info.best_ei = Some(ei);
                info.relative_ei = Some(if round.y_range > 0.0 {
                    ei / round.y_range
                } else {
                    f64::INFINITY
                });
            }
            if round.qei.is_some() {
                round.chosen.push(u.clone());
            } else {
                let lie = self.lie(&round.gp, &u, round.incumbent, round.y_mean, round.y_min);
                if out.len() + 1 < q {
                    round.incumbent = round.incumbent.max(lie);
                    round.gp.push(u.clone(), lie)?;
                }
            }
            round.taken.push(u.clone());
            out.push(self.unit_to_box(&u));
        }
        if let Some(rel) = info.relative_ei {
            if rel < self.settings.stop.relative_ei_threshold {
                self.low_ei_streak = self.low_ei_streak.saturating_add(1);
            } else {
                self.low_ei_streak = 0;
            }
        }
        self.rounds = self.rounds.saturating_add(1);
        Ok(())
    }

    /// A model-based round on `gp` fitted to `data`, with the pending points and those
    /// already in `out` entered: by lies into the GP, or (qEI) as chosen points that enter
    /// jointly through the GP's posterior (no fantasy values).
    fn open_round(&self, gp: Gp, data: &Standardised, xi: f64, out: &[Vec<f64>]) -> Result<Round> {
        let y_max = data.y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let y_min = data.y.iter().copied().fold(f64::INFINITY, f64::min);
        let fantasies: Vec<Vec<f64>> = self
            .pending
            .iter()
            .chain(out.iter())
            .map(|p| self.to_unit(p))
            .collect();
        let mut round = Round {
            gp,
            xi,
            incumbent: y_max,
            y_mean: data.y.iter().sum::<f64>() / data.y.len().max(1) as f64,
            y_min,
            // The range of the modelled outputs (standardised, after the output transform,
            // this epoch): without a transform, EI over the observed range of y; with one, a
            // few compressed misses do not inflate the range.
            y_range: y_max - y_min,
            taken: data.x.clone(),
            chosen: Vec::new(),
            qei: match self.settings.batch {
                BatchStrategy::Qei { samples } => Some(samples.max(1)),
                _ => None,
            },
            // qEI's base samples come from a generator of this round (the main stream is
            // left as it is).
            qei_rng: Rng::new(
                self.seed
                    .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    .wrapping_add(self.rounds as u64),
            ),
        };
        for u in fantasies {
            if round.qei.is_some() {
                round.chosen.push(u.clone());
                round.taken.push(u);
                continue;
            }
            let lie = self.lie(&round.gp, &u, round.incumbent, round.y_mean, y_min);
            round.incumbent = round.incumbent.max(lie);
            round.gp.push(u.clone(), lie)?;
            round.taken.push(u);
        }
        Ok(round)
    }

    /// The next maximiser of the round and its EI (or qEI gain, for a `qei_point`); `first`:
    /// the round's first point.
    fn propose_one(
        &self,
        round: &mut Round,
        qei_point: bool,
        q: usize,
        first: bool,
    ) -> Result<(Vec<f64>, f64)> {
        match round.qei {
            Some(samples) if qei_point => {
                let target = round.incumbent + round.xi;
                let ctx = QeiContext::new(
                    &round.gp,
                    &round.chosen,
                    target,
                    samples,
                    &mut round.qei_rng,
                )?;
                self.maximize_qei(ctx)
            }
            _ => {
                // A qEI batch spreads its points itself: only a round of one point with
                // nothing pending is diversified.
                let alone = round.qei.is_none() || (q == 1 && self.pending.is_empty());
                let (gp, incumbent, xi) = (&round.gp, round.incumbent, round.xi);
                self.ei_point(gp, incumbent, xi, round.y_min, alone && first)
            }
        }
    }

    /// The point to propose for the maximiser `u` of EI `ei`: an exploration step when EI is
    /// below [`Settings::explore_below_ei`] (EI points only: a qEI gain is not an EI), a
    /// random point when `u` was already taken, else `u`.
    fn settle_point(
        &mut self,
        round: &Round,
        u: Vec<f64>,
        ei: f64,
        qei_point: bool,
        info: &mut RoundInfo,
    ) -> Vec<f64> {
        let duplicate = round.taken.iter().any(|t| {
            t.iter()
                .zip(&u)
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f64>()
                < 1e-16
        });
        let explore = !qei_point && matches!(self.settings.explore_below_ei, Some(th) if ei < th);
        if explore {
            info.exploration_points += 1;
            self.exploration_point(&round.gp)
        } else if duplicate {
            self.rng.unit_point(self.dim())
        } else {
            u
        }
    }

    /// The EI (or UCB) maximiser on `gp` and its value. When `first` and this is a
    /// diversification round ([`Settings::diversify_every`]), the EI maximiser is assumed to be
    /// as bad as the worst observation (`y_min`, constant liar) and the next maximiser is
    /// returned instead, `diversify_depth` times.
    fn ei_point(
        &self,
        gp: &Gp,
        incumbent: f64,
        xi: f64,
        y_min: f64,
        first: bool,
    ) -> Result<(Vec<f64>, f64)> {
        let k = self.settings.diversify_every;
        let diversify = k > 0 && first && self.rounds % k == k - 1;
        let depth = self.settings.diversify_depth.max(1);
        let share = if diversify {
            1.0 / (1 + depth) as f64
        } else {
            1.0
        };
        // In a diversification round each maximisation keeps its kernel rows for the next
        // one, whose GP only has fantasy points appended (see `RowMemo`).
        let mut memo = diversify.then(RowMemo::default);
        let (mut u, mut ei) =
            self.maximize_acquisition(gp, incumbent, xi, share, None, memo.as_mut())?;
        if diversify {
            let mut g2 = gp.clone();
            for step in 0..depth {
                g2.push(u.clone(), y_min)?;
                let previous = memo.take();
                memo = (step + 1 < depth).then(RowMemo::default);
                let (u2, ei2) = self.maximize_acquisition(
                    &g2,
                    incumbent,
                    xi,
                    share,
                    previous.as_ref(),
                    memo.as_mut(),
                )?;
                u = u2;
                ei = ei.max(ei2);
            }
        }
        Ok((u, ei))
    }

    /// Space-filling exploration step: the random candidate (100 d uniform draws) with the
    /// largest posterior variance.
    fn exploration_point(&mut self, gp: &Gp) -> Vec<f64> {
        let d = self.dim();
        let mut best = self.rng.unit_point(d);
        let mut best_var = gp.predict(&best).1;
        for _ in 1..100 * d {
            let c = self.rng.unit_point(d);
            let v = gp.predict(&c).1;
            if v > best_var {
                best_var = v;
                best = c;
            }
        }
        best
    }

    fn lie(&self, gp: &Gp, u: &[f64], incumbent: f64, mean: f64, min: f64) -> f64 {
        match self.settings.batch {
            // Qei never lies (its points enter the joint posterior); the arm is for completeness.
            BatchStrategy::KrigingBeliever | BatchStrategy::Qei { .. } => gp.predict(u).0,
            BatchStrategy::ConstantLiarMin => min,
            BatchStrategy::ConstantLiarMean => mean,
            BatchStrategy::ConstantLiarMax => incumbent,
        }
    }

    /// Penalty (and its gradient, added to `g`) inside the balls around earlier epochs'
    /// incumbents: linear in the squared distance, steep enough to dominate the acquisition.
    fn tabu_penalty(&self, u: &[f64], mut g: Option<&mut [f64]>) -> f64 {
        let d = self.dim();
        let radius = self
            .settings
            .restart
            .map_or(0.0, |r| r.tabu_radius * (d as f64).sqrt());
        let r2 = radius * radius;
        let mut p = 0.0;
        if r2 <= 0.0 {
            return p;
        }
        let k = 1e3 / r2;
        for c in &self.tabu {
            let d2: f64 = u.iter().zip(c).map(|(a, b)| (a - b) * (a - b)).sum();
            if d2 < r2 {
                p -= k * (r2 - d2);
                if let Some(g) = g.as_deref_mut() {
                    for ((gi, a), b) in g.iter_mut().zip(u).zip(c) {
                        *gi += 2.0 * k * (a - b);
                    }
                }
            }
        }
        p
    }

    /// Maximise the log qEI gain of `ctx` (plus the restart penalty) on the unit cube: DIRECT
    /// with the acquisition's budget, then (unless [`Settings::polish_starts`] is 0) an L-BFGS
    /// polish of DIRECT's best point with central finite-difference gradients and
    /// [`QEI_POLISH_ITERS`] iterations. Returns the point and its qEI gain (0 on the floor).
    fn maximize_qei(&self, mut ctx: QeiContext<'_>) -> Result<(Vec<f64>, f64)> {
        let d = self.dim();
        let lo = vec![0.0; d];
        let hi = vec![1.0; d];
        let ds = DirectSettings {
            max_evals: (self.settings.direct_evals_per_dim * d).max(2 * d + 1),
            ..DirectSettings::default()
        };
        let res = direct::maximize(
            |u| ctx.log_gain(u) + self.tabu_penalty(u, None),
            &lo,
            &hi,
            &ds,
            1,
        )?;
        let (mut best_u, mut best_v) = (res.x, res.value);
        if self.settings.polish_starts > 0 {
            const H: f64 = 1e-6;
            let mut x = vec![0.0; d];
            let (u, v) = direct::polish(
                |u, g| {
                    x.copy_from_slice(u);
                    for i in 0..d {
                        let (a, b) = ((u[i] - H).max(0.0), (u[i] + H).min(1.0));
                        x[i] = b;
                        let fb = ctx.log_gain(&x);
                        x[i] = a;
                        let fa = ctx.log_gain(&x);
                        x[i] = u[i];
                        g[i] = if b > a && fa > LOG_EI_FLOOR && fb > LOG_EI_FLOOR {
                            (fb - fa) / (b - a)
                        } else {
                            0.0
                        };
                    }
                    ctx.log_gain(u) + self.tabu_penalty(u, Some(g))
                },
                &best_u,
                &lo,
                &hi,
                QEI_POLISH_ITERS,
            );
            if v > best_v && v.is_finite() {
                best_u = u;
                best_v = v;
            }
        }
        let gain = if best_v <= LOG_EI_FLOOR {
            0.0
        } else {
            ctx.log_gain(&best_u).exp()
        };
        Ok((best_u, gain))
    }

    /// Maximise the acquisition on the unit cube: DIRECT then L-BFGS polish from the best
    /// centres. Returns the point and its EI (standardised units; the UCB value for UCB).
    /// `reuse`: kernel rows kept by the previous maximisation on a GP that `gp` extends (see
    /// [`RowMemo`]); `record`: where to keep this one's.
    fn maximize_acquisition(
        &self,
        gp: &Gp,
        incumbent: f64,
        xi: f64,
        budget_share: f64,
        reuse: Option<&RowMemo>,
        mut record: Option<&mut RowMemo>,
    ) -> Result<(Vec<f64>, f64)> {
        let d = self.dim();
        let lo = vec![0.0; d];
        let hi = vec![1.0; d];
        let acq = self.settings.acquisition;
        let mut buffer = Vec::new();
        let (mut k_row, mut v_row) = (Vec::new(), Vec::new());
        if let Some(rec) = record.as_deref_mut() {
            rec.len = gp.len();
            rec.rows.clear();
        }
        let value = |u: &[f64]| -> f64 {
            let (m, v) = if reuse.is_none() && record.is_none() {
                gp.predict_with_buffer(u, &mut buffer)
            } else {
                let rows = (&mut k_row, &mut v_row);
                predict_with_memo(gp, u, reuse, record.as_deref_mut(), rows)
            };
            let a = match acq {
                AcquisitionKind::ExpectedImprovement => {
                    log_expected_improvement(m, v, incumbent, xi)
                }
                AcquisitionKind::Ucb { beta } => acquisition::ucb(m, v, beta),
            };
            a + self.tabu_penalty(u, None)
        };
        let ds = DirectSettings {
            max_evals: ((self.settings.direct_evals_per_dim * d) as f64 * budget_share)
                .max(2.0 * d as f64 + 1.0) as usize,
            ..DirectSettings::default()
        };
        let res = direct::maximize(value, &lo, &hi, &ds, self.settings.polish_starts.max(1))?;
        let (best_u, best_v) =
            self.polish_acquisition(gp, &res.top, incumbent, xi, (res.x, res.value));
        let (m, var) = gp.predict(&best_u);
        let ei = match acq {
            AcquisitionKind::ExpectedImprovement => {
                if best_v <= LOG_EI_FLOOR {
                    0.0
                } else {
                    expected_improvement(m, var, incumbent, xi)
                }
            }
            AcquisitionKind::Ucb { .. } => best_v,
        };
        Ok((best_u, ei))
    }

    /// `best` (DIRECT's maximum of the acquisition on `gp`), improved by an L-BFGS polish
    /// from each of the first [`Settings::polish_starts`] of DIRECT's `top` points.
    fn polish_acquisition(
        &self,
        gp: &Gp,
        top: &[(Vec<f64>, f64)],
        incumbent: f64,
        xi: f64,
        best: (Vec<f64>, f64),
    ) -> (Vec<f64>, f64) {
        let (mut best_u, mut best_v) = best;
        if self.settings.polish_starts == 0 {
            return (best_u, best_v);
        }
        let d = self.dim();
        let (lo, hi) = (vec![0.0; d], vec![1.0; d]);
        let acq = self.settings.acquisition;
        let mut dm = vec![0.0; d];
        let mut dv = vec![0.0; d];
        for (start, _) in top.iter().take(self.settings.polish_starts) {
            let (u, v) = direct::polish(
                |u, g| {
                    let (m, var) = gp.predict_with_grad(u, &mut dm, &mut dv);
                    let a = match acq {
                        AcquisitionKind::ExpectedImprovement => {
                            acquisition::log_ei_with_grad(m, var, &dm, &dv, incumbent, xi, g)
                        }
                        AcquisitionKind::Ucb { beta } => {
                            acquisition::ucb_with_grad(m, var, &dm, &dv, beta, g)
                        }
                    };
                    a + self.tabu_penalty(u, Some(g))
                },
                start,
                &lo,
                &hi,
                self.settings.polish_iters,
            );
            if v > best_v && v.is_finite() {
                best_u = u;
                best_v = v;
            }
        }
        (best_u, best_v)
    }
}

/// The posterior at `u` on `gp` through the kernel rows `rows` (`k`, `L^{-1} k`): those of
/// the first conditioning points come from `reuse` when it kept them for `u`, and the full
/// rows are kept in `record`.
fn predict_with_memo(
    gp: &Gp,
    u: &[f64],
    reuse: Option<&RowMemo>,
    record: Option<&mut RowMemo>,
    (k_row, v_row): (&mut Vec<f64>, &mut Vec<f64>),
) -> (f64, f64) {
    let key: Vec<u64> = u.iter().map(|c| c.to_bits()).collect();
    let mut from = 0;
    if let Some((len, row)) = reuse.and_then(|r| r.rows.get(&key).map(|w| (r.len, w))) {
        k_row.clear();
        k_row.extend_from_slice(&row[..len]);
        v_row.clear();
        v_row.extend_from_slice(&row[len..]);
        from = len;
    }
    let mv = gp.predict_extending(u, from, k_row, v_row);
    if let Some(rec) = record {
        let mut row = Vec::with_capacity(2 * k_row.len());
        row.extend_from_slice(k_row);
        row.extend_from_slice(v_row);
        rec.rows.insert(key, row);
    }
    mv
}

/// One model-based round of [`Optimizer::suggest`] (standardised outputs, unit cube).
struct Round {
    /// The model, with the lies of the points entered so far (not with qEI).
    gp: Gp,
    xi: f64,
    incumbent: f64,
    y_mean: f64,
    y_min: f64,
    /// The range of the modelled outputs, for the relative EI.
    y_range: f64,
    /// Observed, pending and proposed points: a maximiser among them is replaced.
    taken: Vec<Vec<f64>>,
    /// With qEI: the points pending or proposed, which enter the joint posterior.
    chosen: Vec<Vec<f64>>,
    /// With qEI: its number of base samples.
    qei: Option<usize>,
    qei_rng: Rng,
}

/// Kernel rows `k(u, x_i)` and `L^{-1} k` of the first `len` conditioning points at every
/// point `u` (keyed by its bits) where one DIRECT run evaluated the acquisition. The runs of a
/// diversification round maximise on the same GP with fantasy points appended, and DIRECT
/// revisits many of the same points (a third to a half of them): there only the rows of the
/// appended points are computed ([`Gp::predict_extending`], bit-identical to a full
/// prediction).
#[derive(Default)]
struct RowMemo {
    len: usize,
    rows: HashMap<Vec<u64>, Vec<f64>>,
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Smallest squared distance between two points of `pts`.
    fn smallest_gap(pts: &[Vec<f64>]) -> f64 {
        let mut gap = f64::INFINITY;
        for (a, p) in pts.iter().enumerate() {
            for q in &pts[a + 1..] {
                gap = gap.min(p.iter().zip(q).map(|(x, y)| (x - y) * (x - y)).sum());
            }
        }
        gap
    }

    #[test]
    fn latin_hypercube_has_one_point_per_slice_and_maximin_spreads_them() {
        let (n, d) = (10, 6);
        let mut rng = Rng::new(5);
        let one = maximin_latin_hypercube(&mut rng, n, d, 1);
        let best = maximin_latin_hypercube(&mut Rng::new(5), n, d, 200);
        for pts in [&one, &best] {
            assert_eq!(pts.len(), n);
            for j in 0..d {
                let mut slices: Vec<usize> =
                    pts.iter().map(|p| (p[j] * n as f64) as usize).collect();
                slices.sort_unstable();
                assert_eq!(slices, (0..n).collect::<Vec<_>>(), "axis {j}: {pts:?}");
            }
        }
        // the first candidate of the maximin search is the single hypercube drawn from the
        // same stream, so the best of 200 is at least as spread, and here strictly more
        assert!(smallest_gap(&best) > smallest_gap(&one));
    }

    #[test]
    fn the_initial_design_is_handed_out_in_order_across_batches_and_pending_points() {
        let settings = Settings {
            n_init: Some(5),
            initial_design: InitialDesign::MaximinLatinHypercube { candidates: 20 },
            ..Settings::default()
        };
        let mut opt = Optimizer::new(&[(0.0, 10.0), (-1.0, 1.0)], settings, 3).unwrap();
        let mut pts = opt.suggest(2).unwrap();
        pts.extend(opt.suggest(1).unwrap());
        opt.observe(&pts[0], 1.0).unwrap();
        pts.extend(opt.suggest(2).unwrap());
        assert_eq!(opt.last_round().random_points, 2);
        let units: Vec<Vec<f64>> = pts.iter().map(|p| opt.to_unit(p)).collect();
        assert_eq!(units.len(), 5);
        for (u, v) in units.iter().zip(&opt.design) {
            for (a, b) in u.iter().zip(v) {
                assert!((a - b).abs() < 1e-12, "{units:?} against {:?}", opt.design);
            }
        }
        for j in 0..2 {
            let mut slices: Vec<usize> = units.iter().map(|u| (u[j] * 5.0) as usize).collect();
            slices.sort_unstable();
            assert_eq!(slices, vec![0, 1, 2, 3, 4]);
        }
        // The trial of a design point failed (dropped from observations and pending): the
        // next point is the design's next one, never a point still pending.
        let settings = Settings {
            n_init: Some(4),
            ..Settings::default()
        };
        let mut warm = Optimizer::new(&[(0.0, 1.0), (0.0, 1.0)], settings.clone(), 8).unwrap();
        let first = warm.suggest(2).unwrap();
        warm.set_pending(vec![first[1].clone()]).unwrap();
        let third = warm.suggest(1).unwrap();
        assert_eq!(third[0], warm.unit_to_box(&warm.design[2]));
        // rebuilt with the same history: the failed point again, not the pending one
        let mut rebuilt = Optimizer::new(&[(0.0, 1.0), (0.0, 1.0)], settings, 8).unwrap();
        rebuilt.set_pending(vec![first[1].clone()]).unwrap();
        assert_eq!(
            rebuilt.suggest(2).unwrap(),
            vec![first[0].clone(), third[0].clone()]
        );
        let bad = Settings {
            initial_design: InitialDesign::MaximinLatinHypercube { candidates: 0 },
            ..Settings::default()
        };
        assert!(matches!(
            Optimizer::new(&[(0.0, 1.0)], bad, 0),
            Err(BoError::InvalidSetting(_))
        ));
    }

    #[test]
    fn warps_are_monotone_and_invertible() {
        let z = vec![-300.0, -120.0, -50.0, -20.0, -5.0, -1.0, -0.5, -0.4];
        let t = TailWarp::fit(&z).unwrap();
        let r = RankWarp::fit(&z).unwrap();
        for w in [Warp::Tail(t), Warp::Rank(r)] {
            let mut prev = f64::NEG_INFINITY;
            for &v in &z {
                let f = w.forward(v);
                assert!(f > prev);
                prev = f;
                assert!(
                    (w.inverse(f) - v).abs() < 1e-9 * v.abs().max(1.0),
                    "{w:?} {v}"
                );
                assert!(w.slope_at_image(f) > 0.0);
            }
        }
        // the tail warp leaves the good half unchanged and compresses the bad tail
        assert_eq!(t.forward(-0.4), -0.4);
        assert!(t.forward(-5.0) - t.forward(-300.0) < 295.0 / 5.0);
        assert!(TailWarp::fit(&[1.0, 1.0, 1.0]).is_none());
        assert!(RankWarp::fit(&[1.0, 1.0, 1.0]).is_none());
    }
}
