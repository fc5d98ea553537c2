//! The coordinator agent owns a run. It watches hand workers by their liveliness tokens,
//! leases each trial to one idle worker, re-issues a trial whose worker vanished or whose
//! lease expired, asks the planner for as many proposals as there are idle workers, accepts
//! each trial's result exactly once, writes everything to the trial journal (SQLite) as it
//! happens, and publishes the run's status. Restarted on the same journal, it continues the
//! run: completed trials are kept, unfinished ones are issued again.
//!
//! - [`spec`]: what a run is, resuming it, opening it in the journal (journal glue).
//! - [`core`]: the rules, as a state machine without I/O: one method per event, returning
//!   the actions to carry out. [`state`] is its bookkeeping of trials and workers, [`waits`]
//!   what the run waits for.
//! - [`run`]: the async loop, which only moves messages, timers and journal writes.
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod core;
pub mod run;
pub mod spec;
pub mod state;
pub mod waits;

use std::path::PathBuf;

use graspopt_protocol::RunId;
use serde::{Deserialize, Serialize};

pub use crate::core::{Action, Coordinator, Write};
pub use crate::run::{record, run, run_until, split_writes};
pub use crate::spec::{
    Conflicts, RunSpec, open_run, param_names, quoted_runs, reconcile, recorded_runs,
    recorded_spec, resume_conflicts, sole_run, standalone_run, trial_space,
};

/// Coordinator settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CoordinatorConfig {
    pub id: String,
    /// The journal file (empty: `results/<run>/journal.sqlite`, where `graspopt run` and
    /// `graspopt export` look by default).
    pub journal: PathBuf,
    /// A trial without a result after this long is issued again.
    pub lease_ms: u64,
    /// How long to wait for the planner before asking again.
    pub planner_timeout_ms: u64,
    /// Status publication period.
    pub status_period_ms: u64,
}

impl Default for CoordinatorConfig {
    fn default() -> Self {
        CoordinatorConfig {
            id: "coordinator".into(),
            journal: PathBuf::new(),
            lease_ms: 30_000,
            planner_timeout_ms: 30_000,
            status_period_ms: 500,
        }
    }
}

impl CoordinatorConfig {
    /// The journal file of `run` (see [`CoordinatorConfig::journal`]).
    pub fn journal_path(&self, run: &RunId) -> PathBuf {
        if self.journal.as_os_str().is_empty() {
            PathBuf::from("results")
                .join(run.as_str())
                .join("journal.sqlite")
        } else {
            self.journal.clone()
        }
    }
}
