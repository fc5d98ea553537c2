//! How a run ends, for the person who started it: the lines `graspopt run` and the
//! coordinator print at the end (trials completed and failed, why trials failed with how
//! many each, the best trial) and the exit status of the command.

use std::path::Path;

use graspopt_journal::{FailureReason, Journal};
use graspopt_protocol::text::rounded;
use graspopt_protocol::{BestTrial, RunPhase, RunStatus, named_params};

use crate::error::RunnerError;

/// Exit status of a run that spent its budget without completing a single trial (every
/// trial failed): the lines printed say why.
pub const NO_TRIAL_COMPLETED: u8 = 3;
/// Exit status of a run stopped before its end (Ctrl-C, SIGTERM): the shell's code for a
/// command stopped by Ctrl-C.
pub const STOPPED: u8 = 130;

/// Failure reasons named one by one; any others are summed in one line.
pub const SHOWN_REASONS: usize = 5;

/// A run that has ended: its final status and why its failed trials failed.
#[derive(Debug, Clone)]
pub struct RunEnd {
    pub status: RunStatus,
    /// From the journal, the most frequent first.
    pub failures: Vec<FailureReason>,
}

impl RunEnd {
    /// The end of the run whose final status is `status`, with the failure reasons of the
    /// journal at `journal`.
    pub fn read(status: RunStatus, journal: &Path) -> Result<RunEnd, RunnerError> {
        let failures = Journal::open_existing(journal)
            .and_then(|j| j.failure_reasons(status.run_id.as_str()))
            .map_err(|source| RunnerError::Failures {
                journal: journal.to_path_buf(),
                source,
            })?;
        Ok(RunEnd { status, failures })
    }

    /// Whether the run was stopped before its end.
    pub fn stopped(&self) -> bool {
        self.status.phase != RunPhase::Finished
    }

    /// The command's exit status: [`STOPPED`], [`NO_TRIAL_COMPLETED`], or 0.
    pub fn exit_code(&self) -> u8 {
        if self.stopped() {
            STOPPED
        } else if self.status.completed == 0 {
            NO_TRIAL_COMPLETED
        } else {
            0
        }
    }

    /// The lines a person reads: `run "R": C of B trials completed, F failed`, followed by
    /// `then` (how to go on, for a stopped run); then why trials failed (`failed: 30 ×
    /// reason`, the most frequent first) and the best trial.
    pub fn lines(&self, then: &str) -> Vec<String> {
        let s = &self.status;
        let mut out = vec![format!(
            "run {:?}: {} of {} trials completed, {} failed{}",
            s.run_id.as_str(),
            s.completed,
            s.budget,
            s.failed,
            if self.stopped() { then } else { "" }
        )];
        out.extend(failure_lines(&self.failures));
        if let Some(b) = &s.best {
            out.push(format!(
                "best: trial {} score {} at {}{}",
                b.trial_id,
                rounded(b.score),
                named_params(&s.param_names, &b.params, ","),
                closure(b)
            ));
        }
        out
    }

    /// The lines of an embedded run whose results are in `out`: [`RunEnd::lines`], saying
    /// how to go on when it was stopped, then where the results are.
    pub fn embedded_lines(&self, out: &Path) -> Vec<String> {
        let s = &self.status;
        let then = if s.completed + s.failed + s.running == 0 {
            " (stopped before its first trial: the same command starts it afresh)".to_string()
        } else {
            format!(" (stopped; continue with --resume --out {})", out.display())
        };
        let mut lines = self.lines(&then);
        lines.push(format!("results: {}", out.display()));
        lines
    }

    /// The final status as JSON, with `failures`: `[{"reason": ..., "trials": n}, ...]`.
    pub fn json(&self) -> Result<serde_json::Value, serde_json::Error> {
        let mut v = serde_json::to_value(&self.status)?;
        if let Some(map) = v.as_object_mut() {
            map.insert("failures".into(), serde_json::to_value(&self.failures)?);
        }
        Ok(v)
    }
}

/// `failed: N × reason` for one reason; `failed:` and a line per reason for several (the
/// first [`SHOWN_REASONS`], then the others summed).
/// The progress of a run's best trial so far: `best 0.5 (trial 3), force closure`.
pub fn best_so_far(b: &BestTrial) -> String {
    format!(
        "best {} (trial {}){}",
        rounded(b.score),
        b.trial_id,
        closure(b)
    )
}

/// `, force closure` for a best trial in force closure.
fn closure(b: &BestTrial) -> &'static str {
    if b.force_closure == Some(true) {
        ", force closure"
    } else {
        ""
    }
}

fn failure_lines(failures: &[FailureReason]) -> Vec<String> {
    match failures {
        [] => Vec::new(),
        [one] => vec![format!("failed: {} × {}", one.trials, one.reason)],
        many => {
            let mut out = vec!["failed:".to_string()];
            for f in many.iter().take(SHOWN_REASONS) {
                out.push(format!("  {} × {}", f.trials, f.reason));
            }
            let rest = &many[many.len().min(SHOWN_REASONS)..];
            if !rest.is_empty() {
                let n: usize = rest.iter().map(|f| f.trials).sum();
                out.push(format!(
                    "  {n} × {} other reasons (each trial's is in the journal's export)",
                    rest.len()
                ));
            }
            out
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use graspopt_journal::{RunRow, StoredRunPhase, TrialIssue};
    use graspopt_protocol::{BestTrial, RunId};

    fn status(completed: u64, failed: u64, phase: RunPhase) -> RunStatus {
        RunStatus {
            run_id: RunId::new("run").unwrap(),
            phase,
            object: "cylinder".into(),
            param_names: vec!["x".into(), "y".into()],
            budget: completed + failed,
            completed,
            running: 0,
            failed,
            best: None,
            best_history: Vec::new(),
            workers: Vec::new(),
            errors: Default::default(),
            stamp_ms: 0,
            waiting: Vec::new(),
            best_forces: None,
        }
    }

    /// A journal of run "run" whose trials 1..=n failed with `reason(i)`.
    fn journal(dir: &Path, n: u64, reason: impl Fn(u64) -> String) -> std::path::PathBuf {
        let path = dir.join("journal.sqlite");
        let mut j = Journal::open(&path).unwrap();
        j.create_run(&RunRow {
            run_id: "run".into(),
            created_ms: 0,
            config_json: "{}".into(),
            param_names: vec!["x".into(), "y".into()],
            status: StoredRunPhase::Running,
        })
        .unwrap();
        for id in 1..=n {
            j.write_issue(&TrialIssue {
                run_id: "run".into(),
                trial_id: id,
                attempt: 1,
                params: vec![0.0, 0.0],
                worker: "hand-1".into(),
                at_ms: 1,
                lease_until_ms: 100,
                reason: None,
            })
            .unwrap();
            j.write_failure("run", id, 1, &reason(id), 2).unwrap();
        }
        path
    }

    #[test]
    fn a_run_whose_every_trial_failed_says_why_and_exits_with_its_own_status() {
        let dir = tempfile::tempdir().unwrap();
        let why = "worker hand-1 has a my_gripper hand, the trial asks for my_gripper.urdf";
        let path = journal(dir.path(), 6, |_| why.to_string());
        let end = RunEnd::read(status(0, 6, RunPhase::Finished), &path).unwrap();
        assert_eq!(
            end.lines(""),
            [
                "run \"run\": 0 of 6 trials completed, 6 failed".to_string(),
                format!("failed: 6 × {why}"),
            ]
        );
        assert_eq!(end.exit_code(), NO_TRIAL_COMPLETED);
        assert_eq!(end.json().unwrap()["failures"][0]["trials"], 6);
        assert_eq!(end.json().unwrap()["failures"][0]["reason"], why);
        assert_eq!(end.json().unwrap()["completed"], 0);
        // Stopped by Ctrl-C: 130 whatever completed, and how to go on.
        let stopped = RunEnd {
            status: status(0, 6, RunPhase::Stopped),
            ..end
        };
        assert_eq!(stopped.exit_code(), STOPPED);
        assert!(stopped.lines(" (stopped)")[0].ends_with("6 failed (stopped)"));
    }

    #[test]
    fn several_reasons_are_listed_most_frequent_first_and_the_best_is_rounded() {
        let dir = tempfile::tempdir().unwrap();
        // Seven reasons: "r0" for trials 1-4, then one trial each for r1..r6.
        let path = journal(dir.path(), 10, |id| format!("r{}", id.saturating_sub(4)));
        let mut s = status(5, 10, RunPhase::Finished);
        s.best = Some(BestTrial {
            trial_id: 12,
            score: 0.20025899065118113,
            params: vec![0.01, -0.02],
            force_closure: Some(true),
        });
        let end = RunEnd::read(s, &path).unwrap();
        assert_eq!(
            end.lines(""),
            [
                "run \"run\": 5 of 15 trials completed, 10 failed",
                "failed:",
                "  4 × r0",
                "  1 × r1",
                "  1 × r2",
                "  1 × r3",
                "  1 × r4",
                "  2 × 2 other reasons (each trial's is in the journal's export)",
                "best: trial 12 score 0.20026 at x=0.01000,y=-0.02000, force closure",
            ]
        );
        assert_eq!(end.exit_code(), 0);
        // JSON keeps every digit.
        assert_eq!(end.json().unwrap()["best"]["score"], 0.20025899065118113);
    }
}
