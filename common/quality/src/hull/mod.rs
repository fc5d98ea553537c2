//! Convex-hull queries on point sets in R^D (D = 6 for wrenches), without any external
//! hull library.
//!
//! - [`affine`]: affine rank and a well-spread maximal affinely independent subset.
//! - [`min_norm`]: the point of the hull nearest the origin (Wolfe's algorithm), exact
//!   to rounding; the default distance solver.
//! - [`qp`]: the same distance as a second-order cone program solved by Clarabel, kept
//!   as the reference solver.
//! - [`polytope`]: a simplicial polytope grown one point at a time (beneath-beyond),
//!   shared by the two algorithms below; [`ridges`] matches its new facets along their
//!   shared ridges.
//! - [`epa`]: the expanding-polytope algorithm: the distance from an interior origin to
//!   the hull boundary (Largest Sphere), growing only the facets nearest the origin.
//! - [`quickhull`]: the full hull, for its volume and facets.
//!
//! Points are `nalgebra::SVector<f64, D>`; tolerances scale with the largest coordinate.

pub mod affine;
pub mod epa;
pub mod min_norm;
pub mod polytope;
pub mod qp;
pub mod quickhull;
pub mod ridges;

use nalgebra::SVector;

/// The largest absolute coordinate of a point set (at least `f64::MIN_POSITIVE`), the
/// length unit of every tolerance.
pub fn coordinate_scale<const D: usize>(points: &[SVector<f64, D>]) -> f64 {
    points
        .iter()
        .flat_map(|p| p.iter())
        .fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()))
}
