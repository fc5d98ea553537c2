//! The flag set every graspopt tool and agent shares, in the manner of Zenoh's examples.

use std::path::PathBuf;

/// How this process joins the bus.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BusMode {
    /// Talk directly to other peers (and to routers).
    Peer,
    /// Talk only through the router(s) given with `--connect`.
    Client,
    /// Route for others (see `graspopt router`).
    Router,
}

impl BusMode {
    pub fn as_str(self) -> &'static str {
        match self {
            BusMode::Peer => "peer",
            BusMode::Client => "client",
            BusMode::Router => "router",
        }
    }
}

/// Bus flags.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct BusArgs {
    /// Endpoint to connect to, e.g. `tcp/192.168.1.10:7447` (a router); repeatable.
    #[arg(short = 'e', long = "connect", value_name = "ENDPOINT", global = true)]
    pub connect: Vec<String>,
    /// Endpoint to listen on, e.g. `tcp/0.0.0.0:7447`; repeatable.
    #[arg(short = 'l', long = "listen", value_name = "ENDPOINT", global = true)]
    pub listen: Vec<String>,
    /// Session mode (default: peer, or the Zenoh configuration file's).
    #[arg(long, value_enum, global = true)]
    pub mode: Option<BusMode>,
    /// A Zenoh configuration file (json5); the flags override it.
    #[arg(long = "zenoh-config", value_name = "FILE", global = true)]
    pub zenoh_config: Option<PathBuf>,
    /// Do not look for peers by UDP multicast; only the `--connect` endpoints are used.
    #[arg(long, global = true)]
    pub no_multicast_scouting: bool,
    /// Prefix of the shared-memory (iceoryx2) resources, to separate installations on a host.
    #[arg(long, value_name = "PREFIX", global = true)]
    pub shm_prefix: Option<String>,
    /// Never use shared memory for contact clouds (always Zenoh).
    #[arg(long, global = true)]
    pub no_shm: bool,
}

impl BusArgs {
    /// Arguments for a process that talks only over loopback through `endpoint` (tests, the
    /// embedded run): no multicast scouting.
    pub fn loopback(listen: Vec<String>, connect: Vec<String>) -> Self {
        BusArgs {
            connect,
            listen,
            mode: Some(BusMode::Peer),
            zenoh_config: None,
            no_multicast_scouting: true,
            shm_prefix: None,
            no_shm: false,
        }
    }

    /// The Zenoh configuration these flags describe.
    pub fn zenoh_config(&self) -> Result<zenoh::Config, crate::BusError> {
        use crate::BusError;
        let mut config = match &self.zenoh_config {
            Some(path) => zenoh::Config::from_file(path).map_err(|e| {
                BusError::Config(format!("cannot read Zenoh config {}: {e}", path.display()))
            })?,
            None => zenoh::Config::default(),
        };
        let mut set = |key: &str, value: String| {
            config
                .insert_json5(key, &value)
                .map_err(|e| BusError::Config(format!("{key} = {value}: {e}")))
        };
        if let Some(mode) = self.mode {
            // A client talks only through routers: without one to connect to (or a
            // configuration file that names one) it could only fail later, obscurely.
            if mode == BusMode::Client && self.connect.is_empty() && self.zenoh_config.is_none() {
                return Err(BusError::Config(
                    "--mode client needs a router to talk through: give it with --connect \
                     (e.g. --connect tcp/192.168.1.10:7447)"
                        .into(),
                ));
            }
            set("mode", format!("\"{}\"", mode.as_str()))?;
        }
        let list = |v: &[String]| -> Result<String, BusError> {
            for e in v {
                if !e.contains('/') {
                    return Err(BusError::Config(format!(
                        "endpoint {e:?} has no protocol: write e.g. tcp/{e}"
                    )));
                }
            }
            let quoted: Vec<String> = v.iter().map(|e| format!("{e:?}")).collect();
            Ok(format!("[{}]", quoted.join(",")))
        };
        if !self.connect.is_empty() {
            set("connect/endpoints", list(&self.connect)?)?;
        }
        if !self.listen.is_empty() {
            set("listen/endpoints", list(&self.listen)?)?;
        }
        if self.no_multicast_scouting {
            set("scouting/multicast/enabled", "false".into())?;
        }
        Ok(config)
    }
}
