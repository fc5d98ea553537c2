//! The key table: each key bound to the type of its messages, and every key builder.

use std::fmt;
use std::marker::PhantomData;

use super::{AgentKind, Claim, ROOT, RunId, check_agent_id};
use crate::codec::{DecodeError, Encoding};
use crate::messages::{
    ContactClouds, FingertipWrenches, Message, ObjectEstimate, RunStatus, SuggestReply,
    SuggestRequest, TrialCommand, TrialResult,
};

/// Which runs a key names: one, or every run (`*`, for tools that watch them all).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Runs<'a> {
    One(&'a RunId),
    All,
}

impl<'a> From<&'a RunId> for Runs<'a> {
    fn from(run: &'a RunId) -> Self {
        Runs::One(run)
    }
}

/// `graspopt/<run>` (or `graspopt/*`): where every key of `runs` starts. The only place that
/// writes the first two chunks of a key.
fn prefix(runs: Runs) -> String {
    match runs {
        Runs::One(run) => format!("{ROOT}/{}", run.as_str()),
        Runs::All => format!("{ROOT}/*"),
    }
}

/// One row of the key table, without its message type: for tools that list keys and decode
/// what they see.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Entry {
    /// The name tools take (`graspopt topic echo result`).
    pub name: &'static str,
    /// The key after `graspopt/<run>/`; a `*` chunk stands for a worker id.
    pub path: &'static str,
    /// The message a topic carries, or the reply a query gets ([`Message::TYPE`]).
    pub message: &'static str,
    /// A query's request type (`Some("")`: a query without payload); `None` for a topic.
    pub request: Option<&'static str>,
    /// Who publishes the topic, or answers the query.
    pub by: AgentKind,
}

impl Entry {
    /// The key expression of this row in `runs`, with `*` for every worker.
    pub fn key_expr(&self, runs: Runs) -> String {
        format!("{}/{}", prefix(runs), self.path)
    }

    fn worker_expr(&self, runs: Runs, worker: &str) -> String {
        format!("{}/{}", prefix(runs), self.path.replace('*', worker))
    }

    /// Whether this row is a query.
    pub fn is_query(&self) -> bool {
        self.request.is_some()
    }

    /// What travels on it, for people: `TrialResult`, `query SuggestRequest -> SuggestReply`,
    /// `query -> RunStatus`.
    pub fn describe(&self) -> String {
        match self.request {
            None => self.message.to_string(),
            Some("") => format!("query -> {}", self.message),
            Some(request) => format!("query {request} -> {}", self.message),
        }
    }

    /// Whether `rest`, the chunks of a concrete key after its run, is a key of this row.
    fn matches(&self, rest: &[&str]) -> bool {
        let path: Vec<&str> = self.path.split('/').collect();
        path.len() == rest.len()
            && path
                .iter()
                .zip(rest)
                .all(|(p, r)| *p == *r || (*p == "*" && check_agent_id(r).is_ok()))
    }
}

/// A topic of the table: the messages on its keys are `M`s.
pub struct TopicDef<M> {
    entry: Entry,
    _m: PhantomData<fn() -> M>,
}

impl<M: Message> TopicDef<M> {
    const fn new(name: &'static str, path: &'static str, by: AgentKind) -> Self {
        TopicDef {
            entry: Entry {
                name,
                path,
                message: M::TYPE,
                request: None,
                by,
            },
            _m: PhantomData,
        }
    }

    /// Its row.
    pub const fn entry(&self) -> Entry {
        self.entry
    }

    /// Its key in `runs` (every worker, for a worker's topic).
    pub fn key(&self, runs: Runs) -> Key<M> {
        Key::new(self.entry.key_expr(runs))
    }

    /// The key of one worker's topic ([`COMMAND`]: `hand/<worker>/command`); for a topic
    /// without a worker chunk, its [`TopicDef::key`].
    pub fn worker_key(&self, runs: Runs, worker: &str) -> Key<M> {
        Key::new(self.entry.worker_expr(runs, worker))
    }
}

/// A query of the table: requests `Q` (`()`: no payload), replies `R`.
pub struct QueryDef<Q, R> {
    entry: Entry,
    _m: PhantomData<fn(Q) -> R>,
}

impl<Q: Message, R: Message> QueryDef<Q, R> {
    const fn new(name: &'static str, path: &'static str, by: AgentKind) -> Self {
        QueryDef::with_request(name, path, Q::TYPE, R::TYPE, by)
    }
}

impl<R: Message> QueryDef<(), R> {
    const fn without_request(name: &'static str, path: &'static str, by: AgentKind) -> Self {
        QueryDef::with_request(name, path, "", R::TYPE, by)
    }
}

impl<Q, R> QueryDef<Q, R> {
    const fn with_request(
        name: &'static str,
        path: &'static str,
        request: &'static str,
        message: &'static str,
        by: AgentKind,
    ) -> Self {
        QueryDef {
            entry: Entry {
                name,
                path,
                message,
                request: Some(request),
                by,
            },
            _m: PhantomData,
        }
    }

    /// Its row.
    pub const fn entry(&self) -> Entry {
        self.entry
    }

    /// Its key in `run`.
    pub fn key(&self, run: &RunId) -> QueryKey<Q, R> {
        QueryKey {
            expr: self.entry.key_expr(Runs::One(run)),
            _m: PhantomData,
        }
    }
}

/// A key built by the table, bound to the type of the messages on it: only the table
/// makes one, so a message of another type cannot be sent or awaited on it.
///
/// ```compile_fail
/// use graspopt_protocol::keys::{Key, Runs, STATUS};
/// use graspopt_protocol::TrialResult;
/// let key: Key<TrialResult> = STATUS.key(Runs::All); // the status topic carries RunStatus
/// ```
pub struct Key<M> {
    expr: String,
    _m: PhantomData<fn() -> M>,
}

impl<M> Key<M> {
    fn new(expr: String) -> Self {
        Key {
            expr,
            _m: PhantomData,
        }
    }

    /// The key expression.
    pub fn as_str(&self) -> &str {
        &self.expr
    }
}

/// A query's key built by the table, bound to its request and reply types.
pub struct QueryKey<Q, R> {
    expr: String,
    _m: PhantomData<fn(Q) -> R>,
}

impl<Q, R> QueryKey<Q, R> {
    /// The key expression.
    pub fn as_str(&self) -> &str {
        &self.expr
    }
}

macro_rules! key_traits {
    ($name:ident <$($p:ident),+>) => {
        impl<$($p),+> Clone for $name<$($p),+> {
            fn clone(&self) -> Self {
                $name { expr: self.expr.clone(), _m: PhantomData }
            }
        }
        impl<$($p),+> fmt::Debug for $name<$($p),+> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                fmt::Debug::fmt(&self.expr, f)
            }
        }
        impl<$($p),+> fmt::Display for $name<$($p),+> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(&self.expr)
            }
        }
    };
}
key_traits!(Key<M>);
key_traits!(QueryKey<Q, R>);

/// A key that `M`s travel on: a [`Key<M>`] of the table, or a plain key expression whose
/// type the caller names (tests and tools).
pub trait KeyFor<M> {
    fn key_expr(&self) -> &str;
}

impl<M> KeyFor<M> for Key<M> {
    fn key_expr(&self) -> &str {
        &self.expr
    }
}

/// A query key with requests `Q` and replies `R`: a [`QueryKey`] of the table, or a plain
/// key expression.
pub trait QueryFor<Q, R> {
    fn key_expr(&self) -> &str;
}

impl<Q, R> QueryFor<Q, R> for QueryKey<Q, R> {
    fn key_expr(&self) -> &str {
        &self.expr
    }
}

/// A key whose queries carry `Q`s (to answer them): a [`QueryKey`] of the table, or a plain
/// key expression.
pub trait Serves<Q> {
    fn key_expr(&self) -> &str;
}

impl<Q, R> Serves<Q> for QueryKey<Q, R> {
    fn key_expr(&self) -> &str {
        &self.expr
    }
}

macro_rules! plain_keys {
    ($($t:ty),+) => {$(
        impl<M> KeyFor<M> for $t {
            fn key_expr(&self) -> &str {
                self
            }
        }
        impl<Q, R> QueryFor<Q, R> for $t {
            fn key_expr(&self) -> &str {
                self
            }
        }
        impl<Q> Serves<Q> for $t {
            fn key_expr(&self) -> &str {
                self
            }
        }
    )+};
}
plain_keys!(str, String);

/// Declares the topics from one row each: the row's `TopicDef` constant, its [`Topic`]
/// variant, [`Topic::ALL`], [`Topic::entry`], the topic rows of [`TABLE`] and the decoder
/// that [`crate::decode_topic`] runs. The rows, and how to add one, are below.
macro_rules! topics {
    (
        topics {
            $(
                $(#[$doc:meta])*
                $def:ident: $variant:ident = $place:literal
                    => $message:ident, $name:literal, $path:literal, $by:ident;
            )+
        }
        queries { $($query:ident),+ $(,)? }
    ) => {
        $(
            $(#[$doc])*
            pub const $def: TopicDef<$message> = TopicDef::new($name, $path, AgentKind::$by);
        )+

        /// The key table: every topic, then every query (their rows are the `topics!`
        /// invocation in `keys/table.rs`, which says how to add one).
        pub const TABLE: [Entry; TOPIC_COUNT + [$(stringify!($query)),+].len()] =
            [$($def.entry,)+ $($query.entry,)+];

        const TOPIC_COUNT: usize = [$(stringify!($def)),+].len();

        /// The published topics, for tools that list and decode them: the topic rows of
        /// [`TABLE`].
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Topic {
            $(
                #[doc = concat!("`", $name, "`: [`", stringify!($def), "`].")]
                $variant = $place,
            )+
        }

        impl Topic {
            /// Every topic, each at its place (the number in its row): a new topic takes the
            /// next place, so the others keep theirs (fuzz seeds name topics by place).
            pub const ALL: [Topic; TOPIC_COUNT] = places([$(Topic::$variant),+]);

            /// Its row of the table.
            pub const fn entry(self) -> Entry {
                match self {
                    $(Topic::$variant => $def.entry,)+
                }
            }

            /// Decodes (and validates) a message of this topic, as JSON.
            pub(crate) fn decode_json(self) -> DecodeJson {
                match self {
                    $(Topic::$variant => crate::codec::decode_json::<$message>,)+
                }
            }
        }
    };
}

/// How a topic's messages are decoded for display ([`crate::decode_topic`]).
type DecodeJson = fn(&[u8], Encoding) -> Result<serde_json::Value, DecodeError>;

/// The topics in the order of their places; fails the build unless the places are 0, 1, ...
/// each taken once.
const fn places(rows: [Topic; TOPIC_COUNT]) -> [Topic; TOPIC_COUNT] {
    let mut all = rows;
    let mut i = 0;
    while i < rows.len() {
        all[rows[i] as usize] = rows[i];
        i += 1;
    }
    let mut place = 0;
    while place < all.len() {
        assert!(all[place] as usize == place, "two topics take one place");
        place += 1;
    }
    all
}

// The key table. A topic's row: `CONSTANT: Variant = place => Message, "name", "path",
// publisher`.
//
// To add a topic: (1) write its message (a struct that implements `Message`, in the
// `messages` module of its concept); (2) add its row to `topics` here, with the next
// place; (3) add its row to the key table of docs/protocol.md (a test compares the two).
// Its key constant, `Topic` variant, place in `Topic::ALL`, row of `TABLE` and decoder for
// `graspopt topic echo` follow from the row. (Tests that must cover every topic fail until
// they do: the e2e fuzz test wants a stream of malformed messages for it.)
//
// A query is a `QueryDef` constant below, named in `queries`.
topics! {
    topics {
        /// perception -> coordinator, hands, metric: the object estimate.
        OBJECT: Object = 0 => ObjectEstimate, "object", "object", Perception;
        /// coordinator -> one hand: a trial to carry out.
        COMMAND: Command = 1 => TrialCommand, "command", "hand/*/command", Coordinator;
        /// hand -> metric: the contact clouds of a trial (when not through shared memory).
        CLOUDS: Clouds = 2 => ContactClouds, "clouds", "clouds", Hand;
        /// hand -> metric: the fingertip force/torque readings of a trial (hands that sense forces).
        WRENCHES: Wrenches = 5 => FingertipWrenches, "wrenches", "wrenches", Hand;
        /// metric -> coordinator: a trial's score.
        RESULT: Result = 3 => TrialResult, "result", "result", Metric;
        /// coordinator -> monitors: the run's state.
        STATUS: Status = 4 => RunStatus, "status", "status", Coordinator;
    }
    queries { SUGGEST, STATE }
}

/// coordinator asks the planner for points.
pub const SUGGEST: QueryDef<SuggestRequest, SuggestReply> =
    QueryDef::new("suggest", "planner/suggest", AgentKind::Planner);
/// anyone asks the coordinator for the run's state.
pub const STATE: QueryDef<(), RunStatus> =
    QueryDef::without_request("state", "coordinator/state", AgentKind::Coordinator);

/// `graspopt/<run>/alive/<kind>/<host>/<id>`: an agent's liveliness token; with the topic
/// it publishes when it says (`.../<id>/wrenches`: see [`AliveKey::publishes`]).
///
/// [`AliveKey::publishes`]: super::AliveKey::publishes
pub fn alive_token(
    run: &RunId,
    kind: AgentKind,
    host: &str,
    id: &str,
    publishes: Option<Topic>,
) -> String {
    let token = format!(
        "{}/alive/{}/{host}/{id}",
        prefix(Runs::One(run)),
        kind.as_str()
    );
    match publishes {
        Some(topic) => format!("{token}/{}", topic.entry().name),
        None => token,
    }
}

/// The liveliness tokens of `kind` (of every kind if `None`) in `runs`:
/// `graspopt/<run>/alive/<kind>/**`.
pub fn alive_key(runs: Runs, kind: Option<AgentKind>) -> String {
    match kind {
        Some(kind) => format!("{}/alive/{}/**", prefix(runs), kind.as_str()),
        None => format!("{}/alive/**", prefix(runs)),
    }
}

/// `graspopt/<run>/claim/<kind>/<slot>/<nonce>/<phase>`: a liveliness token an agent holds
/// while it makes sure it is alone in its place (`slot`: its id, or `any` for the run's one
/// coordinator). `nonce` is 16 hex digits, random per agent; `phase` is `starting`, then
/// `held` once the agent has its place, and `settled` (beside `held`) once it has held it
/// for a while (see [`Claim`], [`ClaimPhase`], [`parse_claim_key`]).
pub fn claim_token(run: &RunId, kind: AgentKind, slot: &str, claim: Claim) -> String {
    format!(
        "{}/{:016x}/{}",
        claim_base(run, kind, slot),
        claim.nonce,
        claim.phase.as_str()
    )
}

/// The claims of one place: `graspopt/<run>/claim/<kind>/<slot>/**`.
pub fn claim_slot_key(run: &RunId, kind: AgentKind, slot: &str) -> String {
    format!("{}/**", claim_base(run, kind, slot))
}

fn claim_base(run: &RunId, kind: AgentKind, slot: &str) -> String {
    format!("{}/claim/{}/{slot}", prefix(Runs::One(run)), kind.as_str())
}

/// Everything of `runs`: `graspopt/<run>/**`.
pub fn all_key(runs: Runs) -> String {
    format!("{}/**", prefix(runs))
}

/// The name of the shared-memory service that carries a run's contact clouds on a host: the
/// clouds topic's key.
pub fn shm_clouds_service(run: &RunId) -> String {
    CLOUDS.entry.key_expr(Runs::One(run))
}

/// The name of the throwaway shared-memory services that check, at start-up, that shared
/// memory works on a host: `graspopt/shm-probe`.
pub fn shm_probe_service() -> String {
    format!("{ROOT}/shm-probe")
}

impl Topic {
    /// The message type carried.
    pub fn message_type(self) -> &'static str {
        self.entry().message
    }

    /// Who publishes it.
    pub fn publisher(self) -> AgentKind {
        self.entry().by
    }

    /// The topic a tool's name means (`result`).
    pub fn named(name: &str) -> Option<Topic> {
        Topic::ALL.into_iter().find(|t| t.entry().name == name)
    }

    /// Which topic a concrete key belongs to, with its run.
    pub fn classify(key: &str) -> Option<(RunId, Topic)> {
        let parts: Vec<&str> = key.split('/').collect();
        let (root, run, rest) = match parts.as_slice() {
            [root, run, rest @ ..] => (*root, *run, rest),
            _ => return None,
        };
        if root != ROOT {
            return None;
        }
        let run = RunId::new(run).ok()?;
        let topic = Topic::ALL.into_iter().find(|t| t.entry().matches(rest))?;
        Some((run, topic))
    }
}
