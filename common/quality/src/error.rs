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
    /// A coordinate is beyond [`MAX_COORDINATE`](crate::limits::MAX_COORDINATE) in
    /// absolute value.
    #[error(
        "{what} {index}: {field} {value:?} is out of range: each coordinate must be at most {} in absolute value",
        num(*limit)
    )]
    OutOfRange {
        what: &'static str,
        index: usize,
        field: &'static str,
        value: [f64; 3],
        limit: f64,
    },
    /// A wrench has a NaN or infinite component.
    #[error("wrench {index} is not finite ({value:?})")]
    WrenchNotFinite { index: usize, value: [f64; 6] },
    /// A given wrench has a component beyond
    /// [`MAX_COORDINATE`](crate::limits::MAX_COORDINATE) in absolute value.
    #[error(
        "wrench {index}: component {component} = {} is out of range: each component must be at most {} in absolute value",
        num(*value),
        num(*limit)
    )]
    WrenchOutOfRange {
        index: usize,
        component: usize,
        value: f64,
        limit: f64,
    },
    /// A contact generates a wrench that is not finite or has a component beyond
    /// [`MAX_COORDINATE`](crate::limits::MAX_COORDINATE): its distance to the reference
    /// point, `mu`, `gamma` or `1 / torque_scale` is too large.
    #[error(
        "contact {index}: its wrench component {component} = {} is out of range (each must be finite and at most {} in absolute value): the distance from position to reference_point, mu, gamma or 1/torque_scale is too large",
        num(*value),
        num(*limit)
    )]
    ContactWrenchOutOfRange {
        index: usize,
        component: usize,
        value: f64,
        limit: f64,
    },
    /// Contacts that would generate more wrenches than
    /// [`MAX_WRENCHES`](crate::limits::MAX_WRENCHES).
    #[error(
        "{contacts} contacts x {per_contact} wrenches per contact = {count} wrenches, more than the limit of {limit}"
    )]
    TooManyContactWrenches {
        contacts: usize,
        per_contact: usize,
        count: u128,
        limit: usize,
    },
    /// More wrenches given than [`MAX_WRENCHES`](crate::limits::MAX_WRENCHES).
    #[error("{count} wrenches given, more than the limit of {limit}")]
    TooManyWrenches { count: usize, limit: usize },
    /// A contact normal has zero length.
    #[error("contact {index}: normal is zero; a contact normal must be a unit vector")]
    ZeroNormal { index: usize },
    /// A contact normal is not of unit length.
    #[error("contact {index}: normal has length {norm}; a contact normal must be a unit vector")]
    NonUnitNormal { index: usize, norm: f64 },
    /// A model parameter is out of its range.
    #[error("{name} = {} is invalid: {expected}", num(*value))]
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
    /// The wrench hull would need more facets than
    /// [`FACET_LIMIT`](crate::hull::quickhull::FACET_LIMIT): building it is refused
    /// rather than allowed to exhaust memory.
    #[error(
        "the {metric} of {points} wrenches needs a hull of more than {limit} facets, beyond the memory bound: use fewer contacts or cone edges"
    )]
    HullTooLarge {
        metric: &'static str,
        points: usize,
        limit: usize,
    },
    /// A metric came out NaN or infinite (a numerical failure on input that passed the
    /// checks); reported rather than printed as a number.
    #[error("the {metric} came out as {value}: numerical failure")]
    NotFiniteMetric { metric: &'static str, value: f64 },
    /// Contact forces (force analysis) that do not match the contacts one to one.
    #[error(
        "{forces} forces and {torsions} torsions given for {contacts} contacts: give one force and one torsion (0 unless a soft finger) per contact"
    )]
    ForceCount {
        contacts: usize,
        forces: usize,
        torsions: usize,
    },
    /// A contact's torsion (moment about its normal) is not finite or beyond
    /// [`MAX_COORDINATE`](crate::limits::MAX_COORDINATE) in absolute value.
    #[error(
        "contact {index}: torsion {} must be finite and at most {} in absolute value",
        num(*value),
        num(*limit)
    )]
    TorsionOutOfRange {
        index: usize,
        value: f64,
        limit: f64,
    },
    /// A contact carries a torsion but the friction model has no torsional friction
    /// (only a soft finger transmits a moment about the normal).
    #[error(
        "contact {index}: torsion {} given, but only a soft finger transmits a moment about its normal",
        num(*value)
    )]
    TorsionWithoutSoftFinger { index: usize, value: f64 },
    /// The external wrench to resist is not finite or has a component beyond
    /// [`MAX_COORDINATE`](crate::limits::MAX_COORDINATE) in absolute value.
    #[error(
        "the external wrench {value:?} must be finite with each component at most {} in absolute value",
        num(*limit)
    )]
    ExternalWrench { value: [f64; 6], limit: f64 },
    /// A name that is not a metric that may be the score (see
    /// [`Metric::parse`](crate::metrics::Metric::parse)).
    #[error(
        "unknown metric {name:?}: expected {}",
        crate::metrics::objective_names()
    )]
    UnknownMetric { name: String },
    /// The conic solver (Clarabel) failed; the text names the problem and its status.
    #[error("the conic solver failed: {0}")]
    Solver(String),
}

/// A number as a person reads it: plain decimal when that is short, else scientific
/// (`1e308`, not 309 digits).
fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e9).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_messages_stay_short() {
        assert_eq!(num(-1.0), "-1");
        assert_eq!(num(4096.0), "4096");
        assert_eq!(num(1e308), "1e308");
        assert_eq!(num(1e12), "1e12");
        assert_eq!(num(2.5e-7), "2.5e-7");
        assert_eq!(num(f64::NAN), "NaN");
    }
}
