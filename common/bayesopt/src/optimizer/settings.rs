//! The optimizer's settings: batch strategy, initial design, stopping and restart rules.

use super::*;

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
/// search looks for another basin instead of polishing the old one. With
/// `max_relative_ei`, the epoch must also be one whose model expects little more.
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
    /// Restart only when the model agrees that the epoch is stuck: the relative EI of the
    /// last proposal round ([`RoundInfo::relative_ei`], the best EI over the epoch's observed
    /// range of y) is below this as well (None: whatever the EI). An epoch that has not
    /// improved for `window` observations while its model still expects sizeable
    /// improvement is exploring other basins, not polishing a local optimum: a restart would
    /// throw away the model it explores with. A round without a model proposal, or with a
    /// relative EI that is not finite (an epoch of equal values), does not hold a restart
    /// back. Must be finite and > 0.
    #[serde(default)]
    pub max_relative_ei: Option<f64>,
}

/// The large-n mode ([`Settings::model_cap`]): once the epoch holds more than `size`
/// observations, the model of a round is built on `size` of them: the incumbent's nearest
/// neighbours (distance scaled by the last fit's length scales), then the best of the rest by
/// value (other good basins), then a space-filling spread of the rest (greedy farthest
/// point), in the shares below. The choice is deterministic (no random draws), so a capped
/// engine restored from its state proposes what the original would have.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModelCap {
    /// Observations modelled (>= 8).
    pub size: usize,
    /// Share of `size` given to the incumbent's nearest neighbours (0 to 1).
    pub near: f64,
    /// Share given to the best of the others by value (0 to 1, `near + best <= 1`); the
    /// rest is spread.
    pub best: f64,
    /// The batch path of a capped round (kriging believer and constant liars): a point
    /// proposed while others are pending or already proposed in the round gets a DIRECT
    /// budget of this many evaluations per dimension (>= 1) and one polish start, instead of
    /// [`Settings::direct_evals_per_dim`] and [`Settings::polish_starts`].
    pub batch_evals_per_dim: usize,
}

impl ModelCap {
    /// A cap of `size` observations with the shares measured for the planner: half nearest
    /// neighbours, a quarter best values, a quarter spread.
    pub fn of(size: usize) -> Self {
        ModelCap {
            size,
            near: 0.5,
            best: 0.25,
            batch_evals_per_dim: 40,
        }
    }
}

/// Why the optimizer says to stop.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum StopReason {
    /// The evaluation budget is used up.
    Budget,
    /// The best EI stayed below the threshold for `patience` rounds after `min_evals`.
    SmallExpectedImprovement,
}

/// The model cap of [`Settings::for_grasps`] (observations).
pub const GRASP_MODEL_CAP: usize = 150;

/// Smallest [`ModelCap::size`].
pub const MIN_MODEL_CAP: usize = 8;

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
    /// The most observations the model conditions on (None: all of the epoch's, the exact
    /// GP). Beyond it a round models a subset (see [`ModelCap`]) and refits the
    /// hyperparameters from the last fit only, without restarts. Rounds at or below it are
    /// exactly as without a cap.
    #[serde(default)]
    pub model_cap: Option<ModelCap>,
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
            model_cap: None,
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
    ///
    /// With a model cap of [`GRASP_MODEL_CAP`] observations ([`ModelCap::of`]): the planner
    /// of a many-worker run keeps up at thousands of observations (docs/benchmarks.md,
    /// "Planner at thousands of observations"), and runs of at most that many trials are
    /// exactly as without the cap.
    pub fn for_grasps() -> Self {
        Settings {
            output_transform: OutputTransform::TailLog,
            initial_design: InitialDesign::MaximinLatinHypercube { candidates: 50 },
            model_cap: Some(ModelCap::of(GRASP_MODEL_CAP)),
            ..Settings::default()
        }
    }

    /// Default initial-design size for dimension `d`.
    pub fn default_n_init(d: usize) -> usize {
        (5 * d).div_ceil(3).max(5)
    }

    pub(super) fn validate(&self) -> Result<()> {
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
        if let Some(r) = self.restart
            && let Some(th) = r.max_relative_ei
            && !(th > 0.0 && th.is_finite())
        {
            return Err(BoError::InvalidSetting(format!(
                "restart max_relative_ei must be finite and > 0, got {th}"
            )));
        }
        if let BatchStrategy::Qei { samples } = self.batch
            && !(1..=MAX_QEI_SAMPLES).contains(&samples)
        {
            return Err(BoError::InvalidSetting(format!(
                "a qEI batch strategy needs 1 to {MAX_QEI_SAMPLES} samples, got {samples}"
            )));
        }
        if let Some(c) = self.model_cap
            && !(c.size >= MIN_MODEL_CAP
                && c.batch_evals_per_dim >= 1
                && (0.0..=1.0).contains(&c.near)
                && (0.0..=1.0).contains(&c.best)
                && c.near + c.best <= 1.0)
        {
            return Err(BoError::InvalidSetting(format!(
                "a model cap needs a size of at least {MIN_MODEL_CAP}, batch_evals_per_dim >= 1 \
                 and shares near, best in [0, 1] with near + best <= 1, got {c:?}"
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
