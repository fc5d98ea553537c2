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

/// The power of two nearest `scale` (1 for a zero, subnormal or non-finite scale, or
/// one whose power of two is not representable). Data divided by it before a solver
/// with absolute tolerances is scaled exactly, so the result does not depend on units.
pub fn power_of_two_scale(scale: f64) -> f64 {
    if !scale.is_finite() || scale < f64::MIN_POSITIVE {
        return 1.0;
    }
    let exponent = scale.log2().round();
    if !(-1021.0..=1022.0).contains(&exponent) {
        return 1.0;
    }
    // In range, so the exponent is a small integer and 2^exponent is exact.
    2f64.powi(exponent as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_of_two_scale_rounds_to_a_power_of_two() {
        assert_eq!(power_of_two_scale(3.0), 4.0);
        assert_eq!(power_of_two_scale(0.7), 0.5);
        assert_eq!(power_of_two_scale(0.0), 1.0);
        assert_eq!(power_of_two_scale(f64::INFINITY), 1.0);
    }
}
