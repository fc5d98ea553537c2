//! The registry of agent kinds ([`AGENTS`], one row each) and how one agent runs as its
//! own process ([`Standalone`]: `graspopt agent <kind>`, each process of a launch file).
//!
//! To add an agent kind: its row in protocol's `agent_kinds!` (its [`AgentKind`]), its crate
//! with `impl Agent`, and its row here; then its section in docs/agent-config.md.
//! `graspopt agent` makes a subcommand of every row and launch files accept its kind; its
//! settings come from `--config FILE` and `--set key=value` with no code of its own.

use std::future::Future;
use std::path::PathBuf;
use std::pin::Pin;

use graspopt_bus::{Agent, Bus, BusConfig};
use graspopt_coordinator::{CoordinatorAgent, RunSpec};
use graspopt_hand::HandAgent;
use graspopt_metric::MetricAgent;
use graspopt_perception::PerceptionAgent;
use graspopt_planner::PlannerAgent;
use graspopt_protocol::{AgentKind, PlannerMethod, RunId};
use graspopt_sim::ParamKind;
use graspopt_trial::TrialSettings;

use crate::config::load_with;
use crate::ending::RunEnd;
use crate::error::RunnerError;
use crate::signal::shutdown_signal;

/// One agent as its own process: what `graspopt agent <kind>` was given.
#[derive(Debug, Clone, Default)]
pub struct Standalone {
    /// The run to join.
    pub run: String,
    /// The agent's id, over its settings' `id`.
    pub id: Option<String>,
    /// Its settings file (TOML).
    pub config: Option<PathBuf>,
    /// `key=value` overrides of its settings, in order.
    pub set: Vec<String>,
    pub bus: BusConfig,
    /// The run a coordinator serves (the coordinator's only).
    pub spec: Option<SpecSettings>,
}

/// The run a standalone coordinator serves, as given (see
/// [`graspopt_coordinator::standalone_run`]).
#[derive(Debug, Clone, Default)]
pub struct SpecSettings {
    /// Object, hand and parameter ranges.
    pub trial: TrialSettings,
    pub trials: u64,
    pub params: Vec<ParamKind>,
    pub method: PlannerMethod,
    pub initial: Option<u32>,
    pub seed: u64,
    /// Continue the run recorded in the journal.
    pub resume: bool,
    /// The settings given explicitly (by their field names, `run` and `range` among them).
    pub explicit: Vec<String>,
}

/// A running agent process: it ends when stopped (`None`) or, the coordinator, with its
/// run's end.
pub type Served<'a> = Pin<Box<dyn Future<Output = Result<Option<RunEnd>, RunnerError>> + 'a>>;

/// An agent kind: its name and what it does, and how it runs as its own process.
pub struct AgentRow {
    pub kind: AgentKind,
    pub about: &'static str,
    /// Reads its settings as `run` would, to refuse them before anything starts (a launch
    /// file's processes).
    pub check: fn(&Standalone) -> Result<(), RunnerError>,
    /// The keys of its settings (top level, as `--set` and its TOML file name them).
    pub keys: fn() -> Vec<String>,
    pub run: for<'a> fn(&'a Standalone) -> Served<'a>,
}

/// The row of agent `A`, run by `run`.
const fn row<A: Agent>(run: for<'a> fn(&'a Standalone) -> Served<'a>) -> AgentRow {
    AgentRow {
        kind: A::KIND,
        about: A::ABOUT,
        check: |s| settings::<A>(s).map(drop),
        keys: crate::config::keys::<A::Config>,
        run,
    }
}

/// Every agent kind, in [`AgentKind::ALL`]'s order.
pub const AGENTS: [AgentRow; 5] = [
    row::<PerceptionAgent>(|s| Box::pin(serve(PerceptionAgent, s))),
    row::<HandAgent>(|s| Box::pin(serve(HandAgent, s))),
    row::<MetricAgent>(|s| Box::pin(serve(MetricAgent, s))),
    row::<PlannerAgent>(|s| Box::pin(serve(PlannerAgent, s))),
    row::<CoordinatorAgent>(|s| Box::pin(coordinate(s))),
];

/// The row of `kind` (every kind has one: a test checks).
pub fn agent_row(kind: AgentKind) -> &'static AgentRow {
    AGENTS.iter().find(|r| r.kind == kind).unwrap_or(&AGENTS[0])
}

/// The settings of agent `A` as `s` gives them: its file, the `--set` overrides, the id.
pub fn settings<A: Agent>(s: &Standalone) -> Result<A::Config, RunnerError> {
    let mut config: A::Config = load_with(s.config.as_deref(), &s.set)?;
    if let Some(id) = &s.id {
        id.clone_into(A::id(&mut config));
    }
    Ok(config)
}

/// Runs `agent` as `s` says until a shutdown signal: its settings checked before it joins
/// the bus.
pub async fn serve<A: Agent>(agent: A, s: &Standalone) -> Result<Option<RunEnd>, RunnerError> {
    let config = settings::<A>(s)?;
    A::validate(&config).map_err(RunnerError::agent)?;
    let run = RunId::new(&s.run)?;
    let bus = Bus::open(&s.bus).await?;
    let served = agent.run(&bus, &run, &config, shutdown_signal()).await;
    served.map_err(RunnerError::agent)?;
    Ok(None)
}

/// Runs a coordinator as `s` says until its run ends or a shutdown signal stops it (the
/// journal records it as stopped).
async fn coordinate(s: &Standalone) -> Result<Option<RunEnd>, RunnerError> {
    let c = settings::<CoordinatorAgent>(s)?;
    let given = s.spec.clone().unwrap_or_default();
    let explicit = |name: &str| given.explicit.iter().any(|e| e == name);
    let object = given.trial.object()?;
    let hand = &given.trial.hand;
    let spec = RunSpec {
        object: object.name().to_string(),
        hand: graspopt_sim::hand_name(hand).map_err(|source| RunnerError::HandName {
            hand: hand.clone(),
            source,
        })?,
        params: given.params.clone(),
        bounds: None,
        trials: given.trials,
        seed: given.seed,
        method: given.method,
        initial: given.initial,
        settings: None,
    };
    let ranges = &given.trial.ranges;
    let (run, spec) = graspopt_coordinator::standalone_run(
        &s.run,
        &c,
        spec,
        &object,
        ranges,
        given.resume,
        &explicit,
    )
    .map_err(RunnerError::agent)?;
    let bus = Bus::open(&s.bus).await?;
    let agent = CoordinatorAgent {
        spec,
        resume: given.resume,
        progress: None,
    };
    let status = agent.run(&bus, &run, &c, shutdown_signal()).await;
    let status = status.map_err(RunnerError::agent)?;
    Ok(Some(RunEnd::read(status, &c.journal_path(&run))?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_registry_has_every_kind_once_in_order() {
        let kinds: Vec<AgentKind> = AGENTS.iter().map(|r| r.kind).collect();
        assert_eq!(kinds, AgentKind::ALL);
        for kind in AgentKind::ALL {
            assert_eq!(agent_row(kind).kind, kind);
            // Its name in keys and its serde name are one.
            assert_eq!(serde_json::to_value(kind).unwrap(), kind.as_str());
        }
    }

    #[test]
    fn set_overrides_the_settings_by_key_and_names_a_bad_one() {
        let s = |set: &[&str]| Standalone {
            set: set.iter().map(|v| v.to_string()).collect(),
            ..Default::default()
        };
        let c = settings::<HandAgent>(&s(&[
            "trial_cost_ms=200",
            "hand=barrett_ft",
            "sensing=ft",
            "fingertips.noise.force_resolution=0",
        ]))
        .unwrap();
        assert_eq!((c.trial_cost_ms, c.hand.as_str()), (200, "barrett_ft"));
        assert_eq!(c.sensing, graspopt_hand::Sensing::Wrenches);
        assert_eq!(c.fingertips.noise.force_resolution, 0.0);
        let c = settings::<PerceptionAgent>(&Standalone {
            id: Some("eye".into()),
            ..s(&["seed=7", "position_noise=0", "mesh=part.stl", "id=5"])
        })
        .unwrap();
        assert_eq!((c.seed, c.id.as_str()), (7, "eye"));
        assert_eq!(c.mesh, Some(PathBuf::from("part.stl")));
        let err = |set: &str| settings::<HandAgent>(&s(&[set])).unwrap_err().to_string();
        let e = err("trial_cost_ms=soon");
        assert!(e.starts_with("--set trial_cost_ms=soon: "), "{e}");
        let e = err("trial_cost=5");
        assert!(
            e.contains("unknown key `trial_cost` at the top level; the keys there are"),
            "{e}"
        );
        let e = err("fingertips.noise.force=1");
        assert!(
            e.contains("unknown key `force` in [fingertips.noise]"),
            "{e}"
        );
        assert!(err("sensing=sonar").contains("--set sensing=sonar: unknown variant"));
        assert!(err("trial_cost_ms").contains("\"trial_cost_ms\": write it as KEY=VALUE"));
    }
}
