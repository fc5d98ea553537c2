//! `graspopt router`: a Zenoh router for agents on several machines (since Zenoh 1.9 peers do
//! not relay for each other, so agents across machines connect to a router). It has its own
//! flags: the agents' `--mode` and shared-memory flags do not apply to a router.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Args;
use graspopt_bus::{Bus, BusConfig, BusMode};

/// Where the router listens when neither `--listen` nor `--zenoh-config` says.
const DEFAULT_LISTEN: &str = "tcp/0.0.0.0:7447";

#[derive(Args, Debug)]
pub struct RouterArgs {
    /// Endpoint to listen on, e.g. `tcp/0.0.0.0:7447` (the default); repeatable.
    #[arg(short = 'l', long = "listen", value_name = "ENDPOINT")]
    pub listen: Vec<String>,
    /// Another router to connect to, e.g. `tcp/192.168.1.10:7447`; repeatable.
    #[arg(short = 'e', long = "connect", value_name = "ENDPOINT")]
    pub connect: Vec<String>,
    /// A Zenoh configuration file (json5); the flags override it, and the mode is always
    /// router.
    #[arg(long = "zenoh-config", value_name = "FILE")]
    pub zenoh_config: Option<PathBuf>,
    /// Do not look for peers by UDP multicast.
    #[arg(long)]
    pub no_multicast_scouting: bool,
}

impl RouterArgs {
    /// The bus flags of a router: router mode, never shared memory.
    pub fn bus(&self) -> BusConfig {
        let mut listen = self.listen.clone();
        if listen.is_empty() && self.zenoh_config.is_none() {
            listen = vec![DEFAULT_LISTEN.to_string()];
        }
        BusConfig {
            connect: self.connect.clone(),
            listen,
            mode: Some(BusMode::Router),
            zenoh_config: self.zenoh_config.clone(),
            no_multicast_scouting: self.no_multicast_scouting,
            no_shm: true,
            ..BusConfig::default()
        }
    }
}

pub fn run(args: &RouterArgs) -> Result<ExitCode> {
    let bus = args.bus();
    let runtime = tokio::runtime::Runtime::new()?;
    runtime.block_on(async {
        // Zenoh's error does not say which endpoint it could not listen on.
        let session = Bus::open(&bus).await.with_context(|| {
            if bus.listen.is_empty() {
                "cannot listen on the Zenoh configuration's endpoints".to_string()
            } else {
                format!("cannot listen on {}", bus.listen.join(", "))
            }
        })?;
        if bus.listen.is_empty() {
            eprintln!("graspopt router listening on the Zenoh configuration's endpoints");
        } else {
            eprintln!("graspopt router listening on {}", bus.listen.join(", "));
        }
        graspopt_runner::signal::shutdown_signal().await;
        session.close().await?;
        Ok::<(), anyhow::Error>(())
    })?;
    Ok(ExitCode::SUCCESS)
}
