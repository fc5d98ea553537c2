//! `graspopt run`: a whole optimization in one process. Every agent (perception, planner,
//! metric, the hand workers, the coordinator) runs as a task on one Zenoh session that listens
//! on loopback only (no router, no multicast), so `graspopt topic` and `graspopt monitor` can
//! attach from another terminal. Results go to a folder: the journal, every trial as CSV and
//! JSON, and pictures (the best grasp, the trials on the parameter space, the scores).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use tokio::sync::watch;

use super::bus::BusArgs;
use super::setup::{SpecArgs, count, sensing};
use crate::out::outln;
use graspopt_coordinator::MAX_WAIT_MS;
use graspopt_runner::ending::{RunEnd, best_so_far};
use graspopt_runner::{RunSettings, placeholder, run_embedded};

#[derive(Args, Debug, Clone)]
pub struct RunArgs {
    #[command(flatten)]
    pub spec: SpecArgs,
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
    /// Results folder (default: results/<run>).
    #[arg(long)]
    pub out: Option<PathBuf>,
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
            trial: self.spec.sim.settings(),
            workers: self.workers,
            sensing: self.sensing,
            trials: self.spec.trials,
            params: self.spec.params.clone(),
            method: self.spec.method,
            initial: self.spec.initial,
            seed: self.spec.seed,
            out: self.out.clone(),
            resume: self.spec.resume,
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
                        bar.set_message(best_so_far(b));
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
    for line in end.embedded_lines(&e.out) {
        outln!("{line}")?;
    }
    Ok(ExitCode::from(end.exit_code()))
}
