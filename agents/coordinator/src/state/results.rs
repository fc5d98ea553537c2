//! Results: accepting each trial's result once, from the worker and attempt it was
//! issued to, and the observations and best trial it makes.

use graspopt_protocol::{BestTrial, ForceAnalysis, Observation, TrialResult};

use super::{Disposition, RunState, TrialPhase};

impl RunState {
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
}
