//! The full convex hull by Quickhull (each facet keeps the points beyond it; the
//! farthest is added next), for the hull volume (Grasp Wrench Volume) and facet
//! listings. Exponentially many facets can arise in 6D for large, rounded point sets:
//! use [`super::epa`] when only the inscribed radius is needed.
//!
//! Robustness: points within a tolerance of a facet's hyperplane count as on it, the
//! finished hull is checked for convexity against every input point, and if the exact
//! points defeat the construction (near-coplanar contact grids can), the hull of a copy
//! moved by a tiny seeded joggle is built instead and the joggle is reported.
//!
//! Memory: a hull that would need more than [`FACET_LIMIT`] facets is refused
//! ([`HullError::TooManyFacets`]) rather than allowed to exhaust memory.

use nalgebra::SVector;

use super::affine::affine_basis;
use super::coordinate_scale;
pub use super::polytope::FACET_LIMIT;
use super::polytope::{FacetId, Polytope, PolytopeError};

/// Visibility tolerance (relative to the coordinate scale). Points nearer a facet's
/// hyperplane than this count as on it. Much smaller values let near-coplanar input
/// create slivers with ill-conditioned normals.
const VISIBILITY_TOLERANCE: f64 = 1e-10;
/// How far (relative) an input point may lie beyond a facet of the finished hull.
const CONVEXITY_TOLERANCE: f64 = 1e-8;
/// Relative joggles tried, in order, when the hull of the exact points fails. The
/// largest moves points by a ten-thousandth of the coordinate scale: a last resort,
/// reported by [`Hull::joggle`], preferable to no answer (Qhull's `QJ` goes further, to a
/// hundredth). Dense surface-model and patch wrenches of a full-rank grasp (the star
/// prism's edges under barrett_ft's fingertips) defeated every joggle up to 1e-6 and
/// need 1e-5 or 1e-4: their volume was unavailable.
pub const JOGGLES: [f64; 7] = [1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4];

/// Why a hull could not be built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HullError {
    /// The points span fewer than D dimensions (the hull has no interior).
    LowerDimensional { rank: usize },
    /// Floating-point degeneracy that neither the exact nor the joggled points overcame.
    Degenerate,
    /// The hull needs more than [`FACET_LIMIT`] facets.
    TooManyFacets,
}

impl From<PolytopeError> for HullError {
    fn from(e: PolytopeError) -> Self {
        match e {
            PolytopeError::Degenerate => HullError::Degenerate,
            PolytopeError::TooManyFacets => HullError::TooManyFacets,
        }
    }
}

/// The convex hull of a full-dimensional point set: its facets and volume.
#[derive(Debug, Clone)]
pub struct Hull<const D: usize> {
    facets: Vec<(SVector<f64, D>, f64)>,
    volume: f64,
    added: usize,
    joggle: f64,
}

impl<const D: usize> Hull<D> {
    /// Builds the hull of `points`.
    pub fn new(points: &[SVector<f64, D>]) -> Result<Self, HullError> {
        let basis = affine_basis(points);
        if basis.rank < D {
            return Err(HullError::LowerDimensional { rank: basis.rank });
        }
        // Joggling does not reduce the facet count: too many facets is final.
        match construct(points, &basis.indices, 0.0) {
            Ok(hull) => return Ok(hull),
            Err(HullError::TooManyFacets) => return Err(HullError::TooManyFacets),
            Err(_) => {}
        }
        for joggle in JOGGLES {
            let moved = joggled(points, joggle);
            match construct(&moved, &basis.indices, joggle) {
                Ok(hull) => return Ok(hull),
                Err(HullError::TooManyFacets) => return Err(HullError::TooManyFacets),
                Err(_) => {}
            }
        }
        Err(HullError::Degenerate)
    }

    /// The D-volume of the hull.
    pub fn volume(&self) -> f64 {
        self.volume
    }

    /// The number of (simplicial) facets.
    pub fn facet_count(&self) -> usize {
        self.facets.len()
    }

    /// The facets as (outward unit normal, offset) pairs: `normal . x <= offset` inside.
    pub fn facets(&self) -> impl Iterator<Item = (SVector<f64, D>, f64)> + '_ {
        self.facets.iter().copied()
    }

    /// The smallest facet offset: the inscribed radius about the origin when the origin
    /// is inside, negative when it is outside.
    pub fn min_offset(&self) -> f64 {
        self.facets
            .iter()
            .map(|f| f.1)
            .fold(f64::INFINITY, f64::min)
    }

    /// Points added after the initial simplex.
    pub fn added(&self) -> usize {
        self.added
    }

    /// The relative joggle the points needed (0 when the exact points were used).
    pub fn joggle(&self) -> f64 {
        self.joggle
    }
}

/// A copy of `points` with each coordinate moved by at most `joggle` times the
/// coordinate scale, by a fixed-seed generator (the same result on every run).
pub fn joggled<const D: usize>(points: &[SVector<f64, D>], joggle: f64) -> Vec<SVector<f64, D>> {
    let scale = coordinate_scale(points);
    let mut rng = SplitMix(0x9e37_79b9_7f4a_7c15);
    points
        .iter()
        .map(|p| p.map(|x| x + joggle * scale * rng.symmetric()))
        .collect()
}

/// The hull of `points` grown from the initial `simplex` (indices into `points`), the
/// points moved by `joggle` already: each point outside a facet is assigned to the first
/// such facet, and the farthest point of a facet's outside set is added until none is
/// left (quickhull); the result is checked for convexity.
fn construct<const D: usize>(
    points: &[SVector<f64, D>],
    simplex: &[usize],
    joggle: f64,
) -> Result<Hull<D>, HullError> {
    let scale = coordinate_scale(points);
    let eps = VISIBILITY_TOLERANCE * scale;
    let mut poly = Polytope::simplex(points, simplex, eps)?;
    let mut outside = initial_outside(&poly, simplex, eps);
    let mut stack: Vec<FacetId> = (0..outside.len() as FacetId)
        .filter(|&f| !outside[f as usize].is_empty())
        .collect();
    let mut added = 0;
    let mut orphans: Vec<u32> = Vec::new();
    while let Some(f) = stack.pop() {
        let fi = f as usize;
        if !poly.facets[fi].alive || outside[fi].is_empty() {
            continue;
        }
        let apex = farthest(&poly, f, &outside[fi])?;
        let new = poly.add_point(apex as usize, f)?;
        added += 1;
        orphans.clear();
        for &v in poly.last_visible() {
            orphans.append(&mut outside[v as usize]);
        }
        outside.resize_with(poly.facets.len(), Vec::new);
        for &q in &orphans {
            if q == apex {
                continue;
            }
            let p = &points[q as usize];
            if let Some(g) = new
                .clone()
                .find(|&g| poly.facets[g as usize].distance(p) > eps)
            {
                outside[g as usize].push(q);
            }
        }
        stack.extend(new.filter(|&g| !outside[g as usize].is_empty()));
    }
    let facets = convex_facets(&poly, CONVEXITY_TOLERANCE * scale)?;
    Ok(Hull {
        volume: poly.volume(),
        facets,
        added,
        joggle,
    })
}

/// The outside sets of the initial simplex's facets: each point not in `simplex` that is
/// beyond a facet (by more than `eps`), in the first such facet's set.
fn initial_outside<const D: usize>(
    poly: &Polytope<'_, D>,
    simplex: &[usize],
    eps: f64,
) -> Vec<Vec<u32>> {
    let mut outside: Vec<Vec<u32>> = vec![Vec::new(); poly.facets.len()];
    for (i, p) in poly.points.iter().enumerate() {
        if simplex.contains(&i) {
            continue;
        }
        if let Some(f) = poly
            .live_facets()
            .find(|&f| poly.facets[f as usize].distance(p) > eps)
        {
            outside[f as usize].push(i as u32);
        }
    }
    outside
}

/// The point of `candidates` (a facet's outside set) farthest beyond facet `f`.
fn farthest<const D: usize>(
    poly: &Polytope<'_, D>,
    f: FacetId,
    candidates: &[u32],
) -> Result<u32, HullError> {
    let facet = &poly.facets[f as usize];
    candidates
        .iter()
        .copied()
        .max_by(|&a, &b| {
            facet
                .distance(&poly.points[a as usize])
                .total_cmp(&facet.distance(&poly.points[b as usize]))
        })
        .ok_or(HullError::Degenerate)
}

/// The live facets' planes, checked for convexity: no point of the polytope may lie
/// beyond a facet by more than `limit`.
fn convex_facets<const D: usize>(
    poly: &Polytope<'_, D>,
    limit: f64,
) -> Result<Vec<(SVector<f64, D>, f64)>, HullError> {
    let facets: Vec<(SVector<f64, D>, f64)> = poly
        .live_facets()
        .map(|f| {
            (
                poly.facets[f as usize].normal,
                poly.facets[f as usize].offset,
            )
        })
        .collect();
    for (n, b) in &facets {
        if poly.points.iter().any(|p| n.dot(p) - b > limit) {
            return Err(HullError::Degenerate);
        }
    }
    Ok(facets)
}

/// A tiny deterministic generator for the joggle (no dependency, same result on every
/// machine).
struct SplitMix(u64);

impl SplitMix {
    /// Uniform in [-1, 1).
    fn symmetric(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn cube_with_interior_and_duplicate_points() {
        let mut pts = Vec::new();
        for i in 0..8 {
            let c = |b: i32| if i & b != 0 { 1.0 } else { -1.0 };
            pts.push(Vector3::new(c(1), c(2), c(4)));
        }
        pts.push(Vector3::new(0.1, 0.2, -0.3));
        pts.push(pts[3]);
        pts.push(Vector3::new(1.0, 0.0, 0.0)); // on a face
        let hull = Hull::new(&pts).unwrap();
        assert!((hull.volume() - 8.0).abs() < 1e-12);
        assert!((hull.min_offset() - 1.0).abs() < 1e-12);
        assert_eq!(hull.joggle(), 0.0);
        assert!(hull.facets().all(|(n, _)| (n.norm() - 1.0).abs() < 1e-12));
    }

    #[test]
    fn points_on_a_sphere_approach_its_volume() {
        // Deterministic spiral points on the unit sphere.
        let n = 400;
        let pts: Vec<Vector3<f64>> = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let phi = i as f64 * 2.399963229728653;
                Vector3::new(r * phi.cos(), r * phi.sin(), z)
            })
            .collect();
        let hull = Hull::new(&pts).unwrap();
        let v = hull.volume();
        let ball = 4.0 / 3.0 * std::f64::consts::PI;
        assert!(v < ball && v > 0.97 * ball, "volume {v}");
        // Every point is a vertex: Euler's formula for a triangulated sphere: F = 2V - 4.
        assert_eq!(hull.facet_count(), 2 * n - 4);
    }

    #[test]
    fn flat_sets_are_lower_dimensional() {
        let flat = [
            Vector3::new(0.0, 0.0, 1.0),
            Vector3::new(1.0, 0.0, 1.0),
            Vector3::new(0.0, 1.0, 1.0),
        ];
        assert!(matches!(
            Hull::new(&flat),
            Err(HullError::LowerDimensional { rank: 2 })
        ));
    }

    #[test]
    fn joggle_values_are_symmetric_and_bounded() {
        let mut rng = SplitMix(1);
        let xs: Vec<f64> = (0..10_000).map(|_| rng.symmetric()).collect();
        assert!(xs.iter().all(|x| (-1.0..1.0).contains(x)));
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        assert!(mean.abs() < 0.03, "{mean}");
    }
}
