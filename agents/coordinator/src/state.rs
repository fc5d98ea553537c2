//! The coordinator's bookkeeping, without a network: trials and their leases, live workers,
//! the observations for the planner, the best trial, the error counters. The async loop in
//! [`crate::run`] feeds it events and carries out what it decides.

use std::collections::{BTreeMap, BTreeSet};

use graspopt_protocol::{
    BestTrial, ErrorCounts, ForceAnalysis, Observation, TrialResult, WorkerStatus,
};

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

/// The median of `values` (`None` when empty).
fn median(values: &[i64]) -> Option<i64> {
    let mut v = values.to_vec();
    v.sort_unstable();
    v.get(v.len() / 2).copied()
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

    /// A worker appeared.
    pub fn worker_up(&mut self, id: &str, host: &str) {
        self.workers
            .entry(id.to_string())
            .or_insert_with(|| Worker {
                host: host.to_string(),
                trial: None,
                release_at_ms: None,
            });
    }

    /// A worker vanished: its trial (if not completed) goes back to the queue. Returns it.
    pub fn worker_down(&mut self, id: &str) -> Option<u64> {
        let worker = self.workers.remove(id)?;
        let trial_id = worker.trial?;
        let trial = self.trials.get_mut(&trial_id)?;
        match &trial.phase {
            TrialPhase::Running { worker, .. } if worker == id => {
                trial.phase = TrialPhase::Queued {
                    reason: Some(format!("worker {id} lost")),
                };
                self.errors.reissued += 1;
                Some(trial_id)
            }
            _ => None,
        }
    }

    /// Workers holding no trial, by id.
    pub fn idle_workers(&self) -> Vec<String> {
        self.workers
            .iter()
            .filter(|(_, w)| w.trial.is_none())
            .map(|(id, _)| id.clone())
            .collect()
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

    /// Leases a queued trial to an idle worker at `now_ms`; returns the attempt number.
    pub fn assign(
        &mut self,
        trial_id: u64,
        worker: &str,
        now_ms: i64,
        lease_until_ms: i64,
    ) -> Option<u32> {
        let w = self.workers.get_mut(worker)?;
        if w.trial.is_some() {
            return None;
        }
        let t = self.trials.get_mut(&trial_id)?;
        if !matches!(t.phase, TrialPhase::Queued { .. }) {
            return None;
        }
        t.attempts += 1;
        t.issued_to.insert(t.attempts, worker.to_string());
        t.phase = TrialPhase::Running {
            worker: worker.to_string(),
            issued_ms: now_ms,
            lease_until_ms,
        };
        w.trial = Some(trial_id);
        w.release_at_ms = None;
        Some(t.attempts)
    }

    /// Trials running now (their results depend on a metric agent being there).
    pub fn running_trials(&self) -> Vec<u64> {
        self.open_trials()
            .filter(|(_, t)| matches!(t.phase, TrialPhase::Running { .. }))
            .map(|(id, _)| id)
            .collect()
    }

    /// A metric agent is back after none was alive. The trials in `orphaned` (running when
    /// the last one vanished) that are still running may have had their clouds sent to
    /// nobody. Each worker is taken to be done with its trial twice a typical trial's
    /// duration after it was issued (the median of the completed ones; the lease when none
    /// has completed yet): a trial whose worker is done by now is queued again at once and
    /// the worker freed; otherwise its lease is cut to that moment (and the worker freed
    /// then), so a worker still executing it can still deliver it to the agent that is back.
    /// Returns the trials queued again now.
    pub fn requeue_orphaned(&mut self, orphaned: &[u64], now_ms: i64) -> Vec<u64> {
        let typical = median(&self.trial_ms);
        let mut out = Vec::new();
        for id in orphaned {
            let Some(t) = self.trials.get_mut(id) else {
                continue;
            };
            let TrialPhase::Running {
                worker,
                issued_ms,
                lease_until_ms,
            } = &mut t.phase
            else {
                continue;
            };
            let done_by = typical.map_or(*lease_until_ms, |d| {
                (*issued_ms + 2 * d).min(*lease_until_ms)
            });
            if let Some(w) = self.workers.get_mut(worker.as_str())
                && w.trial == Some(*id)
            {
                w.release_at_ms = Some(done_by);
                if done_by <= now_ms {
                    w.trial = None;
                    w.release_at_ms = None;
                }
            }
            if done_by <= now_ms {
                t.phase = TrialPhase::Queued {
                    reason: Some(format!("no metric agent scored the clouds of {worker}")),
                };
                out.push(*id);
            } else {
                *lease_until_ms = done_by;
            }
        }
        self.errors.reissued += out.len() as u64;
        out
    }

    /// Every worker but `except` still holding `trial` is freed after the grace (unless it
    /// answers first).
    fn release_holders(&mut self, trial: u64, except: Option<&str>, now_ms: i64) {
        for (id, w) in self.workers.iter_mut() {
            if w.trial == Some(trial) && except != Some(id.as_str()) && w.release_at_ms.is_none() {
                w.release_at_ms = Some(now_ms + self.grace_ms);
            }
        }
    }

    /// Re-queues trials whose lease expired. The worker stays busy (it may be slow, not
    /// dead) for `grace_ms` more; if it has not answered by then it is freed, since a live
    /// worker that never answers has lost its command or its result (with one worker, keeping
    /// it busy forever would stall the run). Returns the re-queued trials.
    pub fn expire_leases(&mut self, now_ms: i64, grace_ms: i64) -> Vec<u64> {
        let mut out = Vec::new();
        for id in &self.open {
            let Some(t) = self.trials.get_mut(id) else {
                continue;
            };
            if let TrialPhase::Running {
                worker,
                lease_until_ms,
                ..
            } = &t.phase
                && *lease_until_ms < now_ms
            {
                if let Some(w) = self.workers.get_mut(worker)
                    && w.trial == Some(*id)
                {
                    // An earlier release (an orphaned trial) stands.
                    let at = now_ms + grace_ms;
                    w.release_at_ms = Some(w.release_at_ms.map_or(at, |r| r.min(at)));
                }
                t.phase = TrialPhase::Queued {
                    reason: Some(format!("lease of worker {worker} expired")),
                };
                out.push(*id);
            }
        }
        for w in self.workers.values_mut() {
            if w.release_at_ms.is_some_and(|at| at <= now_ms) {
                w.trial = None;
                w.release_at_ms = None;
            }
        }
        self.errors.reissued += out.len() as u64;
        out
    }

    /// Applies a result (already accepted by the journal when `Completed`/`Failed`) at
    /// `now_ms`.
    pub fn on_result(&mut self, result: &TrialResult, now_ms: i64) -> Disposition {
        if !self.was_issued(result) {
            if self.trials.contains_key(&result.trial_id) {
                self.errors.not_issued += 1;
                return Disposition::NotIssued;
            }
            self.errors.unknown_trial += 1;
            return Disposition::Unknown;
        }
        if let Some(w) = self.workers.get_mut(&result.worker)
            && w.trial == Some(result.trial_id)
        {
            w.trial = None;
            w.release_at_ms = None;
        }
        if self.stale_failure(result) {
            return Disposition::StaleFailure;
        }
        // Other workers still on this trial (an earlier or later attempt) are freed after
        // the grace: their result can only be a duplicate now.
        self.release_holders(result.trial_id, Some(&result.worker), now_ms);
        let Some(t) = self.trials.get_mut(&result.trial_id) else {
            self.errors.unknown_trial += 1;
            return Disposition::Unknown;
        };
        if matches!(
            t.phase,
            TrialPhase::Completed { .. } | TrialPhase::Failed { .. }
        ) {
            self.errors.duplicates += 1;
            return Disposition::Duplicate;
        }
        if let Some(e) = &result.error {
            t.phase = TrialPhase::Failed { error: e.clone() };
            self.open.remove(&result.trial_id);
            self.failed += 1;
            self.errors.failed += 1;
            return Disposition::Failed;
        }
        if let TrialPhase::Running { issued_ms, .. } = t.phase
            && result.attempt == t.attempts
        {
            self.trial_ms.push(now_ms - issued_ms);
        }
        t.phase = TrialPhase::Completed {
            score: result.score,
        };
        self.open.remove(&result.trial_id);
        self.completed += 1;
        let params = t.params.clone();
        self.observe(
            result.trial_id,
            params,
            result.score,
            result
                .metrics
                .as_ref()
                .and_then(|m| m.flag("force_closure")),
            result.forces.as_ref(),
        );
        Disposition::Completed
    }

    /// Whether `result` is a failure of an earlier attempt of a trial whose later attempt is
    /// issued and still open.
    pub fn stale_failure(&self, result: &TrialResult) -> bool {
        result.error.is_some()
            && self.trials.get(&result.trial_id).is_some_and(|t| {
                result.attempt < t.attempts
                    && matches!(
                        t.phase,
                        TrialPhase::Running { .. } | TrialPhase::Queued { .. }
                    )
            })
    }

    /// Whether the trial the result names exists and the attempt it names was issued to the
    /// worker it names.
    pub fn was_issued(&self, result: &TrialResult) -> bool {
        self.trials.get(&result.trial_id).is_some_and(|t| {
            t.issued_to
                .get(&result.attempt)
                .is_some_and(|w| *w == result.worker)
        })
    }

    /// Records a completed trial's observation and the best so far.
    pub fn observe(
        &mut self,
        trial_id: u64,
        params: Vec<f64>,
        score: f64,
        force_closure: Option<bool>,
        forces: Option<&ForceAnalysis>,
    ) {
        self.observations.push(Observation {
            x: params.clone(),
            y: score,
        });
        if self.best.as_ref().is_none_or(|b| score > b.score) {
            self.best = Some(BestTrial {
                trial_id,
                score,
                params,
                force_closure,
            });
            self.best_forces = forces.cloned();
        }
        if let Some(b) = &self.best {
            self.best_history.push(b.score);
        }
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
pub(crate) mod tests {
    use super::*;
    use graspopt_protocol::RunId;

    /// A result of attempt 1 of run `r`.
    pub(crate) fn result(trial_id: u64, worker: &str, score: f64) -> TrialResult {
        TrialResult {
            run_id: RunId::new("r").unwrap(),
            trial_id,
            attempt: 1,
            worker: worker.into(),
            scorer: "m".into(),
            score,
            metrics: None,
            contacts: 1,
            fingers_in_contact: 1,
            cloud_points: 1,
            cloud_transport: String::new(),
            error: None,
            forces: None,
        }
    }

    /// (completed, failed, queued or running) counted over every trial, and the open set
    /// checked against it.
    fn scanned(s: &RunState) -> (u64, u64, u64) {
        let n = |f: fn(&TrialPhase) -> bool| s.trials.values().filter(|t| f(&t.phase)).count();
        let open: BTreeSet<u64> = s
            .trials
            .iter()
            .filter(|(_, t)| {
                matches!(
                    t.phase,
                    TrialPhase::Queued { .. } | TrialPhase::Running { .. }
                )
            })
            .map(|(id, _)| *id)
            .collect();
        assert_eq!(open, s.open);
        (
            n(|p| matches!(p, TrialPhase::Completed { .. })) as u64,
            n(|p| matches!(p, TrialPhase::Failed { .. })) as u64,
            open.len() as u64,
        )
    }

    #[test]
    fn the_counts_kept_follow_every_change_of_phase() {
        let mut s = RunState::new(6);
        let counts = |s: &RunState| (s.completed(), s.failed(), s.running());
        // A resumed run: one trial completed, one failed, one running, the last replaced.
        let restored = |phase| Trial {
            params: vec![0.0],
            attempts: 1,
            issued_to: BTreeMap::from([(1, "a".to_string())]),
            phase,
        };
        s.restore_trial(1, restored(TrialPhase::Completed { score: 0.1 }));
        s.restore_trial(2, restored(TrialPhase::Failed { error: "x".into() }));
        s.restore_trial(3, restored(TrialPhase::Completed { score: 0.2 }));
        s.restore_trial(3, restored(TrialPhase::Queued { reason: None }));
        assert_eq!(counts(&s), (1, 1, 1));
        assert_eq!(counts(&s), scanned(&s));
        s.worker_up("a", "h");
        s.worker_up("b", "h");
        let t4 = s.add_trial(vec![0.4]);
        assert_eq!(s.assign(3, "a", 0, 100), Some(2));
        assert_eq!(s.assign(t4, "b", 0, 100), Some(1));
        assert_eq!(counts(&s), (1, 1, 2));
        // b is lost, a's lease expires: both trials queued, still open.
        assert_eq!(s.worker_down("b"), Some(t4));
        assert_eq!(s.expire_leases(101, 0), [3]);
        assert_eq!(s.queued().len(), 2);
        assert_eq!(counts(&s), scanned(&s));
        // Trial 3 completes (late, from a), trial 4 fails, a duplicate changes nothing.
        let mut r = result(3, "a", 0.9);
        r.attempt = 2;
        assert_eq!(s.on_result(&r, 102), Disposition::Completed);
        assert_eq!(s.on_result(&r, 103), Disposition::Duplicate);
        assert_eq!(s.assign(t4, "a", 104, 200), Some(2));
        let mut f = result(t4, "a", 0.0);
        f.attempt = 2;
        f.error = Some("unreachable".into());
        assert_eq!(s.on_result(&f, 105), Disposition::Failed);
        assert_eq!(counts(&s), (2, 2, 0));
        assert_eq!(counts(&s), scanned(&s));
        assert!(s.running_trials().is_empty() && s.pending_points().is_empty());
    }

    #[test]
    fn a_lost_worker_trial_is_requeued_and_completed_once() {
        let mut s = RunState::new(2);
        s.worker_up("a", "h");
        s.worker_up("b", "h");
        assert_eq!(s.proposals_needed(), 2);
        let t1 = s.add_trial(vec![0.1]);
        let t2 = s.add_trial(vec![0.2]);
        assert_eq!((t1, t2), (1, 2));
        assert_eq!(s.assign(t1, "a", 0, 100), Some(1));
        assert_eq!(s.assign(t2, "b", 0, 100), Some(1));
        assert_eq!(s.proposals_needed(), 0);
        // Worker a dies holding trial 1.
        assert_eq!(s.worker_down("a"), Some(1));
        assert_eq!(s.queued().len(), 1);
        assert_eq!(s.on_result(&result(2, "b", 0.5), 0), Disposition::Completed);
        assert_eq!(s.idle_workers(), vec!["b".to_string()]);
        assert_eq!(s.assign(1, "b", 0, 200), Some(2));
        let mut r = result(1, "b", 0.7);
        r.attempt = 2;
        assert_eq!(s.on_result(&r, 0), Disposition::Completed);
        r.score = 0.9;
        assert_eq!(s.on_result(&r, 0), Disposition::Duplicate);
        assert!(s.finished());
        assert_eq!(s.completed(), 2);
        assert_eq!(s.errors.duplicates, 1);
        assert_eq!(s.errors.reissued, 1);
        assert_eq!(s.best.as_ref().unwrap().trial_id, 1);
        assert_eq!(s.best_history, vec![0.5, 0.7]);
    }

    #[test]
    fn expired_leases_requeue_and_keep_the_slow_worker_busy() {
        let mut s = RunState::new(1);
        s.worker_up("a", "h");
        let t = s.add_trial(vec![0.0]);
        s.assign(t, "a", 0, 1000);
        assert!(s.expire_leases(999, 500).is_empty());
        assert_eq!(s.expire_leases(1001, 500), vec![t]);
        assert!(s.idle_workers().is_empty());
        // The slow worker's late result still completes the trial.
        assert_eq!(s.on_result(&result(t, "a", 1.0), 0), Disposition::Completed);
        assert!(s.finished());
        assert_eq!(s.on_result(&result(42, "a", 1.0), 0), Disposition::Unknown);
        assert_eq!(s.errors.unknown_trial, 1);
    }

    #[test]
    fn a_silent_worker_is_freed_after_the_grace_and_gets_the_trial_again() {
        let mut s = RunState::new(1);
        s.worker_up("only", "h");
        let t = s.add_trial(vec![0.0]);
        assert_eq!(s.assign(t, "only", 0, 1000), Some(1));
        assert_eq!(s.expire_leases(1001, 500), vec![t]);
        // Still busy during the grace...
        assert!(s.expire_leases(1400, 500).is_empty());
        assert!(s.idle_workers().is_empty());
        // ...then free: the lone worker takes its trial again (attempt 2).
        assert!(s.expire_leases(1502, 500).is_empty());
        assert_eq!(s.idle_workers(), ["only"]);
        assert_eq!(s.assign(t, "only", 0, 3000), Some(2));
        assert_eq!(
            s.on_result(&result(t, "only", 0.5), 0),
            Disposition::Completed
        );
        assert!(s.finished());
    }

    #[test]
    fn a_result_is_accepted_only_from_the_worker_and_attempt_issued() {
        let mut s = RunState::new(1);
        s.worker_up("a", "h");
        s.worker_up("b", "h");
        let t = s.add_trial(vec![0.0]);
        assert_eq!(s.assign(t, "a", 0, 1000), Some(1));
        // Another worker, an attempt never issued, a trial never proposed.
        assert_eq!(s.on_result(&result(t, "b", 9.0), 0), Disposition::NotIssued);
        let mut r = result(t, "a", 9.0);
        r.attempt = 2;
        assert_eq!(s.on_result(&r, 0), Disposition::NotIssued);
        assert_eq!(s.on_result(&result(7, "a", 9.0), 0), Disposition::Unknown);
        assert_eq!((s.errors.not_issued, s.errors.unknown_trial), (2, 1));
        // Worker a still holds its trial; its own result completes it.
        assert!(s.idle_workers() == ["b"]);
        assert_eq!(s.on_result(&result(t, "a", 0.5), 0), Disposition::Completed);
        assert_eq!(s.best.as_ref().unwrap().score, 0.5);
    }

    #[test]
    fn trials_orphaned_by_the_metric_agent_are_requeued_when_it_is_back() {
        let mut s = RunState::new(4);
        s.grace_ms = 60_000;
        s.worker_up("a", "h");
        s.worker_up("b", "h");
        s.worker_up("c", "h");
        // One trial took 100 ms: a typical trial.
        let t0 = s.add_trial(vec![0.0]);
        s.assign(t0, "c", 0, 60_000);
        assert_eq!(
            s.on_result(&result(t0, "c", 0.1), 100),
            Disposition::Completed
        );
        let t1 = s.add_trial(vec![0.1]);
        let t2 = s.add_trial(vec![0.2]);
        let t3 = s.add_trial(vec![0.3]);
        s.assign(t1, "a", 1000, 61_000);
        s.assign(t2, "b", 1000, 61_000);
        s.assign(t3, "c", 1150, 61_150);
        let orphaned = s.running_trials();
        assert_eq!(orphaned, [t1, t2, t3]);
        // Trial 2's result made it before the metric agent went away.
        assert_eq!(
            s.on_result(&result(t2, "b", 0.5), 1100),
            Disposition::Completed
        );
        // Back at 1250: a is done with trial 1 (issued at 1000, 2 x 100 ms); c may still be
        // executing trial 3 until 1350.
        assert_eq!(s.requeue_orphaned(&orphaned, 1250), [t1]);
        assert_eq!(s.idle_workers(), ["a", "b"]);
        assert!(s.expire_leases(1300, 60_000).is_empty());
        assert_eq!(s.expire_leases(1351, 60_000), [t3]);
        assert_eq!(s.idle_workers(), ["a", "b", "c"]);
        assert_eq!(s.assign(t1, "b", 1400, 61_400), Some(2));
        // The first attempt's result, late, still counts.
        assert_eq!(
            s.on_result(&result(t1, "a", 0.7), 1500),
            Disposition::Completed
        );
        assert_eq!(s.errors.reissued, 2);
    }

    #[test]
    fn a_late_failure_does_not_beat_a_live_attempt_and_other_holders_are_freed() {
        let mut s = RunState::new(1);
        s.grace_ms = 100;
        s.worker_up("a", "h");
        s.worker_up("b", "h");
        let t = s.add_trial(vec![0.0]);
        s.assign(t, "a", 0, 1000);
        assert_eq!(s.expire_leases(1001, 100), vec![t]);
        assert_eq!(s.assign(t, "b", 0, 5000), Some(2));
        // Attempt 1 reports a failure late: ignored, a is free again, b goes on.
        let mut late = result(t, "a", 0.0);
        late.error = Some("invalid contact clouds".into());
        assert_eq!(s.on_result(&late, 1050), Disposition::StaleFailure);
        assert_eq!(s.idle_workers(), ["a"]);
        // Attempt 1 succeeding instead would complete the trial, and b, which can only
        // produce a duplicate now, is freed after the grace.
        let mut s2 = s.clone();
        assert_eq!(
            s2.on_result(&result(t, "a", 0.4), 1060),
            Disposition::Completed
        );
        assert!(s2.expire_leases(1100, 100).is_empty());
        assert_eq!(s2.idle_workers(), ["a"]);
        s2.expire_leases(1161, 100);
        assert_eq!(s2.idle_workers(), ["a", "b"]);
        // In s, b's own result completes the trial.
        let mut r = result(t, "b", 0.6);
        r.attempt = 2;
        assert_eq!(s.on_result(&r, 1100), Disposition::Completed);
        assert_eq!(s.errors.failed, 0);
    }

    #[test]
    fn failures_count_against_the_budget() {
        let mut s = RunState::new(1);
        s.worker_up("a", "h");
        let t = s.add_trial(vec![0.0]);
        s.assign(t, "a", 0, 10);
        let mut r = result(t, "a", 0.0);
        r.error = Some("unreachable".into());
        assert_eq!(s.on_result(&r, 0), Disposition::Failed);
        assert!(s.finished());
        assert!(s.observations.is_empty());
    }
}
