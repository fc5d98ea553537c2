//! The point of a convex hull nearest the origin, by Wolfe's algorithm (1976): keep a
//! small "corral" of affinely independent points and their convex weights; add the
//! point that most decreases the norm; when the affine minimiser of the corral leaves
//! its simplex, step back to the simplex boundary and drop points. It is exact up to
//! rounding once the corral is right, and needs one pass over the points per step.

use nalgebra::SVector;

/// Relative optimality gap at which the search stops: `x.x - min_j x.p_j` below this
/// times `|x|` times the largest norm `M`. Since the distance `d` satisfies
/// `d >= min_j x.p_j / |x|`, the reported `|x|` is then within `GAP_TOLERANCE * M` of
/// `d`, however small `d` is relative to `M`. (A gap relative to `M^2` alone, as
/// before, only resolved distances down to `sqrt(tolerance) * M`: with points
/// `+-1e8 e_x, +-e_y` it stopped at `e_y` and reported distance 1 for a hull that
/// contains the origin.) The gap is computed with a rounding error of a few `eps |x| M`,
/// well below this.
const GAP_TOLERANCE: f64 = 1e-14;
/// A step that shortens `|x|^2` by less than this fraction is no progress: the search
/// stops there (the gap test alone would let rounding cycle the corral for hundreds of
/// steps on some grasps).
const STALL: f64 = 1e-12;
/// Weights below this (relative) are treated as zero.
const WEIGHT_TOLERANCE: f64 = 1e-13;
/// Major iterations at most (the algorithm is finite; this is a guard against cycling
/// in floating point).
const MAX_ITERATIONS: usize = 10_000;

/// The minimum-norm point of a hull and how it is written as a convex combination.
#[derive(Debug, Clone, PartialEq)]
pub struct MinNormPoint<const D: usize> {
    /// The nearest point of the hull to the origin.
    pub point: SVector<f64, D>,
    /// Its norm: the distance from the origin to the hull.
    pub distance: f64,
    /// The corral: indices of the points with positive weight, and their weights.
    pub support: Vec<(usize, f64)>,
}

/// The point of `conv(points)` nearest the origin. `points` must not be empty.
pub fn min_norm_point<const D: usize>(points: &[SVector<f64, D>]) -> MinNormPoint<D> {
    if points.is_empty() {
        return MinNormPoint {
            point: SVector::zeros(),
            distance: f64::INFINITY,
            support: Vec::new(),
        };
    }
    let max_sq = points.iter().fold(0.0f64, |m, p| m.max(p.norm_squared()));
    // Absolute accuracy of the distance.
    let accuracy = GAP_TOLERANCE * max_sq.sqrt().max(f64::MIN_POSITIVE);

    let start = (0..points.len())
        .min_by(|&a, &b| {
            points[a]
                .norm_squared()
                .total_cmp(&points[b].norm_squared())
        })
        .unwrap_or(0);
    let mut corral: Vec<usize> = vec![start];
    let mut weights: Vec<f64> = vec![1.0];
    let mut x = points[start];

    let mut previous = f64::INFINITY;
    for _ in 0..MAX_ITERATIONS {
        let xx = x.norm_squared();
        let norm = xx.sqrt();
        // Stop at the answer, or when a step no longer shortens x: near the optimum,
        // rounding can make the corral cycle with no real progress.
        if norm <= accuracy || xx >= previous * (1.0 - STALL) {
            break;
        }
        previous = xx;
        let (j, xp) = lowest_along(points, &x, xx);
        if xx - xp <= accuracy * norm || corral.contains(&j) || corral.len() > D {
            break;
        }
        corral.push(j);
        weights.push(0.0);
        minor_cycle(points, &mut corral, &mut weights);
        if corral.is_empty() {
            corral.push(j);
            weights.push(1.0);
        }
        x = combination(points, &corral, &weights);
    }
    MinNormPoint {
        distance: x.norm(),
        point: x,
        support: corral.into_iter().zip(weights).collect(),
    }
}

/// The point with the smallest `x.p` (the one that most decreases the norm) and that
/// product (`(0, xx)` for no points).
fn lowest_along<const D: usize>(
    points: &[SVector<f64, D>],
    x: &SVector<f64, D>,
    xx: f64,
) -> (usize, f64) {
    points
        .iter()
        .enumerate()
        .map(|(i, p)| (i, x.dot(p)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((0, xx))
}

/// The point of the corral with its weights.
fn combination<const D: usize>(
    points: &[SVector<f64, D>],
    corral: &[usize],
    weights: &[f64],
) -> SVector<f64, D> {
    corral
        .iter()
        .zip(weights)
        .map(|(&i, &w)| points[i] * w)
        .sum()
}

/// The minor cycle: moves the corral's weights to its affine minimiser, stepping back to
/// the simplex boundary (and dropping the points whose weight vanished) while the
/// minimiser lies outside. A numerically dependent corral loses its newest point instead.
/// The corral may end up empty.
fn minor_cycle<const D: usize>(
    points: &[SVector<f64, D>],
    corral: &mut Vec<usize>,
    weights: &mut Vec<f64>,
) {
    loop {
        let Some(alpha) = affine_min_norm_weights(points, corral) else {
            // Numerically dependent corral: drop the newest point and stop here.
            corral.pop();
            weights.pop();
            return;
        };
        if alpha.iter().all(|&a| a > WEIGHT_TOLERANCE) {
            *weights = alpha;
            return;
        }
        step_back(weights, &alpha);
        drop_vanished(corral, weights);
        if corral.is_empty() {
            return;
        }
        let sum: f64 = weights.iter().sum();
        weights.iter_mut().for_each(|w| *w /= sum);
    }
}

/// Moves `weights` toward `alpha` as far as the simplex allows (to the first weight that
/// reaches zero).
fn step_back(weights: &mut [f64], alpha: &[f64]) {
    let mut theta = 1.0f64;
    for (l, a) in weights.iter().zip(alpha) {
        if *a <= WEIGHT_TOLERANCE && l - a > 0.0 {
            theta = theta.min(l / (l - a));
        }
    }
    for (l, a) in weights.iter_mut().zip(alpha) {
        *l = (1.0 - theta) * *l + theta * a;
    }
}

/// Drops the points whose weight vanished (at least the one that set the step).
fn drop_vanished(corral: &mut Vec<usize>, weights: &mut Vec<f64>) {
    let min_w = weights.iter().copied().fold(f64::INFINITY, f64::min);
    let mut k = 0;
    while k < corral.len() {
        if weights[k] <= WEIGHT_TOLERANCE || weights[k] == min_w {
            corral.swap_remove(k);
            weights.swap_remove(k);
        } else {
            k += 1;
        }
    }
}

/// Weights `alpha` (summing to 1) of the point of the affine hull of `corral` nearest
/// the origin, by least squares on the edge vectors with modified Gram-Schmidt.
/// `None` when the corral is affinely dependent to rounding.
fn affine_min_norm_weights<const D: usize>(
    points: &[SVector<f64, D>],
    corral: &[usize],
) -> Option<Vec<f64>> {
    let s0 = points[corral[0]];
    let k = corral.len() - 1;
    if k == 0 {
        return Some(vec![1.0]);
    }
    // QR of B = [s_i - s_0] (D x k) by twice-applied Gram-Schmidt.
    let mut q: Vec<SVector<f64, D>> = Vec::with_capacity(k);
    let mut r = vec![0.0f64; k * k]; // r[row * k + col]
    for col in 0..k {
        let b = points[corral[col + 1]] - s0;
        let mut v = b;
        for _ in 0..2 {
            for (row, qi) in q.iter().enumerate() {
                let c = qi.dot(&v);
                r[row * k + col] += c;
                v -= qi * c;
            }
        }
        let norm = v.norm();
        if norm <= 1e-14 * b.norm().max(s0.norm()).max(f64::MIN_POSITIVE) {
            return None;
        }
        r[col * k + col] = norm;
        q.push(v / norm);
    }
    // Solve R beta = Q^T (-s0).
    let rhs: Vec<f64> = q.iter().map(|qi| -qi.dot(&s0)).collect();
    let mut beta = vec![0.0f64; k];
    for row in (0..k).rev() {
        let mut acc = rhs[row];
        for col in row + 1..k {
            acc -= r[row * k + col] * beta[col];
        }
        beta[row] = acc / r[row * k + row];
    }
    let mut alpha = Vec::with_capacity(k + 1);
    alpha.push(1.0 - beta.iter().sum::<f64>());
    alpha.extend(beta);
    Some(alpha)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn distance_to_a_segment_and_a_triangle() {
        let seg = [Vector2::new(-1.0, 1.0), Vector2::new(3.0, 1.0)];
        let m = min_norm_point(&seg);
        assert!((m.distance - 1.0).abs() < 1e-15);
        assert!((m.point - Vector2::new(0.0, 1.0)).norm() < 1e-15);
        let tri = [
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::new(0.0, 0.0, 1.0),
        ];
        let m = min_norm_point(&tri);
        assert!((m.distance - 1.0 / 3.0f64.sqrt()).abs() < 1e-15);
        assert_eq!(m.support.len(), 3);
    }

    #[test]
    fn origin_inside_gives_zero() {
        let pts = [
            Vector2::new(1.0, 0.1),
            Vector2::new(-1.0, 0.5),
            Vector2::new(0.2, -2.0),
            Vector2::new(5.0, 5.0),
        ];
        assert!(min_norm_point(&pts).distance < 1e-14);
    }

    #[test]
    fn nearest_vertex_and_duplicates() {
        let pts = [
            Vector2::new(2.0, 2.0),
            Vector2::new(3.0, 1.0),
            Vector2::new(2.0, 2.0),
            Vector2::new(4.0, 4.0),
        ];
        let m = min_norm_point(&pts);
        // Nearest point lies on the segment (2,2)-(3,1): (2,2) + t(1,-1) with t = 0: the
        // gradient at (2,2) along (1,-1) is 2-2 = 0, so (2,2) itself.
        assert!((m.distance - 8.0f64.sqrt()).abs() < 1e-14);
    }

    #[test]
    fn small_features_of_a_large_set_are_resolved() {
        // The hull of +-s e_x, +-e_y contains the origin at every scale s; the old
        // stopping rule (gap relative to the largest squared norm) stopped at e_y and
        // reported distance 1 from s = 1e8 on.
        for s in [1.0, 1e6, 1e8, 1e10, 1e12] {
            let pts = [
                Vector2::new(0.0, 1.0),
                Vector2::new(s, 0.0),
                Vector2::new(-s, 0.0),
                Vector2::new(0.0, -1.0),
            ];
            assert!(min_norm_point(&pts).distance < 1e-13 * s, "scale {s}");
            // Shifted by 0.5 along y: the hull's nearest point is (0, -0.5).
            let shifted = pts.map(|p| p + Vector2::new(0.0, 1.5));
            let d = min_norm_point(&shifted).distance;
            assert!((d - 0.5).abs() < 1e-13 * s, "scale {s}: {d}");
        }
    }
}
