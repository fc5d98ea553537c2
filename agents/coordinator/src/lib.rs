//! The coordinator agent owns a run. It watches hand workers by their liveliness tokens,
//! leases each trial to one idle worker, re-issues a trial whose worker vanished or whose
//! lease expired, asks the planner for as many proposals as there are idle workers, accepts
//! each trial's result exactly once, writes everything to the trial journal (SQLite) as it
//! happens, and publishes the run's status. Restarted on the same journal, it continues the
//! run: completed trials are kept, unfinished ones are issued again.
//!
//! - [`spec`]: what a run is, resuming it, opening it in the journal (journal glue).
//! - [`core`]: the rules, as a state machine without I/O: every [`Event`] goes through
//!   [`Coordinator::handle`], which returns the [`Action`]s to carry out. [`state`] is its bookkeeping of trials and workers, [`waits`]
//!   what the run waits for.
//! - [`run`](mod@run): the async loop, which only moves messages, timers and journal writes.
//! - [`error`]: what stops a coordinator or refuses a run ([`CoordinatorError`]).
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod core;
pub mod error;
pub mod run;
pub mod spec;
pub mod state;
pub mod waits;

use std::path::PathBuf;

use graspopt_protocol::RunId;
use serde::{Deserialize, Serialize};

pub use crate::core::{Action, Coordinator, Event, Write};
pub use crate::error::CoordinatorError;
pub use crate::run::{run, run_until, split_writes, write_journal};
pub use crate::spec::{
    Conflicts, MAX_TRIALS, RunSpec, bounds_of, check_trials, journaled_runs, journaled_spec,
    open_run, param_names, quoted_runs, range_conflicts, reconcile, resume_conflicts, sole_run,
    standalone_run, trial_space,
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

/// The longest lease and planner timeout accepted (a week, in milliseconds): longer ones
/// would overflow the millisecond clock's arithmetic, and mean "never" anyway.
pub const MAX_WAIT_MS: u64 = 7 * 24 * 3600 * 1000;

impl CoordinatorConfig {
    /// Refuses settings the coordinator cannot keep: a lease or planner timeout of 0 (every
    /// trial would expire at once, every question time out) or over [`MAX_WAIT_MS`]. The
    /// message names the setting.
    pub fn validate(&self) -> Result<(), CoordinatorError> {
        for (name, v) in [
            ("lease_ms", self.lease_ms),
            ("planner_timeout_ms", self.planner_timeout_ms),
        ] {
            if !(1..=MAX_WAIT_MS).contains(&v) {
                return Err(CoordinatorError::Wait { name, value: v });
            }
        }
        Ok(())
    }

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

/// The coordinator as an [`graspopt_bus::Agent`] (`graspopt agent coordinator`, the embedded
/// run's): it serves the run `spec` describes (with `resume`, the one in its journal) and
/// gives every status it publishes to `progress`.
pub struct CoordinatorAgent {
    pub spec: RunSpec,
    pub resume: bool,
    pub progress: Option<tokio::sync::watch::Sender<graspopt_protocol::RunStatus>>,
}

impl graspopt_bus::Agent for CoordinatorAgent {
    const KIND: graspopt_protocol::AgentKind = graspopt_protocol::AgentKind::Coordinator;
    const ABOUT: &'static str = "Owns the run and its journal";
    type Config = CoordinatorConfig;
    type Output = graspopt_protocol::RunStatus;
    type Error = CoordinatorError;

    fn id(config: &mut CoordinatorConfig) -> &mut String {
        &mut config.id
    }

    fn validate(config: &CoordinatorConfig) -> Result<(), Self::Error> {
        config.validate()
    }

    async fn run(
        &self,
        bus: &graspopt_bus::Bus,
        run: &RunId,
        config: &CoordinatorConfig,
        stop: impl Future<Output = ()> + Send,
    ) -> Result<Self::Output, Self::Error> {
        let progress = self.progress.clone();
        run_until(bus, run, &self.spec, config, self.resume, progress, stop).await
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_a_coordinator_cannot_keep_are_refused_by_name() {
        assert!(CoordinatorConfig::default().validate().is_ok());
        let zero = CoordinatorConfig {
            lease_ms: 0,
            ..Default::default()
        };
        assert_eq!(
            zero.validate().unwrap_err().to_string(),
            "lease_ms is 0: it must be between 1 and 604800000 (a week)"
        );
        let forever = CoordinatorConfig {
            planner_timeout_ms: u64::MAX,
            ..Default::default()
        };
        let err = forever.validate().unwrap_err().to_string();
        assert!(
            err.starts_with("planner_timeout_ms is 18446744073709551615"),
            "{err}"
        );
    }
}
