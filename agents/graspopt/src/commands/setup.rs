//! The flags every simulated-trial command shares (`trial`, `scan`, `record`, `run`, `agent
//! coordinator`): which object, hand, contact model, metric, reference frame and parameter
//! ranges, and the value parsers of the flags that name a library type (`--contacts`,
//! `--metric`, `--frame`, `--params`, `--range`, `--method`).

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use graspopt_coordinator::MAX_TRIALS;
use graspopt_protocol::PlannerMethod;
use graspopt_protocol::text::grouped;
use graspopt_sim::{ContactModel, ParamKind, ParamSpec};
use graspopt_trial::{Evaluator, Metric, ReferenceFrame, TrialSettings};

#[derive(Args, Debug, Clone)]
pub struct SimArgs {
    /// Built-in object: sphere, wine_glass, cylinder, mug, cuboid, rotated_cuboid, star_prism.
    #[arg(long, default_value = "mug", conflicts_with = "mesh")]
    pub object: String,
    /// A user mesh (OBJ or STL, closed) instead of a built-in object.
    #[arg(long)]
    pub mesh: Option<PathBuf>,
    /// Factor from the mesh file's units to metres (0.001 for a mesh in millimetres).
    #[arg(long, default_value_t = 1.0, requires = "mesh")]
    pub mesh_scale: f64,
    /// Hand: a built-in name (barrett, barrett_ft, parallel_jaw, franka_hand; see `graspopt hands`) or a
    /// URDF file (FILE.urdf, settings in FILE.toml beside it).
    #[arg(long, default_value = "barrett")]
    pub hand: String,
    /// Contact model: surface (thesis 2.3), patch (circular patch) or mean (mean point).
    #[arg(long, default_value = "surface", value_parser = contact_model())]
    pub contacts: ContactModel,
    /// Metric scored: bw, epsilon (ls), volume (gwv) or isotropy (docs/metric-conventions.md).
    #[arg(long, default_value = "bw", value_parser = metric())]
    pub metric: Metric,
    /// Reference point for torques: object (centre of mass), world or palm.
    #[arg(long, default_value = "object", value_parser = frame())]
    pub frame: ReferenceFrame,
    /// Torque scale in metres (default: the object's bounding radius).
    #[arg(long)]
    pub torque_scale: Option<f64>,
    #[arg(long, value_name = "NAME=LO:HI", value_delimiter = ',', value_parser = param_range())]
    #[arg(help = graspopt_sim::pose::ranges_help())]
    pub range: Vec<ParamSpec>,
}

/// What a run is (`run`, `agent coordinator`): the trial flags, the budget, the
/// parameters, how trials are proposed, and whether it resumes.
#[derive(Args, Debug, Clone)]
pub struct SpecArgs {
    #[command(flatten)]
    pub sim: SimArgs,
    /// Number of trials (with --resume: raises the recorded budget).
    #[arg(long, default_value_t = 60, value_parser = count::<u64>(1, MAX_TRIALS))]
    pub trials: u64,
    /// Trial parameters, comma-separated: x (approach), y (vertical), lateral, rx, ry, rz.
    #[arg(long, visible_alias = "axes", default_value = "x,y", value_delimiter = ',',
          value_parser = trial_param())]
    pub params: Vec<ParamKind>,
    /// How trials are proposed: bo (Bayesian optimization: GP, EI, DIRECT) or random
    /// (uniform random search, a baseline).
    #[arg(long, default_value = "bo", value_parser = planner_method())]
    pub method: PlannerMethod,
    /// Size of the initial design (space-filling, not model-based) (default: the engine's).
    #[arg(long, value_parser = count::<u32>(0, u32::MAX.into()))]
    pub initial: Option<u32>,
    /// Seed of the planner's random choices (the same seed proposes the same trials) and,
    /// in `graspopt run`, of perception's noise.
    #[arg(long, default_value_t = 0, value_parser = count::<u64>(0, u64::MAX))]
    pub seed: u64,
    /// Continue the run recorded in the journal (its only run, unless --run names one),
    /// with its recorded settings (`graspopt run`: its results folder's journal, and its
    /// workers). Without --resume, a run recorded with no trial (a start that stopped
    /// before its first) starts afresh.
    #[arg(long)]
    pub resume: bool,
}

/// `--range`: `NAME=LO:HI` ([`ParamSpec::parse_range`]).
fn param_range() -> impl TypedValueParser<Value = ParamSpec> {
    clap::builder::NonEmptyStringValueParser::new().try_map(|s| ParamSpec::parse_range(&s))
}

/// `--contacts`: the simulator's contact models by name.
pub fn contact_model() -> impl TypedValueParser<Value = ContactModel> {
    PossibleValuesParser::new(ContactModel::ALL.map(|m| m.name()))
        .try_map(|s| ContactModel::parse(&s))
}

/// `--metric`: the metrics that may be the score (the metric table's objectives), with
/// their short names as aliases.
fn metric() -> impl TypedValueParser<Value = Metric> {
    let values = Metric::objectives().map(|m| PossibleValue::new(m.key()).aliases(m.def().aliases));
    PossibleValuesParser::new(values).try_map(|s| Metric::parse(&s))
}

/// `--frame`: the named reference frames.
fn frame() -> impl TypedValueParser<Value = ReferenceFrame> {
    PossibleValuesParser::new(ReferenceFrame::NAMED.map(|f| f.name()))
        .try_map(|s| ReferenceFrame::parse(&s))
}

/// `--params`: a trial parameter by any of its names ([`ParamKind::parse`]).
pub fn trial_param() -> impl TypedValueParser<Value = ParamKind> {
    clap::builder::NonEmptyStringValueParser::new().try_map(|s| ParamKind::parse(&s))
}

/// A count flag (`--trials`, `--workers`, `--seeds`): a whole number from `min` to `max`
/// (`u64::MAX`: no bound), anything else refused naming that range. Every flag takes a
/// negative number as a value (see `main`), so `-5` is refused here too, not taken for a flag.
pub fn count<T: TryFrom<u64> + Clone + Send + Sync + 'static>(
    min: u64,
    max: u64,
) -> impl TypedValueParser<Value = T> {
    clap::builder::NonEmptyStringValueParser::new().try_map(move |s| {
        let range = match max {
            u64::MAX => format!("of {} or more", grouped(min)),
            _ => format!("from {} to {}", grouped(min), grouped(max)),
        };
        let whole = s.parse::<u64>().ok().filter(|v| (min..=max).contains(v));
        let whole = whole.and_then(|v| T::try_from(v).ok());
        whole.ok_or_else(|| format!("must be a whole number {range}"))
    })
}

/// `--sensing`: what a hand measures, by name.
pub fn sensing() -> impl TypedValueParser<Value = graspopt_hand::Sensing> {
    PossibleValuesParser::new(graspopt_hand::Sensing::ALL.map(graspopt_hand::Sensing::name))
        .try_map(|s| graspopt_hand::Sensing::parse(&s).ok_or("unknown sensing"))
}

/// `--method`: the planner's methods by name.
pub fn planner_method() -> impl TypedValueParser<Value = PlannerMethod> {
    PossibleValuesParser::new(PlannerMethod::ALL.map(PlannerMethod::name))
        .try_map(|s| PlannerMethod::parse(&s).ok_or("unknown method"))
}

impl SimArgs {
    /// The settings the flags name.
    pub fn settings(&self) -> TrialSettings {
        TrialSettings {
            object: self.object.clone(),
            mesh: self.mesh.clone(),
            mesh_scale: self.mesh_scale,
            hand: self.hand.clone(),
            contacts: self.contacts,
            metric: self.metric,
            frame: self.frame,
            torque_scale: self.torque_scale,
            ranges: self.range.clone(),
        }
    }

    /// An evaluator over the trial space with the given parameters (default bounds, or
    /// `--range`).
    pub fn evaluator(&self, kinds: &[ParamKind]) -> Result<Evaluator> {
        Ok(Evaluator::from_settings(&self.settings(), kinds)?)
    }
}
