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

/// Empty answers in a row after which [`Bus::wait_until_unique`] takes a place as free.
pub const UNIQUE_CHECKS: u32 = 6;

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

    /// Waits (up to `wait`) until no other agent of `kind` holds the place this one is about
    /// to take in `run`: one with the same `id` or, when `id` is `None`, any agent of that
    /// kind. A predecessor that was just killed has its token removed within moments; one
    /// still alive after `wait` is an error naming it, so that two hands never run each
    /// other's trials and two coordinators never share a run. A session that has just opened
    /// may not know every token yet, so the place counts as free only after
    /// [`UNIQUE_CHECKS`] empty answers in a row, 200 ms apart (one second). A session that
    /// only listens ([`Bus::reaches_out`] false: the embedded run's, on a fresh loopback
    /// port) cannot meet an earlier agent and skips the check.
    pub async fn wait_until_unique(
        &self,
        run: &RunId,
        kind: AgentKind,
        id: Option<&str>,
        wait: std::time::Duration,
    ) -> Result<(), BusError> {
        if !self.reaches_out() {
            return Ok(());
        }
        let deadline = tokio::time::Instant::now() + wait;
        let mut free = 0;
        loop {
            let holders: Vec<AliveKey> = self
                .alive_now(&run.alive_kind_key(kind))
                .await?
                .into_iter()
                .filter(|a| a.run == *run && id.is_none_or(|id| a.id == id))
                .collect();
            match holders.first() {
                None => {
                    free += 1;
                    if free >= UNIQUE_CHECKS {
                        return Ok(());
                    }
                }
                Some(holder) => {
                    free = 0;
                    if tokio::time::Instant::now() >= deadline {
                        let what = match id {
                            Some(id) => format!("a {} with the id {id}", kind.as_str()),
                            None => format!("a {} ({})", kind.as_str(), holder.id),
                        };
                        return Err(BusError::Taken(format!(
                            "run {run} already has {what}, alive on host {}: stop it first{}",
                            holder.host,
                            if id.is_some() {
                                ", or give this one another --id"
                            } else {
                                ""
                            }
                        )));
                    }
                }
            }
            tokio::time::sleep(std::time::Duration::from_millis(200)).await;
        }
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
