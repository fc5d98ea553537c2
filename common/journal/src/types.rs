//! The journal's plain record types: what goes in and what comes out.

use serde::{Deserialize, Serialize};

/// One optimisation run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunRow {
    pub run_id: String,
    /// Creation time, milliseconds since the Unix epoch (the caller's clock).
    pub created_ms: i64,
    /// The run's configuration as JSON text (stored verbatim).
    pub config_json: String,
    /// Names of the search-space dimensions, in the order of `TrialIssue::params`.
    pub param_names: Vec<String>,
    pub status: StoredRunPhase,
}

/// Lifecycle of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StoredRunPhase {
    Running,
    Finished,
    Stopped,
}

impl StoredRunPhase {
    /// The text stored in the database (the serde name).
    pub fn as_str(self) -> &'static str {
        match self {
            StoredRunPhase::Running => "running",
            StoredRunPhase::Finished => "finished",
            StoredRunPhase::Stopped => "stopped",
        }
    }

    /// Inverse of [`StoredRunPhase::as_str`].
    pub fn parse(s: &str) -> Option<StoredRunPhase> {
        match s {
            "running" => Some(StoredRunPhase::Running),
            "finished" => Some(StoredRunPhase::Finished),
            "stopped" => Some(StoredRunPhase::Stopped),
            _ => None,
        }
    }
}

/// A trial handed to a worker: attempt 1 is the first issue, attempt n+1 a re-issue.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialIssue {
    pub run_id: String,
    pub trial_id: u64,
    pub attempt: u32,
    pub params: Vec<f64>,
    pub worker: String,
    pub at_ms: i64,
    pub lease_until_ms: i64,
    /// Why the trial is re-issued; stored as the note of the `reissued` (or
    /// `issued`) event.
    pub reason: Option<String>,
}

/// A worker's result for one attempt of a trial.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResultRow {
    pub run_id: String,
    pub trial_id: u64,
    pub attempt: u32,
    pub worker: String,
    pub at_ms: i64,
    pub score: f64,
    pub metrics: Option<MetricValues>,
    pub contacts: u32,
    pub fingers_in_contact: u32,
    pub cloud_points: u32,
    /// Free-form JSON from the worker, stored verbatim.
    pub details_json: String,
    /// The contact-force analysis of the result, stored as JSON.
    pub forces: Option<ForceAnalysis>,
}

/// Grasp-quality metrics of one trial, stored one column per metric of the metric table:
/// the result message's own type, so a result is journaled without a copy of its fields.
pub use graspopt_protocol::{MetricValue, MetricValues};

/// A trial's contact-force analysis: the result message's own type, stored as JSON.
pub use graspopt_protocol::ForceAnalysis;

/// What `write_result` did with a result.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ResultOutcome {
    /// The result completed the trial.
    Accepted,
    /// The trial already had its final outcome; the trial row is unchanged and
    /// a `duplicate` event was written.
    Duplicate,
    /// The run (or the run's trial) is not in the journal; nothing was written.
    UnknownTrial,
}

/// State of a trial, stored as its snake_case name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StoredTrialPhase {
    Running,
    Completed,
    Failed,
}

impl StoredTrialPhase {
    /// The text stored in the database (the serde name).
    pub fn as_str(self) -> &'static str {
        match self {
            StoredTrialPhase::Running => "running",
            StoredTrialPhase::Completed => "completed",
            StoredTrialPhase::Failed => "failed",
        }
    }

    /// Inverse of [`StoredTrialPhase::as_str`].
    pub fn parse(s: &str) -> Option<StoredTrialPhase> {
        match s {
            "running" => Some(StoredTrialPhase::Running),
            "completed" => Some(StoredTrialPhase::Completed),
            "failed" => Some(StoredTrialPhase::Failed),
            _ => None,
        }
    }
}

/// One trial as stored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialRow {
    pub run_id: String,
    pub trial_id: u64,
    pub state: StoredTrialPhase,
    /// Number of times the trial was issued (1 + re-issues).
    pub attempts: u32,
    pub params: Vec<f64>,
    /// The last worker involved: the latest issue's worker, or the worker
    /// whose result completed the trial.
    pub worker: String,
    /// Time of the first issue.
    pub issued_ms: i64,
    /// Lease deadline of the latest issue.
    pub lease_until_ms: i64,
    /// Set only for a completed trial: the accepted result's time.
    pub completed_ms: Option<i64>,
    /// Which attempt produced the accepted result (may be older than `attempts`).
    pub result_attempt: Option<u32>,
    pub score: Option<f64>,
    pub metrics: Option<MetricValues>,
    /// Result counts; 0 while the trial has no result.
    pub contacts: u32,
    pub fingers_in_contact: u32,
    pub cloud_points: u32,
    pub details_json: Option<String>,
    /// The failure message of a failed trial.
    pub error: Option<String>,
    /// The accepted result's contact-force analysis, if it had one.
    pub forces: Option<ForceAnalysis>,
}

/// One line of a run's event log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventRow {
    /// Journal-wide insertion order.
    pub seq: i64,
    pub run_id: String,
    pub trial_id: u64,
    pub attempt: u32,
    /// One of the [`event_kind`](crate::event_kind) names.
    pub kind: String,
    pub worker: String,
    pub at_ms: i64,
    pub note: Option<String>,
}

/// The `kind` values of [`EventRow`].
pub mod event_kind {
    /// First issue of a trial (attempt 1).
    pub const ISSUED: &str = "issued";
    /// A later attempt; `note` is the reason given.
    pub const REISSUED: &str = "reissued";
    /// The accepted result; `note` says when it came from an older attempt.
    pub const RESULT: &str = "result";
    /// A result for a trial that already had its final outcome.
    pub const DUPLICATE: &str = "duplicate";
    /// The trial failed permanently; `note` is the message.
    pub const FAILED: &str = "failed";
}

/// Number of a run's trials in each state.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct StateCounts {
    pub running: usize,
    pub completed: usize,
    pub failed: usize,
}

/// A whole run as exported by [`crate::export::write_json`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunExport {
    pub run: RunRow,
    pub trials: Vec<TrialRow>,
}
