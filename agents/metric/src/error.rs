//! Why the metric agent cannot score.

/// What can go wrong in the metric agent.
#[derive(Debug, thiserror::Error)]
pub enum MetricError {
    /// Contact-model or force settings it cannot use.
    #[error("metric agent settings")]
    Settings(#[source] Box<dyn std::error::Error + Send + Sync>),
    #[error("metric: scoring thread panicked")]
    Panicked(#[source] tokio::task::JoinError),
    #[error(transparent)]
    Bus(#[from] graspopt_bus::BusError),
}
