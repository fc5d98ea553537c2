//! Why a run's trials failed: each distinct failure message and how many trials it ended.

use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::journal::{Journal, require_run};

/// One failure message of a run and the number of its trials that failed with it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct FailureReason {
    /// The message the failed trials carry (their `error` column).
    pub reason: String,
    /// How many trials failed with it.
    pub trials: usize,
}

/// The reason of a failed trial that has no message (a journal written by hand, say).
pub const NO_REASON: &str = "no reason recorded";

impl Journal {
    /// The reasons the run's failed trials failed with, each with its count: the most
    /// frequent first, then by message. Empty when no trial failed;
    /// [`crate::JournalError::UnknownRun`] for an unknown run.
    pub fn failure_reasons(&self, run_id: &str) -> Result<Vec<FailureReason>> {
        let tx = self.read_tx()?;
        require_run(&tx, run_id)?;
        let mut stmt = tx.prepare_cached(
            "SELECT coalesce(error, ?2) AS reason, count(*) AS n FROM trials
             WHERE run_id = ?1 AND state = 'failed'
             GROUP BY reason ORDER BY n DESC, reason ASC",
        )?;
        let rows = stmt
            .query_map([run_id, NO_REASON], |r| {
                Ok(FailureReason {
                    reason: r.get(0)?,
                    trials: usize::try_from(r.get::<_, i64>(1)?).unwrap_or(0),
                })
            })?
            .collect::<rusqlite::Result<Vec<_>>>()?;
        Ok(rows)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{RunRow, StoredRunPhase, TrialIssue};

    fn issue(trial_id: u64) -> TrialIssue {
        TrialIssue {
            run_id: "r".into(),
            trial_id,
            attempt: 1,
            params: vec![0.0],
            worker: "hand-1".into(),
            at_ms: 10,
            lease_until_ms: 1_000,
            reason: None,
        }
    }

    #[test]
    fn reasons_are_counted_most_frequent_first() {
        let mut j = Journal::open_in_memory().unwrap();
        j.create_run(&RunRow {
            run_id: "r".into(),
            created_ms: 0,
            config_json: "{}".into(),
            param_names: vec!["x".into()],
            status: StoredRunPhase::Running,
        })
        .unwrap();
        assert_eq!(j.failure_reasons("r").unwrap(), []);
        // Trials 1-3 fail with "a", 4 with "b", 5 with "a hand": 6 stays running.
        let reasons = ["a", "a", "b", "a", "a hand"];
        for (i, reason) in reasons.iter().enumerate() {
            let id = i as u64 + 1;
            j.write_issue(&issue(id)).unwrap();
            assert!(j.write_failure("r", id, 1, reason, 20).unwrap());
        }
        j.write_issue(&issue(6)).unwrap();
        let got = j.failure_reasons("r").unwrap();
        let want = [("a", 3), ("a hand", 1), ("b", 1)].map(|(reason, trials)| FailureReason {
            reason: reason.into(),
            trials,
        });
        assert_eq!(got, want);
        assert!(matches!(
            j.failure_reasons("other"),
            Err(crate::JournalError::UnknownRun(r)) if r == "other"
        ));
    }
}
