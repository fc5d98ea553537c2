//! `graspopt run`: a whole optimization in one process. Every agent (perception, planner,
//! metric, the hand workers, the coordinator) runs as a task on one Zenoh session that listens
//! on loopback only (no router, no multicast), so `graspopt topic` and `graspopt monitor` can
//! attach from another terminal. Results go to a folder: the journal, every trial as CSV and
//! JSON, and pictures (the best grasp, the trials on the parameter space, the scores).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Args;
use clap::builder::{PossibleValuesParser, TypedValueParser};
use graspopt_bus::BusArgs;
use graspopt_protocol::{PlannerMethod, RunPhase, RunStatus};
use graspopt_sim::ParamKind;
use indicatif::{ProgressBar, ProgressStyle};
use tokio::sync::watch;

use super::setup::SimArgs;
use crate::out::outln;
use graspopt_pictures::chart;
use graspopt_runner::{Embedded, RunSettings, placeholder, run_embedded};
use graspopt_watch::named_params;

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
        value_delimiter = ',',
        value_parser = trial_param()
    )]
    pub params: Vec<ParamKind>,
    /// How trials are proposed: bo (Bayesian optimization: GP, EI, DIRECT) or random
    /// (uniform random search, a baseline).
    #[arg(long, default_value = "bo", value_parser = planner_method())]
    pub method: PlannerMethod,
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

/// `--params`: a trial parameter by any of its names ([`ParamKind::parse`]).
pub fn trial_param() -> impl TypedValueParser<Value = ParamKind> {
    clap::builder::NonEmptyStringValueParser::new().try_map(|s| ParamKind::parse(&s))
}

/// `--method`: the planner's methods by name.
pub fn planner_method() -> impl TypedValueParser<Value = PlannerMethod> {
    PossibleValuesParser::new(PlannerMethod::ALL.map(PlannerMethod::name))
        .try_map(|s| PlannerMethod::parse(&s).ok_or("unknown method"))
}

impl RunArgs {
    /// The run the flags ask for.
    pub fn settings(&self) -> RunSettings {
        RunSettings {
            run: self.run.clone(),
            trial: self.sim.settings(),
            workers: self.workers,
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
            bus: self.bus.clone(),
        }
    }
}

/// Writes `trials.csv`, `trials.json` and the pictures ([`write_pictures`]) from the journal.
pub fn write_results(e: &Embedded, status: &RunStatus) -> Result<()> {
    let journal = graspopt_journal::Journal::open(&e.coordinator.journal)?;
    let csv = e.out.join("trials.csv");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&csv)?);
    graspopt_journal::export::write_csv(&journal, e.run.as_str(), &mut f)?;
    let json = e.out.join("trials.json");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&json)?);
    graspopt_journal::export::write_json(&journal, e.run.as_str(), &mut f)?;
    write_pictures(e, &status.object, &journal.export(e.run.as_str())?.trials)
}

/// The pictures of a run, from its trials: `best.png`, the best grasp drawn as `graspopt
/// trial --preview` draws it (simulated again at its parameters, on the object's true pose);
/// `trials.svg`, every trial on the parameter space (the first two parameters); `best.svg`,
/// each trial's score and the best so far, in the order the trials completed. Trials that
/// touched nothing are grey and never set a scale.
fn write_pictures(e: &Embedded, object: &str, trials: &[graspopt_journal::TrialRow]) -> Result<()> {
    let mut done: Vec<&graspopt_journal::TrialRow> =
        trials.iter().filter(|t| t.score.is_some()).collect();
    done.sort_by_key(|t| (t.completed_ms, t.trial_id));
    // A trial that touched nothing scores below every grasp: `None` on the pictures.
    let hit = |t: &graspopt_journal::TrialRow| t.score.filter(|_| t.contacts > 0);
    let scores: Vec<Option<f64>> = done.iter().map(|t| hit(t)).collect();
    let plot = chart::progress_plot(&format!("{object}: score by trial, best so far"), &scores);
    std::fs::write(e.out.join("best.svg"), plot)?;

    let names: Vec<String> = e
        .spec
        .params
        .iter()
        .map(|k| match k {
            ParamKind::RotX | ParamKind::RotY | ParamKind::RotZ => format!("{} (rad)", k.name()),
            _ => format!("{} offset (m)", k.name()),
        })
        .collect();
    let labels: Vec<&str> = names.iter().map(String::as_str).collect();
    let shown = if names.len() > 2 {
        format!(" (the first two of {} parameters)", names.len())
    } else {
        String::new()
    };
    let points: Vec<(Vec<f64>, Option<f64>)> =
        done.iter().map(|t| (t.params.clone(), hit(t))).collect();
    let map = chart::trials_map(
        &format!(
            "{object}: {} trials on the parameter space{shown}",
            done.len()
        ),
        &labels,
        &e.evaluator.space.bounds(),
        &points,
    );
    std::fs::write(e.out.join("trials.svg"), map)?;

    let Some(best) = done.iter().max_by(|a, b| {
        a.score
            .unwrap_or(f64::NAN)
            .total_cmp(&b.score.unwrap_or(f64::NAN))
    }) else {
        return Ok(());
    };
    let grasp = e
        .evaluator
        .evaluate(&best.params)
        .with_context(|| format!("cannot simulate the best trial {} again", best.trial_id))?;
    let words = match (&best.metrics, best.score) {
        (Some(m), Some(s)) if m.force_closure => format!("score {s:.4}, force closure"),
        (Some(_), Some(s)) => format!("score {s:.4}"),
        _ => "no contact".to_string(),
    };
    let short: Vec<String> = e.spec.params.iter().map(|k| k.name().to_string()).collect();
    let title = format!(
        "run {}, best trial {} at {}: {words}",
        e.run,
        best.trial_id,
        named_params(&short, &best.params, ",")
    );
    super::trial::preview_image(&e.evaluator, &grasp, &title)?.save_png(&e.out.join("best.png"))
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
