#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]
//! The graspopt trial journal: every trial of every run, durable in an
//! embedded SQLite database.
//!
//! This crate owns the journal's database: its schema and version, the
//! recording rules (a trial is issued, maybe re-issued, and ends exactly once,
//! completed by one result or failed), the event log of every issue, result,
//! duplicate and failure, and the CSV/JSON exports of a run (written safely by
//! [`output`]).
//!
//! It must not know the network or the bus, the planner, the simulator or any
//! other graspopt crate but protocol's plain data (a result's `MetricValues`) and the
//! quality crate's metric table (which metric columns a trial has: see `metrics.rs`): it
//! defines its own record types, and the caller converts. It reads no clock (every timestamp is given by the caller) and
//! starts no thread: one owner (a thread, a task or a mutex) calls it; a
//! [`Journal`] is `Send`, not `Sync`.

pub mod batch;
mod error;
pub mod export;
mod failures;
mod journal;
mod metrics;
pub mod output;
mod rows;
mod schema;
mod types;
mod writes;

pub use batch::{Write, Written};
pub use error::{JournalError, Result};
pub use failures::{FailureReason, NO_REASON};
pub use journal::Journal;
pub use schema::SCHEMA_VERSION;
pub use types::{
    EventRow, ForceAnalysis, MetricValue, MetricValues, ResultOutcome, ResultRow, RunExport,
    RunRow, StateCounts, StoredRunPhase, StoredTrialPhase, TrialIssue, TrialRow, event_kind,
};
