//! Byte-message channels between processes on one host, over iceoryx2 shared
//! memory (publish-subscribe, no daemon).
//!
//! # What this crate owns
//!
//! - [`ShmConfig`]: the iceoryx2 prefix that isolates one run (or one test)
//!   from every other, and the capacities of each service.
//! - [`ShmPublisher`]: copies a byte slice into a loaned shared-memory slice
//!   (or lets the caller write the message straight into it), sends it, then
//!   wakes the subscribers through an iceoryx2 event service of the same name.
//! - [`ShmSubscriber`]: a dedicated thread that sleeps on that event service,
//!   drains the samples and hands each payload to a callback.
//! - The small protocol beside the data: wake-ups from publishers to
//!   subscribers on that event service, and "connected" acknowledgements from
//!   each subscriber to a new publisher on a second one (`<name>/acks`).
//! - [`available`] and [`clean_stale`]: the start-up probe that decides
//!   between shared memory and the network, and the removal of resources left
//!   by processes that died.
//!
//! # What it must not know
//!
//! Nothing of Zenoh, of the network fallback, or of graspopt message types
//! and their encoding: it moves opaque bytes (`&[u8]` in, `&[u8]` out). The
//! caller decides what a service name means and what the bytes are.
//!
//! # Threading
//!
//! Ports are built on `iceoryx2::service::ipc_threadsafe::Service`, whose
//! node, port factories and ports are `Send` (the plain `ipc::Service` ports
//! are not). A publisher therefore needs no thread of its own: its ports live
//! behind a mutex and [`ShmPublisher::send`] copies straight from the caller's
//! slice into shared memory on the caller's thread. Each subscriber owns one
//! thread, because iceoryx2 has no async API and its wait calls block.
//!
//! # Wake-up
//!
//! After each send the publisher notifies the subscribers' listeners on the
//! event service (a Unix datagram, sent only if the listener is not already
//! notified); a subscriber thread blocks in the listener's wait, so it uses
//! no CPU between messages and wakes within microseconds. The wait also times
//! out every 20 ms, which bounds how long dropping a subscriber takes and
//! covers a lost wake-up.
//!
//! # Delivery
//!
//! Services are created without safe overflow: when a subscriber's buffer is
//! full, `send` waits for it to make room, for at most
//! [`ShmConfig::delivery_timeout`]; after that the message is dropped for that
//! subscriber only (counted by [`ShmPublisher::discarded_deliveries`]) and the
//! service is scanned for dead processes. A live subscriber thread drains its
//! buffer as fast as its callback returns, so nothing is lost in normal
//! operation and a stuck or killed subscriber cannot block a publisher forever.
//!
//! iceoryx2 drops, rather than waits, when the full buffer belongs to a
//! subscriber that has not yet connected to the publisher (its own thread
//! connects it). Both `open`s therefore return only once the connections
//! exist: [`ShmSubscriber::open`] connects to every existing publisher before
//! it returns, and [`ShmPublisher::open`] waits until every existing
//! subscriber has acknowledged the new publisher.
//!
//! # Capacity
//!
//! One service carries every hand's clouds of a run on a host, so its
//! publisher capacity bounds the hands: [`DEFAULT_MAX_PUBLISHERS`] (1024; it
//! was 16, and the 17th hand fell back to Zenoh). Measured with
//! `examples/capacity.rs` (release build, 64 publishers, 2-core machine under
//! load): the capacity costs no memory that is used, since each publisher's
//! shared memory is sized by the subscribers' buffers (64 publishers map
//! 17.5 GB of address space, 42 MB of it allocated, whether the service
//! admits 256, 1024 or 4096); creating the service takes 35-180 ms at any
//! capacity; the median send-to-callback of 480 KB was 160-280 µs at 256,
//! 1024 and 4096 alike (noise; 92-127 µs with 16 publishers present).
//! iceoryx2 does walk every publisher and listener slot per message: at
//! opt-level 1, 4096 cost 2.7 ms a message against 0.3 ms at 1024. So 1024:
//! far more hands than a host runs, at no measurable cost. A service per hand
//! would lift the bound but make each metric agent discover and wait on one
//! service per hand (a thread, or an iceoryx2 wait set, per hand).
//!
//! # Stale resources
//!
//! A process killed with SIGKILL leaves its node, ports and shared memory
//! behind. Creating a node and opening a service remove those of dead
//! processes (iceoryx2's dead-node cleanup, enabled explicitly in the
//! configuration), so a new process can always open the same service;
//! [`clean_stale`] does it on demand, and a publisher also scans when a
//! delivery times out and, at most once a second, in
//! [`ShmPublisher::subscriber_count`].

#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

use std::fmt::Display;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, Once};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use iceoryx2::identifiers::{UniqueNodeId, UniquePublisherId};
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::port::{BackpressureAction, BackpressureInfo};
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::event::PortFactory as EventFactory;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory as PubSubFactory;

/// iceoryx2 service variant whose ports may move between threads.
type Ipc = ipc_threadsafe::Service;

mod error;
mod probe;
mod subscriber;

use error::service_err;
pub use error::{Result, ShmError};
pub use probe::{available, clean_stale, clean_stale_prefixes};
pub use subscriber::ShmSubscriber;

/// Longest accepted [`ShmConfig::prefix`], in bytes.
///
/// The prefix is part of every file iceoryx2 creates, including the Unix
/// socket path of each event listener (`/tmp/iceoryx2/<prefix><39
/// digits>.event`), which must fit in the 108 bytes of `sun_path`.
pub const MAX_PREFIX_LEN: usize = 32;

/// Publishers a service admits unless configured otherwise: one per hand of a run on one
/// host. See "Capacity" in the crate documentation for why this number.
pub const DEFAULT_MAX_PUBLISHERS: usize = 1024;

/// Text every prefix made by [`run_prefix`] starts with.
pub const PREFIX_BASE: &str = "graspopt_";

/// How long a subscriber thread sleeps at most between two looks at its stop
/// flag and its buffer (publishers wake it earlier through the event service).
/// Bounds the time [`ShmSubscriber`]'s drop waits for the thread.
const SUBSCRIBER_POLL: Duration = Duration::from_millis(20);

/// Port name of each subscriber's wake-up listener.
const WAKE_LISTENER: &str = "graspopt-shm-wake";
/// Port name of each publisher's listener for "connected" acknowledgements.
const ACK_LISTENER: &str = "graspopt-shm-ack";
/// Appended to a service's name to name its acknowledgement event service.
const ACK_SERVICE_SUFFIX: &str = "/acks";
/// Event id of a wake-up (publisher to subscribers).
const WAKE: EventId = EventId::new(0);
/// Event id of a "connected" acknowledgement (subscriber to one publisher).
const ACK: EventId = EventId::new(1);

/// Pause of a subscriber thread after a failed wait.
const ERROR_BACKOFF: Duration = Duration::from_millis(1);

/// Least time between two dead-process scans from
/// [`ShmPublisher::subscriber_count`].
const STALE_SCAN_INTERVAL: Duration = Duration::from_secs(1);

/// How long [`clean_stale`] waits for another process that is already cleaning
/// up the same dead node.
const CLEANUP_WAIT: Duration = Duration::from_millis(200);

/// Settings shared by every process that uses the same services: processes
/// that open one service must agree on all of them except `delivery_timeout`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ShmConfig {
    /// iceoryx2 `global.prefix`: every file and shared-memory object starts
    /// with it, so two prefixes never see each other's services. Use
    /// [`run_prefix`] (or [`ShmConfig::for_run`]) to build one from arbitrary
    /// run text; `open` refuses anything but ASCII letters, digits, `_`, `-`
    /// and `.` (not first), up to [`MAX_PREFIX_LEN`] bytes.
    pub prefix: String,
    /// Most publishers on one service (default [`DEFAULT_MAX_PUBLISHERS`]).
    pub max_publishers: usize,
    /// Most subscribers on one service (default 8).
    pub max_subscribers: usize,
    /// Messages a subscriber can have queued before publishers wait
    /// (default 64).
    pub subscriber_buffer: usize,
    /// Bytes of each publisher's first shared-memory slices (default 64 KiB);
    /// a larger message makes the publisher reallocate to the next power of
    /// two.
    pub initial_payload: usize,
    /// How long `send` waits for one subscriber with a full buffer before it
    /// drops the message for that subscriber, and how long
    /// [`ShmPublisher::open`] waits for the existing subscribers to connect
    /// (default 1 s).
    pub delivery_timeout: Duration,
    /// The name under which [`available`] opens its throwaway services (`<name>/<pid>/<n>`):
    /// the user of this crate names it (graspopt: `graspopt/shm-probe`).
    pub probe_service: String,
}

impl Default for ShmConfig {
    fn default() -> Self {
        Self {
            prefix: PREFIX_BASE.to_owned(),
            max_publishers: DEFAULT_MAX_PUBLISHERS,
            max_subscribers: 8,
            subscriber_buffer: 64,
            initial_payload: 64 * 1024,
            delivery_timeout: Duration::from_secs(1),
            probe_service: "shm-probe".to_owned(),
        }
    }
}

impl ShmConfig {
    /// Default settings with the prefix [`run_prefix`]`(run)`.
    pub fn for_run(run: &str) -> Self {
        Self {
            prefix: run_prefix(run),
            ..Self::default()
        }
    }

    /// Checks the prefix and capacities.
    pub fn validate(&self) -> Result<()> {
        let p = &self.prefix;
        if p.is_empty() {
            return Err(ShmError::InvalidConfig("the prefix is empty".into()));
        }
        if p.len() > MAX_PREFIX_LEN {
            return Err(ShmError::InvalidConfig(format!(
                "the prefix {p:?} has {} bytes, more than {MAX_PREFIX_LEN}",
                p.len()
            )));
        }
        if let Some(c) = p.chars().find(|&c| !is_prefix_char(c)) {
            return Err(ShmError::InvalidConfig(format!(
                "the prefix {p:?} contains {c:?}; only ASCII letters, digits, '_', '-' and '.' are allowed"
            )));
        }
        if p.starts_with('.') {
            return Err(ShmError::InvalidConfig(format!(
                "the prefix {p:?} starts with '.'"
            )));
        }
        for (name, value) in [
            ("max_publishers", self.max_publishers),
            ("max_subscribers", self.max_subscribers),
            ("subscriber_buffer", self.subscriber_buffer),
            ("initial_payload", self.initial_payload),
        ] {
            if value == 0 {
                return Err(ShmError::InvalidConfig(format!(
                    "{name} must be at least 1"
                )));
            }
        }
        Ok(())
    }

    /// The iceoryx2 configuration: iceoryx2's defaults (no config file is
    /// read, so every process agrees) with this prefix.
    fn iceoryx(&self) -> Result<Config> {
        self.validate()?;
        let mut config = Config::default();
        config.global.prefix = FileName::new(self.prefix.as_bytes()).map_err(|e| {
            ShmError::InvalidConfig(format!(
                "iceoryx2 refuses the prefix {:?}: {e:?}",
                self.prefix
            ))
        })?;
        // Already iceoryx2's defaults; stated because stale-resource recovery
        // relies on them.
        config.global.node.cleanup_dead_nodes_on_creation = true;
        config.global.node.cleanup_dead_nodes_on_destruction = true;
        config.global.service.cleanup_dead_nodes_on_open = true;
        Ok(config)
    }

    /// Nodes that may open one service: one per publisher and subscriber.
    fn max_nodes(&self) -> usize {
        self.max_publishers.saturating_add(self.max_subscribers)
    }
}

fn is_prefix_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.')
}

/// A valid prefix for one run: `"graspopt_" + run + "_"`, with every
/// character outside `[A-Za-z0-9_-.]` replaced by `_`. Run text too long for
/// [`MAX_PREFIX_LEN`] is cut and followed by a hash of the whole text, so two
/// long run names that share a beginning still get different prefixes.
pub fn run_prefix(run: &str) -> String {
    let clean: String = run
        .chars()
        .map(|c| if is_prefix_char(c) { c } else { '_' })
        .collect();
    let room = MAX_PREFIX_LEN - PREFIX_BASE.len() - 1;
    let body = if clean.len() <= room {
        clean
    } else {
        // FNV-1a over the original text: stable across builds and platforms.
        let hash = run.bytes().fold(0x811c_9dc5_u32, |h, b| {
            (h ^ u32::from(b)).wrapping_mul(0x0100_0193)
        });
        let keep = room - 9;
        format!("{}-{hash:08x}", &clean[..keep])
    };
    format!("{PREFIX_BASE}{body}_")
}

/// Sets iceoryx2's log level once: `IOX2_LOG_LEVEL` if set, otherwise errors
/// only. Its default, info, is noisy on stderr, and its warnings include a
/// long dump each time the ports of a dead process are found, which is what
/// [`clean_stale`] is for (a killed worker is an event the coordinator reports).
fn init_logging() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| set_log_level_from_env_or(LogLevel::Error));
}

/// The iceoryx2 name `name` of one of `service`'s services.
fn service_name(service: &str, name: &str) -> Result<ServiceName> {
    ServiceName::new(name).map_err(|e| ShmError::InvalidServiceName {
        service: service.to_owned(),
        reason: format!("{e:?}"),
    })
}

fn port_name(service: &str, name: &str) -> Result<PortName> {
    PortName::new(name).map_err(service_err(service, "name port"))
}

/// The node and the three services behind one name: the data, the wake-ups
/// (publishers notify, subscribers listen) and the acknowledgements
/// (subscribers notify, publishers listen).
///
/// The two directions are two event services because an iceoryx2 notifier
/// connects to every listener of its service (a socket and a mapped file
/// each): with one service for both, each hand's notifier connected to every
/// other hand's acknowledgement listener, and a run with every agent in one
/// process held 2,800 descriptors with 32 hands and 9,700 with 64 (growing as
/// the square of the hands), past a default limit of 1,024 open files at 20.
/// Apart, a notifier connects only to the ports that listen to it.
/// Field order is drop order.
struct Endpoints {
    wakes: EventFactory<Ipc>,
    acks: EventFactory<Ipc>,
    pubsub: PubSubFactory<Ipc, [u8], ()>,
    _node: Node<Ipc>,
}

impl Endpoints {
    fn open(config: &ShmConfig, service: &str, role: &str) -> Result<Self> {
        init_logging();
        let ice = config.iceoryx()?;
        let name = service_name(service, service)?;
        let node_name = NodeName::new(role).map_err(service_err(service, "name node"))?;
        let node = NodeBuilder::new()
            .name(&node_name)
            .config(&ice)
            // The host process owns SIGINT/SIGTERM; iceoryx2 must not install handlers.
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<Ipc>()
            .map_err(service_err(service, "create iceoryx2 node"))?;
        let pubsub = node
            .service_builder(&name)
            .publish_subscribe::<[u8]>()
            .max_publishers(config.max_publishers)
            .max_subscribers(config.max_subscribers)
            .max_nodes(config.max_nodes())
            .subscriber_max_buffer_size(config.subscriber_buffer)
            .subscriber_max_borrowed_samples(1)
            .history_size(0)
            .enable_safe_overflow(false)
            .open_or_create()
            .map_err(service_err(service, "open publish-subscribe service"))?;
        // Port capacities as the data service's nodes: the publisher port,
        // not one of its event ports, is what a full service refuses first.
        let events = |name: &ServiceName, what| {
            node.service_builder(name)
                .event()
                .max_notifiers(config.max_nodes())
                .max_listeners(config.max_nodes())
                .max_nodes(config.max_nodes())
                .open_or_create()
                .map_err(service_err(service, what))
        };
        let wakes = events(&name, "open wake-up event service")?;
        let ack_name = service_name(service, &format!("{service}{ACK_SERVICE_SUFFIX}"))?;
        let acks = events(&ack_name, "open acknowledgement event service")?;
        Ok(Self {
            wakes,
            acks,
            pubsub,
            _node: node,
        })
    }
}

/// Publisher ports. Field order is drop order: ports before their services.
struct PublisherPorts {
    notifier: Notifier<Ipc>,
    publisher: Publisher<Ipc, [u8], ()>,
    acks: Listener<Ipc>,
    endpoints: Endpoints,
    last_stale_scan: Instant,
}

impl PublisherPorts {
    fn open(
        config: &ShmConfig,
        service: &str,
        timed_out: Arc<AtomicBool>,
        discarded: Arc<AtomicU64>,
    ) -> Result<Self> {
        let endpoints = Endpoints::open(config, service, "graspopt-shm-publisher")?;
        // Before the publisher port: a subscriber that sees the publisher
        // must find this listener to acknowledge to.
        let acks = endpoints
            .acks
            .listener_builder()
            .name(&port_name(service, ACK_LISTENER)?)
            .create()
            .map_err(service_err(service, "create acknowledgement listener"))?;
        let timeout = config.delivery_timeout;
        let publisher = endpoints
            .pubsub
            .publisher_builder()
            .initial_max_slice_len(config.initial_payload)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .max_loaned_samples(1)
            .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered)
            .set_backpressure_handler(move |info: &BackpressureInfo| {
                if info.elapsed_time < timeout {
                    BackpressureAction::Retry
                } else {
                    timed_out.store(true, Ordering::Relaxed);
                    discarded.fetch_add(1, Ordering::Relaxed);
                    BackpressureAction::DiscardData
                }
            })
            .create()
            .map_err(service_err(service, "create publisher"))?;
        let notifier = endpoints
            .wakes
            .notifier_builder()
            .default_event_id(WAKE)
            .create()
            .map_err(service_err(service, "create notifier"))?;
        let ports = Self {
            notifier,
            publisher,
            acks,
            endpoints,
            last_stale_scan: Instant::now(),
        };
        ports.wait_for_subscribers(config.delivery_timeout);
        Ok(ports)
    }

    /// Wakes every subscriber thread on the service. A failed wake-up only
    /// delays delivery until the subscriber's next poll.
    fn wake_subscribers(&self) {
        let _ = self.notifier.notify();
    }

    /// Waits until every subscriber on the service has connected to this
    /// publisher, or `timeout` passed.
    ///
    /// A subscriber connects from its own thread. Until it has, iceoryx2
    /// queues messages for it but, once its queue is full, drops further ones
    /// instead of waiting (it cannot tell a slow subscriber from one that will
    /// never connect). So a publisher that sent more than `subscriber_buffer`
    /// messages right after opening could lose some; each subscriber instead
    /// acknowledges the new publisher once connected, and `open` waits for
    /// the acknowledgements.
    fn wait_for_subscribers(&self, timeout: Duration) -> bool {
        let start = Instant::now();
        let mut acknowledged = 0u64;
        self.wake_subscribers();
        loop {
            let subscribers = self
                .endpoints
                .pubsub
                .dynamic_config()
                .number_of_subscribers() as u64;
            if acknowledged >= subscribers {
                return true;
            }
            let left = timeout.saturating_sub(start.elapsed());
            if left.is_zero() {
                return false;
            }
            let _ = self.acks.timed_wait(
                |event| {
                    if event.id == ACK {
                        acknowledged += event.count;
                    }
                },
                left.min(SUBSCRIBER_POLL),
            );
        }
    }

    fn send(&self, service: &str, bytes: &[u8]) -> Result<()> {
        let sample = self
            .publisher
            .loan_slice_uninit(bytes.len())
            .map_err(service_err(service, "loan shared-memory slice"))?;
        sample
            .write_from_slice(bytes)
            .send()
            .map_err(service_err(service, "send"))?;
        self.wake_subscribers();
        Ok(())
    }

    fn send_with<E: From<ShmError>>(
        &self,
        service: &str,
        len: usize,
        fill: impl FnOnce(&mut [u8]) -> Result<(), E>,
    ) -> Result<(), E> {
        // Zero-filled: the safe API has no uninitialised bytes to hand out
        // (examples/fill.rs measures the alternatives).
        let mut sample = self
            .publisher
            .loan_slice(len)
            .map_err(service_err(service, "loan shared-memory slice"))?;
        // An error drops the sample unsent, returning it to the publisher.
        fill(sample.payload_mut())?;
        sample.send().map_err(service_err(service, "send"))?;
        self.wake_subscribers();
        Ok(())
    }
}

struct PublisherShared {
    service: String,
    timed_out: Arc<AtomicBool>,
    discarded: Arc<AtomicU64>,
    ports: Mutex<PublisherPorts>,
}

/// Sends byte messages on one service. `Send + Sync + Clone`; clones share the
/// same iceoryx2 node and publisher (dropped with the last clone), and sends
/// from clones are serialised.
#[derive(Clone)]
pub struct ShmPublisher {
    shared: Arc<PublisherShared>,
}

impl std::fmt::Debug for ShmPublisher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShmPublisher")
            .field("service", &self.shared.service)
            .finish_non_exhaustive()
    }
}

impl ShmPublisher {
    /// Opens (creating if needed) `service`, a name like
    /// `"graspopt/run-1/clouds"`, and a publisher on it. Resources of dead
    /// processes are removed first. Returns once every subscriber already on
    /// the service has connected to the new publisher (so a burst sent at
    /// once is not lost), or after [`ShmConfig::delivery_timeout`] if one
    /// does not answer (its thread stuck in a callback).
    pub fn open(config: &ShmConfig, service: &str) -> Result<ShmPublisher> {
        let timed_out = Arc::new(AtomicBool::new(false));
        let discarded = Arc::new(AtomicU64::new(0));
        let ports = PublisherPorts::open(config, service, timed_out.clone(), discarded.clone())?;
        Ok(ShmPublisher {
            shared: Arc::new(PublisherShared {
                service: service.to_owned(),
                timed_out,
                discarded,
                ports: Mutex::new(ports),
            }),
        })
    }

    /// The service name.
    pub fn service(&self) -> &str {
        &self.shared.service
    }

    fn lock(&self, operation: &'static str) -> Result<MutexGuard<'_, PublisherPorts>> {
        self.shared.ports.lock().map_err(|_| ShmError::Service {
            service: self.shared.service.clone(),
            operation,
            detail: "the publisher lock is poisoned (an earlier call panicked)".into(),
        })
    }

    /// Copies `bytes` into a loaned shared-memory slice, sends it to every
    /// connected subscriber and wakes them. Returns once the message is in
    /// every subscriber's queue (or dropped for a subscriber whose queue stayed
    /// full for [`ShmConfig::delivery_timeout`]). Messages larger than
    /// [`ShmConfig::initial_payload`] make the publisher reallocate its
    /// shared memory to the next power of two.
    pub fn send(&self, bytes: &[u8]) -> Result<()> {
        let ports = self.lock("send")?;
        let sent = ports.send(&self.shared.service, bytes);
        self.after_send(&ports);
        sent
    }

    /// Like [`send`](Self::send), but the message is written straight into
    /// shared memory: loans a zero-filled slice of `len` bytes, hands it to
    /// `fill`, then sends it. If `fill` fails, nothing is sent and its error
    /// is returned.
    pub fn send_with<E: From<ShmError>>(
        &self,
        len: usize,
        fill: impl FnOnce(&mut [u8]) -> Result<(), E>,
    ) -> Result<(), E> {
        let ports = self.lock("send")?;
        let sent = ports.send_with(&self.shared.service, len, fill);
        self.after_send(&ports);
        sent
    }

    fn after_send(&self, ports: &PublisherPorts) {
        if self.shared.timed_out.swap(false, Ordering::Relaxed) {
            // A subscriber stayed full: if its process died, remove it so the
            // next send does not wait for it again.
            ports.endpoints.pubsub.try_cleanup_dead_nodes();
        }
    }

    /// Number of subscribers currently on the service (from its dynamic
    /// config), whichever process they are in. At most once a second this
    /// also removes subscribers of dead processes, so a killed subscriber is
    /// not counted for long.
    pub fn subscriber_count(&self) -> Result<usize> {
        let mut ports = self.lock("count subscribers")?;
        if ports.last_stale_scan.elapsed() >= STALE_SCAN_INTERVAL {
            ports.endpoints.pubsub.try_cleanup_dead_nodes();
            ports.last_stale_scan = Instant::now();
        }
        Ok(ports
            .endpoints
            .pubsub
            .dynamic_config()
            .number_of_subscribers())
    }

    /// Deliveries dropped so far because a subscriber's queue stayed full
    /// for [`ShmConfig::delivery_timeout`] (one per message and subscriber).
    pub fn discarded_deliveries(&self) -> u64 {
        self.shared.discarded.load(Ordering::Relaxed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn handles_can_move_between_threads() {
        fn shareable<T: Send + Sync + Clone>() {}
        fn movable<T: Send + Sync>() {}
        shareable::<ShmPublisher>();
        movable::<ShmSubscriber>();
    }

    #[test]
    fn run_prefix_sanitises_and_bounds() {
        assert_eq!(run_prefix("run-1"), "graspopt_run-1_");
        assert_eq!(run_prefix("a/b c:d"), "graspopt_a_b_c_d_");
        let long = "x".repeat(100);
        let p = run_prefix(&long);
        assert_eq!(p.len(), MAX_PREFIX_LEN);
        assert_ne!(p, run_prefix(&format!("{long}y")));
        for run in ["", "é", "../..", &long] {
            let config = ShmConfig::for_run(run);
            config.validate().unwrap();
            config.iceoryx().unwrap();
        }
    }

    #[test]
    fn bad_prefixes_are_refused() {
        for prefix in ["", "a/b", ".hidden", "é", &"x".repeat(MAX_PREFIX_LEN + 1)] {
            let config = ShmConfig {
                prefix: prefix.into(),
                ..ShmConfig::default()
            };
            let err = config.validate().unwrap_err();
            assert!(
                matches!(err, ShmError::InvalidConfig(_)),
                "{prefix:?}: {err}"
            );
        }
        let zero = ShmConfig {
            subscriber_buffer: 0,
            ..ShmConfig::default()
        };
        assert!(zero.validate().is_err());
    }
}
