//! A [`Bus`]: one Zenoh session and typed operations on it.

use std::marker::PhantomData;
use std::time::Duration;

use graspopt_protocol::keys::{KeyFor, QueryFor, Serves};
use graspopt_protocol::{Encoding, Message, Request, decode, encode};
use zenoh::Session;
use zenoh::bytes::Encoding as ZEncoding;
use zenoh::handlers::{FifoChannel, FifoChannelHandler, RingChannel, RingChannelHandler};
use zenoh::pubsub::Subscriber;
use zenoh::qos::CongestionControl;
use zenoh::query::{Query, Queryable};
use zenoh::sample::Sample;

use crate::reach::{Target, linked, watch_reach};
use crate::{BusConfig, BusError};

/// The protocol encoding as a Zenoh encoding.
pub fn zenoh_encoding(encoding: Encoding) -> ZEncoding {
    match encoding {
        Encoding::Json => ZEncoding::APPLICATION_JSON,
        Encoding::Bincode => ZEncoding::from(encoding.mime()),
    }
}

/// The protocol encoding a Zenoh encoding declares.
pub fn protocol_encoding(encoding: &ZEncoding) -> Encoding {
    Encoding::from_mime(&encoding.to_string())
}

/// A joined bus.
#[derive(Clone)]
pub struct Bus {
    session: Session,
    host: String,
    shm: Option<graspopt_shm::ShmConfig>,
    /// Whether other processes can be found from here without them connecting to us first
    /// (`--connect` endpoints, multicast scouting or a configuration file): a session that
    /// only listens (the embedded run) was just made and holds no other agents yet.
    reaches_out: bool,
    /// Where it connects, and who it logs in as there.
    target: Target,
}

impl std::fmt::Debug for Bus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Bus")
            .field("host", &self.host)
            .field("shm", &self.shm.is_some())
            .finish()
    }
}

/// This host's name as a key chunk (`GRASPOPT_HOST` overrides, for tests that pretend to be
/// on several hosts).
pub fn host_name() -> String {
    let raw = std::env::var("GRASPOPT_HOST")
        .ok()
        .or_else(|| std::fs::read_to_string("/etc/hostname").ok())
        .unwrap_or_else(|| "localhost".to_string());
    graspopt_protocol::keys::sanitize_chunk(raw.trim())
}

/// Sessions on loopback for tests: a hub listening on a free port (`endpoint`) and sessions
/// connected to it, none with shared memory.
pub struct LoopbackSessions {
    /// The listening session.
    pub hub: Bus,
    /// Where the hub listens (`tcp/127.0.0.1:PORT`), for more peers ([`Bus::loopback_peer`]).
    pub endpoint: String,
    /// The connected sessions.
    pub peers: Vec<Bus>,
}

impl Bus {
    /// A hub on a free loopback port and `peers` sessions connected to it (no shared
    /// memory): what a test of several agents on one machine needs.
    pub async fn loopback(peers: usize) -> Result<LoopbackSessions, BusError> {
        let port = crate::free_loopback_port()
            .map_err(|e| BusError::Config(format!("no free loopback port: {e}")))?;
        let endpoint = format!("tcp/127.0.0.1:{port}");
        let mut args = BusConfig::loopback(vec![endpoint.clone()], Vec::new());
        args.no_shm = true;
        let hub = Bus::open(&args).await?;
        let mut connected = Vec::with_capacity(peers);
        for _ in 0..peers {
            connected.push(Bus::loopback_peer(&endpoint).await?);
        }
        Ok(LoopbackSessions {
            hub,
            endpoint,
            peers: connected,
        })
    }

    /// A session connected to `endpoint` (a [`Bus::loopback`] hub's), without shared memory.
    pub async fn loopback_peer(endpoint: &str) -> Result<Bus, BusError> {
        let mut args = BusConfig::loopback(Vec::new(), vec![endpoint.to_string()]);
        args.no_shm = true;
        Bus::open(&args).await
    }

    /// Opens a session as `args` describes. A client refused by the router it connects to (a
    /// failed login: Zenoh says only "Unable to connect") is [`BusError::Unreached`], saying
    /// so.
    pub async fn open(args: &BusConfig) -> Result<Bus, BusError> {
        Bus::open_with(args, true).await
    }

    /// A session for a tool that watches the bus (`topic`, `monitor`): no shared memory and,
    /// when `quiet`, no warnings in the background about endpoints that do not answer: a
    /// command that ends soon says so itself ([`Bus::check_linked`]).
    pub async fn open_watcher(args: &BusConfig, quiet: bool) -> Result<Bus, BusError> {
        let args = BusConfig {
            no_shm: true,
            ..args.clone()
        };
        Bus::open_with(&args, !quiet).await
    }

    async fn open_with(args: &BusConfig, warn_reach: bool) -> Result<Bus, BusError> {
        let config = args.zenoh_config()?;
        let target = Target::of(&config, args.zenoh_config.as_deref());
        let shm = if args.no_shm {
            None
        } else {
            let prefix = args
                .shm_prefix
                .clone()
                .unwrap_or_else(|| graspopt_shm::PREFIX_BASE.to_string());
            let config = graspopt_shm::ShmConfig {
                prefix,
                probe_service: graspopt_protocol::keys::shm_probe_service(),
                ..graspopt_shm::ShmConfig::default()
            };
            // A prefix given that cannot be used is the user's mistake, not a reason to fall
            // back to the network in silence.
            config
                .validate()
                .map_err(|e| BusError::Config(format!("--shm-prefix: {e}")))?;
            Some(config)
        };
        let session = match zenoh::open(config).await {
            Ok(session) => session,
            // A client that reaches none of its endpoints fails at once: say why.
            Err(e) if e.to_string().contains("Unable to connect") => {
                return Err(BusError::Unreached(target.why_unreached().await));
            }
            Err(e) => return Err(BusError::zenoh("opening the session", e)),
        };
        // A peer does not fail when its `--connect` endpoints are unreachable: Zenoh keeps
        // trying in the background, in silence. Say which cannot be reached, and when they
        // are.
        if warn_reach && !args.connect.is_empty() && args.mode != Some(crate::BusMode::Client) {
            tokio::spawn(watch_reach(session.clone(), target.clone()));
        }
        // Resources of processes that died under this prefix (a killed worker).
        if let Some(config) = &shm
            && let Err(e) = graspopt_shm::clean_stale(config)
        {
            tracing::warn!("shared memory: stale-resource cleanup failed: {e}");
        }
        Ok(Bus {
            session,
            host: host_name(),
            shm,
            reaches_out: !args.connect.is_empty()
                || args.multicast_scouting()
                || args.zenoh_config.is_some(),
            target,
        })
    }

    /// Ok when the session holds a link, or connects nowhere (it meets others by multicast
    /// or as they connect to it); else [`BusError::Unreached`], naming the endpoints and why
    /// (nothing answers, a name that does not resolve, a router that refused the login).
    pub async fn check_linked(&self) -> Result<(), BusError> {
        if self.target.endpoints.is_empty() || self.is_linked().await {
            return Ok(());
        }
        Err(BusError::Unreached(self.target.why_unreached().await))
    }

    pub fn session(&self) -> &Session {
        &self.session
    }

    /// Whether this session can meet agents it did not start with (see
    /// [`Bus::wait_until_unique`]).
    pub fn reaches_out(&self) -> bool {
        self.reaches_out
    }

    /// This host's name (a key chunk).
    /// Whether the session holds a link to a router or another peer: false while none of
    /// its `--connect` endpoints answers (and no peer was scouted).
    pub async fn is_linked(&self) -> bool {
        linked(&self.session).await
    }

    pub fn host(&self) -> &str {
        &self.host
    }

    /// Shared-memory settings, unless disabled.
    pub fn shm(&self) -> Option<&graspopt_shm::ShmConfig> {
        self.shm.as_ref()
    }

    /// Puts a message reliably: blocks under congestion rather than dropping (trial
    /// commands, clouds, results). `key`: a [`Key<T>`](graspopt_protocol::Key) of the key
    /// table, so that only a `T` can go there (or a plain key expression).
    pub async fn put<T: Message>(
        &self,
        key: &(impl KeyFor<T> + ?Sized),
        msg: &T,
        encoding: Encoding,
    ) -> Result<(), BusError> {
        let bytes = encode(msg, encoding)?;
        self.put_bytes(key.key_expr(), bytes, encoding, CongestionControl::Block)
            .await
    }

    /// Puts a message that a newer one soon replaces (status): dropped under congestion.
    pub async fn put_droppable<T: Message>(
        &self,
        key: &(impl KeyFor<T> + ?Sized),
        msg: &T,
        encoding: Encoding,
    ) -> Result<(), BusError> {
        let bytes = encode(msg, encoding)?;
        self.put_bytes(key.key_expr(), bytes, encoding, CongestionControl::Drop)
            .await
    }

    /// Puts raw bytes declared as `encoding` (tests and tools).
    pub async fn put_bytes(
        &self,
        key: &str,
        bytes: Vec<u8>,
        encoding: Encoding,
        congestion: CongestionControl,
    ) -> Result<(), BusError> {
        self.session
            .put(key, bytes)
            .encoding(zenoh_encoding(encoding))
            .congestion_control(congestion)
            .await
            .map_err(|e| BusError::zenoh(format!("put on {key}"), e))
    }

    /// Subscribes to `key` with a bounded queue (back-pressure on the sender's side when the
    /// queue is full: for agents that keep up). The messages are `T`s: the type of the
    /// [`Key<T>`](graspopt_protocol::Key).
    pub async fn subscribe<T: Message>(
        &self,
        key: &(impl KeyFor<T> + ?Sized),
    ) -> Result<Subscription<T>, BusError> {
        let key = key.key_expr();
        let sub = self
            .session
            .declare_subscriber(key)
            .with(FifoChannel::new(1024))
            .await
            .map_err(|e| BusError::zenoh(format!("subscribing to {key}"), e))?;
        Ok(Subscription {
            inner: Inner::Fifo(sub),
            _t: PhantomData,
        })
    }

    /// Subscribes to `key` through a ring buffer of `capacity` samples: a slow reader loses
    /// the oldest samples and never slows the publishers (monitors, terminals).
    pub async fn subscribe_ring<T: Message>(
        &self,
        key: &(impl KeyFor<T> + ?Sized),
        capacity: usize,
    ) -> Result<Subscription<T>, BusError> {
        Ok(Subscription {
            inner: Inner::Ring(self.ring_subscriber(key.key_expr(), capacity).await?),
            _t: PhantomData,
        })
    }

    /// Subscribes to every sample under `key` (a key expression), undecoded, through a ring
    /// buffer of `capacity` samples: for tools that watch topics. A slow reader loses the
    /// oldest samples and never slows the publishers.
    pub async fn subscribe_raw(
        &self,
        key: &str,
        capacity: usize,
    ) -> Result<RawSubscription, BusError> {
        Ok(RawSubscription {
            sub: self.ring_subscriber(key, capacity).await?,
        })
    }

    async fn ring_subscriber(
        &self,
        key: &str,
        capacity: usize,
    ) -> Result<Subscriber<RingChannelHandler<Sample>>, BusError> {
        self.session
            .declare_subscriber(key)
            .with(RingChannel::new(capacity.max(1)))
            .await
            .map_err(|e| BusError::zenoh(format!("subscribing to {key}"), e))
    }

    /// Sends a query and decodes the first reply.
    pub async fn query<Q: Message, R: Message>(
        &self,
        key: &(impl QueryFor<Q, R> + ?Sized),
        request: &Q,
        timeout: Duration,
    ) -> Result<R, BusError> {
        let key = key.key_expr();
        let bytes = encode(request, Encoding::Bincode)?;
        let started = std::time::Instant::now();
        let replies = self
            .session
            .get(key)
            .payload(bytes)
            .encoding(zenoh_encoding(Encoding::Bincode))
            // The first reply is wanted as soon as it arrives: consolidation would hold it
            // until every responder has finished, and a responder cut off by a network
            // fault would then delay it to the timeout.
            .consolidation(zenoh::query::ConsolidationMode::None)
            .timeout(timeout)
            .await
            .map_err(|e| BusError::zenoh(format!("query on {key}"), e))?;
        first_reply(key, &replies, timeout, started).await
    }

    /// Sends a query without a payload (the coordinator's state, say) and decodes the first
    /// reply.
    pub async fn get<R: Message>(
        &self,
        key: &(impl QueryFor<(), R> + ?Sized),
        timeout: Duration,
    ) -> Result<R, BusError> {
        let key = key.key_expr();
        let started = std::time::Instant::now();
        let replies = self
            .session
            .get(key)
            .consolidation(zenoh::query::ConsolidationMode::None)
            .timeout(timeout)
            .await
            .map_err(|e| BusError::zenoh(format!("query on {key}"), e))?;
        first_reply(key, &replies, timeout, started).await
    }

    /// Answers queries on `key`, whose requests are `Q`s.
    pub async fn serve<Q: Request>(
        &self,
        key: &(impl Serves<Q> + ?Sized),
    ) -> Result<Server<Q>, BusError> {
        let key = key.key_expr();
        let queryable = self
            .session
            .declare_queryable(key)
            .await
            .map_err(|e| BusError::zenoh(format!("serving {key}"), e))?;
        Ok(Server {
            queryable,
            _q: PhantomData,
        })
    }

    /// Closes the session (liveliness tokens vanish at once for the others).
    pub async fn close(&self) -> Result<(), BusError> {
        self.session
            .close()
            .await
            .map_err(|e| BusError::zenoh("closing the session", e))
    }
}

enum Inner {
    Fifo(Subscriber<FifoChannelHandler<Sample>>),
    Ring(Subscriber<RingChannelHandler<Sample>>),
}

/// A sample received on a subscription: the key it came on and the decoded message, or why
/// it did not decode.
#[derive(Debug)]
pub struct Received<T> {
    pub key: String,
    pub encoding: Encoding,
    pub size: usize,
    pub message: Result<T, graspopt_protocol::DecodeError>,
}

/// A typed subscription.
pub struct Subscription<T> {
    inner: Inner,
    _t: PhantomData<fn() -> T>,
}

impl<T: Message> Subscription<T> {
    /// The next sample; `None` when the session closed.
    pub async fn recv(&self) -> Option<Received<T>> {
        let sample = match &self.inner {
            Inner::Fifo(s) => s.recv_async().await.ok()?,
            Inner::Ring(s) => s.recv_async().await.ok()?,
        };
        Some(decode_sample(&sample))
    }

    /// The next sample if one has arrived (`None`: none has, or the session closed): what
    /// arrived together with a sample just received, taken without waiting.
    pub fn try_recv(&self) -> Option<Received<T>> {
        let sample = match &self.inner {
            Inner::Fifo(s) => s.try_recv().ok().flatten()?,
            Inner::Ring(s) => s.try_recv().ok().flatten()?,
        };
        Some(decode_sample(&sample))
    }
}

/// The first reply of a query sent at `started`. A query that ends without a reply well
/// before its timeout found nothing that answers on `key` ([`BusError::NoResponder`]).
async fn first_reply<R: Message>(
    key: &str,
    replies: &FifoChannelHandler<zenoh::query::Reply>,
    timeout: Duration,
    started: std::time::Instant,
) -> Result<R, BusError> {
    match replies.recv_async().await {
        Ok(reply) => match reply.result() {
            Ok(sample) => {
                let enc = protocol_encoding(sample.encoding());
                Ok(decode::<R>(&sample.payload().to_bytes(), enc)?)
            }
            Err(err) => Err(BusError::ReplyError {
                key: key.to_string(),
                detail: String::from_utf8_lossy(&err.payload().to_bytes()).into_owned(),
            }),
        },
        Err(_) if started.elapsed() < timeout / 2 => Err(BusError::NoResponder {
            key: key.to_string(),
        }),
        Err(_) => Err(BusError::NoReply {
            key: key.to_string(),
            timeout_ms: timeout.as_millis() as u64,
        }),
    }
}

/// A sample as it came: key, declared encoding, bytes.
#[derive(Debug, Clone)]
pub struct RawSample {
    pub key: String,
    pub encoding: Encoding,
    pub bytes: Vec<u8>,
}

/// An undecoded subscription (see [`Bus::subscribe_raw`]).
pub struct RawSubscription {
    sub: Subscriber<RingChannelHandler<Sample>>,
}

impl RawSubscription {
    /// The next sample; `None` when the session closed.
    pub async fn recv(&self) -> Option<RawSample> {
        let sample = self.sub.recv_async().await.ok()?;
        Some(RawSample {
            key: sample.key_expr().as_str().to_string(),
            encoding: protocol_encoding(sample.encoding()),
            bytes: sample.payload().to_bytes().into_owned(),
        })
    }
}

/// Decodes a sample as a `T`, by its declared encoding.
pub fn decode_sample<T: Message>(sample: &Sample) -> Received<T> {
    let encoding = protocol_encoding(sample.encoding());
    let bytes = sample.payload().to_bytes();
    Received {
        key: sample.key_expr().as_str().to_string(),
        encoding,
        size: bytes.len(),
        message: decode::<T>(&bytes, encoding),
    }
}

/// Answers queries.
pub struct Server<Q> {
    queryable: Queryable<FifoChannelHandler<Query>>,
    _q: PhantomData<fn() -> Q>,
}

/// One query: the decoded request (or why it did not decode) and the means to answer.
pub struct Incoming<Q> {
    query: Query,
    pub request: Result<Q, graspopt_protocol::DecodeError>,
}

impl<Q: Request> Server<Q> {
    /// The next query; `None` when the session closed.
    pub async fn recv(&self) -> Option<Incoming<Q>> {
        let query = self.queryable.recv_async().await.ok()?;
        let enc = query
            .encoding()
            .map(protocol_encoding)
            .unwrap_or(Encoding::Bincode);
        let payload = query.payload().map(|p| p.to_bytes().into_owned());
        let request = Q::from_payload(payload.as_deref(), enc);
        Some(Incoming { query, request })
    }
}

impl<Q> Incoming<Q> {
    /// Answers with a message, in the encoding the request came in.
    pub async fn reply<R: Message>(&self, reply: &R) -> Result<(), BusError> {
        let enc = self
            .query
            .encoding()
            .map(protocol_encoding)
            .unwrap_or(Encoding::Bincode);
        let bytes = encode(reply, enc)?;
        self.query
            .reply(self.query.key_expr().clone(), bytes)
            .encoding(zenoh_encoding(enc))
            .await
            .map_err(|e| BusError::zenoh("replying", e))
    }

    /// Answers with an error text.
    pub async fn reply_error(&self, text: &str) -> Result<(), BusError> {
        self.query
            .reply_err(text.as_bytes().to_vec())
            .await
            .map_err(|e| BusError::zenoh("replying with an error", e))
    }
}
