//! `graspopt router`: a Zenoh router for agents on several machines (since Zenoh 1.9 peers do
//! not relay for each other, so agents across machines connect to a router).

use std::process::ExitCode;

use anyhow::{Result, bail};
use clap::Args;
use graspopt_bus::{Bus, BusArgs, BusMode};

#[derive(Args, Debug)]
#[command(after_help = "A router always runs in router mode: `--mode` may only be `router`.")]
pub struct RouterArgs {
    #[command(flatten)]
    pub bus: BusArgs,
}

/// Errors on a `--mode` other than `router`: this command is a router.
pub fn check_mode(mode: Option<BusMode>) -> Result<()> {
    match mode {
        None | Some(BusMode::Router) => Ok(()),
        Some(other) => bail!(
            "--mode {}: `graspopt router` always runs as a router; leave out --mode (peer and \
             client are modes of the agents)",
            other.as_str()
        ),
    }
}

pub fn run(args: &RouterArgs) -> Result<ExitCode> {
    check_mode(args.bus.mode)?;
    let mut bus = args.bus.clone();
    bus.mode = Some(BusMode::Router);
    if bus.listen.is_empty() && bus.zenoh_config.is_none() {
        bus.listen = vec!["tcp/0.0.0.0:7447".to_string()];
    }
    bus.no_shm = true;
    let runtime = tokio::runtime::Runtime::new()?;
    runtime.block_on(async {
        let session = Bus::open(&bus).await?;
        if bus.listen.is_empty() {
            eprintln!("graspopt router listening on the Zenoh configuration's endpoints");
        } else {
            eprintln!("graspopt router listening on {}", bus.listen.join(", "));
        }
        super::agent::shutdown_signal().await;
        session.close().await?;
        Ok::<(), anyhow::Error>(())
    })?;
    Ok(ExitCode::SUCCESS)
}
