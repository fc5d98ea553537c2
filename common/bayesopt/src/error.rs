//! Typed errors of the engine: every public fallible function returns [`BoError`].

use thiserror::Error;

/// Everything that can go wrong when using the engine with bad input or degenerate data.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BoError {
    /// No bounds were given (zero-dimensional problem).
    #[error("bounds are empty: at least one dimension is needed")]
    EmptyBounds,
    /// A bound is not finite or lower >= upper.
    #[error(
        "invalid bound in dimension {dim}: lower {lower} must be finite and below upper {upper}"
    )]
    InvalidBound {
        /// Offending dimension.
        dim: usize,
        /// Lower bound given.
        lower: f64,
        /// Upper bound given.
        upper: f64,
    },
    /// A point has the wrong number of coordinates.
    #[error("dimension mismatch: expected {expected}, got {got}")]
    DimensionMismatch {
        /// Dimension of the problem.
        expected: usize,
        /// Dimension of the input.
        got: usize,
    },
    /// A coordinate or observation is NaN or infinite.
    #[error("non-finite value in {what}")]
    NonFinite {
        /// Which input was not finite.
        what: &'static str,
    },
    /// A point lies outside the bounds.
    #[error("point outside the bounds in dimension {dim}: {value} not in [{lower}, {upper}]")]
    OutOfBounds {
        /// Offending dimension.
        dim: usize,
        /// Coordinate given.
        value: f64,
        /// Lower bound.
        lower: f64,
        /// Upper bound.
        upper: f64,
    },
    /// A setting is outside its valid range.
    #[error("invalid setting: {0}")]
    InvalidSetting(String),
    /// One seed of a benchmark failed.
    #[error("seed {seed}: {error}")]
    Seed {
        /// The seed.
        seed: u64,
        /// What went wrong.
        error: Box<BoError>,
    },
    /// Not enough data for the requested operation (e.g. a GP with no observation).
    #[error("not enough data: {0}")]
    NotEnoughData(String),
    /// The kernel matrix stayed non positive definite even with the largest jitter.
    #[error("Cholesky factorisation failed even with jitter {jitter:e}")]
    CholeskyFailed {
        /// Last jitter tried.
        jitter: f64,
    },
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, BoError>;
