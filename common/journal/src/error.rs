//! The journal's error type.

use crate::types::StoredTrialPhase;

/// Everything that can go wrong in the journal. Each variant names the run,
/// trial or field concerned so that a log line is enough to find the cause.
///
/// The wrapped errors (SQLite, JSON, I/O) are part of the message and not a `source()`:
/// an error chain printed with `{:#}` would otherwise say them twice.
#[derive(Debug, thiserror::Error)]
pub enum JournalError {
    /// The database itself failed (I/O, lock timeout, constraint, ...).
    #[error("journal database error: {0}")]
    Sqlite(rusqlite::Error),
    /// The journal file cannot be opened or written; `reason` says why (a missing folder,
    /// a permission, ...).
    #[error("{reason}")]
    Open {
        path: std::path::PathBuf,
        reason: String,
    },
    /// The run id is not in the journal.
    #[error("unknown run {0:?}")]
    UnknownRun(String),
    /// `create_run` for an existing run id whose stored config (or parameter
    /// names) differ from the ones given.
    #[error("run {run_id:?} already exists with a different config")]
    ConfigMismatch { run_id: String },
    /// A NaN or infinite value where a finite number is required; nothing was written.
    #[error("non-finite value in field {field} (NaN and infinities are refused)")]
    NonFinite { field: String },
    /// A value out of its range (the message names the field); nothing was written.
    #[error("invalid value: {0}")]
    Invalid(String),
    /// The database file carries a schema version this code does not know.
    #[error(
        "journal schema version {found} is not supported (this build reads version {expected})"
    )]
    SchemaVersion { found: i64, expected: i64 },
    /// The database has the right version number but not the expected layout,
    /// or is some other SQLite database.
    #[error("not a graspopt journal: {0}")]
    Schema(String),
    /// The database could not be put in write-ahead-log mode.
    #[error("journal could not enable WAL mode (journal_mode is {0:?})")]
    JournalMode(String),
    /// JSON (de)serialisation failed.
    #[error("journal JSON error: {0}")]
    Json(serde_json::Error),
    /// Writing an export failed.
    #[error("journal I/O error: {0}")]
    Io(std::io::Error),
    /// An operation that requires an issued trial named one the run does not know.
    #[error("run {run_id:?} has no trial {trial_id}")]
    UnknownTrial { run_id: String, trial_id: u64 },
    /// `write_issue` with an attempt number that is not the next one.
    #[error("run {run_id:?} trial {trial_id}: attempt {found} issued, expected attempt {expected}")]
    AttemptMismatch {
        run_id: String,
        trial_id: u64,
        expected: u32,
        found: u32,
    },
    /// `write_issue` for a trial that already reached a final state.
    #[error("run {run_id:?} trial {trial_id} is already {state:?} and cannot be re-issued")]
    TrialClosed {
        run_id: String,
        trial_id: u64,
        state: StoredTrialPhase,
    },
    /// A re-issue whose parameters differ from the trial's stored ones.
    #[error("run {run_id:?} trial {trial_id} re-issued with different parameters")]
    ParamsMismatch { run_id: String, trial_id: u64 },
    /// A trial whose parameter vector length differs from the run's parameter names.
    #[error(
        "run {run_id:?} has {expected} parameter names but trial {trial_id} has {found} parameters"
    )]
    ParamCount {
        run_id: String,
        trial_id: u64,
        expected: usize,
        found: usize,
    },
    /// An export's output file that cannot be written, or must not be (the journal).
    #[error("output {path}: {reason}")]
    Output { path: String, reason: String },
    /// Trial ids are stored as SQLite integers (i64); larger ids are refused.
    #[error("trial id {0} is too large for the journal (max {max})", max = i64::MAX)]
    TrialIdRange(u64),
}

impl From<rusqlite::Error> for JournalError {
    fn from(e: rusqlite::Error) -> Self {
        JournalError::Sqlite(e)
    }
}

impl From<serde_json::Error> for JournalError {
    fn from(e: serde_json::Error) -> Self {
        JournalError::Json(e)
    }
}

impl From<std::io::Error> for JournalError {
    fn from(e: std::io::Error) -> Self {
        JournalError::Io(e)
    }
}

/// The journal's result type.
pub type Result<T> = std::result::Result<T, JournalError>;
