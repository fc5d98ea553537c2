//! Affine rank of a point set and a maximal affinely independent subset of it, chosen
//! greedily (each new point the farthest from the affine hull of those chosen so far),
//! which also makes a large initial simplex for the hull algorithms.

use nalgebra::SVector;

/// Relative tolerance of the affine rank: a point counts as outside the affine hull of
/// the others when its distance exceeds this times the set's diameter.
pub const RANK_TOLERANCE: f64 = 1e-9;

/// A maximal affinely independent subset: `indices.len() == rank + 1` (empty input:
/// no indices, rank 0).
#[derive(Debug, Clone, PartialEq)]
pub struct AffineBasis {
    pub indices: Vec<usize>,
    pub rank: usize,
}

/// The affine rank of `points` with the default tolerance, and the subset realising it.
pub fn affine_basis<const D: usize>(points: &[SVector<f64, D>]) -> AffineBasis {
    affine_basis_with_tolerance(points, RANK_TOLERANCE)
}

/// As [`affine_basis`], with a relative tolerance of one's own.
pub fn affine_basis_with_tolerance<const D: usize>(
    points: &[SVector<f64, D>],
    relative_tolerance: f64,
) -> AffineBasis {
    let n = points.len();
    if n == 0 {
        return AffineBasis {
            indices: Vec::new(),
            rank: 0,
        };
    }
    let centroid = points.iter().sum::<SVector<f64, D>>() / n as f64;
    let first = argmax(points.iter().map(|p| (p - centroid).norm_squared()));
    let origin = points[first];
    // Residuals of every point against the span of the chosen directions.
    let mut residual: Vec<SVector<f64, D>> = points.iter().map(|p| p - origin).collect();
    let diameter = residual.iter().fold(0.0f64, |m, r| m.max(r.norm()));
    let tolerance = relative_tolerance * diameter;
    let mut indices = vec![first];
    let mut basis: Vec<SVector<f64, D>> = Vec::with_capacity(D);
    while basis.len() < D {
        let best = argmax(residual.iter().map(|r| r.norm_squared()));
        let r = residual[best];
        let norm = r.norm();
        if norm <= tolerance || norm == 0.0 {
            break;
        }
        // Re-orthogonalise against the basis once more for accuracy.
        let mut q = r / norm;
        for b in &basis {
            q -= b * b.dot(&q);
        }
        let qn = q.norm();
        if qn == 0.0 {
            break;
        }
        q /= qn;
        for res in residual.iter_mut() {
            let c = res.dot(&q);
            *res -= q * c;
        }
        basis.push(q);
        indices.push(best);
    }
    AffineBasis {
        rank: basis.len(),
        indices,
    }
}

/// The affine rank of a point set (dimension of its affine hull).
pub fn affine_rank<const D: usize>(points: &[SVector<f64, D>]) -> usize {
    affine_basis(points).rank
}

fn argmax(values: impl Iterator<Item = f64>) -> usize {
    let mut best = 0;
    let mut best_value = f64::NEG_INFINITY;
    for (i, v) in values.enumerate() {
        if v > best_value {
            best = i;
            best_value = v;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn ranks_of_simple_sets() {
        let p = |x, y, z| Vector3::new(x, y, z);
        assert_eq!(affine_rank::<3>(&[]), 0);
        assert_eq!(affine_rank(&[p(1.0, 2.0, 3.0), p(1.0, 2.0, 3.0)]), 0);
        assert_eq!(
            affine_rank(&[p(0.0, 0.0, 0.0), p(1.0, 1.0, 1.0), p(2.0, 2.0, 2.0)]),
            1
        );
        let square = [
            p(0.0, 0.0, 1.0),
            p(1.0, 0.0, 1.0),
            p(0.0, 1.0, 1.0),
            p(1.0, 1.0, 1.0),
        ];
        let b = affine_basis(&square);
        assert_eq!(b.rank, 2);
        assert_eq!(b.indices.len(), 3);
        let mut tetra = square.to_vec();
        tetra.push(p(0.5, 0.5, 3.0));
        assert_eq!(affine_rank(&tetra), 3);
    }

    #[test]
    fn a_tiny_offset_below_tolerance_does_not_count() {
        let p = |x, y, z| Vector3::new(x, y, z);
        let nearly_flat = [
            p(0.0, 0.0, 0.0),
            p(1.0, 0.0, 0.0),
            p(0.0, 1.0, 0.0),
            p(1.0, 1.0, 1e-13),
        ];
        assert_eq!(affine_rank(&nearly_flat), 2);
        let flat_enough = [
            p(0.0, 0.0, 0.0),
            p(1.0, 0.0, 0.0),
            p(0.0, 1.0, 0.0),
            p(1.0, 1.0, 1e-6),
        ];
        assert_eq!(affine_rank(&flat_enough), 3);
    }
}
