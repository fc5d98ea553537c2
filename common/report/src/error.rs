//! The errors of writing a command's output: each says what could not be written or drawn.

use std::path::PathBuf;

use thiserror::Error;

/// An error writing a report, a scan, a run's files or a trial's pictures.
#[derive(Debug, Error)]
pub enum ReportError {
    /// A file could not be written.
    #[error("cannot write {}", path.display())]
    Write {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A folder could not be created.
    #[error("cannot create {}", dir.display())]
    CreateDir {
        dir: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// `--scene` or `--preview` names a file of a type graspopt does not write.
    #[error("{0}")]
    Output(String),
    /// A scan (or a study's curve) without a point.
    #[error("empty scan")]
    EmptyScan,
    /// A study without a run of Bayesian optimisation.
    #[error("no BO run")]
    NoBoRun,
    /// The best trial of a run could not be simulated again for its picture.
    #[error("cannot simulate the best trial {trial} again")]
    Resimulate {
        trial: u64,
        #[source]
        source: graspopt_trial::TrialError,
    },
    #[error(transparent)]
    Io(#[from] std::io::Error),
    #[error(transparent)]
    Journal(#[from] graspopt_journal::JournalError),
    #[error(transparent)]
    Trial(#[from] graspopt_trial::TrialError),
    #[error(transparent)]
    Sim(#[from] graspopt_sim::SimError),
    /// (Boxed: a study's error is large.)
    #[error(transparent)]
    Experiment(Box<graspopt_experiment::ExperimentError>),
    /// A picture or a scene that could not be drawn or written (said by
    /// `graspopt-pictures` or `graspopt-scene`).
    #[error(transparent)]
    Picture(Box<dyn std::error::Error + Send + Sync>),
}

impl From<graspopt_experiment::ExperimentError> for ReportError {
    fn from(e: graspopt_experiment::ExperimentError) -> Self {
        ReportError::Experiment(Box::new(e))
    }
}

impl ReportError {
    /// A picture's or a scene's error.
    pub fn picture(e: impl Into<Box<dyn std::error::Error + Send + Sync>>) -> Self {
        ReportError::Picture(e.into())
    }
}

/// The result of writing output.
pub type Result<T, E = ReportError> = std::result::Result<T, E>;
