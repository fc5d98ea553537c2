//! The coordinator's bookkeeping, without a network: trials and their leases, live workers,
//! the observations for the planner, the best trial, the error counters. The async loop in
//! [`crate::run`](mod@crate::run) feeds it events and carries out what it decides.
//!
//! - `workers`: live workers and the leases of their trials.
//! - `results`: accepting results, the observations and the best trial.

use std::collections::{BTreeMap, BTreeSet};

use graspopt_protocol::{BestTrial, ErrorCounts, ForceAnalysis, Observation, WorkerStatus};

mod results;
mod workers;

/// Where a trial is.
#[derive(Debug, Clone, PartialEq)]
pub enum TrialPhase {
    /// Waiting for a worker (new, or re-queued after a lost worker or an expired lease).
    Queued {
        reason: Option<String>,
    },
    /// Leased to a worker.
    Running {
        worker: String,
        issued_ms: i64,
        lease_until_ms: i64,
    },
    Completed {
        score: f64,
    },
    Failed {
        error: String,
    },
}

/// One trial.
#[derive(Debug, Clone, PartialEq)]
pub struct Trial {
    pub params: Vec<f64>,
    /// Attempts issued so far.
    pub attempts: u32,
    /// The worker each attempt was issued to: a result is accepted only from one of them.
    pub issued_to: BTreeMap<u32, String>,
    pub phase: TrialPhase,
}

/// A live hand worker.
#[derive(Debug, Clone, PartialEq)]
pub struct Worker {
    pub host: String,
    /// The trial it holds (it is busy until a result for it arrives).
    pub trial: Option<u64>,
    /// Set when the lease of its trial expired: if it has not answered by then, it is
    /// freed (its command or its result was lost) and may take trials again.
    pub release_at_ms: Option<i64>,
}

/// What a result did.
#[derive(Debug, Clone, PartialEq)]
pub enum Disposition {
    /// First result of the trial: completed.
    Completed,
    /// The trial failed (the hand or the scorer said so).
    Failed,
    /// The trial already had its result: ignored.
    Duplicate,
    /// No such trial in this run: ignored.
    Unknown,
    /// The trial exists, but no attempt of it was issued to the worker the result names:
    /// ignored (a corrupted or stray result must not complete a trial).
    NotIssued,
    /// A failure reported by an earlier attempt while a later one is still running: ignored
    /// (the later attempt may well succeed).
    StaleFailure,
}

/// The state of one run.
#[derive(Debug, Clone, Default)]
pub struct RunState {
    budget: u64,
    trials: BTreeMap<u64, Trial>,
    /// The trials queued or running. A completed or failed trial never is again, so the
    /// scans done on every event (queued, running, pending trials, leases) walk these
    /// only: their cost follows the workers, not the number of trials the run has made.
    open: BTreeSet<u64>,
    completed: u64,
    failed: u64,
    workers: BTreeMap<String, Worker>,
    /// Completed trials in completion order, for the planner.
    observations: Vec<Observation>,
    best: Option<BestTrial>,
    /// The best trial's force analysis, if its result had one.
    best_forces: Option<ForceAnalysis>,
    best_history: Vec<f64>,
    errors: ErrorCounts,
    /// How long a worker that may still be executing a trial stays busy after the trial no
    /// longer needs it (re-issued elsewhere, or completed by another attempt).
    grace_ms: i64,
    /// How long completed attempts took, issue to result (milliseconds).
    trial_ms: Vec<i64>,
}

impl RunState {
    pub fn new(budget: u64) -> RunState {
        RunState {
            budget,
            ..RunState::default()
        }
    }

    /// Sets how long a worker stays busy after its trial no longer needs it.
    pub fn set_grace_ms(&mut self, grace_ms: i64) {
        self.grace_ms = grace_ms;
    }

    /// Puts back a trial recorded in the journal (a resumed run).
    pub fn restore_trial(&mut self, trial_id: u64, trial: Trial) {
        self.count_phase(trial_id, &trial.phase, 1);
        if let Some(old) = self.trials.insert(trial_id, trial) {
            self.count_phase(trial_id, &old.phase, -1);
        }
    }

    /// Counts a trial in `phase` in (`sign` 1) or out (-1) of the open set and counters.
    fn count_phase(&mut self, trial_id: u64, phase: &TrialPhase, sign: i8) {
        let add = |n: &mut u64| {
            *n = if sign > 0 {
                *n + 1
            } else {
                n.saturating_sub(1)
            }
        };
        match phase {
            TrialPhase::Completed { .. } => add(&mut self.completed),
            TrialPhase::Failed { .. } => add(&mut self.failed),
            TrialPhase::Queued { .. } | TrialPhase::Running { .. } => {
                if sign > 0 {
                    self.open.insert(trial_id);
                } else {
                    self.open.remove(&trial_id);
                }
            }
        }
    }

    /// The trial `trial_id`, if the run has it.
    pub fn trial(&self, trial_id: u64) -> Option<&Trial> {
        self.trials.get(&trial_id)
    }

    /// Number of trials proposed so far.
    pub fn trial_count(&self) -> usize {
        self.trials.len()
    }

    /// Whether any hand worker is alive.
    pub fn has_workers(&self) -> bool {
        !self.workers.is_empty()
    }

    /// Completed trials in completion order, for the planner.
    pub fn observations(&self) -> &[Observation] {
        &self.observations
    }

    pub fn best(&self) -> Option<&BestTrial> {
        self.best.as_ref()
    }

    pub fn best_forces(&self) -> Option<&ForceAnalysis> {
        self.best_forces.as_ref()
    }

    pub fn best_history(&self) -> &[f64] {
        &self.best_history
    }

    pub fn errors(&self) -> ErrorCounts {
        self.errors
    }

    /// Counts a message that was not acted on.
    pub fn count_bad_message(&mut self) {
        self.errors.bad_messages += 1;
    }

    /// Queued trials, oldest first, with the reason they were re-queued.
    pub fn queued(&self) -> Vec<(u64, Option<String>)> {
        self.open_trials()
            .filter_map(|(id, t)| match &t.phase {
                TrialPhase::Queued { reason } => Some((id, reason.clone())),
                _ => None,
            })
            .collect()
    }

    /// The trials queued or running, by id.
    fn open_trials(&self) -> impl Iterator<Item = (u64, &Trial)> {
        self.open
            .iter()
            .filter_map(|id| self.trials.get(id).map(|t| (*id, t)))
    }

    /// How many new trials to ask the planner for now.
    pub fn proposals_needed(&self) -> usize {
        let idle = self.workers.values().filter(|w| w.trial.is_none()).count();
        let queued = self
            .open_trials()
            .filter(|(_, t)| matches!(t.phase, TrialPhase::Queued { .. }))
            .count();
        let left = self.budget.saturating_sub(self.trials.len() as u64) as usize;
        idle.saturating_sub(queued).min(left)
    }

    /// Adds a new trial (queued); returns its id (ids start at 1).
    pub fn add_trial(&mut self, params: Vec<f64>) -> u64 {
        let id = self.trials.keys().next_back().map_or(1, |k| k + 1);
        self.open.insert(id);
        self.trials.insert(
            id,
            Trial {
                params,
                attempts: 0,
                issued_to: BTreeMap::new(),
                phase: TrialPhase::Queued { reason: None },
            },
        );
        id
    }

    /// Parameters of trials issued and not finished (for the planner).
    pub fn pending_points(&self) -> Vec<Vec<f64>> {
        self.open_trials()
            .map(|(_, t)| t)
            .filter(|t| {
                matches!(
                    t.phase,
                    TrialPhase::Queued { .. } | TrialPhase::Running { .. }
                )
            })
            .map(|t| t.params.clone())
            .collect()
    }

    pub fn completed(&self) -> u64 {
        self.completed
    }

    pub fn failed(&self) -> u64 {
        self.failed
    }

    /// Trials queued or running.
    pub fn running(&self) -> u64 {
        self.open.len() as u64
    }

    /// Every trial of the budget issued and finished.
    pub fn finished(&self) -> bool {
        self.trials.len() as u64 >= self.budget && self.completed() + self.failed() >= self.budget
    }

    pub fn worker_statuses(&self) -> Vec<WorkerStatus> {
        self.workers
            .iter()
            .map(|(id, w)| WorkerStatus {
                id: id.clone(),
                host: w.host.clone(),
                trial: w.trial,
            })
            .collect()
    }
}

#[cfg(test)]
pub(crate) mod tests;
