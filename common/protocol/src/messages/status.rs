//! The state of a run ([`RunStatus`], the `status` topic and the coordinator's state query),
//! and how the tools print parts of it.

use serde::{Deserialize, Serialize};

use super::forces::ForceAnalysisBeforeUnavailable;
use super::{ForceAnalysis, Message};
use crate::error::ValidationError;
use crate::keys::RunId;

/// The phase of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RunPhase {
    /// Waiting for the object estimate, a planner or workers.
    Waiting,
    Running,
    Finished,
    /// Stopped before its end (Ctrl-C, SIGTERM): the journal records it stopped, and
    /// `--resume` continues it. Added last, within wire version 3.
    Stopped,
}

/// `name=value` for each parameter of a trial (5 decimals), joined by `sep`: how the
/// tools print a trial's parameters with [`RunStatus::param_names`].
pub fn named_params(names: &[String], values: &[f64], sep: &str) -> String {
    let parts: Vec<String> = names
        .iter()
        .zip(values)
        .map(|(n, v)| format!("{n}={v:.5}"))
        .collect();
    parts.join(sep)
}

/// The best trial so far.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BestTrial {
    pub trial_id: u64,
    pub score: f64,
    pub params: Vec<f64>,
    pub force_closure: Option<bool>,
}

/// A live hand worker.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorkerStatus {
    pub id: String,
    pub host: String,
    /// The trial it holds, if any.
    pub trial: Option<u64>,
}

/// Counters of what the coordinator refused or repaired.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub struct ErrorCounts {
    /// Payloads that did not decode or failed validation.
    pub bad_messages: u64,
    /// Results for trials this run does not know.
    pub unknown_trial: u64,
    /// Second and later results for a completed trial.
    pub duplicates: u64,
    /// Results naming a trial of this run with an attempt or worker it was never issued to.
    pub not_issued: u64,
    /// Trials re-issued after a lost worker or an expired lease.
    pub reissued: u64,
    /// Trials that failed.
    pub failed: u64,
}

/// What a run can be waiting for before trials go out (or go on).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WaitReason {
    /// No object estimate yet: no perception agent publishes on the run.
    ObjectEstimate,
    /// No metric agent alive: trials are held back, their clouds would not be scored.
    MetricAgent,
    /// No hand worker alive.
    Hand,
    /// No answer from the planner (none running, or it has not answered yet).
    Planner,
}

impl WaitReason {
    /// Every reason, in the order they are shown.
    pub const ALL: [WaitReason; 4] = [
        WaitReason::ObjectEstimate,
        WaitReason::MetricAgent,
        WaitReason::Hand,
        WaitReason::Planner,
    ];

    /// What is missing, for people: "no metric agent".
    pub fn describe(self) -> &'static str {
        match self {
            WaitReason::ObjectEstimate => "no object estimate yet",
            WaitReason::MetricAgent => "no metric agent",
            WaitReason::Hand => "no hand",
            WaitReason::Planner => "no planner answer",
        }
    }
}

/// One thing a run waits for, and since when (milliseconds since the Unix epoch).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Waiting {
    pub reason: WaitReason,
    pub since_ms: i64,
}

/// `waits` for people, with how long each has lasted at `now_ms`: "no metric agent (12 s), no
/// hand (3 s)" (the coordinator's log, the monitor).
pub fn describe_waits(waits: &[Waiting], now_ms: i64) -> String {
    waits
        .iter()
        .map(|w| {
            format!(
                "{} ({:.0} s)",
                w.reason.describe(),
                (now_ms - w.since_ms).max(0) as f64 / 1000.0
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// coordinator -> monitors: the state of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunStatus {
    pub run_id: RunId,
    pub phase: RunPhase,
    pub object: String,
    pub param_names: Vec<String>,
    pub budget: u64,
    pub completed: u64,
    pub running: u64,
    pub failed: u64,
    pub best: Option<BestTrial>,
    /// Best score after each completed trial.
    pub best_history: Vec<f64>,
    pub workers: Vec<WorkerStatus>,
    pub errors: ErrorCounts,
    pub stamp_ms: i64,
    /// What the run has been waiting for, for a second or more (empty: nothing). Added last,
    /// within wire version 3: a status without it (an older coordinator's) decodes with none
    /// (see [`RunStatus::decode_older`]).
    #[serde(default)]
    pub waiting: Vec<Waiting>,
    /// The best trial's force analysis, if its result had one. Added last, within wire
    /// version 3 (see [`RunStatus::decode_older`]).
    #[serde(default)]
    pub best_forces: Option<ForceAnalysis>,
}

/// [`RunStatus`] as wire version 3 first had it, before `waiting`.
#[derive(Deserialize)]
struct RunStatusBeforeWaiting {
    run_id: RunId,
    phase: RunPhase,
    object: String,
    param_names: Vec<String>,
    budget: u64,
    completed: u64,
    running: u64,
    failed: u64,
    best: Option<BestTrial>,
    best_history: Vec<f64>,
    workers: Vec<WorkerStatus>,
    errors: ErrorCounts,
    stamp_ms: i64,
}

impl Message for RunStatus {
    const TYPE: &'static str = "RunStatus";
    fn run_id(&self) -> &RunId {
        &self.run_id
    }
    /// The best trial's forces are checked as a result's are (the coordinator copies them
    /// from a validated result); the rest is left as sent.
    fn validate(&self) -> Result<(), ValidationError> {
        if let Some(f) = &self.best_forces {
            f.validate_in(Self::TYPE, "best_forces")?;
        }
        Ok(())
    }
    /// Three older layouts: before `best_forces.unavailable` (the fields up to
    /// `best_forces`, which bincode writes as the triple below), before `best_forces` (the
    /// pair), and before `waiting`.
    fn decode_older(body: &[u8]) -> Option<(Self, usize)> {
        type BeforeUnavailable = (
            RunStatusBeforeWaiting,
            Vec<Waiting>,
            Option<ForceAnalysisBeforeUnavailable>,
        );
        let whole = |read: &usize| *read == body.len();
        let decoded = crate::codec::decode_bincode_body::<BeforeUnavailable>(body)
            .ok()
            .filter(|(_, read)| whole(read))
            .or_else(|| {
                crate::codec::decode_bincode_body::<(RunStatusBeforeWaiting, Vec<Waiting>)>(body)
                    .ok()
                    .filter(|(_, read)| whole(read))
                    .map(|((s, waiting), read)| ((s, waiting, None), read))
            })
            .or_else(|| {
                crate::codec::decode_bincode_body::<RunStatusBeforeWaiting>(body)
                    .ok()
                    .map(|(s, read)| ((s, Vec::new(), None), read))
            });
        let ((s, waiting, best_forces), read) = decoded?;
        let status = RunStatus {
            run_id: s.run_id,
            phase: s.phase,
            object: s.object,
            param_names: s.param_names,
            budget: s.budget,
            completed: s.completed,
            running: s.running,
            failed: s.failed,
            best: s.best,
            best_history: s.best_history,
            workers: s.workers,
            errors: s.errors,
            stamp_ms: s.stamp_ms,
            waiting,
            best_forces: best_forces.map(ForceAnalysis::from),
        };
        Some((status, read))
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn named_params_pairs_names_and_values() {
        let names = ["a".to_string(), "b".to_string()];
        assert_eq!(
            super::named_params(&names, &[0.5, -1.0], ","),
            "a=0.50000,b=-1.00000"
        );
        // Extra values (or names) are left out, not paired with nothing.
        assert_eq!(
            super::named_params(&names[..1], &[0.5, -1.0], ","),
            "a=0.50000"
        );
    }
}
