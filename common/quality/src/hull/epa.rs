//! The expanding-polytope algorithm for the Largest Sphere (epsilon) metric: the
//! distance from the origin to the boundary of `conv(points)` when the origin is inside.
//!
//! Start from a simplex of input points; repeatedly take the facet of the current
//! polytope nearest the origin and ask for the input point farthest along its normal
//! (the support point). If no point lies beyond that facet, the facet belongs to the
//! true hull, and as the current polytope is inside the hull, no hull facet is nearer:
//! its offset is the answer. Otherwise add the support point and repeat. Only facets
//! nearer than the answer are ever refined, so the cost grows with the part of the hull
//! near the inscribed ball, not with the full facet count (which explodes for surface
//! patches).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use nalgebra::SVector;

use super::affine::{AffineBasis, affine_basis};
use super::coordinate_scale;
use super::polytope::{FacetId, Polytope, PolytopeError};
use super::quickhull;

/// Relative tolerance (times the coordinate scale) at which a support point no longer
/// counts as beyond a facet.
const SUPPORT_TOLERANCE: f64 = 1e-10;
/// Visibility tolerance of the polytope (relative); at most the support tolerance, so
/// the facet that asked for a point always sees it.
const VISIBILITY_TOLERANCE: f64 = 1e-10;

/// Outcome of the expanding-polytope search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InnerDistance {
    /// The signed distance from the origin to the nearest facet hyperplane of the hull:
    /// positive when the origin is inside, zero or negative otherwise.
    pub offset: f64,
    /// Points added to the initial simplex.
    pub iterations: usize,
}

/// The signed distance from the origin to the nearest facet of `conv(points)`, for a
/// full-dimensional set (affine rank D); `None` when the set is lower-dimensional.
///
/// The value is exact for an origin inside the hull (the Largest Sphere radius). For an
/// origin outside it is only a certificate (negative), not the distance to the hull.
pub fn inner_distance<const D: usize>(points: &[SVector<f64, D>]) -> Option<InnerDistance> {
    inner_distance_with_basis(points, &affine_basis(points))
}

/// As [`inner_distance`], with the affine basis of `points` already computed; `None`
/// also when no polytope could be grown (see [`try_inner_distance_with_basis`]).
pub fn inner_distance_with_basis<const D: usize>(
    points: &[SVector<f64, D>],
    basis: &AffineBasis,
) -> Option<InnerDistance> {
    try_inner_distance_with_basis(points, basis).ok().flatten()
}

/// The largest relative joggle the expanding polytope tries before the full hull.
const MAX_JOGGLE: f64 = 1e-6;

/// As [`inner_distance_with_basis`], but a search that would need more than
/// [`quickhull::FACET_LIMIT`] facets is an error rather than `None`. Degenerate
/// geometry that neither the joggled points nor the full hull overcome is still `None`.
pub fn try_inner_distance_with_basis<const D: usize>(
    points: &[SVector<f64, D>],
    basis: &AffineBasis,
) -> Result<Option<InnerDistance>, quickhull::HullError> {
    if basis.rank < D {
        return Ok(None);
    }
    let scale = coordinate_scale(points);
    match expand(points, &basis.indices, scale) {
        Ok(r) => return Ok(Some(r)),
        Err(PolytopeError::TooManyFacets) => return Err(quickhull::HullError::TooManyFacets),
        Err(PolytopeError::Degenerate) => {}
    }
    // Floating-point degeneracy (near-coplanar contact grids): retry on slightly
    // joggled copies (at most `MAX_JOGGLE`: the radius keeps its accuracy), then fall
    // back to the full hull, which has its own recovery, with larger joggles.
    for joggle in quickhull::JOGGLES.into_iter().filter(|&j| j <= MAX_JOGGLE) {
        match expand(&quickhull::joggled(points, joggle), &basis.indices, scale) {
            Ok(r) => return Ok(Some(r)),
            Err(PolytopeError::TooManyFacets) => {
                return Err(quickhull::HullError::TooManyFacets);
            }
            Err(PolytopeError::Degenerate) => {}
        }
    }
    match quickhull::Hull::new(points) {
        Ok(h) => Ok(Some(InnerDistance {
            offset: h.min_offset(),
            iterations: h.added(),
        })),
        Err(quickhull::HullError::TooManyFacets) => Err(quickhull::HullError::TooManyFacets),
        Err(_) => Ok(None),
    }
}

#[derive(PartialEq, PartialOrd)]
struct Key(f64);
impl Eq for Key {}
#[allow(clippy::derive_ord_xor_partial_ord)]
impl Ord for Key {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

fn expand<const D: usize>(
    points: &[SVector<f64, D>],
    simplex: &[usize],
    scale: f64,
) -> Result<InnerDistance, PolytopeError> {
    let mut poly = Polytope::simplex(points, simplex, VISIBILITY_TOLERANCE * scale)?;
    let tolerance = SUPPORT_TOLERANCE * scale;
    let mut heap: BinaryHeap<Reverse<(Key, FacetId)>> = poly
        .live_facets()
        .map(|f| Reverse((Key(poly.facets[f as usize].offset), f)))
        .collect();
    let mut iterations = 0;
    // The least support value seen. The inscribed radius is at most the support value
    // along any unit direction, so while that bound is positive a facet farther than it
    // is never the answer and is not queued. (A polytope that does not contain the
    // origin has a facet at offset <= 0, which stays queued, so the result is then
    // still a non-positive certificate. A bound <= 0 prunes nothing.)
    let mut upper = f64::INFINITY;
    let mut used = vec![false; points.len()];
    for &i in simplex {
        used[i] = true;
    }
    while let Some(Reverse((Key(offset), f))) = heap.pop() {
        let facet = &poly.facets[f as usize];
        if !facet.alive {
            continue;
        }
        let normal = facet.normal;
        let (best, height) = points
            .iter()
            .enumerate()
            .map(|(i, p)| (i, normal.dot(p)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .ok_or(PolytopeError::Degenerate)?;
        if height - offset <= tolerance {
            return Ok(InnerDistance { offset, iterations });
        }
        upper = upper.min(height);
        // A point is added at most once; asked for again, the polytope has gone
        // non-convex in rounding: give up on it (the caller falls back to the full hull).
        if std::mem::replace(&mut used[best], true) {
            return Err(PolytopeError::Degenerate);
        }
        let new = poly.add_point(best, f)?;
        iterations += 1;
        for g in new {
            let offset = poly.facets[g as usize].offset;
            if upper <= 0.0 || offset <= upper + tolerance {
                heap.push(Reverse((Key(offset), g)));
            }
        }
    }
    Err(PolytopeError::Degenerate)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn square_and_cube_inradius() {
        let square: Vec<Vector2<f64>> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|&(x, y)| Vector2::new(x, y))
            .collect();
        let r = inner_distance(&square).unwrap();
        assert!((r.offset - 1.0).abs() < 1e-12);
        let mut cube = Vec::new();
        for i in 0..8 {
            let c = |b: i32| if i & b != 0 { 1.0 } else { -1.0 };
            cube.push(Vector3::new(c(1) + 0.5, c(2), c(4)));
        }
        // Shifted by 0.5 along x: the nearest facet, x = -0.5, is at distance 0.5.
        let r = inner_distance(&cube).unwrap();
        assert!((r.offset - 0.5).abs() < 1e-12);
    }

    #[test]
    fn six_dimensional_cross_polytope_and_cube() {
        let mut cross = Vec::new();
        for i in 0..6 {
            for s in [1.0, -1.0] {
                let mut p = SVector::<f64, 6>::zeros();
                p[i] = s;
                cross.push(p);
            }
        }
        let r = inner_distance(&cross).unwrap();
        assert!((r.offset - 1.0 / 6.0f64.sqrt()).abs() < 1e-12, "{r:?}");
        // 64 vertices, 32 on each facet: heavily coplanar.
        let cube: Vec<SVector<f64, 6>> = (0..64u32)
            .map(|i| SVector::from_fn(|k, _| if i >> k & 1 == 1 { 1.0 } else { -1.0 }))
            .collect();
        let r = inner_distance(&cube).unwrap();
        assert!((r.offset - 1.0).abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn agrees_with_the_full_hull_on_random_sets() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x9e37_79b9_7f4a_7c15);
        for (n, grid) in [(20, 0.0), (48, 0.0), (48, 0.25), (120, 0.0), (200, 0.5)] {
            for _ in 0..5 {
                // Points in a box around the origin; with a grid, rounded to it, which
                // makes many of them coplanar.
                let points: Vec<SVector<f64, 6>> = (0..n)
                    .map(|_| {
                        SVector::from_fn(|_, _| {
                            let x: f64 = rng.random_range(-1.0..1.0) + 0.1;
                            if grid > 0.0 {
                                (x / grid).round() * grid
                            } else {
                                x
                            }
                        })
                    })
                    .collect();
                let hull = quickhull::Hull::new(&points).unwrap();
                let r = inner_distance(&points).unwrap();
                assert!(
                    (r.offset - hull.min_offset()).abs() < 1e-9,
                    "n {n} grid {grid}: {r:?} vs {}",
                    hull.min_offset()
                );
            }
        }
    }

    #[test]
    fn origin_outside_random_sets_give_non_positive_certificates() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x2545_f491_4f6c_dd1d);
        for shift in [0.6, 1.0, 3.0] {
            let points: Vec<SVector<f64, 6>> = (0..48)
                .map(|_| {
                    SVector::from_fn(|k, _| {
                        rng.random_range(-0.5..0.5) + if k == 0 { shift } else { 0.0 }
                    })
                })
                .collect();
            let r = inner_distance(&points).unwrap();
            assert!(r.offset <= 1e-12, "shift {shift}: {r:?}");
        }
    }

    #[test]
    fn origin_outside_gives_a_negative_certificate() {
        let tri = [
            Vector2::new(1.0, 0.0),
            Vector2::new(2.0, 0.0),
            Vector2::new(1.0, 1.0),
        ];
        assert!(inner_distance(&tri).unwrap().offset < 0.0);
        let flat = [
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::new(0.0, 0.0, 0.0),
        ];
        assert_eq!(inner_distance(&flat), None);
    }
}
