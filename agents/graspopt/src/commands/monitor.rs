//! `graspopt monitor`: a live dashboard of the runs on the bus (graspopt_watch::monitor).
//! `q` or Esc quits, Tab switches runs. `--once` prints the same as text and exits (for
//! scripts).

use std::process::ExitCode;

use anyhow::Result;
use clap::Args;
use graspopt_bus::Bus;
use graspopt_protocol::RunId;
use graspopt_watch::monitor;

use super::bus::BusArgs;
use crate::out::outln;

#[derive(Args, Debug)]
pub struct MonitorArgs {
    /// Only this run (default: every run with a live coordinator).
    #[arg(long)]
    pub run: Option<String>,
    /// Print the runs' state as text once and exit.
    #[arg(long)]
    pub once: bool,
    #[command(flatten)]
    pub bus: BusArgs,
}

pub fn run(args: &MonitorArgs) -> Result<ExitCode> {
    let only = args.run.as_deref().map(RunId::new).transpose()?;
    tokio::runtime::Runtime::new()?.block_on(async {
        // --once says itself when nothing answers where it connects.
        let bus = Bus::open_watcher(&args.bus.config(), args.once).await?;
        let r = if args.once {
            match monitor::once(&bus, only.as_ref()).await {
                Ok(lines) => lines
                    .iter()
                    .try_for_each(|l| outln!("{l}"))
                    .map_err(Into::into),
                Err(e) => Err(e.into()),
            }
        } else {
            let stop = graspopt_runner::signal::shutdown_signal();
            monitor::dashboard(&bus, only.as_ref(), stop).await
        };
        let _ = bus.close().await;
        r
    })?;
    Ok(ExitCode::SUCCESS)
}
