//! The bus flags every tool and agent shares, in the manner of Zenoh's examples; they fill
//! the bus crate's plain [`BusConfig`].

use std::path::PathBuf;

use clap::Args;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use graspopt_bus::{BusConfig, BusMode};

/// Bus flags.
#[derive(Debug, Clone, Default, Args)]
pub struct BusArgs {
    /// Endpoint to connect to, e.g. `tcp/192.168.1.10:7447` (a router); repeatable. An
    /// endpoint that does not parse is refused at once; one that does not answer is named in
    /// a warning within a few seconds and tried again in the background. Turns multicast
    /// scouting off (see `--scout`).
    #[arg(short = 'e', long = "connect", value_name = "ENDPOINT", global = true)]
    pub connect: Vec<String>,
    /// Endpoint to listen on, e.g. `tcp/0.0.0.0:7447`; repeatable.
    #[arg(short = 'l', long = "listen", value_name = "ENDPOINT", global = true)]
    pub listen: Vec<String>,
    /// Session mode (default: peer, or the Zenoh configuration file's).
    #[arg(long, global = true, value_parser = bus_mode())]
    pub mode: Option<BusMode>,
    /// A Zenoh configuration file (json5); the flags override it.
    #[arg(long = "zenoh-config", value_name = "FILE", global = true)]
    pub zenoh_config: Option<PathBuf>,
    /// Do not look for peers by UDP multicast; only the `--connect` endpoints are used (the
    /// default whenever `--connect` is given).
    #[arg(long, global = true)]
    pub no_multicast_scouting: bool,
    /// Also look for peers by UDP multicast when `--connect` is given. Without it, a process
    /// given `--connect` meets only what it connects to, so a wrong address fails on one
    /// machine as it would across two.
    #[arg(long, global = true, conflicts_with = "no_multicast_scouting")]
    pub scout: bool,
    /// Prefix of the shared-memory (iceoryx2) resources, to separate installations on a host.
    #[arg(long, value_name = "PREFIX", global = true)]
    pub shm_prefix: Option<String>,
    /// Never use shared memory for contact clouds (always Zenoh).
    #[arg(long, global = true)]
    pub no_shm: bool,
}

/// `--mode`: the session modes by name.
fn bus_mode() -> impl TypedValueParser<Value = BusMode> {
    PossibleValuesParser::new([
        PossibleValue::new("peer").help("Talk directly to other peers (and to routers)"),
        PossibleValue::new("client").help("Talk only through the router(s) given with `--connect`"),
        PossibleValue::new("router").help("Route for others (see `graspopt router`)"),
    ])
    .try_map(|s| BusMode::parse(&s).ok_or("unknown mode"))
}

impl BusArgs {
    /// The bus these flags describe.
    pub fn config(&self) -> BusConfig {
        BusConfig {
            connect: self.connect.clone(),
            listen: self.listen.clone(),
            mode: self.mode,
            zenoh_config: self.zenoh_config.clone(),
            no_multicast_scouting: self.no_multicast_scouting,
            scout: self.scout,
            shm_prefix: self.shm_prefix.clone(),
            no_shm: self.no_shm,
        }
    }
}
