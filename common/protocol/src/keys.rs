//! The key-expression scheme. Every key is `graspopt/<run>/...`:
//!
//! | key                                   | message            | published by        |
//! |---------------------------------------|--------------------|---------------------|
//! | `graspopt/<run>/object`               | [`ObjectEstimate`] | perception          |
//! | `graspopt/<run>/hand/<worker>/command`| [`TrialCommand`]   | coordinator         |
//! | `graspopt/<run>/clouds`               | [`ContactClouds`]  | hand                |
//! | `graspopt/<run>/result`               | [`TrialResult`]    | metric              |
//! | `graspopt/<run>/status`               | [`RunStatus`]      | coordinator         |
//! | `graspopt/<run>/planner/suggest`      | [`SuggestRequest`] -> [`SuggestReply`] (query) | planner answers |
//! | `graspopt/<run>/coordinator/state`    | [`RunStatus`] (query) | coordinator answers |
//! | `graspopt/<run>/alive/<kind>/<host>/<id>[/json]` | liveliness token (`/json`: send me JSON) | every agent |
//!
//! Run ids, hosts and agent ids are single key chunks: ASCII letters, digits, `-`, `_` and `.`.
//!
//! [`ObjectEstimate`]: crate::ObjectEstimate
//! [`TrialCommand`]: crate::TrialCommand
//! [`ContactClouds`]: crate::ContactClouds
//! [`TrialResult`]: crate::TrialResult
//! [`RunStatus`]: crate::RunStatus
//! [`SuggestRequest`]: crate::SuggestRequest
//! [`SuggestReply`]: crate::SuggestReply

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::codec::Encoding;

/// The first chunk of every key.
pub const ROOT: &str = "graspopt";

/// A key chunk that is not valid (empty, too long or with a character outside the allowed set).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "invalid {what} {value:?}: use 1 to 64 ASCII letters, digits, '-', '_' or '.' (not starting with '.')"
)]
pub struct KeyError {
    pub what: &'static str,
    pub value: String,
}

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

    fn prefix(&self) -> String {
        format!("{ROOT}/{}", self.0)
    }

    /// `graspopt/<run>/object`
    pub fn object_key(&self) -> String {
        format!("{}/object", self.prefix())
    }

    /// `graspopt/<run>/hand/<worker>/command`
    pub fn command_key(&self, worker: &str) -> String {
        format!("{}/hand/{worker}/command", self.prefix())
    }

    /// `graspopt/<run>/clouds`
    pub fn clouds_key(&self) -> String {
        format!("{}/clouds", self.prefix())
    }

    /// `graspopt/<run>/result`
    pub fn result_key(&self) -> String {
        format!("{}/result", self.prefix())
    }

    /// `graspopt/<run>/status`
    pub fn status_key(&self) -> String {
        format!("{}/status", self.prefix())
    }

    /// `graspopt/<run>/planner/suggest`
    pub fn suggest_key(&self) -> String {
        format!("{}/planner/suggest", self.prefix())
    }

    /// `graspopt/<run>/coordinator/state`
    pub fn state_key(&self) -> String {
        format!("{}/coordinator/state", self.prefix())
    }

    /// `graspopt/<run>/alive/<kind>/<host>/<id>`
    pub fn alive_key(&self, kind: AgentKind, host: &str, id: &str) -> String {
        format!("{}/alive/{}/{host}/{id}", self.prefix(), kind.as_str())
    }

    /// `graspopt/<run>/alive/<kind>/**`
    pub fn alive_kind_key(&self, kind: AgentKind) -> String {
        format!("{}/alive/{}/**", self.prefix(), kind.as_str())
    }

    /// `graspopt/<run>/alive/**`
    pub fn alive_all_key(&self) -> String {
        format!("{}/alive/**", self.prefix())
    }

    /// `graspopt/<run>/claim/<kind>/<slot>/<nonce>/<phase>`: a liveliness token an agent
    /// holds while it makes sure it is alone in its place (`slot`: its id, or `any` for the
    /// run's one coordinator). `nonce` is 16 hex digits, random per agent; `phase` is
    /// `starting`, then `held` once the agent has its place (see [`Claim`]).
    pub fn claim_key(&self, kind: AgentKind, slot: &str, claim: Claim) -> String {
        let phase = if claim.held { "held" } else { "starting" };
        format!(
            "{}/claim/{}/{slot}/{:016x}/{phase}",
            self.prefix(),
            kind.as_str(),
            claim.nonce
        )
    }

    /// `graspopt/<run>/claim/<kind>/<slot>/**`
    pub fn claim_slot_key(&self, kind: AgentKind, slot: &str) -> String {
        format!("{}/claim/{}/{slot}/**", self.prefix(), kind.as_str())
    }

    /// Everything of this run: `graspopt/<run>/**`.
    pub fn all_key(&self) -> String {
        format!("{}/**", self.prefix())
    }

    /// The name of the shared-memory service that carries this run's contact clouds on a host.
    pub fn shm_clouds_service(&self) -> String {
        format!("{}/clouds", self.prefix())
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

/// A claim token's nonce and phase (see [`RunId::claim_key`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Claim {
    pub nonce: u64,
    pub held: bool,
}

/// The claim a key names, if it is a claim key.
pub fn parse_claim_key(key: &str) -> Option<Claim> {
    let mut chunks = key.rsplit('/');
    let held = match chunks.next()? {
        "held" => true,
        "starting" => false,
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
        held,
    })
}

/// Checks an agent id or host name used in a key.
pub fn check_agent_id(id: &str) -> Result<(), KeyError> {
    check_chunk("agent id", id)
}

/// The kinds of agent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AgentKind {
    Perception,
    Hand,
    Metric,
    Planner,
    Coordinator,
}

impl AgentKind {
    pub const ALL: [AgentKind; 5] = [
        AgentKind::Perception,
        AgentKind::Hand,
        AgentKind::Metric,
        AgentKind::Planner,
        AgentKind::Coordinator,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            AgentKind::Perception => "perception",
            AgentKind::Hand => "hand",
            AgentKind::Metric => "metric",
            AgentKind::Planner => "planner",
            AgentKind::Coordinator => "coordinator",
        }
    }

    /// Parses a kind name.
    pub fn parse(name: &str) -> Option<AgentKind> {
        AgentKind::ALL.into_iter().find(|k| k.as_str() == name)
    }
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
}

/// Parses `graspopt/<run>/alive/<kind>/<host>/<id>` and
/// `graspopt/<run>/alive/<kind>/<host>/<id>/json`.
pub fn parse_alive_key(key: &str) -> Option<AliveKey> {
    let parts: Vec<&str> = key.split('/').collect();
    let (root, run, kind, host, id, encoding) = match parts.as_slice() {
        [root, run, "alive", kind, host, id] => (root, run, kind, host, id, Encoding::Bincode),
        [root, run, "alive", kind, host, id, "json"] => (root, run, kind, host, id, Encoding::Json),
        _ => return None,
    };
    // Host and id become parts of other keys (a worker's command key): a token whose host
    // or id is not a valid chunk (a `*`, say) is not an agent.
    if *root != ROOT || check_chunk("host", host).is_err() || check_agent_id(id).is_err() {
        return None;
    }
    Some(AliveKey {
        run: RunId::new(run).ok()?,
        kind: AgentKind::parse(kind)?,
        host: (*host).to_string(),
        id: (*id).to_string(),
        encoding,
    })
}

/// The published topics, for tools that list and decode them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Topic {
    Object,
    Command,
    Clouds,
    Result,
    Status,
}

impl Topic {
    pub const ALL: [Topic; 5] = [
        Topic::Object,
        Topic::Command,
        Topic::Clouds,
        Topic::Result,
        Topic::Status,
    ];

    /// The message type carried.
    pub fn message_type(self) -> &'static str {
        match self {
            Topic::Object => "ObjectEstimate",
            Topic::Command => "TrialCommand",
            Topic::Clouds => "ContactClouds",
            Topic::Result => "TrialResult",
            Topic::Status => "RunStatus",
        }
    }

    /// Who publishes it.
    pub fn publisher(self) -> AgentKind {
        match self {
            Topic::Object => AgentKind::Perception,
            Topic::Command => AgentKind::Coordinator,
            Topic::Clouds => AgentKind::Hand,
            Topic::Result => AgentKind::Metric,
            Topic::Status => AgentKind::Coordinator,
        }
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
        let topic = match rest {
            ["object"] => Topic::Object,
            ["hand", _, "command"] => Topic::Command,
            ["clouds"] => Topic::Clouds,
            ["result"] => Topic::Result,
            ["status"] => Topic::Status,
            _ => return None,
        };
        Some((run, topic))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_ids_are_single_chunks() {
        assert!(RunId::new("mug-2026_11.22").is_ok());
        for bad in ["", "a/b", "a*", "$x", "a b", ".hidden", &"x".repeat(65)] {
            let e = RunId::new(bad).unwrap_err();
            assert_eq!(e.value, bad);
        }
        assert!(serde_json::from_str::<RunId>("\"a/b\"").is_err());
    }

    #[test]
    fn claim_keys_parse_back_and_nothing_else_does() {
        let run = RunId::new("r1").unwrap();
        for claim in [
            Claim {
                nonce: 0x00ab_cdef_0123_4567,
                held: false,
            },
            Claim {
                nonce: u64::MAX,
                held: true,
            },
        ] {
            let key = run.claim_key(AgentKind::Hand, "hand-1", claim);
            assert_eq!(parse_claim_key(&key), Some(claim), "{key}");
        }
        assert_eq!(
            run.claim_key(
                AgentKind::Coordinator,
                "any",
                Claim {
                    nonce: 1,
                    held: true
                }
            ),
            "graspopt/r1/claim/coordinator/any/0000000000000001/held"
        );
        for bad in [
            "graspopt/r1/claim/hand/h/+000000000000000/held",
            "graspopt/r1/claim/hand/h/00000000000000001/held",
            "graspopt/r1/claim/hand/h/0000000000000001/taken",
            "graspopt/r1/alive/hand/h/0000000000000001/held",
            "graspopt/r1/claim/hand/0000000000000001/held",
        ] {
            assert_eq!(parse_claim_key(bad), None, "{bad}");
        }
    }

    #[test]
    fn keys_classify_back_to_their_topic() {
        let run = RunId::new("r1").unwrap();
        let cases = [
            (run.object_key(), Topic::Object),
            (run.command_key("w-1"), Topic::Command),
            (run.clouds_key(), Topic::Clouds),
            (run.result_key(), Topic::Result),
            (run.status_key(), Topic::Status),
        ];
        for (key, topic) in cases {
            assert_eq!(Topic::classify(&key), Some((run.clone(), topic)), "{key}");
        }
        assert_eq!(Topic::classify("graspopt/r1/unknown"), None);
        assert_eq!(Topic::classify("other/r1/result"), None);
    }

    #[test]
    fn alive_keys_parse() {
        let run = RunId::new("r1").unwrap();
        let key = run.alive_key(AgentKind::Hand, "host-a", "hand-1");
        assert_eq!(key, "graspopt/r1/alive/hand/host-a/hand-1");
        let parsed = parse_alive_key(&key).unwrap();
        assert_eq!(parsed.kind, AgentKind::Hand);
        assert_eq!(parsed.host, "host-a");
        assert_eq!(parsed.id, "hand-1");
        assert_eq!(parsed.encoding, Encoding::Bincode);
        assert!(parse_alive_key("graspopt/r1/alive/robot/h/i").is_none());
        // A JSON-speaking agent's token.
        let parsed = parse_alive_key(&format!("{key}/json")).unwrap();
        assert_eq!(
            (parsed.id.as_str(), parsed.encoding),
            ("hand-1", Encoding::Json)
        );
        assert!(parse_alive_key(&format!("{key}/xml")).is_none());
        assert!(parse_alive_key("graspopt/r/alive/hand/h/*").is_none());
        assert!(parse_alive_key("graspopt/r/alive/hand/**/h1").is_none());
    }

    #[test]
    fn sanitize_makes_valid_chunks() {
        for text in ["my host.local", "", ".x", "a/b*c"] {
            let s = sanitize_chunk(text);
            assert!(check_agent_id(&s).is_ok(), "{text:?} -> {s:?}");
        }
        assert_eq!(sanitize_chunk("a b/c"), "a_b_c");
    }
}
