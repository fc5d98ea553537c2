//! Errors of an experiment: the engine's, the trial's, or bad settings.

use thiserror::Error;

/// Why an experiment could not run. A wrapped error named in the message is not also a
/// `source()`: an error chain printed with `{:#}` would say it twice.
#[derive(Debug, Error)]
pub enum ExperimentError {
    /// The optimisation engine refused (bad bounds or settings).
    #[error("optimizer: {0}")]
    Optimizer(graspopt_bayesopt::BoError),
    /// A trial could not be run or scored.
    #[error("trial at {params:?}: {error}")]
    Trial {
        params: Vec<f64>,
        error: graspopt_trial::TrialError,
    },
    /// A trial scored a value that is not finite.
    #[error("trial at {params:?} scored {score}, not a finite number")]
    NonFinite { params: Vec<f64>, score: f64 },
    /// A grid scan failed (its error names the point).
    #[error(transparent)]
    Scan(#[from] graspopt_trial::TrialError),
    /// An object or a trial space could not be built.
    #[error(transparent)]
    Sim(#[from] graspopt_sim::SimError),
    /// The hand could not be loaded (the source names it: its file, or the unknown name).
    #[error("cannot load the hand")]
    Hand {
        name: String,
        source: graspopt_sim::SimError,
    },
    /// The experiment's own settings are wrong.
    #[error("{0}")]
    Settings(String),
}

impl From<graspopt_bayesopt::BoError> for ExperimentError {
    fn from(e: graspopt_bayesopt::BoError) -> Self {
        ExperimentError::Optimizer(e)
    }
}
