//! How a process joins the bus: a plain [`BusConfig`] (the `graspopt` binary fills it from
//! its bus flags, `--connect`, `--listen`, `--mode`, ..., in the manner of Zenoh's
//! examples; tests and the embedded run by hand), and the check of an endpoint.

use std::path::PathBuf;

/// How this process joins the bus.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BusMode {
    /// Talk directly to other peers (and to routers).
    Peer,
    /// Talk only through the router(s) given with `--connect`.
    Client,
    /// Route for others (see `graspopt router`).
    Router,
}

impl BusMode {
    /// Every mode, in the order `--help` lists them.
    pub const ALL: [BusMode; 3] = [BusMode::Peer, BusMode::Client, BusMode::Router];

    pub fn as_str(self) -> &'static str {
        match self {
            BusMode::Peer => "peer",
            BusMode::Client => "client",
            BusMode::Router => "router",
        }
    }

    /// A mode by its name.
    pub fn parse(name: &str) -> Option<BusMode> {
        Self::ALL.into_iter().find(|m| m.as_str() == name)
    }
}

/// How a session is opened: its endpoints, mode and Zenoh configuration, and the shared
/// memory it may use. The error messages name the flags that set each field.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BusConfig {
    /// Endpoints to connect to, e.g. `tcp/192.168.1.10:7447` (a router).
    pub connect: Vec<String>,
    /// Endpoints to listen on, e.g. `tcp/0.0.0.0:7447`.
    pub listen: Vec<String>,
    /// Session mode (`None`: peer, or the Zenoh configuration file's).
    pub mode: Option<BusMode>,
    /// A Zenoh configuration file (json5); the fields above override it.
    pub zenoh_config: Option<PathBuf>,
    /// No UDP multicast scouting: only the `connect` endpoints.
    pub no_multicast_scouting: bool,
    /// Multicast scouting even when `connect` is given.
    pub scout: bool,
    /// Prefix of the shared-memory (iceoryx2) resources, to separate installations on a host.
    pub shm_prefix: Option<String>,
    /// Never use shared memory for contact clouds (always Zenoh).
    pub no_shm: bool,
}

impl BusConfig {
    /// The configuration of a process that talks only over loopback through `endpoint` (tests, the
    /// embedded run): no multicast scouting.
    pub fn loopback(listen: Vec<String>, connect: Vec<String>) -> Self {
        BusConfig {
            connect,
            listen,
            mode: Some(BusMode::Peer),
            zenoh_config: None,
            no_multicast_scouting: true,
            scout: false,
            shm_prefix: None,
            no_shm: false,
        }
    }

    /// The Zenoh configuration this describes.
    pub fn zenoh_config(&self) -> Result<zenoh::Config, crate::BusError> {
        use crate::BusError;
        use crate::error::without_source_locations;
        let mut config = match &self.zenoh_config {
            Some(path) => zenoh::Config::from_file(path).map_err(|e| {
                BusError::Config(format!(
                    "cannot read Zenoh config {}: {}",
                    path.display(),
                    without_source_locations(&e.to_string())
                ))
            })?,
            None => zenoh::Config::default(),
        };
        let mut set = |key: &str, value: String| {
            config.insert_json5(key, &value).map_err(|e| {
                BusError::Config(format!(
                    "{key} = {value}: {}",
                    without_source_locations(&e.to_string())
                ))
            })
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
        let list = |v: &[String], use_: EndpointUse| -> Result<String, BusError> {
            for e in v {
                check_endpoint(e, use_)?;
            }
            let quoted: Vec<String> = v.iter().map(|e| format!("{e:?}")).collect();
            Ok(format!("[{}]", quoted.join(",")))
        };
        if !self.connect.is_empty() {
            set(
                "connect/endpoints",
                list(&self.connect, EndpointUse::Connect)?,
            )?;
        }
        if !self.listen.is_empty() {
            set("listen/endpoints", list(&self.listen, EndpointUse::Listen)?)?;
        }
        if !self.multicast_scouting() {
            set("scouting/multicast/enabled", "false".into())?;
        }
        Ok(config)
    }

    /// Whether this leaves UDP multicast scouting on: not with `--no-multicast-scouting`,
    /// and not with `--connect` unless `--scout` asks for it (a Zenoh configuration file
    /// decides when neither flag is given).
    pub fn multicast_scouting(&self) -> bool {
        !self.no_multicast_scouting && (self.connect.is_empty() || self.scout)
    }
}

/// What an endpoint is for: a port is needed to connect, while a listener may take port 0
/// (any free port).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EndpointUse {
    Connect,
    Listen,
}

/// The transports this build speaks (Zenoh's protocol names).
pub const PROTOCOLS: [&str; 2] = ["tcp", "unixsock-stream"];

/// Checks an endpoint given on the command line or in a launch file, before Zenoh sees it:
/// `tcp/HOST:PORT` (an IPv6 address in brackets: `tcp/[::1]:7447`) or
/// `unixsock-stream/PATH`, each optionally followed by Zenoh's `?metadata` and `#config`. The
/// error names the endpoint and what is wrong with it (Zenoh would take a port out of range or
/// an unknown protocol and keep failing to connect, in silence).
pub fn check_endpoint(endpoint: &str, use_: EndpointUse) -> Result<(), crate::BusError> {
    let bad = |why: String| crate::BusError::Config(format!("endpoint {endpoint:?}: {why}"));
    let Some((protocol, rest)) = endpoint.split_once('/') else {
        return Err(bad(format!("no protocol: write e.g. tcp/{endpoint}")));
    };
    // Zenoh's own parser: metadata and configuration after the address.
    let parsed = zenoh::config::EndPoint::try_from(endpoint.to_string())
        .map_err(|e| bad(crate::error::without_source_locations(&e.to_string())))?;
    let address = parsed.address();
    let address = address.as_str();
    if !PROTOCOLS.contains(&protocol) {
        return Err(bad(format!(
            "unknown protocol {protocol:?}: graspopt speaks {}",
            PROTOCOLS.join(" and ")
        )));
    }
    if rest.is_empty() || address.is_empty() {
        return Err(bad("no address after the protocol".into()));
    }
    if protocol != "tcp" {
        return Ok(());
    }
    let Some((host, port)) = address.rsplit_once(':') else {
        return Err(bad(format!("no port: write e.g. tcp/{address}:7447")));
    };
    let port: u32 = port
        .parse()
        .map_err(|_| bad(format!("the port {port:?} is not a number")))?;
    let lowest = match use_ {
        EndpointUse::Connect => 1,
        EndpointUse::Listen => 0,
    };
    if !(lowest..=65535).contains(&port) {
        return Err(bad(format!(
            "port {port} is out of range ({lowest} to 65535)"
        )));
    }
    if let Some(v6) = host.strip_prefix('[') {
        let ok = v6
            .strip_suffix(']')
            .is_some_and(|a| a.parse::<std::net::Ipv6Addr>().is_ok());
        if !ok {
            return Err(bad(format!("{host} is not an IPv6 address in brackets")));
        }
    } else if host.contains(':') {
        return Err(bad(format!(
            "an IPv6 address goes in brackets: tcp/[{host}]:{port}"
        )));
    } else if host.is_empty()
        || !host
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '.' || c == '_')
    {
        return Err(bad(format!("{host:?} is not a host name or address")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn connect(e: &str) -> Result<(), String> {
        check_endpoint(e, EndpointUse::Connect).map_err(|e| e.to_string())
    }

    #[test]
    fn endpoints_that_do_not_parse_are_refused_with_their_name() {
        for ok in [
            "tcp/127.0.0.1:7447",
            "tcp/lab-pc.local:7447",
            "tcp/nosuchhost.invalid:7447",
            "tcp/[::1]:7447",
            "tcp/127.0.0.1:7447?prio=1-3",
            "unixsock-stream//tmp/graspopt.sock",
        ] {
            assert_eq!(connect(ok), Ok(()), "{ok}");
        }
        assert_eq!(
            check_endpoint("tcp/0.0.0.0:0", EndpointUse::Listen).ok(),
            Some(())
        );
        for (bad, why) in [
            (
                "tcp/127.0.0.1:99999",
                "port 99999 is out of range (1 to 65535)",
            ),
            ("tcp/127.0.0.1:0", "port 0 is out of range"),
            ("tcp/127.0.0.1:port", "the port \"port\" is not a number"),
            (
                "127.0.0.1:7447",
                "no protocol: write e.g. tcp/127.0.0.1:7447",
            ),
            (
                "udp/127.0.0.1:7447",
                "unknown protocol \"udp\": graspopt speaks tcp and unixsock-stream",
            ),
            ("tpc/127.0.0.1:7447", "unknown protocol \"tpc\""),
            ("tcp/127.0.0.1", "no port"),
            ("tcp/", "endpoint \"tcp/\""),
            ("tcp/::1:7447", "an IPv6 address goes in brackets"),
            ("tcp/lab pc:7447", "is not a host name or address"),
        ] {
            let e = connect(bad).expect_err(bad);
            assert!(e.contains(&format!("endpoint {bad:?}")), "{e}");
            assert!(e.contains(why), "{bad}: {e}");
            assert!(!e.contains(".rs:"), "{e}");
        }
    }

    #[test]
    fn connect_turns_multicast_scouting_off_unless_asked() {
        let mut args = BusConfig::default();
        assert!(args.multicast_scouting());
        args.connect = vec!["tcp/127.0.0.1:7447".into()];
        assert!(!args.multicast_scouting());
        let scouting = |a: &BusConfig| {
            a.zenoh_config()
                .unwrap()
                .get_json("scouting/multicast/enabled")
                .unwrap()
        };
        assert_eq!(scouting(&args), "false");
        args.scout = true;
        assert!(args.multicast_scouting());
        assert_ne!(scouting(&args), "false");
    }
}
