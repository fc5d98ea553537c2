//! The run's status as the core sees it, and what the run waits for.

use graspopt_protocol::{RunPhase, RunStatus, WaitReason};

use super::{Action, Coordinator};
use crate::spec::param_names;
use crate::waits;

impl Coordinator {
    /// Time to publish the status (and to log what the run waits for, when that changed).
    pub(super) fn on_status_tick(&mut self, now: i64) -> Vec<Action> {
        let s = self.status(now);
        if let Some(m) = self.waits.message(s.stamp_ms) {
            tracing::warn!("coordinator: run {:?} {m}", self.run);
        }
        vec![Action::Publish(s.clone()), Action::Progress(s)]
    }

    /// The run's status now: running once the trial space is known, waiting before.
    pub fn status(&self, now: i64) -> RunStatus {
        let phase = if self.space.is_some() {
            RunPhase::Running
        } else {
            RunPhase::Waiting
        };
        self.status_at(phase, now)
    }

    /// The run's status in `phase` (a finished run waits for nothing).
    pub fn status_at(&self, phase: RunPhase, now: i64) -> RunStatus {
        RunStatus {
            run_id: self.run.clone(),
            phase,
            object: self.spec.object.clone(),
            param_names: param_names(&self.spec),
            budget: self.spec.trials,
            completed: self.state.completed(),
            running: self.state.running(),
            failed: self.state.failed(),
            best: self.state.best().cloned(),
            best_history: self.state.best_history().to_vec(),
            workers: self.state.worker_statuses(),
            errors: self.state.errors(),
            stamp_ms: now,
            waiting: if phase == RunPhase::Finished {
                Vec::new()
            } else {
                self.waits.shown(now)
            },
            best_forces: self.state.best_forces().cloned(),
        }
    }

    /// Notes what the run waits for now: the object estimate (since the start), a metric
    /// agent and a hand (since the start or since the last one left), and the planner (since
    /// it stopped answering, or since a question went unanswered for
    /// [`waits::PLANNER_SLOW_MS`]).
    pub(super) fn note_waits(&mut self, now: i64) {
        let since = |waiting: bool| waiting.then_some(now);
        self.waits.set(
            WaitReason::ObjectEstimate,
            self.space.is_none().then_some(self.started_ms),
        );
        self.waits
            .set(WaitReason::MetricAgent, since(self.scorers.is_empty()));
        self.waits
            .set(WaitReason::Hand, since(!self.state.has_workers()));
        let slow = self
            .planner
            .asking_since
            .filter(|t| now - t >= waits::PLANNER_SLOW_MS);
        self.waits
            .set(WaitReason::Planner, self.planner.down_since.or(slow));
    }
}
