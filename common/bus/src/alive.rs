//! Liveliness: every agent declares a token `graspopt/<run>/alive/<kind>/<host>/<id>`; the
//! coordinator and tools watch them. A token vanishes when its process dies or loses the
//! network, which is how a killed hand worker is noticed.

use graspopt_protocol::keys::{AliveKey, parse_alive_key};
use graspopt_protocol::{AgentKind, RunId};
use zenoh::handlers::FifoChannelHandler;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Subscriber;
use zenoh::sample::{Sample, SampleKind};

use crate::{Bus, BusError};

/// An agent appeared or vanished.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AliveEvent {
    pub alive: bool,
    pub agent: AliveKey,
}

/// A stream of [`AliveEvent`]s, starting with the agents already alive.
pub struct AliveWatch {
    sub: Subscriber<FifoChannelHandler<Sample>>,
}

impl AliveWatch {
    /// The next event; `None` when the session closed. Keys that are not agent tokens are
    /// skipped.
    pub async fn recv(&self) -> Option<AliveEvent> {
        loop {
            let sample = self.sub.recv_async().await.ok()?;
            if let Some(agent) = parse_alive_key(sample.key_expr().as_str()) {
                return Some(AliveEvent {
                    alive: sample.kind() == SampleKind::Put,
                    agent,
                });
            }
        }
    }
}

impl Bus {
    /// Declares this agent alive until the token is dropped.
    pub async fn declare_alive(
        &self,
        run: &RunId,
        kind: AgentKind,
        id: &str,
    ) -> Result<LivelinessToken, BusError> {
        graspopt_protocol::keys::check_agent_id(id).map_err(|e| BusError::Config(e.to_string()))?;
        let key = run.alive_key(kind, self.host(), id);
        self.session()
            .liveliness()
            .declare_token(key.clone())
            .await
            .map_err(|e| BusError::zenoh(format!("declaring liveliness {key}"), e))
    }

    /// Watches the tokens under `key` (e.g. [`RunId::alive_kind_key`]), starting with those
    /// already declared.
    pub async fn watch_alive(&self, key: &str) -> Result<AliveWatch, BusError> {
        let sub = self
            .session()
            .liveliness()
            .declare_subscriber(key)
            .history(true)
            .await
            .map_err(|e| BusError::zenoh(format!("watching liveliness {key}"), e))?;
        Ok(AliveWatch { sub })
    }

    /// The agents alive now under `key`.
    pub async fn alive_now(&self, key: &str) -> Result<Vec<AliveKey>, BusError> {
        let replies = self
            .session()
            .liveliness()
            .get(key)
            .await
            .map_err(|e| BusError::zenoh(format!("liveliness query {key}"), e))?;
        let mut out = Vec::new();
        while let Ok(reply) = replies.recv_async().await {
            if let Ok(sample) = reply.result()
                && let Some(agent) = parse_alive_key(sample.key_expr().as_str())
            {
                out.push(agent);
            }
        }
        Ok(out)
    }
}
