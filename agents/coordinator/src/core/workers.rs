//! The core's view of the agents that do the work: hand workers, which take trials, and
//! metric agents, without which trials wait.

use graspopt_protocol::keys::AliveKey;

use super::Coordinator;

impl Coordinator {
    /// A hand worker's token came or went: a worker lost with a trial has it re-issued.
    pub(super) fn on_hand(&mut self, agent: &AliveKey, alive: bool) {
        if agent.run != self.run {
            return;
        }
        if alive {
            self.encodings.insert(agent.id.clone(), agent.encoding);
            self.state.worker_up(&agent.id, &agent.host);
        } else if let Some(t) = self.state.worker_down(&agent.id) {
            tracing::warn!(
                "coordinator: worker {} lost with trial {t}: re-issuing",
                agent.id
            );
        }
    }

    /// A metric agent's token came or went. Trials wait while none is alive (clouds sent to
    /// nobody are lost); the ones running when the last left are re-issued once one is back.
    pub(super) fn on_metric(&mut self, agent: &AliveKey, alive: bool, now: i64) {
        if agent.run != self.run {
            return;
        }
        let key = format!("{}/{}", agent.host, agent.id);
        if alive {
            let was_empty = self.scorers.is_empty();
            self.scorers.insert(key);
            if was_empty {
                let orphaned = std::mem::take(&mut self.orphaned);
                for t in self.state.requeue_orphaned(&orphaned, now) {
                    tracing::warn!(
                        "coordinator: trial {t} ran while no metric agent was alive: re-issuing"
                    );
                }
            }
        } else {
            self.scorers.remove(&key);
            if self.scorers.is_empty() {
                self.orphaned = self.state.running_trials();
                tracing::warn!("coordinator: no metric agent left: trials wait for one");
            }
        }
    }
}
