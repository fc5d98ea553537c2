//! The errors of this crate ([`ShmError`]): each names the service (or prefix) and the
//! operation that failed.

use std::fmt::Display;

/// Errors of this crate. Each names the service (or prefix) and the operation
/// that failed.
#[derive(Debug, thiserror::Error)]
pub enum ShmError {
    /// The [`ShmConfig`](crate::ShmConfig) cannot be used (bad prefix, zero capacity).
    #[error("invalid shared-memory config: {0}")]
    InvalidConfig(String),
    /// The service name is not a valid iceoryx2 service name.
    #[error("invalid shared-memory service name {service:?}: {reason}")]
    InvalidServiceName {
        /// The name that was refused.
        service: String,
        /// Why.
        reason: String,
    },
    /// An operation on one service failed.
    #[error("shared-memory service {service:?}: {operation} failed: {detail}")]
    Service {
        /// The service name.
        service: String,
        /// What was being done.
        operation: &'static str,
        /// The underlying error.
        detail: String,
    },
    /// An operation over all services of a prefix failed.
    #[error("shared memory (prefix {prefix:?}): {operation} failed: {detail}")]
    Host {
        /// The iceoryx2 prefix.
        prefix: String,
        /// What was being done.
        operation: &'static str,
        /// The underlying error.
        detail: String,
    },
}

/// Result type of this crate.
pub type Result<T, E = ShmError> = std::result::Result<T, E>;

/// Maps an iceoryx2 error to [`ShmError::Service`].
pub(crate) fn service_err<'a, E: Display>(
    service: &'a str,
    operation: &'static str,
) -> impl FnOnce(E) -> ShmError + 'a {
    move |e| ShmError::Service {
        service: service.to_owned(),
        operation,
        detail: e.to_string(),
    }
}
