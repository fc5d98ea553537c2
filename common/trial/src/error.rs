//! Errors of a scored trial: from the simulator, the quality core, or the settings.

use thiserror::Error;

#[derive(Debug, Error)]
pub enum TrialError {
    #[error(transparent)]
    Sim(#[from] graspopt_sim::SimError),
    #[error(transparent)]
    Quality(#[from] graspopt_quality::QualityError),
    #[error("cannot load the mesh {}", path.display())]
    Mesh {
        path: std::path::PathBuf,
        source: Box<graspopt_sim::SimError>,
    },
    #[error("{0}")]
    Settings(String),
}
