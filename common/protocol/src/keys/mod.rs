//! The key-expression scheme. Every key is `graspopt/<run>/...`:
//!
//! - a topic or a query per row of the key table ([`TABLE`]): `object`, `hand/<worker>/command`,
//!   `clouds`, `wrenches`, `result`, `status`, `planner/suggest`, `coordinator/state`
//!   (docs/protocol.md says who publishes each and what it carries);
//! - `alive/<kind>/<host>/<id>[/json][/<topic>]`: an agent's liveliness token (`/json`: send
//!   me JSON; `/<topic>`: the topic it publishes, `clouds` or `wrenches` for a hand);
//! - `claim/<kind>/<slot>/<nonce>/<phase>`: an agent taking its place ([`claim_token`]).
//!
//! The key table (`table.rs`) binds each key to the type of its messages: a [`Key<M>`] comes
//! only from its row ([`RESULT`]`.key(run)`), and the bus sends and awaits only `M`s on it.
//! Its topics are one list, the `topics!` invocation, from which each topic's key constant,
//! its [`Topic`] and its decoder for [`crate::decode_topic`] follow; that list says how to
//! add a topic. The liveliness and claim keys are built beside it. Nothing else writes a key
//! chunk.
//!
//! Run ids, hosts and agent ids are single key chunks: ASCII letters, digits, `-`, `_` and `.`.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::codec::Encoding;

mod table;
pub use table::*;

/// The first chunk of every key.
pub const ROOT: &str = "graspopt";

pub use crate::error::KeyError;

fn check_chunk(what: &'static str, value: &str) -> Result<(), KeyError> {
    let ok = !value.is_empty()
        && value.len() <= 64
        && !value.starts_with('.')
        && value
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'));
    if ok {
        Ok(())
    } else {
        // The value goes into error messages and logs: at most 80 characters of it.
        let shown: String = match value.char_indices().nth(80) {
            Some((cut, _)) => format!("{}...", &value[..cut]),
            None => value.to_string(),
        };
        Err(KeyError { what, value: shown })
    }
}

/// Turns any text (a host name, say) into a valid key chunk: invalid characters become `_`,
/// and the result is cut to 64 characters. Empty text becomes `unnamed`.
pub fn sanitize_chunk(text: &str) -> String {
    let mut s: String = text
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .take(64)
        .collect();
    if s.starts_with('.') {
        s.replace_range(0..1, "_");
    }
    if s.is_empty() {
        s = "unnamed".to_string();
    }
    s
}

/// A run id: one key chunk. Messages print it quoted (`{run:?}`, `run "mug"`), so that the
/// default id reads as a name (`run "run"`, not `run run`).
#[derive(Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct RunId(String);

impl RunId {
    /// Checks and wraps a run id.
    pub fn new(id: &str) -> Result<Self, KeyError> {
        check_chunk("run id", id)?;
        Ok(RunId(id.to_string()))
    }

    pub fn as_str(&self) -> &str {
        &self.0
    }

    /// The name of the shared-memory service that carries this run's contact clouds on a host.
    pub fn shm_clouds_service(&self) -> String {
        shm_clouds_service(self)
    }
}

impl fmt::Debug for RunId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.0.as_str(), f)
    }
}

impl fmt::Display for RunId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl TryFrom<String> for RunId {
    type Error = KeyError;
    fn try_from(value: String) -> Result<Self, Self::Error> {
        check_chunk("run id", &value)?;
        Ok(RunId(value))
    }
}

impl From<RunId> for String {
    fn from(value: RunId) -> Self {
        value.0
    }
}

/// A claim token's nonce and phase (see [`claim_token`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Claim {
    pub nonce: u64,
    pub phase: ClaimPhase,
}

/// How far an agent has got in taking its place; the key's last chunk.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum ClaimPhase {
    /// Looking at the other claims before holding the place (`starting`).
    Starting,
    /// Holding the place (`held`).
    Held,
    /// Holding it and settled in it: held long enough that a claim seen later is a
    /// newcomer's (`settled`, declared beside `held`).
    Settled,
}

impl ClaimPhase {
    /// The key chunk.
    pub fn as_str(self) -> &'static str {
        match self {
            ClaimPhase::Starting => "starting",
            ClaimPhase::Held => "held",
            ClaimPhase::Settled => "settled",
        }
    }

    /// Whether an agent in this phase holds the place.
    pub fn holds(self) -> bool {
        self != ClaimPhase::Starting
    }
}

/// The claim a key names, if it is a claim key.
pub fn parse_claim_key(key: &str) -> Option<Claim> {
    let mut chunks = key.rsplit('/');
    let phase = match chunks.next()? {
        "starting" => ClaimPhase::Starting,
        "held" => ClaimPhase::Held,
        "settled" => ClaimPhase::Settled,
        _ => return None,
    };
    let nonce = chunks.next()?;
    if nonce.len() != 16 || !nonce.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    let _slot = chunks.next()?;
    let _kind = chunks.next()?;
    if chunks.next()? != "claim" {
        return None;
    }
    Some(Claim {
        nonce: u64::from_str_radix(nonce, 16).ok()?,
        phase,
    })
}

/// Checks an agent id or host name used in a key.
pub fn check_agent_id(id: &str) -> Result<(), KeyError> {
    check_chunk("agent id", id)
}

/// Declares [`AgentKind`] from one row per kind: its variant and its name (in keys, in
/// `graspopt agent <name>`, in launch files; serde writes it too).
macro_rules! agent_kinds {
    ($($kind:ident => $name:literal,)+) => {
        /// The kinds of agent. To add one: its row in the `agent_kinds!` list below, its
        /// crate's `impl graspopt_bus::Agent`, and its row in the runner's registry.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
        #[serde(rename_all = "snake_case")]
        pub enum AgentKind {
            $($kind,)+
        }

        impl AgentKind {
            pub const ALL: [AgentKind; [$($name),+].len()] = [$(AgentKind::$kind),+];

            pub fn as_str(self) -> &'static str {
                match self {
                    $(AgentKind::$kind => $name,)+
                }
            }
            /// Parses a kind name.
            pub fn parse(name: &str) -> Option<AgentKind> {
                AgentKind::ALL.into_iter().find(|k| k.as_str() == name)
            }
        }
    };
}

agent_kinds! {
    Perception => "perception",
    Hand => "hand",
    Metric => "metric",
    Planner => "planner",
    Coordinator => "coordinator",
}

impl fmt::Display for AgentKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A liveliness key taken apart.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AliveKey {
    pub run: RunId,
    pub kind: AgentKind,
    pub host: String,
    pub id: String,
    /// The encoding this agent wants its messages in: a token ending in `/json`
    /// (`graspopt/<run>/alive/hand/<host>/<id>/json`) asks for JSON, so an agent written
    /// without bincode (a Python hand) gets its trial commands as JSON.
    pub encoding: Encoding,
    /// Which of its kind's topics the agent publishes, when its token says (a last chunk
    /// naming it: a hand's `clouds` or `wrenches`); `None`: it does not say.
    pub publishes: Option<Topic>,
}

/// Parses `graspopt/<run>/alive/<kind>/<host>/<id>`, optionally followed by `/json` and then
/// by the name of a topic that agents of `kind` publish (`/clouds`, `/wrenches` for a hand).
pub fn parse_alive_key(key: &str) -> Option<AliveKey> {
    let parts: Vec<&str> = key.split('/').collect();
    let [root, run, "alive", kind, host, id, rest @ ..] = parts.as_slice() else {
        return None;
    };
    let kind = AgentKind::parse(kind)?;
    let (encoding, rest) = match rest {
        ["json", rest @ ..] => (Encoding::Json, rest),
        rest => (Encoding::Bincode, rest),
    };
    let publishes = match rest {
        [] => None,
        [name] => Some(Topic::named(name).filter(|t| t.publisher() == kind)?),
        _ => return None,
    };
    // Host and id become parts of other keys (a worker's command key): a token whose host
    // or id is not a valid chunk (a `*`, say) is not an agent.
    if *root != ROOT || check_chunk("host", host).is_err() || check_agent_id(id).is_err() {
        return None;
    }
    Some(AliveKey {
        run: RunId::new(run).ok()?,
        kind,
        host: (*host).to_string(),
        id: (*id).to_string(),
        encoding,
        publishes,
    })
}

#[cfg(test)]
mod tests;
