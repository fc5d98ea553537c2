//! Why a hand agent cannot serve ([`HandAgentError`]), and why one trial failed
//! ([`HandError`], sent in the trial's `error` field; the agent goes on).

use std::path::PathBuf;

use graspopt_sim::SimError;

use crate::replay::RecordingError;

/// Why a hand could not execute a trial: the trial fails with this reason (its text), the
/// agent goes on.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HandError {
    /// A driver's own reason (a real hand's fault, say).
    #[error("{0}")]
    Fault(String),
    /// The command asks for another hand than the driver moves.
    #[error("worker {worker} has a {has} hand, the trial asks for {asked}")]
    OtherHand {
        worker: String,
        has: String,
        asked: String,
    },
    /// The simulator could not run the trial.
    #[error("hand could not execute the trial: {0}")]
    Simulation(String),
    /// The simulated fingertip sensors could not read the contacts.
    #[error("fingertip sensors: {0}")]
    Fingertips(String),
    /// No object estimate has built the simulated world yet.
    #[error("the hand's world holds no object")]
    NoObject,
    /// The replay hand's nearest recorded grasp is of another hand.
    #[error("the recording {} was made with a {recorded} hand, the trial asks for {asked}", path.display())]
    RecordedHand {
        path: PathBuf,
        recorded: String,
        asked: String,
    },
    /// The replay hand's grasps have another number of parameters than the trial.
    #[error("the recording {} has {recorded} parameters per grasp, the trial has {asked}", path.display())]
    RecordedParams {
        path: PathBuf,
        recorded: usize,
        asked: usize,
    },
}

/// Why a hand agent cannot start or goes no further.
#[derive(Debug, thiserror::Error)]
pub enum HandAgentError {
    #[error("{context}")]
    Hand {
        context: &'static str,
        #[source]
        source: SimError,
    },
    /// The hand or its sensor settings cannot sense fingertip forces.
    #[error("{context}")]
    Sensing {
        context: &'static str,
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    #[error(transparent)]
    Recording(#[from] RecordingError),
    #[error("hand: trial thread panicked")]
    Panicked(#[source] tokio::task::JoinError),
    #[error(transparent)]
    Bus(#[from] graspopt_bus::BusError),
}
