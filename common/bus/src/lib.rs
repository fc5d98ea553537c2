//! graspopt on the network. This is the only common crate that knows there is a network
//! (`graspopt-protocol` defines what is said, not how it travels):
//!
//! - [`agent`]: the [`Agent`] trait every agent implements (its kind, settings, run).
//! - [`config`]: how a process joins the bus, a plain [`BusConfig`] (the binary's bus flags
//!   fill it: `--connect`, `--listen`, `--mode`, `--zenoh-config`, `--no-multicast-scouting`,
//!   `--shm-prefix`, `--no-shm`).
//! - [`session`]: a [`Bus`]: a Zenoh session plus typed put / subscribe / query / serve over the
//!   protocol's codecs. Trial commands and results are put with `CongestionControl::Block`:
//!   they are never dropped under congestion. Payloads that do not decode are handed to the
//!   caller as errors (to count and log), never acted on.
//! - [`alive`]: liveliness tokens and watching who is alive.
//! - `reach`: whether a session reached the endpoints it connects to, and if not, why (a
//!   router that refused the login among them).
//! - [`inbox`]: accepting the messages of one run, counting and logging the bad ones.
//! - [`clouds`]: the contact-cloud channel: iceoryx2 shared memory when a metric agent listens
//!   on the same host, Zenoh otherwise, chosen per message.
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod agent;
pub mod alive;
pub mod clouds;
pub mod config;
pub mod error;
pub mod inbox;
mod reach;
pub mod session;
mod task;

pub use agent::Agent;
pub use alive::{AliveEvent, AliveWatch, Claim};
pub use clouds::{CloudPath, CloudReceiver, CloudSender, ReceivedClouds};
pub use config::{BusConfig, BusMode};
pub use error::BusError;
pub use inbox::Inbox;
pub use reach::{REACH_GRACE, REACH_REMINDER};
pub use session::{
    Bus, Incoming, LoopbackSessions, RawSample, RawSubscription, Received, Server, Subscription,
    host_name, protocol_encoding, zenoh_encoding,
};
/// Whether a put waits (`Block`) or drops (`Drop`) under congestion.
pub use zenoh::qos::CongestionControl;

/// A free TCP port on the loopback interface (bound then released: for tests and for the
/// embedded run's default listener).
pub fn free_loopback_port() -> std::io::Result<u16> {
    let listener = std::net::TcpListener::bind(("127.0.0.1", 0))?;
    Ok(listener.local_addr()?.port())
}

/// Milliseconds since the Unix epoch.
pub fn now_ms() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_millis() as i64)
        .unwrap_or(0)
}
