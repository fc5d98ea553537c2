//! `graspopt router`: a Zenoh router for agents on several machines (since Zenoh 1.9 peers do
//! not relay for each other, so agents across machines connect to a router).

use std::process::ExitCode;

use anyhow::Result;
use clap::Args;
use graspopt_bus::{Bus, BusArgs, BusMode};

#[derive(Args, Debug)]
pub struct RouterArgs {
    #[command(flatten)]
    pub bus: BusArgs,
}

pub fn run(args: &RouterArgs) -> Result<ExitCode> {
    let mut bus = args.bus.clone();
    bus.mode = Some(BusMode::Router);
    if bus.listen.is_empty() && bus.zenoh_config.is_none() {
        bus.listen = vec!["tcp/0.0.0.0:7447".to_string()];
    }
    bus.no_shm = true;
    let runtime = tokio::runtime::Runtime::new()?;
    runtime.block_on(async {
        let session = Bus::open(&bus).await?;
        eprintln!("graspopt router listening on {}", bus.listen.join(", "));
        super::agent::shutdown_signal().await;
        session.close().await?;
        Ok::<(), anyhow::Error>(())
    })?;
    Ok(ExitCode::SUCCESS)
}
