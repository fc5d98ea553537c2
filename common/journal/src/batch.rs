//! Several writes in one transaction: what a coordinator decided at one moment (the issues
//! of one planner reply, the results that arrived together) committed at once.
//!
//! Why: a commit costs a write of the log and, under load, waits for the disk; with one
//! transaction per write, commits were 60-80% of a coordinator's time and capped it near
//! 500-1,800 trials/s (`graspopt bench coordinator`, docs/benchmarks.md). A batch costs one
//! commit.
//!
//! What a batch keeps of the single writes' rules:
//! - Each write is checked and refused alone, exactly as its single method would refuse
//!   it (a savepoint per write: a refused write leaves nothing, the others stand).
//! - The batch is atomic: a process killed before the commit leaves none of it, after the
//!   commit all of it (SQLite's write-ahead log). A caller that sends a command only after
//!   the batch with its issue is committed keeps the promise "never a command without its
//!   issue in the journal".

use rusqlite::Connection;

use crate::error::Result;
use crate::journal::Journal;
use crate::types::{ResultOutcome, ResultRow, TrialIssue};
use crate::writes::{failure_in, issue_in, planner_state_in, result_in};

/// One write of a run's journal (the run is given to [`Journal::record`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Write {
    /// A trial attempt leased to a worker ([`Journal::write_issue`]).
    Issue(TrialIssue),
    /// A trial attempt that failed ([`Journal::write_failure`]).
    Failure {
        trial_id: u64,
        attempt: u32,
        error: String,
        at_ms: i64,
    },
    /// A trial's result ([`Journal::write_result`]), boxed: it is larger than the other
    /// writes (its force analysis) by far.
    Result(Box<ResultRow>),
    /// The planner's engine after its last reply ([`Journal::set_planner_state`]).
    PlannerState { engine: Vec<u8>, at_ms: i64 },
}

/// What one write of a batch did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Written {
    Issue,
    /// Whether the failure was recorded (false: the trial had already ended, or is unknown).
    Failure(bool),
    Result(ResultOutcome),
    PlannerState,
}

impl Journal {
    /// Carries out `writes` of run `run_id` in order, in one transaction. The outer error
    /// is the transaction's own (it could not start or commit): then nothing was written.
    /// Otherwise each write has its outcome, in order; a write refused (its error) left
    /// nothing, and the others are committed.
    pub fn write(&mut self, run_id: &str, writes: &[Write]) -> Result<Vec<Result<Written>>> {
        let mut tx = self.write_tx()?;
        let mut outcomes = Vec::with_capacity(writes.len());
        for write in writes {
            let mut point = tx.savepoint()?;
            let outcome = apply(&point, run_id, write);
            if outcome.is_ok() {
                point.commit()?;
            } else {
                point.rollback()?;
            }
            outcomes.push(outcome);
        }
        tx.commit()?;
        Ok(outcomes)
    }
}

fn apply(conn: &Connection, run_id: &str, write: &Write) -> Result<Written> {
    Ok(match write {
        Write::Issue(issue) => {
            issue_in(conn, issue)?;
            Written::Issue
        }
        Write::Failure {
            trial_id,
            attempt,
            error,
            at_ms,
        } => Written::Failure(failure_in(
            conn, run_id, *trial_id, *attempt, error, *at_ms,
        )?),
        Write::Result(result) => Written::Result(result_in(conn, result)?),
        Write::PlannerState { engine, at_ms } => {
            planner_state_in(conn, run_id, engine, *at_ms)?;
            Written::PlannerState
        }
    })
}
