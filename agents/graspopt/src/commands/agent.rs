//! `graspopt agent <kind>`: one agent as its own process, on the bus the flags describe.
//! Settings come from `--config FILE` (TOML, the agent's settings struct) and flags override
//! them.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use graspopt_bus::{Bus, BusArgs};
use graspopt_coordinator::{CoordinatorConfig, RunSpec};
use graspopt_protocol::RunId;
use serde::de::DeserializeOwned;

use super::run::Method;
use super::setup::{SimArgs, param_kind};

#[derive(Args, Debug)]
pub struct AgentArgs {
    #[command(subcommand)]
    pub kind: Kind,
}

#[derive(Args, Debug, Clone)]
pub struct Common {
    /// The run to join.
    #[arg(long, default_value = "run")]
    pub run: String,
    /// Settings file (TOML).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Agent id (unique per run and kind).
    #[arg(long)]
    pub id: Option<String>,
    #[command(flatten)]
    pub bus: BusArgs,
}

#[derive(Subcommand, Debug)]
pub enum Kind {
    /// Publishes the object estimate.
    Perception {
        #[command(flatten)]
        common: Common,
        /// Built-in object.
        #[arg(long)]
        object: Option<String>,
        /// A user mesh (OBJ/STL).
        #[arg(long)]
        mesh: Option<PathBuf>,
        #[arg(long)]
        position_noise: Option<f64>,
        #[arg(long)]
        rotation_noise: Option<f64>,
        #[arg(long)]
        seed: Option<u64>,
    },
    /// Executes trials on the simulated hand.
    Hand {
        #[command(flatten)]
        common: Common,
        /// A built-in hand (see `graspopt hands`) or a URDF file.
        #[arg(long)]
        hand: Option<String>,
        /// Minimum trial duration (milliseconds).
        #[arg(long)]
        trial_cost_ms: Option<u64>,
        /// Answer trials from recorded contact data (JSON lines, `graspopt record` writes
        /// them) instead of simulating.
        #[arg(long, value_name = "FILE")]
        replay: Option<PathBuf>,
    },
    /// Scores contact clouds.
    Metric {
        #[command(flatten)]
        common: Common,
    },
    /// Proposes trials.
    Planner {
        #[command(flatten)]
        common: Common,
    },
    /// Owns the run and its journal.
    Coordinator {
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        sim: SimArgs,
        /// The journal file (default: results/<run>/journal.sqlite, where `graspopt export`
        /// looks).
        #[arg(long)]
        journal: Option<PathBuf>,
        /// Number of trials (with --resume: raises the recorded budget).
        #[arg(long, default_value_t = 60)]
        trials: u64,
        /// Trial parameters, comma-separated: x (approach), y (vertical), lateral, rx, ry, rz.
        #[arg(
            long,
            visible_alias = "axes",
            default_value = "x,y",
            value_delimiter = ','
        )]
        params: Vec<String>,
        #[arg(long, value_enum, default_value_t = Method::Bo)]
        method: Method,
        #[arg(long)]
        initial: Option<u32>,
        #[arg(long, default_value_t = 0)]
        seed: u64,
        #[arg(long)]
        lease_ms: Option<u64>,
        /// Continue the run recorded in the journal, with its recorded settings.
        #[arg(long)]
        resume: bool,
    },
}

/// Reads a TOML settings file (defaults when none).
pub fn load<T: DeserializeOwned + Default>(path: Option<&Path>) -> Result<T> {
    match path {
        None => Ok(T::default()),
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .with_context(|| format!("cannot read the settings file {}", p.display()))?;
            toml::from_str(&text).with_context(|| format!("settings file {}", p.display()))
        }
    }
}

/// Resolves on Ctrl-C or SIGTERM.
pub async fn shutdown_signal() {
    let term = async {
        #[cfg(unix)]
        if let Ok(mut s) = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())
        {
            s.recv().await;
            return;
        }
        std::future::pending::<()>().await
    };
    tokio::select! {
        _ = tokio::signal::ctrl_c() => {},
        _ = term => {},
    }
}

async fn until_signal<F: std::future::Future<Output = Result<()>>>(agent: F) -> Result<()> {
    tokio::select! {
        r = agent => r,
        _ = shutdown_signal() => Ok(()),
    }
}

/// `graspopt agent`; `explicit(name)` says whether `--name` was given on the command line.
pub fn run(args: &AgentArgs, explicit: &dyn Fn(&str) -> bool) -> Result<ExitCode> {
    let runtime = tokio::runtime::Runtime::new()?;
    runtime.block_on(run_async(args, explicit))
}

async fn run_async(args: &AgentArgs, explicit: &dyn Fn(&str) -> bool) -> Result<ExitCode> {
    match &args.kind {
        Kind::Perception {
            common,
            object,
            mesh,
            position_noise,
            rotation_noise,
            seed,
        } => {
            let mut c: graspopt_perception::PerceptionConfig = load(common.config.as_deref())?;
            if let Some(v) = &common.id {
                c.id = v.clone();
            }
            if let Some(v) = object {
                c.object = v.clone();
            }
            if mesh.is_some() {
                c.mesh = mesh.clone();
            }
            c.position_noise = position_noise.unwrap_or(c.position_noise);
            c.rotation_noise = rotation_noise.unwrap_or(c.rotation_noise);
            c.seed = seed.unwrap_or(c.seed);
            let (bus, run) = join(common).await?;
            until_signal(graspopt_perception::run(&bus, &run, &c)).await?;
            Ok(ExitCode::SUCCESS)
        }
        Kind::Hand {
            common,
            hand,
            trial_cost_ms,
            replay,
        } => {
            let mut c: graspopt_hand::HandConfig = load(common.config.as_deref())?;
            if let Some(v) = &common.id {
                c.id = v.clone();
            }
            if let Some(v) = hand {
                c.hand = v.clone();
            }
            c.trial_cost_ms = trial_cost_ms.unwrap_or(c.trial_cost_ms);
            if replay.is_some() {
                c.replay = replay.clone();
            }
            let (bus, run) = join(common).await?;
            until_signal(graspopt_hand::run(&bus, &run, &c)).await?;
            Ok(ExitCode::SUCCESS)
        }
        Kind::Metric { common } => {
            let mut c: graspopt_metric::MetricConfig = load(common.config.as_deref())?;
            if let Some(v) = &common.id {
                c.id = v.clone();
            }
            let (bus, run) = join(common).await?;
            until_signal(graspopt_metric::run(&bus, &run, &c)).await?;
            Ok(ExitCode::SUCCESS)
        }
        Kind::Planner { common } => {
            let mut c: graspopt_planner::PlannerConfig = load(common.config.as_deref())?;
            if let Some(v) = &common.id {
                c.id = v.clone();
            }
            let (bus, run) = join(common).await?;
            until_signal(graspopt_planner::run(&bus, &run, &c)).await?;
            Ok(ExitCode::SUCCESS)
        }
        Kind::Coordinator {
            common,
            sim,
            journal,
            trials,
            params,
            method,
            initial,
            seed,
            lease_ms,
            resume,
        } => {
            let mut c: CoordinatorConfig = load(common.config.as_deref())?;
            if let Some(v) = &common.id {
                c.id = v.clone();
            }
            if let Some(v) = journal {
                c.journal = v.clone();
            }
            c.lease_ms = lease_ms.unwrap_or(c.lease_ms);
            let kinds = params
                .iter()
                .map(|p| param_kind(p))
                .collect::<Result<Vec<_>>>()?;
            anyhow::ensure!(*trials >= 1, "--trials must be at least 1");
            let run_id = RunId::new(&common.run)?;
            let given = RunSpec {
                object: sim.object()?.name().to_string(),
                hand: sim.hand.clone(),
                params: kinds,
                bounds: None,
                trials: *trials,
                seed: *seed,
                method: method.planner(),
                initial: *initial,
                settings: None,
            };
            let journal_path = c.journal_path(&run_id);
            // With --resume, the recorded run's settings win (flags that contradict them are
            // refused); a run not recorded yet is started, so that a supervised coordinator
            // can be restarted with one command line.
            let recorded = if *resume {
                graspopt_coordinator::recorded_spec(&journal_path, &run_id)?
            } else {
                None
            };
            let spec = match recorded {
                Some(recorded) => {
                    graspopt_coordinator::reconcile(&run_id, &recorded, &given, explicit)?
                }
                None => given,
            };
            if let Some(dir) = journal_path.parent()
                && !dir.as_os_str().is_empty()
            {
                std::fs::create_dir_all(dir)
                    .with_context(|| format!("cannot create the folder {}", dir.display()))?;
            }
            let (bus, run) = join(common).await?;
            let status = graspopt_coordinator::run_until(
                &bus,
                &run,
                &spec,
                &c,
                *resume,
                None,
                shutdown_signal(),
            )
            .await?;
            println!("{}", serde_json::to_string(&status)?);
            // 130: the shell's code for a command stopped by Ctrl-C.
            Ok(if status.phase == graspopt_protocol::RunPhase::Finished {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(130)
            })
        }
    }
}

async fn join(common: &Common) -> Result<(Bus, RunId)> {
    let run = RunId::new(&common.run)?;
    let bus = Bus::open(&common.bus).await?;
    Ok((bus, run))
}
