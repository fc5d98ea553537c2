//! `graspopt launch FILE`: starts the agents a launch file places on this machine, each as
//! its own process, and supervises them ([`graspopt_runner::launch`]).
//!
//! A launch file (TOML) names the run, the router endpoint every agent connects to, an
//! optional router, and the agents. An entry with a `host` runs only on the machine launched
//! with that `--host` (default: this machine's host name), so one file describes a whole
//! installation and each machine runs its part; an entry without `host` runs wherever the
//! file is launched. `deploy/local.toml` and `deploy/two-machines.toml` are examples.
//!
//! The router starts first (launch waits until it accepts connections), then the agents in
//! file order. Each process's stderr goes to `<logs>/<name>.log`; stdout is passed through
//! (the coordinator prints the final status there). When the coordinator exits, the others
//! are stopped (SIGTERM, then SIGKILL) and launch exits with the coordinator's status; if
//! another process exits first, launch stops everything and names it. Ctrl-C stops all.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::Args;
use graspopt_runner::ending::NO_TRIAL_COMPLETED;
use graspopt_runner::launch::{Children, LaunchFile, Outcome, resume_coordinator, tail};

use crate::out::outln;

#[derive(Args, Debug)]
pub struct LaunchArgs {
    /// The launch file (TOML).
    pub file: PathBuf,
    /// This machine's name in the launch file (default: GRASPOPT_HOST or the host name).
    #[arg(long)]
    pub host: Option<String>,
    /// Override the launch file's router endpoint (agents connect to it; a router in the file
    /// listens on it).
    #[arg(long)]
    pub endpoint: Option<String>,
    /// Folder for the processes' logs (default: logs/<run>).
    #[arg(long)]
    pub logs: Option<PathBuf>,
    /// Print the commands this machine would run, and exit.
    #[arg(long)]
    pub dry_run: bool,
    /// Continue the file's run from its journal (a launch stopped by Ctrl-C, say): the
    /// coordinator starts with --resume. Give it on the machine that runs the coordinator.
    #[arg(long)]
    pub resume: bool,
}

pub fn run(args: &LaunchArgs) -> Result<ExitCode> {
    let text = std::fs::read_to_string(&args.file)
        .with_context(|| format!("cannot read the launch file {}", args.file.display()))?;
    let mut file = LaunchFile::parse(&text, &args.file)?;
    if let Some(e) = &args.endpoint {
        file.endpoint = e.clone();
        if let Some(r) = &mut file.router {
            r.listen = None;
        }
    }
    let host = args.host.clone().unwrap_or_else(graspopt_bus::host_name);
    let base = args
        .file
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let mut plan = file.plan(&host, &base)?;
    if plan.is_empty() {
        bail!(
            "launch file {}: nothing runs on host {host:?} (use --host to pick an entry's host)",
            args.file.display()
        );
    }
    if args.resume {
        resume_coordinator(&mut plan, &host)?;
    }
    // Every process's flags, parsed as it will parse them, before any starts: a typo in
    // one entry's `args` would otherwise stop the launch after the router and the agents
    // before it have started.
    for p in &plan {
        let argv = std::iter::once("graspopt").chain(p.args.iter().map(String::as_str));
        if let Err(e) = crate::command().try_get_matches_from(argv) {
            let rendered = e.render().to_string();
            let why = rendered
                .lines()
                .next()
                .unwrap_or("")
                .trim_start_matches("error: ");
            bail!("launch file {}: {}: {why}", args.file.display(), p.name);
        }
    }
    if args.dry_run {
        for p in &plan {
            outln!("graspopt {}", p.args.join(" "))?;
        }
        return Ok(ExitCode::SUCCESS);
    }
    let logs = args
        .logs
        .clone()
        .unwrap_or_else(|| Path::new("logs").join(&file.run));
    let exe = std::env::current_exe().context("cannot find the graspopt executable")?;
    let mut children = Children::start(&plan, &exe, &logs, |name, log| {
        eprintln!("graspopt launch: started {name} (log {})", log.display());
    })?;
    let runtime = tokio::runtime::Runtime::new()?;
    // The signal handlers need the runtime: registered inside it.
    let outcome = runtime.block_on(async {
        let stop = graspopt_runner::signal::shutdown_signal();
        children.supervise(stop).await
    });
    match outcome {
        Outcome::Coordinator(Some(0), _) => Ok(ExitCode::SUCCESS),
        Outcome::Coordinator(code, log) => {
            let log = log.unwrap_or_default();
            let what = if code == Some(i32::from(NO_TRIAL_COMPLETED)) {
                "no trial of the run completed"
            } else {
                "the coordinator failed"
            };
            eprintln!(
                "graspopt launch: {what}; the coordinator's log ({}):\n{}",
                log.display(),
                tail(&log, 20)
            );
            // Its exit status is launch's (1 if it was killed by a signal).
            let code = code.and_then(|c| u8::try_from(c).ok()).unwrap_or(1);
            Ok(ExitCode::from(code))
        }
        Outcome::Died(name, status, log) => bail!(
            "{name} stopped ({status}) before the run finished; everything was stopped. Its log ({}):\n{}",
            log.display(),
            tail(&log, 20)
        ),
        Outcome::Interrupted => {
            eprintln!(
                "graspopt launch: interrupted, every process stopped; continue the run with graspopt launch --resume {}",
                args.file.display()
            );
            Ok(ExitCode::from(130))
        }
    }
}
