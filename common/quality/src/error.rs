//! Errors of the quality crate. Each names the input that is wrong.

use thiserror::Error;

/// What is wrong with the input of a quality computation.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum QualityError {
    /// No contacts (or no wrenches) were given: a grasp that touches nothing has no
    /// wrench space, so the metrics are undefined. Callers decide the score of such a
    /// trial.
    #[error("no {0} given: a grasp needs at least one contact")]
    Empty(&'static str),
    /// A coordinate is NaN or infinite.
    #[error("{what} {index}: {field} is not finite ({value:?})")]
    NotFinite {
        what: &'static str,
        index: usize,
        field: &'static str,
        value: [f64; 3],
    },
    /// A wrench has a NaN or infinite component.
    #[error("wrench {index} is not finite ({value:?})")]
    WrenchNotFinite { index: usize, value: [f64; 6] },
    /// A contact normal has zero length.
    #[error("contact {index}: normal is zero; a contact normal must be a unit vector")]
    ZeroNormal { index: usize },
    /// A contact normal is not of unit length.
    #[error("contact {index}: normal has length {norm}; a contact normal must be a unit vector")]
    NonUnitNormal { index: usize, norm: f64 },
    /// A model parameter is out of its range.
    #[error("{name} = {value} is invalid: {expected}")]
    Parameter {
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
    /// The normals of a contact cloud cancel out, so it has no mean normal.
    #[error("the normals of the contact cloud cancel out: no mean normal")]
    NoMeanNormal,
    /// The full wrench hull could not be built (floating-point degeneracy that neither
    /// the exact nor the joggled points overcame), so its volume is unavailable.
    #[error(
        "the wrench hull of {points} wrenches could not be built (degenerate geometry); its volume is unavailable"
    )]
    HullFailed { points: usize },
    /// The conic solver failed.
    #[error("the distance QP solver failed: {0}")]
    Solver(String),
}
