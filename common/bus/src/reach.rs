//! Whether a session reached the endpoints it connects to and, when it did not, why: a host
//! name that does not resolve, nothing listening there, or a router that answered but refused
//! the session, which is what a failed login looks like (Zenoh says only that it was
//! "Unable to connect", as when nothing listens).

use std::path::{Path, PathBuf};
use std::time::Duration;

use zenoh::Session;

/// How long a process waits for its `--connect` endpoints before saying it cannot reach them.
pub const REACH_GRACE: Duration = Duration::from_secs(3);
/// How often it says so again while Zenoh keeps trying (every 1 to 4 s, in the background).
pub const REACH_REMINDER: Duration = Duration::from_secs(15);
/// How long a look at whether an endpoint accepts a TCP connection may take.
const KNOCK: Duration = Duration::from_secs(1);

/// Where a session connects and who it logs in as there.
#[derive(Debug, Clone, Default)]
pub(crate) struct Target {
    /// The endpoints it connects to (`--connect`, or its Zenoh configuration's).
    pub endpoints: Vec<String>,
    /// The user of its `transport.auth.usrpwd` (`None`: it gives no credentials).
    user: Option<String>,
    /// Its Zenoh configuration file.
    file: Option<PathBuf>,
}

impl Target {
    /// The endpoints and login of `config` (read from `file`, if any).
    pub(crate) fn of(config: &zenoh::Config, file: Option<&Path>) -> Target {
        let json = |key: &str| config.get_json(key).unwrap_or_default();
        // JSON text: a list of endpoints (or one per mode), and a user name or null.
        let endpoints = json("connect/endpoints")
            .split('"')
            .skip(1)
            .step_by(2)
            .filter(|s| s.contains('/'))
            .map(str::to_string)
            .collect();
        let user = json("transport/auth/usrpwd/user");
        let user = user
            .trim()
            .strip_prefix('"')
            .and_then(|u| u.strip_suffix('"'));
        Target {
            endpoints,
            user: user.map(str::to_string),
            file: file.map(Path::to_path_buf),
        }
    }

    fn names(&self) -> String {
        self.endpoints.join(", ")
    }

    /// Why none of the endpoints was reached, said to a person.
    pub(crate) async fn why_unreached(&self) -> String {
        let names = self.names();
        match self.look().await {
            Unreached::Refused => self.refused(),
            Unreached::Unresolved(why) => format!("cannot reach {names}: {}", why.join("; ")),
            Unreached::Silent => format!(
                "nothing answers at {names}: check the address, and that the router runs and \
                 its port is open"
            ),
        }
    }

    /// Why none of the endpoints was reached, for an agent that goes on trying.
    async fn why_still_trying(&self) -> String {
        let names = self.names();
        let why = match self.look().await {
            Unreached::Refused => self.refused(),
            Unreached::Unresolved(why) => format!("cannot reach {names}: {}", why.join("; ")),
            Unreached::Silent => format!(
                "cannot reach {names}: nothing answers there: check the address, and that the \
                 router runs and its port is open"
            ),
        };
        format!("{why}. Still trying in the background")
    }

    /// A router that answered and refused: the login failed.
    fn refused(&self) -> String {
        let names = self.names();
        let file = self
            .file
            .as_ref()
            .map_or("its Zenoh config".to_string(), |f| f.display().to_string());
        match &self.user {
            Some(user) => format!(
                "authentication failed at {names}: the router answered but refused this session: \
                 check the user \"{user}\" and its password (transport.auth.usrpwd in {file}) \
                 against the router's credentials dictionary (the file its \
                 transport.auth.usrpwd.dictionary_file names)"
            ),
            None => format!(
                "authentication failed at {names}: the router answered but refused this session, \
                 and this process gives no user name and password: give them in its Zenoh config \
                 (transport.auth.usrpwd, --zenoh-config; deploy/zenoh/secure/ has a file per \
                 role) as the router's credentials dictionary has them"
            ),
        }
    }

    /// Why the endpoints were not reached: names that do not resolve, else a TCP endpoint
    /// that accepts a connection (a router that refused the session), else nothing there.
    async fn look(&self) -> Unreached {
        let mut unresolved = Vec::new();
        for e in &self.endpoints {
            if let Some(reason) = unresolved_host(e).await {
                unresolved.push(reason);
            }
        }
        if !unresolved.is_empty() {
            return Unreached::Unresolved(unresolved);
        }
        for e in &self.endpoints {
            if accepts_tcp(e).await {
                return Unreached::Refused;
            }
        }
        Unreached::Silent
    }
}

/// Why a session has no link to its endpoints.
enum Unreached {
    /// Host names that do not resolve, each with the reason.
    Unresolved(Vec<String>),
    /// An endpoint accepts TCP connections, so a router listens there and refused the
    /// session.
    Refused,
    /// Nothing accepts a connection there.
    Silent,
}

/// Whether the session holds a link to a router or peer.
pub(crate) async fn linked(session: &Session) -> bool {
    let info = session.info();
    info.routers_zid().await.next().is_some() || info.peers_zid().await.next().is_some()
}

/// Warns, [`REACH_GRACE`] after the session opened, that none of the endpoints answered
/// (naming them and why: see [`Target::why_unreached`]), then every [`REACH_REMINDER`]
/// while that lasts; says so when one answers at last. Ends with the session.
pub(crate) async fn watch_reach(session: Session, target: Target) {
    let started = tokio::time::Instant::now();
    let poll = Duration::from_millis(100);
    while started.elapsed() < REACH_GRACE {
        if session.is_closed() || linked(&session).await {
            return;
        }
        tokio::time::sleep(poll).await;
    }
    tracing::warn!("{}", target.why_still_trying().await);
    let names = target.names();
    let mut told = tokio::time::Instant::now();
    loop {
        tokio::time::sleep(poll).await;
        if session.is_closed() {
            return;
        }
        if linked(&session).await {
            tracing::warn!(
                "reached {names} after {:.0} s",
                started.elapsed().as_secs_f64()
            );
            return;
        }
        if told.elapsed() >= REACH_REMINDER {
            told = tokio::time::Instant::now();
            tracing::warn!(
                "still cannot reach {names} after {:.0} s: still trying",
                started.elapsed().as_secs_f64()
            );
        }
    }
}

/// `HOST:PORT` of a `tcp/HOST:PORT` endpoint (without its `?` options and `#` settings).
fn tcp_address(endpoint: &str) -> Option<&str> {
    endpoint.strip_prefix("tcp/")?.split(['?', '#']).next()
}

/// Why a `tcp/HOST:PORT` endpoint cannot be reached when its host name does not resolve.
async fn unresolved_host(endpoint: &str) -> Option<String> {
    let (host, _) = tcp_address(endpoint)?.rsplit_once(':')?;
    if host.starts_with('[') || host.parse::<std::net::Ipv4Addr>().is_ok() {
        return None;
    }
    let host = host.to_string();
    let lookup = tokio::task::spawn_blocking(move || {
        std::net::ToSocketAddrs::to_socket_addrs(&(host.as_str(), 0))
            .map(|_| ())
            .map_err(|e| (host, e))
    });
    match lookup.await {
        Ok(Err((host, e))) => Some(format!("the host name {host} does not resolve ({e})")),
        _ => None,
    }
}

/// Whether a `tcp/` endpoint accepts a TCP connection within [`KNOCK`] (the connection is
/// closed at once).
async fn accepts_tcp(endpoint: &str) -> bool {
    let Some(address) = tcp_address(endpoint).map(str::to_string) else {
        return false;
    };
    let knock = tokio::task::spawn_blocking(move || {
        let addresses = std::net::ToSocketAddrs::to_socket_addrs(&address.as_str());
        addresses
            .is_ok_and(|mut a| a.any(|a| std::net::TcpStream::connect_timeout(&a, KNOCK).is_ok()))
    });
    knock.await.unwrap_or(false)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn target(json5: &str) -> Target {
        let mut config = zenoh::Config::default();
        for line in json5.lines() {
            let (key, value) = line.split_once('=').unwrap();
            config.insert_json5(key, value).unwrap();
        }
        Target::of(&config, Some(Path::new("hand.json5")))
    }

    #[test]
    fn the_target_is_read_from_the_configuration() {
        let t = target(
            "connect/endpoints=[\"tcp/127.0.0.1:7447\",\"tcp/[::1]:7448\"]\n\
             transport/auth/usrpwd/user=\"hand\"\ntransport/auth/usrpwd/password=\"x\"",
        );
        assert_eq!(t.endpoints, ["tcp/127.0.0.1:7447", "tcp/[::1]:7448"]);
        assert_eq!(t.user.as_deref(), Some("hand"));
        let t = target("connect/endpoints=[]");
        assert!(t.endpoints.is_empty() && t.user.is_none());
    }

    /// An endpoint where something listens but no session came is a refusal; one where
    /// nothing listens is silent.
    #[tokio::test]
    async fn a_listening_port_is_told_from_a_silent_one() {
        let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let open = format!("tcp/{}", listener.local_addr().unwrap());
        let closed = format!("tcp/127.0.0.1:{}", crate::free_loopback_port().unwrap());
        let mut t = target("transport/auth/usrpwd/user=\"hand\"");
        t.endpoints = vec![open.clone()];
        let why = t.why_unreached().await;
        assert!(
            why.starts_with(&format!("authentication failed at {open}: "))
                && why.contains("\"hand\""),
            "{why}"
        );
        t.endpoints = vec![closed.clone()];
        assert_eq!(
            t.why_unreached().await,
            format!(
                "nothing answers at {closed}: check the address, and that the router runs and its \
                 port is open"
            )
        );
    }
}
