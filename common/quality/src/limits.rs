//! Bounds on the input of a quality computation.
//!
//! Every count that sizes an allocation and every magnitude that enters the wrench-space
//! geometry is bounded, so that bad input is an error naming the field rather than an
//! out-of-memory abort or a metric that overflowed to infinity or NaN:
//!
//! | what | bound | why |
//! |---|---|---|
//! | friction-cone `edges` | `3 ..= `[`MAX_EDGES`] (4,096) | a cone sampled finer than 0.1 degree changes no metric; each edge is one wrench (two for a soft finger) |
//! | wrenches of a grasp (contacts x wrenches per contact, or given) | [`MAX_WRENCHES`] (2,000,000) | about 100 MB of wrenches; the hull algorithms need several passes over them |
//! | friction coefficient `mu` | `0 ..= `[`MAX_MU`] (1e6) | a cone half-angle within 1e-6 rad of 90 degrees; beyond that the normal force is lost to rounding |
//! | contact `position`, `reference_point`, torsional `gamma` | [`MAX_COORDINATE`] (1e12) in absolute value | see below |
//! | every wrench component, given or generated | [`MAX_COORDINATE`] (1e12) in absolute value | squares and 6-volumes of the hull stay far from overflow (1e72 at most) |
//! | facets of a hull (volume, or the expanding polytope for epsilon) | [`FACET_LIMIT`](crate::hull::quickhull::FACET_LIMIT) (5,000,000) | about 700 MB; the volume of three 256-edge cones already needs more ([`QualityError::HullTooLarge`](crate::QualityError::HullTooLarge)) |
//!
//! Tolerances of the hull algorithms are relative to the largest coordinate of the set
//! (see [`crate::hull`]): a feature much smaller than that (below about 1e-9 of it for
//! the affine rank) is below the resolution of the metrics. Wrench sets of ordinary
//! dimensionless grasps have coordinates of order 1.

/// Most friction-cone edges a contact model may have.
pub const MAX_EDGES: usize = 4096;

/// Most wrenches one grasp may have: contacts times wrenches per contact, or the
/// wrenches given directly.
pub const MAX_WRENCHES: usize = 2_000_000;

/// Largest friction coefficient accepted.
pub const MAX_MU: f64 = 1e6;

/// Largest absolute value of a position or reference-point coordinate, of the torsional
/// coefficient `gamma`, and of any wrench component (given, or generated from contacts).
pub const MAX_COORDINATE: f64 = 1e12;
