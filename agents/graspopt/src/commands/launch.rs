//! `graspopt launch FILE`: starts the agents a launch file places on this machine, each as
//! its own process, and supervises them (the launch file and the supervision:
//! [`graspopt_runner::launch`]).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Args, FromArgMatches};
use graspopt_runner::launch::{Children, Planned, prepare};

use super::agent::AgentArgs;
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
    let host = args.host.clone().unwrap_or_else(graspopt_bus::host_name);
    let endpoint = args.endpoint.as_deref();
    let (file, plan) = prepare(&args.file, &host, endpoint, args.resume)?;
    // Every process's flags and settings, read as it will read them, before any starts: a
    // typo in one entry's `args` would otherwise stop the launch after the router and the
    // agents before it have started.
    for p in &plan {
        if let Err(why) = check(p) {
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
    let (code, said) = outcome.ending(&args.file)?;
    if let Some(said) = said {
        eprintln!("{said}");
    }
    Ok(ExitCode::from(code))
}

/// Why process `p` would refuse its flags (the first line of clap's message) or, an agent,
/// its settings.
fn check(p: &Planned) -> std::result::Result<(), String> {
    let argv = std::iter::once("graspopt").chain(p.args.iter().map(String::as_str));
    let matches = crate::command().try_get_matches_from(argv).map_err(|e| {
        let rendered = e.render().to_string();
        let first = rendered.lines().next().unwrap_or("");
        first.trim_start_matches("error: ").to_string()
    })?;
    let Some(agent) = matches.subcommand_matches("agent") else {
        return Ok(());
    };
    let agent = AgentArgs::from_arg_matches(agent).map_err(|e| e.to_string())?;
    let row = graspopt_runner::agents::agent_row(agent.kind);
    (row.check)(&agent.standalone()).map_err(|e| graspopt_runner::error::chain(&e))
}
