//! `graspopt run`: a whole optimization in one process. Every agent (perception, planner,
//! metric, the hand workers, the coordinator) runs as a task on one Zenoh session that listens
//! on loopback only (no router, no multicast), so `graspopt topic` and `graspopt monitor` can
//! attach from another terminal. Results go to a folder: the journal, a CSV of every trial and
//! a plot of the best score so far.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use graspopt_bus::{Bus, BusArgs, free_loopback_port};
use graspopt_coordinator::{CoordinatorConfig, RunSpec};
use graspopt_protocol::{PlannerMethod, RunId, RunStatus};
use indicatif::{ProgressBar, ProgressStyle};
use tokio::sync::watch;

use super::setup::{SimArgs, param_kind};
use super::svg;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// Bayesian optimization (GP, EI, DIRECT).
    Bo,
    /// Uniform random search (a baseline).
    Random,
}

impl Method {
    pub fn planner(self) -> PlannerMethod {
        match self {
            Method::Bo => PlannerMethod::Bo,
            Method::Random => PlannerMethod::Random,
        }
    }
}

#[derive(Args, Debug)]
pub struct RunArgs {
    #[command(flatten)]
    pub sim: SimArgs,
    /// Run id (one key chunk: letters, digits, '-', '_', '.').
    #[arg(long, default_value = "run")]
    pub run: String,
    /// Number of simulated hand workers.
    #[arg(long, default_value_t = 3)]
    pub workers: usize,
    /// Number of trials.
    #[arg(long, default_value_t = 60)]
    pub trials: u64,
    /// Trial parameters, comma-separated: x (approach), y (vertical), lateral, rx, ry, rz.
    #[arg(long, default_value = "x,y", value_delimiter = ',')]
    pub params: Vec<String>,
    /// How trials are proposed.
    #[arg(long, value_enum, default_value_t = Method::Bo)]
    pub method: Method,
    /// Size of the initial design (space-filling, not model-based) (default: the engine's).
    #[arg(long)]
    pub initial: Option<u32>,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Results folder (default: results/<run>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Continue the run recorded in the results folder's journal.
    #[arg(long)]
    pub resume: bool,
    /// Minimum duration of a simulated trial, to model a robot (milliseconds).
    #[arg(long, default_value_t = 0)]
    pub trial_cost_ms: u64,
    /// Lease of a trial: re-issued if no result comes within this time (milliseconds).
    #[arg(long, default_value_t = 30_000)]
    pub lease_ms: u64,
    /// Perception's position error, standard deviation per axis (metres).
    #[arg(long, default_value_t = 0.0)]
    pub position_noise: f64,
    /// Perception's orientation error, standard deviation per axis (radians).
    #[arg(long, default_value_t = 0.0)]
    pub rotation_noise: f64,
    /// No progress bar (for logs and scripts).
    #[arg(long)]
    pub quiet: bool,
    #[command(flatten)]
    pub bus: BusArgs,
}

/// Everything one embedded run needs, resolved from flags.
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
}

impl Embedded {
    pub fn from_args(args: &RunArgs) -> Result<Embedded> {
        let run = RunId::new(&args.run)?;
        anyhow::ensure!(args.workers >= 1, "--workers must be at least 1");
        anyhow::ensure!(args.trials >= 1, "--trials must be at least 1");
        let kinds = args
            .params
            .iter()
            .map(|p| param_kind(p))
            .collect::<Result<Vec<_>>>()?;
        let evaluator = args.sim.evaluator(&kinds)?;
        let object_name = evaluator.object.name().to_string();
        let out = args
            .out
            .clone()
            .unwrap_or_else(|| Path::new("results").join(run.as_str()));
        let mut bus = args.bus.clone();
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
        Ok(Embedded {
            spec: RunSpec {
                object: object_name.clone(),
                hand: args.sim.hand.clone(),
                params: kinds,
                bounds: None,
                trials: args.trials,
                seed: args.seed,
                method: args.method.planner(),
                initial: args.initial,
            },
            workers: args.workers,
            resume: args.resume,
            perception: graspopt_perception::PerceptionConfig {
                object: object_name,
                mesh: args.sim.mesh.clone(),
                position_noise: args.position_noise,
                rotation_noise: args.rotation_noise,
                seed: args.seed,
                period_ms: 500,
                ..Default::default()
            },
            metric: graspopt_metric::MetricConfig {
                score: evaluator.score,
                contacts: evaluator.contacts,
                ..Default::default()
            },
            hand: graspopt_hand::HandConfig {
                hand: args.sim.hand.clone(),
                trial_cost_ms: args.trial_cost_ms,
                ..Default::default()
            },
            coordinator: CoordinatorConfig {
                journal: out.join("journal.sqlite"),
                lease_ms: args.lease_ms,
                ..Default::default()
            },
            out,
            run,
            bus,
        })
    }
}

/// Runs every agent in this process until the coordinator finishes.
pub async fn run_embedded(
    e: &Embedded,
    progress: Option<watch::Sender<RunStatus>>,
) -> Result<RunStatus> {
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
    let coordinator =
        graspopt_coordinator::run(&bus, &e.run, &e.spec, &e.coordinator, e.resume, progress);
    let status = tokio::select! {
        s = coordinator => s,
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

/// Writes `trials.csv`, `trials.json` and `best.svg` from the journal.
pub fn write_results(e: &Embedded, status: &RunStatus) -> Result<()> {
    let journal = graspopt_journal::Journal::open(&e.coordinator.journal)?;
    let csv = e.out.join("trials.csv");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&csv)?);
    graspopt_journal::export::write_csv(&journal, e.run.as_str(), &mut f)?;
    let json = e.out.join("trials.json");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&json)?);
    graspopt_journal::export::write_json(&journal, e.run.as_str(), &mut f)?;
    let xs: Vec<f64> = (1..=status.best_history.len()).map(|i| i as f64).collect();
    let plot = svg::line_plot(
        &format!("{}: best score so far", status.object),
        "trial",
        "best score",
        &xs,
        &status.best_history,
    );
    std::fs::write(e.out.join("best.svg"), plot)?;
    Ok(())
}

pub fn run(args: &RunArgs) -> Result<ExitCode> {
    let e = Embedded::from_args(args)?;
    let runtime = tokio::runtime::Runtime::new()?;
    let (status_tx, mut status_rx) = watch::channel(placeholder(&e));
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        let bar = ProgressBar::new(e.spec.trials);
        bar.set_style(
            ProgressStyle::with_template("{bar:30} {pos}/{len} trials  {elapsed}  {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar
    };
    let endpoint = e.bus.listen.join(", ");
    if !args.quiet && !endpoint.is_empty() {
        eprintln!(
            "graspopt: run {} on {endpoint} (attach with --connect)",
            e.run
        );
    }
    let status = runtime.block_on(async {
        let follow = {
            let bar = bar.clone();
            tokio::spawn(async move {
                while status_rx.changed().await.is_ok() {
                    let s = status_rx.borrow().clone();
                    bar.set_position(s.completed + s.failed);
                    if let Some(b) = &s.best {
                        bar.set_message(format!(
                            "best {:.4} (trial {}){}",
                            b.score,
                            b.trial_id,
                            if b.force_closure == Some(true) {
                                ", force closure"
                            } else {
                                ""
                            }
                        ));
                    }
                }
            })
        };
        let s = run_embedded(&e, Some(status_tx)).await;
        follow.abort();
        s
    })?;
    bar.finish_and_clear();
    write_results(&e, &status)?;
    println!(
        "run {}: {} trials completed, {} failed",
        status.run_id, status.completed, status.failed
    );
    if let Some(b) = &status.best {
        println!(
            "best: trial {} score {} at {}",
            b.trial_id,
            b.score,
            named_params(&status.param_names, &b.params, ",")
        );
    }
    println!("results: {}", e.out.display());
    Ok(ExitCode::SUCCESS)
}

/// `name=value` for each parameter (5 decimals), joined by `sep`.
pub fn named_params(names: &[String], values: &[f64], sep: &str) -> String {
    let parts: Vec<String> = names
        .iter()
        .zip(values)
        .map(|(n, v)| format!("{n}={v:.5}"))
        .collect();
    parts.join(sep)
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
    }
}
