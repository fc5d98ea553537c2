//! `graspopt run`: a whole optimization in one process. Every agent (perception, planner,
//! metric, the hand workers, the coordinator) runs as a task on one Zenoh session that listens
//! on loopback only (no router, no multicast), so `graspopt topic` and `graspopt monitor` can
//! attach from another terminal. Results go to a folder: the journal, every trial as CSV and
//! JSON, and pictures (the best grasp, the trials on the parameter space, the scores).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use graspopt_bus::BusArgs;
use graspopt_coordinator::{CoordinatorConfig, RunSpec};
use graspopt_protocol::{PlannerMethod, RunId, RunPhase, RunStatus};
use indicatif::{ProgressBar, ProgressStyle};
use serde::{Deserialize, Serialize};
use tokio::sync::watch;

use super::setup::{Contacts, Frame, SimArgs, param_kind};
use crate::out::outln;
use graspopt_runner::{Embedded, placeholder, run_embedded};

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

#[derive(Args, Debug, Clone)]
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
    #[arg(
        long,
        visible_alias = "axes",
        default_value = "x,y",
        value_delimiter = ','
    )]
    pub params: Vec<String>,
    /// How trials are proposed.
    #[arg(long, value_enum, default_value_t = Method::Bo)]
    pub method: Method,
    /// Size of the initial design (space-filling, not model-based) (default: the engine's).
    #[arg(long)]
    pub initial: Option<u32>,
    /// Seed of the planner's random choices and of perception's noise (the same seed
    /// proposes the same trials).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Results folder (default: results/<run>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Continue the run recorded in the results folder's journal (its only run, unless
    /// --run names one), with its recorded settings and workers (a larger --trials raises
    /// its budget).
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

/// The settings of an embedded run beyond its spec (the object's mesh, the scoring,
/// perception's noise), recorded in the run's spec so that `--resume` restores them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct EmbeddedSettings {
    mesh: Option<PathBuf>,
    /// Runs recorded before `--mesh-scale` existed used their meshes in metres.
    #[serde(default = "unit_scale")]
    mesh_scale: f64,
    contacts: String,
    metric: String,
    frame: String,
    torque_scale: Option<f64>,
    position_noise: f64,
    rotation_noise: f64,
    /// How the run was executed (absent in runs recorded before they were kept): the
    /// proposals depend on the number of workers, so a resumed run keeps it unless
    /// `--workers` is given.
    #[serde(default)]
    workers: Option<usize>,
    #[serde(default)]
    trial_cost_ms: Option<u64>,
    #[serde(default)]
    lease_ms: Option<u64>,
}

fn unit_scale() -> f64 {
    1.0
}

fn value_name<T: ValueEnum>(v: &T) -> String {
    v.to_possible_value()
        .map_or_else(String::new, |p| p.get_name().to_string())
}

impl EmbeddedSettings {
    fn of(args: &RunArgs) -> EmbeddedSettings {
        EmbeddedSettings {
            mesh: args
                .sim
                .mesh
                .as_ref()
                .map(|m| std::fs::canonicalize(m).unwrap_or_else(|_| m.clone())),
            mesh_scale: args.sim.mesh_scale,
            contacts: value_name(&args.sim.contacts),
            metric: args.sim.metric.clone(),
            frame: value_name(&args.sim.frame),
            torque_scale: args.sim.torque_scale,
            position_noise: args.position_noise,
            rotation_noise: args.rotation_noise,
            workers: Some(args.workers),
            trial_cost_ms: Some(args.trial_cost_ms),
            lease_ms: Some(args.lease_ms),
        }
    }
}

/// `args` with the recorded settings of the run they resume (see [`graspopt_coordinator::reconcile`]):
/// a flag given on the command line (`explicit`) that contradicts the record is an error.
fn resumed_args(args: &RunArgs, out: &Path, explicit: &dyn Fn(&str) -> bool) -> Result<RunArgs> {
    let run = RunId::new(&args.run)?;
    let journal = out.join("journal.sqlite");
    if !journal.exists() {
        bail!(
            "no journal at {}: there is nothing to resume (start the run without --resume)",
            journal.display()
        );
    }
    let Some(recorded) = graspopt_coordinator::recorded_spec(&journal, &run)? else {
        let runs = graspopt_coordinator::recorded_runs(&journal)?;
        if runs.is_empty() {
            bail!(
                "run {run:?} is not in {}: there is nothing to resume (start it without --resume)",
                journal.display()
            );
        }
        bail!(
            "run {run:?} is not in {}, which holds run {}: resume one of those (--run ID, or no --run if there is one), or start {run:?} without --resume",
            journal.display(),
            graspopt_coordinator::quoted_runs(&runs),
        );
    };
    let given = RunSpec {
        object: args.sim.object.clone(),
        hand: args.sim.hand.clone(),
        params: args
            .params
            .iter()
            .map(|p| param_kind(p))
            .collect::<Result<Vec<_>>>()?,
        bounds: recorded.bounds.clone(),
        trials: args.trials,
        seed: args.seed,
        method: args.method.planner(),
        initial: args.initial,
        settings: None,
    };
    let mut conflicts = graspopt_coordinator::resume_conflicts(&recorded, &given, explicit);
    let recorded_settings = recorded
        .settings
        .as_ref()
        .and_then(|v| serde_json::from_value::<EmbeddedSettings>(v.clone()).ok());
    if let Some(recorded) = &recorded_settings {
        settings_conflicts(
            &mut conflicts,
            recorded,
            &EmbeddedSettings::of(args),
            explicit,
        );
    }
    if let Some(e) = conflicts.into_error(&run) {
        return Err(e);
    }
    let spec = graspopt_coordinator::reconcile(&run, &recorded, &given, explicit)?;
    let mut out_args = args.clone();
    out_args.sim.hand = spec.hand.clone();
    out_args.params = spec.params.iter().map(|k| k.name().to_string()).collect();
    out_args.trials = spec.trials;
    out_args.seed = spec.seed;
    out_args.method = match spec.method {
        PlannerMethod::Bo => Method::Bo,
        PlannerMethod::Random => Method::Random,
    };
    out_args.initial = spec.initial;
    let Some(recorded_settings) = recorded_settings else {
        // Created by a standalone coordinator: only the spec is on record.
        if args.sim.mesh.is_none() {
            out_args.sim.object = spec.object.clone();
        }
        return Ok(out_args);
    };
    out_args.sim.mesh = recorded_settings.mesh.clone();
    out_args.sim.mesh_scale = recorded_settings.mesh_scale;
    if out_args.sim.mesh.is_none() {
        out_args.sim.object = spec.object.clone();
    }
    out_args.sim.contacts = Contacts::from_str(&recorded_settings.contacts, true)
        .map_err(|e| anyhow::anyhow!("run {run:?}: recorded contact model: {e}"))?;
    out_args.sim.metric = recorded_settings.metric.clone();
    out_args.sim.frame = Frame::from_str(&recorded_settings.frame, true)
        .map_err(|e| anyhow::anyhow!("run {run:?}: recorded frame: {e}"))?;
    out_args.sim.torque_scale = recorded_settings.torque_scale;
    out_args.position_noise = recorded_settings.position_noise;
    out_args.rotation_noise = recorded_settings.rotation_noise;
    // The workers, trial cost and lease the run was started with, unless given now.
    if let Some(v) = recorded_settings.workers.filter(|_| !explicit("workers")) {
        out_args.workers = v;
    }
    if let Some(v) = recorded_settings
        .trial_cost_ms
        .filter(|_| !explicit("trial_cost_ms"))
    {
        out_args.trial_cost_ms = v;
    }
    if let Some(v) = recorded_settings.lease_ms.filter(|_| !explicit("lease_ms")) {
        out_args.lease_ms = v;
    }
    Ok(out_args)
}

/// Notes the scoring and perception flags given on the command line that contradict the
/// record.
fn settings_conflicts(
    c: &mut graspopt_coordinator::Conflicts,
    recorded: &EmbeddedSettings,
    given: &EmbeddedSettings,
    explicit: &dyn Fn(&str) -> bool,
) {
    let path = |m: &Option<PathBuf>| {
        m.as_ref()
            .map_or("none".into(), |p| p.display().to_string())
    };
    c.check(explicit, "mesh", path(&given.mesh), path(&recorded.mesh));
    c.check(
        explicit,
        "mesh_scale",
        given.mesh_scale,
        recorded.mesh_scale,
    );
    c.check(explicit, "contacts", &given.contacts, &recorded.contacts);
    c.check(explicit, "metric", &given.metric, &recorded.metric);
    c.check(explicit, "frame", &given.frame, &recorded.frame);
    let scale = |t: Option<f64>| t.map_or("the object's radius".into(), |v| v.to_string());
    let (given_scale, recorded_scale) = (scale(given.torque_scale), scale(recorded.torque_scale));
    c.check(explicit, "torque_scale", given_scale, recorded_scale);
    let (p, r) = (given.position_noise, recorded.position_noise);
    c.check(explicit, "position_noise", p, r);
    let (p, r) = (given.rotation_noise, recorded.rotation_noise);
    c.check(explicit, "rotation_noise", p, r);
}

/// Refuses a new run in a results folder whose journal holds other runs: their
/// `trials.csv`, `trials.json` and `best.svg` would be overwritten.
fn check_folder_is_free(out: &Path, run: &RunId) -> Result<()> {
    let path = out.join("journal.sqlite");
    if !path.exists() {
        return Ok(());
    }
    let journal = graspopt_journal::Journal::open(&path)
        .with_context(|| format!("cannot open the journal {}", path.display()))?;
    let others: Vec<String> = journal
        .runs()?
        .into_iter()
        .map(|r| r.run_id)
        .filter(|id| id != run.as_str())
        .collect();
    if !others.is_empty() {
        bail!(
            "the results folder {} holds run {} already (its trials.csv, trials.json and best.svg would be overwritten): choose another --out, or resume {} with --resume --out {}{}",
            out.display(),
            graspopt_coordinator::quoted_runs(&others),
            if others.len() == 1 { "it" } else { "one" },
            out.display(),
            if others.len() == 1 { "" } else { " --run ID" }
        );
    }
    Ok(())
}

/// The run the flags describe, nothing taken as given explicitly (see [`embedded_with`]).
pub fn embedded(args: &RunArgs) -> Result<Embedded> {
    embedded_with(args, &|_| false)
}

/// The run the flags describe. With `--resume`, the run's recorded settings replace the
/// flags' defaults; `explicit(name)` says whether `--name` was given on the command line.
pub fn embedded_with(args: &RunArgs, explicit: &dyn Fn(&str) -> bool) -> Result<Embedded> {
    let mut run = RunId::new(&args.run)?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("results").join(run.as_str()));
    // `--resume --out DIR` continues the run of DIR's journal: its id need not be given.
    if args.resume
        && !explicit("run")
        && let Some(only) = graspopt_coordinator::sole_run(&out.join("journal.sqlite"))?
    {
        run = only;
    }
    let resumed;
    let args = if args.resume {
        let named = RunArgs {
            run: run.as_str().to_string(),
            ..args.clone()
        };
        resumed = resumed_args(&named, &out, explicit)?;
        &resumed
    } else {
        check_folder_is_free(&out, &run)?;
        args
    };
    anyhow::ensure!(args.workers >= 1, "--workers must be at least 1");
    anyhow::ensure!(args.trials >= 1, "--trials must be at least 1");
    let kinds = args
        .params
        .iter()
        .map(|p| param_kind(p))
        .collect::<Result<Vec<_>>>()?;
    let evaluator = args.sim.evaluator(&kinds)?;
    let object_name = evaluator.object.name().to_string();
    let bus = graspopt_runner::embedded::own_bus(args.bus.clone(), &run)?;
    let perception = graspopt_perception::PerceptionConfig {
        object: object_name.clone(),
        mesh: args.sim.mesh.clone(),
        mesh_scale: args.sim.mesh_scale,
        position_noise: args.position_noise,
        rotation_noise: args.rotation_noise,
        seed: args.seed,
        period_ms: 500,
        ..Default::default()
    };
    // Checked before anything is written, so a refused run leaves no trace.
    perception
        .validate()
        .map_err(|e| anyhow::anyhow!("{e:#}").context("--position-noise / --rotation-noise"))?;
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
            settings: Some(serde_json::to_value(EmbeddedSettings::of(args))?),
        },
        workers: args.workers,
        resume: args.resume,
        perception,
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
        evaluator,
    })
}

/// Writes `trials.csv`, `trials.json` and the pictures from the journal
/// ([`graspopt_report::run::write_results`]).
pub fn write_results(e: &Embedded, status: &RunStatus) -> Result<()> {
    let folder = graspopt_report::run::RunFolder {
        out: &e.out,
        journal: &e.coordinator.journal,
        run: e.run.as_str(),
        params: &e.spec.params,
        evaluator: &e.evaluator,
    };
    graspopt_report::run::write_results(&folder, &status.object)
}

/// `graspopt run`; `explicit(name)` says whether `--name` was given on the command line.
pub fn run(args: &RunArgs, explicit: &dyn Fn(&str) -> bool) -> Result<ExitCode> {
    let e = embedded_with(args, explicit)?;
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
            "graspopt: run {:?} on {endpoint} (attach with --connect)",
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
    let stopped = status.phase != RunPhase::Finished;
    outln!(
        "run {:?}: {} trials completed, {} failed{}",
        status.run_id,
        status.completed,
        status.failed,
        if stopped {
            format!(
                " (stopped; continue with --resume --out {})",
                e.out.display()
            )
        } else {
            String::new()
        }
    )?;
    if let Some(b) = &status.best {
        outln!(
            "best: trial {} score {} at {}",
            b.trial_id,
            b.score,
            named_params(&status.param_names, &b.params, ",")
        )?;
    }
    outln!("results: {}", e.out.display())?;
    // 130: the shell's code for a command stopped by Ctrl-C.
    Ok(if stopped {
        ExitCode::from(130)
    } else {
        ExitCode::SUCCESS
    })
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
