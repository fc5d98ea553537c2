//! `graspopt run`: a whole optimization in one process. Every agent (perception, planner,
//! metric, the hand workers, the coordinator) runs as a task on one Zenoh session that listens
//! on loopback only (no router, no multicast), so `graspopt topic` and `graspopt monitor` can
//! attach from another terminal. Results go to a folder: the journal, every trial as CSV and
//! JSON, and pictures (the best grasp, the trials on the parameter space, the scores).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::Args;
use graspopt_protocol::PlannerMethod;
use graspopt_protocol::text::rounded;
use graspopt_sim::ParamKind;
use indicatif::{ProgressBar, ProgressStyle};
use tokio::sync::watch;

use super::bus::BusArgs;
use super::setup::{SimArgs, count, planner_method, sensing, trial_param};
use crate::out::outln;
use graspopt_coordinator::{MAX_TRIALS, MAX_WAIT_MS};
use graspopt_runner::ending::RunEnd;
use graspopt_runner::{RunSettings, placeholder, run_embedded};

#[derive(Args, Debug, Clone)]
pub struct RunArgs {
    #[command(flatten)]
    pub sim: SimArgs,
    /// Run id (one key chunk: letters, digits, '-', '_', '.').
    #[arg(long, default_value = "run")]
    pub run: String,
    /// Number of simulated hand workers (0: none, the run waits for hands that attach to
    /// its endpoint, `--listen`, such as a real hand's agent).
    #[arg(long, default_value_t = 3, value_parser = count::<usize>(0, u64::MAX))]
    pub workers: usize,
    /// What the simulated hands measure: clouds (contact clouds) or ft (fingertip
    /// force/torque readings; a hand with sensing fingertips, barrett_ft).
    #[arg(long, default_value = "clouds", value_parser = sensing())]
    pub sensing: graspopt_hand::Sensing,
    /// Number of trials.
    #[arg(long, default_value_t = 60, value_parser = count::<u64>(1, MAX_TRIALS))]
    pub trials: u64,
    /// Trial parameters, comma-separated: x (approach), y (vertical), lateral, rx, ry, rz.
    #[arg(
        long,
        visible_alias = "axes",
        default_value = "x,y",
        value_delimiter = ',',
        value_parser = trial_param()
    )]
    pub params: Vec<ParamKind>,
    /// How trials are proposed: bo (Bayesian optimization: GP, EI, DIRECT) or random
    /// (uniform random search, a baseline).
    #[arg(long, default_value = "bo", value_parser = planner_method())]
    pub method: PlannerMethod,
    /// Size of the initial design (space-filling, not model-based) (default: the engine's).
    #[arg(long, value_parser = count::<u32>(0, u32::MAX.into()))]
    pub initial: Option<u32>,
    /// Seed of the planner's random choices and of perception's noise (the same seed
    /// proposes the same trials).
    #[arg(long, default_value_t = 0, value_parser = count::<u64>(0, u64::MAX))]
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
    #[arg(long, default_value_t = 0, value_parser = count::<u64>(0, u64::MAX))]
    pub trial_cost_ms: u64,
    /// Lease of a trial: re-issued if no result comes within this time (milliseconds).
    #[arg(long, default_value_t = 30_000, value_parser = count::<u64>(1, MAX_WAIT_MS))]
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

impl RunArgs {
    /// The run the flags ask for.
    pub fn settings(&self) -> RunSettings {
        RunSettings {
            run: self.run.clone(),
            trial: self.sim.settings(),
            workers: self.workers,
            sensing: self.sensing,
            trials: self.trials,
            params: self.params.clone(),
            method: self.method,
            initial: self.initial,
            seed: self.seed,
            out: self.out.clone(),
            resume: self.resume,
            trial_cost_ms: self.trial_cost_ms,
            lease_ms: self.lease_ms,
            position_noise: self.position_noise,
            rotation_noise: self.rotation_noise,
            bus: self.bus.config(),
        }
    }
}

/// `graspopt run`; `explicit(name)` says whether `--name` was given on the command line.
pub fn run(args: &RunArgs, explicit: &dyn Fn(&str) -> bool) -> Result<ExitCode> {
    let e = args.settings().resolve(explicit)?;
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
    // Said once the run has started (its first status), so that a run refused at start
    // (its folder, its journal, the open-file limit) does not first announce itself.
    let endpoint = e.bus.listen.join(", ");
    let mut announce = (!args.quiet && !endpoint.is_empty()).then(|| {
        format!(
            "graspopt: run {:?} on {endpoint} (attach with --connect)",
            e.run
        )
    });
    let status = runtime.block_on(async {
        let follow = {
            let bar = bar.clone();
            tokio::spawn(async move {
                while status_rx.changed().await.is_ok() {
                    if let Some(line) = announce.take() {
                        bar.suspend(|| eprintln!("{line}"));
                    }
                    let s = status_rx.borrow().clone();
                    bar.set_position(s.completed + s.failed);
                    if let Some(b) = &s.best {
                        bar.set_message(format!(
                            "best {} (trial {}){}",
                            rounded(b.score),
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
    let folder = graspopt_report::run::RunFolder {
        out: &e.out,
        journal: &e.coordinator.journal,
        run: e.run.as_str(),
        params: &e.spec.params,
        evaluator: &e.evaluator,
    };
    graspopt_report::run::write_results(&folder, &status.object)?;
    let end = RunEnd::read(status, &e.coordinator.journal)?;
    let s = &end.status;
    let then = if s.completed + s.failed + s.running == 0 {
        " (stopped before its first trial: the same command starts it afresh)".to_string()
    } else {
        format!(
            " (stopped; continue with --resume --out {})",
            e.out.display()
        )
    };
    for line in end.lines(&then) {
        outln!("{line}")?;
    }
    outln!("results: {}", e.out.display())?;
    Ok(ExitCode::from(end.exit_code()))
}
