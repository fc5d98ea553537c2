//! Why the perception agent cannot publish an estimate.

use std::path::PathBuf;

/// What can go wrong in the perception agent.
#[derive(Debug, thiserror::Error)]
pub enum PerceptionError {
    /// A noise level that is not a standard deviation it can use.
    #[error(
        "perception: {name} must be a standard deviation between 0 and {max} {unit}, got {value}"
    )]
    Noise {
        name: &'static str,
        max: f64,
        unit: &'static str,
        value: f64,
    },
    #[error("perception: cannot load mesh {}", path.display())]
    Mesh {
        path: PathBuf,
        #[source]
        source: graspopt_sim::SimError,
    },
    #[error("perception")]
    Object(#[source] graspopt_sim::SimError),
    #[error(transparent)]
    Bus(#[from] graspopt_bus::BusError),
}
