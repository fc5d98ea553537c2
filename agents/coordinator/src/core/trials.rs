//! The core's trials: leasing queued trials to idle workers, expiring leases, and
//! accepting each trial's result once.

use graspopt_journal::{ResultRow, TrialIssue};
use graspopt_protocol::{Encoding, RunPhase, TrialCommand, TrialResult};
use graspopt_sim::TrialSpace;

use super::{Action, Coordinator, Write};
use crate::error::CoordinatorError;
use crate::state::{Disposition, TrialPhase};

impl Coordinator {
    /// Leases queued trials to idle workers: a journal write and a command each.
    pub(super) fn issue_queued(&mut self, now: i64) -> Result<Vec<Action>, CoordinatorError> {
        let mut out = Vec::new();
        let Some((space, _)) = &self.space else {
            return Ok(out);
        };
        let mut idle = self.state.idle_workers().into_iter();
        for (trial_id, reason) in self.state.queued() {
            let Some(worker) = idle.next() else { break };
            let lease_until = now + self.lease_ms as i64;
            let Some(attempt) = self.state.assign(trial_id, &worker, now, lease_until) else {
                continue;
            };
            let issue = TrialIssue {
                run_id: self.run.as_str().to_string(),
                trial_id,
                attempt,
                params: self
                    .state
                    .trial(trial_id)
                    .map(|t| t.params.clone())
                    .unwrap_or_default(),
                worker,
                at_ms: now,
                lease_until_ms: lease_until,
                reason,
            };
            let send = self.command(space, &issue)?;
            out.push(Action::Write(Write::Issue(issue)));
            out.push(send);
        }
        Ok(out)
    }

    /// The command that sends `issue` to its worker, in the encoding it asked for.
    fn command(&self, space: &TrialSpace, issue: &TrialIssue) -> Result<Action, CoordinatorError> {
        let palm = space
            .palm_pose(&issue.params)
            .map_err(|source| CoordinatorError::PalmPose {
                trial: issue.trial_id,
                source,
            })?;
        let command = TrialCommand {
            run_id: self.run.clone(),
            trial_id: issue.trial_id,
            attempt: issue.attempt,
            worker: issue.worker.clone(),
            hand: self.spec.hand.clone(),
            params: issue.params.clone(),
            palm_pose: graspopt_convert::pose(&palm),
            lease_ms: self.lease_ms,
            issued_ms: issue.at_ms,
        };
        let encoding = self.encodings.get(&issue.worker).copied();
        Ok(Action::Send {
            worker: issue.worker.clone(),
            encoding: encoding.unwrap_or(Encoding::Bincode),
            command,
        })
    }

    /// Trials whose lease expired are queued again.
    pub(super) fn on_lease_tick(&mut self, now: i64) {
        for t in self.state.expire_leases(now, self.lease_ms as i64) {
            tracing::warn!("coordinator: lease of trial {t} expired: re-issuing");
        }
    }

    /// A result of this run: journaled if it is the first of an attempt issued to the
    /// worker it names; counted otherwise.
    pub(super) fn on_result(&mut self, result: &TrialResult, now: i64) -> Vec<Action> {
        let mut out = Vec::new();
        // A result must name an attempt issued to the worker it names: anything else (a
        // forged or corrupted message, a trial never proposed) is counted and never
        // reaches the journal. A duplicate leaves the journal as it is.
        let first = self.state.was_issued(result)
            && !self.state.stale_failure(result)
            && self.state.trial(result.trial_id).is_some_and(|t| {
                !matches!(
                    t.phase,
                    TrialPhase::Completed { .. } | TrialPhase::Failed { .. }
                )
            });
        if first {
            out.push(Action::Write(match &result.error {
                Some(error) => Write::Failure {
                    trial_id: result.trial_id,
                    attempt: result.attempt,
                    error: error.clone(),
                    at_ms: now,
                },
                None => Write::Result(Box::new(journal_result(result, now))),
            }));
        }
        log_disposition(result, self.state.on_result(result, now));
        out.push(Action::Progress(self.status_at(RunPhase::Running, now)));
        out
    }
}

/// Logs what a result that completed nothing did.
fn log_disposition(result: &TrialResult, disposition: Disposition) {
    let (trial, attempt) = (result.trial_id, result.attempt);
    match disposition {
        Disposition::Unknown => {
            tracing::warn!("coordinator: result for unknown trial {trial}")
        }
        Disposition::Duplicate => {
            tracing::info!("coordinator: duplicate result for trial {trial}")
        }
        Disposition::NotIssued => tracing::warn!(
            "coordinator: result for trial {trial} attempt {attempt} from {}, which was never issued that attempt",
            result.worker
        ),
        Disposition::StaleFailure => tracing::warn!(
            "coordinator: attempt {attempt} of trial {trial} failed, a later attempt is running: ignored"
        ),
        Disposition::Completed | Disposition::Failed => {}
    }
}

/// A result as the journal records it.
pub(crate) fn journal_result(r: &TrialResult, at_ms: i64) -> ResultRow {
    ResultRow {
        run_id: r.run_id.as_str().to_string(),
        trial_id: r.trial_id,
        attempt: r.attempt,
        worker: r.worker.clone(),
        at_ms,
        score: r.score,
        metrics: r.metrics.clone(),
        contacts: r.contacts,
        fingers_in_contact: r.fingers_in_contact,
        cloud_points: r.cloud_points,
        details_json: serde_json::json!({
            "scorer": r.scorer,
            "cloud_transport": r.cloud_transport,
        })
        .to_string(),
        forces: r.forces.clone(),
    }
}
