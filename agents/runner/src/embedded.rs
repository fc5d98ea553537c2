//! Every agent of a run in this process, on one loopback bus: the main job's embedded default.

use std::path::PathBuf;

use graspopt_bus::{Agent, Bus, BusConfig, free_loopback_port};
use graspopt_coordinator::{CoordinatorAgent, CoordinatorConfig, RunSpec};
use graspopt_hand::{HandAgent, HandConfig};
use graspopt_metric::MetricAgent;
use graspopt_perception::PerceptionAgent;
use graspopt_planner::{PlannerAgent, PlannerConfig};
use graspopt_protocol::{RunId, RunStatus};
use tokio::sync::watch;
use tokio::task::JoinSet;

use crate::error::RunnerError;

/// Everything one embedded run needs, resolved from flags (`graspopt run` builds it).
pub struct Embedded {
    pub run: RunId,
    pub spec: RunSpec,
    pub workers: usize,
    pub out: PathBuf,
    pub resume: bool,
    pub perception: graspopt_perception::PerceptionConfig,
    pub metric: graspopt_metric::MetricConfig,
    pub hand: HandConfig,
    pub coordinator: CoordinatorConfig,
    pub bus: BusConfig,
    /// The trials as simulated here (for the pictures of the results).
    pub evaluator: graspopt_trial::Evaluator,
}

/// The bus of an embedded run: unless `bus` names an endpoint or a Zenoh configuration, a free
/// loopback port with multicast scouting off (no other run on the network hears it); unless
/// it names a shared-memory prefix, one of this run and this process.
pub fn own_bus(mut bus: BusConfig, run: &RunId) -> Result<BusConfig, RunnerError> {
    if bus.listen.is_empty() && bus.connect.is_empty() && bus.zenoh_config.is_none() {
        bus.listen = vec![format!("tcp/127.0.0.1:{}", free_loopback_port()?)];
        bus.no_multicast_scouting = true;
    }
    if bus.shm_prefix.is_none() {
        bus.shm_prefix = Some(graspopt_shm::run_prefix(&format!(
            "{}_{}",
            run.as_str(),
            std::process::id()
        )));
    }
    Ok(bus)
}

/// Runs every agent in this process until the coordinator finishes (or Ctrl-C stops it:
/// the status returned is then not [`RunPhase::Finished`]).
pub async fn run_embedded(
    e: &Embedded,
    progress: Option<watch::Sender<RunStatus>>,
) -> Result<RunStatus, RunnerError> {
    // Before anything is written: a run refused for its open-file limit leaves no trace.
    crate::open_files::ensure(e.workers)?;
    std::fs::create_dir_all(&e.out).map_err(|source| RunnerError::CreateFolder {
        path: e.out.clone(),
        source,
    })?;
    let bus = Bus::open(&e.bus).await?;
    let mut tasks = JoinSet::new();
    spawn(
        &mut tasks,
        PerceptionAgent,
        &bus,
        &e.run,
        e.perception.clone(),
    );
    spawn(
        &mut tasks,
        PlannerAgent,
        &bus,
        &e.run,
        PlannerConfig::default(),
    );
    spawn(&mut tasks, MetricAgent, &bus, &e.run, e.metric.clone());
    for i in 1..=e.workers {
        let hand = HandConfig {
            id: format!("hand-{i}"),
            ..e.hand.clone()
        };
        spawn(&mut tasks, HandAgent, &bus, &e.run, hand);
    }
    let coordinator = CoordinatorAgent {
        spec: e.spec.clone(),
        resume: e.resume,
        progress,
    };
    // Ctrl-C (or SIGTERM) stops the run cleanly: the journal records it as stopped.
    let stop = crate::signal::shutdown_signal();
    let status = tokio::select! {
        s = coordinator.run(&bus, &e.run, &e.coordinator, stop) => s.map_err(RunnerError::agent),
        Some(agent) = tasks.join_next() => {
            // An agent stopped before the run finished: that is an error.
            match agent {
                Ok(Ok(())) => Err(RunnerError::AgentStopped),
                Ok(Err(err)) => Err(err),
                Err(join) => Err(RunnerError::AgentPanicked(join)),
            }
        }
    };
    tasks.abort_all();
    while tasks.join_next().await.is_some() {}
    let _ = bus.close().await;
    status
}

/// Starts `agent` as a task of `tasks`, serving `run` on `bus` with `config` until aborted.
fn spawn<A: Agent + 'static>(
    tasks: &mut JoinSet<Result<(), RunnerError>>,
    agent: A,
    bus: &Bus,
    run: &RunId,
    config: A::Config,
) {
    let (bus, run) = (bus.clone(), run.clone());
    tasks.spawn(async move {
        let served = agent.run(&bus, &run, &config, std::future::pending());
        served.await.map(drop).map_err(RunnerError::agent)
    });
}

/// The status before the coordinator's first one.
pub fn placeholder(e: &Embedded) -> RunStatus {
    RunStatus {
        run_id: e.run.clone(),
        phase: graspopt_protocol::RunPhase::Waiting,
        object: e.spec.object.clone(),
        param_names: graspopt_coordinator::param_names(&e.spec),
        budget: e.spec.trials,
        completed: 0,
        running: 0,
        failed: 0,
        best: None,
        best_history: Vec::new(),
        workers: Vec::new(),
        errors: Default::default(),
        stamp_ms: 0,
        waiting: Vec::new(),
        best_forces: None,
    }
}
