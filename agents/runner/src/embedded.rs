//! Every agent of a run in this process, on one loopback bus: the main job's embedded default.

use std::path::PathBuf;

use anyhow::{Context, Result};
use graspopt_bus::{Bus, BusArgs, free_loopback_port};
use graspopt_coordinator::{CoordinatorConfig, RunSpec};
use graspopt_protocol::{RunId, RunStatus};
use tokio::sync::watch;

/// Everything one embedded run needs, resolved from flags (`graspopt run` builds it).
pub struct Embedded {
    pub run: RunId,
    pub spec: RunSpec,
    pub workers: usize,
    pub out: PathBuf,
    pub resume: bool,
    pub perception: graspopt_perception::PerceptionConfig,
    pub metric: graspopt_metric::MetricConfig,
    pub hand: graspopt_hand::HandConfig,
    pub coordinator: CoordinatorConfig,
    pub bus: BusArgs,
    /// The trials as simulated here (for the pictures of the results).
    pub evaluator: graspopt_trial::Evaluator,
}

/// The bus of an embedded run: unless `bus` names an endpoint or a Zenoh configuration, a free
/// loopback port with multicast scouting off (no other run on the network hears it); unless
/// it names a shared-memory prefix, one of this run and this process.
pub fn own_bus(mut bus: BusArgs, run: &RunId) -> Result<BusArgs> {
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
) -> Result<RunStatus> {
    // Before anything is written: a run refused for its open-file limit leaves no trace.
    crate::open_files::ensure(e.workers)?;
    std::fs::create_dir_all(&e.out)
        .with_context(|| format!("cannot create the results folder {}", e.out.display()))?;
    let bus = Bus::open(&e.bus).await?;
    let mut tasks = tokio::task::JoinSet::new();
    {
        let (b, r, c) = (bus.clone(), e.run.clone(), e.perception.clone());
        tasks.spawn(async move { graspopt_perception::run(&b, &r, &c).await });
    }
    {
        let (b, r) = (bus.clone(), e.run.clone());
        tasks.spawn(async move {
            graspopt_planner::run(&b, &r, &graspopt_planner::PlannerConfig::default()).await
        });
    }
    {
        let (b, r, c) = (bus.clone(), e.run.clone(), e.metric.clone());
        tasks.spawn(async move { graspopt_metric::run(&b, &r, &c).await });
    }
    for i in 1..=e.workers {
        let (b, r) = (bus.clone(), e.run.clone());
        let c = graspopt_hand::HandConfig {
            id: format!("hand-{i}"),
            ..e.hand.clone()
        };
        tasks.spawn(async move { graspopt_hand::run(&b, &r, &c).await });
    }
    // Ctrl-C (or SIGTERM) stops the run cleanly: the journal records it as stopped.
    let coordinator = graspopt_coordinator::run_until(
        &bus,
        &e.run,
        &e.spec,
        &e.coordinator,
        e.resume,
        progress,
        crate::signal::shutdown_signal(),
    );
    let status = tokio::select! {
        s = coordinator => s.map_err(anyhow::Error::from),
        Some(agent) = tasks.join_next() => {
            // An agent stopped before the run finished: that is an error.
            match agent {
                Ok(Ok(())) => Err(anyhow::anyhow!("an agent stopped before the run finished")),
                Ok(Err(err)) => Err(err),
                Err(join) => Err(anyhow::anyhow!("an agent panicked: {join}")),
            }
        }
    };
    tasks.abort_all();
    while tasks.join_next().await.is_some() {}
    let _ = bus.close().await;
    status
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
