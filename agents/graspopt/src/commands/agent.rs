//! `graspopt agent <kind>`: one agent as its own process, on the bus the flags describe.
//! Settings come from `--config FILE` (TOML, the agent's settings struct) and flags override
//! them.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use graspopt_bus::{Bus, BusArgs};
use graspopt_coordinator::{CoordinatorConfig, MAX_TRIALS, MAX_WAIT_MS, RunSpec};
use graspopt_protocol::PlannerMethod;
use graspopt_protocol::RunId;
use graspopt_runner::config::load;
use graspopt_runner::ending::RunEnd;
use graspopt_runner::signal::{shutdown_signal, until_signal};
use graspopt_sim::ParamKind;

use super::setup::{SimArgs, count, planner_method, sensing, trial_param};
use crate::out::outln;

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
    /// Settings file (TOML; its keys, with an example per agent: docs/agent-config.md).
    /// Flags given win over it.
    #[arg(long, value_name = "FILE")]
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
        /// Built-in object: sphere, wine_glass, cylinder, mug, cuboid, rotated_cuboid,
        /// star_prism (default: mug).
        #[arg(long)]
        object: Option<String>,
        /// A user mesh (OBJ/STL).
        #[arg(long)]
        mesh: Option<PathBuf>,
        /// Factor from the mesh file's units to metres (0.001 for millimetres).
        #[arg(long, requires = "mesh")]
        mesh_scale: Option<f64>,
        /// Position error of the estimate, standard deviation per axis (metres; default 0).
        #[arg(long)]
        position_noise: Option<f64>,
        /// Orientation error of the estimate, standard deviation per axis (radians; default
        /// 0).
        #[arg(long)]
        rotation_noise: Option<f64>,
        /// Seed of the estimate's noise (default 0).
        #[arg(long, value_parser = count::<u64>(0, u64::MAX))]
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
        #[arg(long, value_parser = count::<u64>(0, u64::MAX))]
        trial_cost_ms: Option<u64>,
        /// Answer trials from recorded contact data (JSON lines, `graspopt record` writes
        /// them) instead of simulating.
        #[arg(long, value_name = "FILE")]
        replay: Option<PathBuf>,
        /// What the simulated hand measures: clouds (contact points and normals), or ft
        /// (force/torque sensors under spherical fingertips: use --hand barrett_ft).
        #[arg(long, value_parser = sensing())]
        sensing: Option<graspopt_hand::Sensing>,
        /// Fingertip sensors' force resolution (N; the noise's standard deviation and
        /// quantum; default 1/320, an ATI Nano17's; 0: exact).
        #[arg(long, requires = "sensing")]
        force_resolution: Option<f64>,
        /// Fingertip sensors' torque resolution (N m; default 1.5625e-5, 1/64 N mm; 0: exact).
        #[arg(long, requires = "sensing")]
        torque_resolution: Option<f64>,
    },
    /// Scores contact clouds and fingertip force readings.
    Metric {
        #[command(flatten)]
        common: Common,
        /// The object's mass for the force analysis (kg; default 0.5).
        #[arg(long)]
        object_mass: Option<f64>,
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
        #[arg(long, default_value_t = 60, value_parser = count::<u64>(1, MAX_TRIALS))]
        trials: u64,
        /// Trial parameters, comma-separated: x (approach), y (vertical), lateral, rx, ry, rz.
        #[arg(
            long,
            visible_alias = "axes",
            default_value = "x,y",
            value_delimiter = ',',
            value_parser = trial_param()
        )]
        params: Vec<ParamKind>,
        /// How trials are proposed: bo or random.
        #[arg(long, default_value = "bo", value_parser = planner_method())]
        method: PlannerMethod,
        /// Size of the initial design (space-filling, not model-based) (default: the
        /// engine's).
        #[arg(long, value_parser = count::<u32>(0, u32::MAX.into()))]
        initial: Option<u32>,
        /// Seed of the planner's random choices (the same seed proposes the same trials).
        #[arg(long, default_value_t = 0, value_parser = count::<u64>(0, u64::MAX))]
        seed: u64,
        /// Lease of a trial: re-issued if no result comes within this time (milliseconds;
        /// default 30000).
        #[arg(long, value_parser = count::<u64>(1, MAX_WAIT_MS))]
        lease_ms: Option<u64>,
        /// Continue the run recorded in the journal (its only run, unless --run names one),
        /// with its recorded settings. Without --resume, a run recorded with no trial (a
        /// start that stopped before its first) starts afresh.
        #[arg(long)]
        resume: bool,
    },
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
            mesh_scale,
            position_noise,
            rotation_noise,
            seed,
        } => {
            let mut c: graspopt_perception::PerceptionConfig = load(common.config.as_deref())?;
            common.set_id(&mut c.id);
            if let Some(v) = object {
                c.object = v.clone();
            }
            if mesh.is_some() {
                c.mesh = mesh.clone();
            }
            c.mesh_scale = mesh_scale.unwrap_or(c.mesh_scale);
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
            sensing,
            force_resolution,
            torque_resolution,
        } => {
            let mut c: graspopt_hand::HandConfig = load(common.config.as_deref())?;
            common.set_id(&mut c.id);
            if let Some(v) = hand {
                c.hand = v.clone();
            }
            c.trial_cost_ms = trial_cost_ms.unwrap_or(c.trial_cost_ms);
            if replay.is_some() {
                c.replay = replay.clone();
            }
            c.sensing = sensing.unwrap_or(c.sensing);
            let noise = &mut c.fingertips.noise;
            noise.force_resolution = force_resolution.unwrap_or(noise.force_resolution);
            noise.torque_resolution = torque_resolution.unwrap_or(noise.torque_resolution);
            graspopt_hand::check(&c)?;
            let (bus, run) = join(common).await?;
            until_signal(graspopt_hand::run(&bus, &run, &c)).await?;
            Ok(ExitCode::SUCCESS)
        }
        Kind::Metric {
            common,
            object_mass,
        } => {
            let mut c: graspopt_metric::MetricConfig = load(common.config.as_deref())?;
            common.set_id(&mut c.id);
            c.forces.object_mass = object_mass.unwrap_or(c.forces.object_mass);
            let (bus, run) = join(common).await?;
            until_signal(graspopt_metric::run(&bus, &run, &c)).await?;
            Ok(ExitCode::SUCCESS)
        }
        Kind::Planner { common } => {
            let mut c: graspopt_planner::PlannerConfig = load(common.config.as_deref())?;
            common.set_id(&mut c.id);
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
            common.set_id(&mut c.id);
            if let Some(v) = journal {
                c.journal = v.clone();
            }
            c.lease_ms = lease_ms.unwrap_or(c.lease_ms);
            let object = sim.object()?;
            let given = RunSpec {
                object: object.name().to_string(),
                hand: graspopt_sim::hand_name(&sim.hand).with_context(|| {
                    format!(
                        "--hand {}: the coordinator knows a hand by its name; where its file \
                         is not on this host, give the name `graspopt hands FILE` prints",
                        sim.hand
                    )
                })?,
                params: params.clone(),
                bounds: None,
                trials: *trials,
                seed: *seed,
                method: *method,
                initial: *initial,
                settings: None,
            };
            let (run_id, spec) = graspopt_coordinator::standalone_run(
                &common.run,
                &c,
                given,
                &object,
                &sim.range,
                *resume,
                explicit,
            )?;
            let bus = Bus::open(&common.bus).await?;
            let status = graspopt_coordinator::run_until(
                &bus,
                &run_id,
                &spec,
                &c,
                *resume,
                None,
                shutdown_signal(),
            )
            .await?;
            let end = RunEnd::read(status, &c.journal_path(&run_id))?;
            outln!("{}", end.json()?)?;
            for line in end.lines(" (stopped)") {
                eprintln!("coordinator: {line}");
            }
            Ok(ExitCode::from(end.exit_code()))
        }
    }
}

impl Common {
    /// `--id`, when given, over the settings file's id.
    fn set_id(&self, id: &mut String) {
        if let Some(v) = &self.id {
            id.clone_from(v);
        }
    }
}

async fn join(common: &Common) -> Result<(Bus, RunId)> {
    let run = RunId::new(&common.run)?;
    let bus = Bus::open(&common.bus).await?;
    Ok((bus, run))
}
