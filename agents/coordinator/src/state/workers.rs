//! Live hand workers and the leases of their trials: who holds what, and when a trial
//! whose worker vanished, went silent or lost its metric agent is queued again.

use super::{RunState, TrialPhase, Worker};

impl RunState {
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
    pub(super) fn release_holders(&mut self, trial: u64, except: Option<&str>, now_ms: i64) {
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
}

/// The median of `values` (`None` when empty).
fn median(values: &[i64]) -> Option<i64> {
    let mut v = values.to_vec();
    v.sort_unstable();
    v.get(v.len() / 2).copied()
}
