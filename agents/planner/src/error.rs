//! Why the planner cannot answer, or cannot serve.

use graspopt_bayesopt::error::BoError;
use graspopt_protocol::RunId;

/// Why the planner cannot answer.
#[derive(Debug, thiserror::Error)]
pub enum PlannerError {
    /// The engine refused (bounds, a proposal).
    #[error(transparent)]
    Bo(#[from] BoError),
    #[error("observation rejected: {0}")]
    Observation(BoError),
    #[error("pending point rejected: {0}")]
    Pending(BoError),
    /// A saved engine state that cannot be used or written.
    #[error("{0}")]
    State(String),
    #[error("this planner serves run {serving:?}, not {asked:?}")]
    OtherRun { serving: RunId, asked: RunId },
    #[error("planner state poisoned")]
    Poisoned,
    #[error("planner state missing")]
    Missing,
    #[error("planner: proposal thread panicked")]
    Panicked(#[source] tokio::task::JoinError),
    #[error(transparent)]
    Bus(#[from] graspopt_bus::BusError),
}
