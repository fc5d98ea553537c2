//! The distance from the origin to `conv(W)` as a conic program solved by Clarabel
//! (thesis eq. 2.19, solved there with cvxopt):
//!
//! minimise `t` over `(t, y, lambda)` subject to `y = W lambda`, `sum(lambda) = 1`,
//! `lambda >= 0`, `||y|| <= t`.
//!
//! The second-order cone makes `t` the distance itself rather than its square, so the
//! solver's tolerance applies to the distance directly. Kept as the reference for the
//! faster [`super::min_norm`] solver.
//!
//! The solver's tolerances are absolute, so the wrenches are first scaled by a power of
//! two (exact in floating point) that brings their largest coordinate near 1, and the
//! distance is scaled back: the result does not depend on the units of the input.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

use super::{coordinate_scale, power_of_two_scale};
use crate::error::QualityError;
use crate::wrench::Wrench;

/// Solver tolerance (gap and feasibility).
const TOLERANCE: f64 = 1e-10;

/// The distance from the origin to the hull of `w`, by Clarabel.
pub fn distance_to_hull(w: &[Wrench]) -> Result<f64, QualityError> {
    if w.is_empty() {
        return Err(QualityError::Empty("wrenches"));
    }
    let unit = power_of_two_scale(coordinate_scale(w));
    if unit == 1.0 {
        return solve(w);
    }
    let scaled: Vec<Wrench> = w.iter().map(|x| x / unit).collect();
    Ok(solve(&scaled)? * unit)
}

/// [`distance_to_hull`] without the scaling.
fn solve(w: &[Wrench]) -> Result<f64, QualityError> {
    let m = w.len();
    let n = 7 + m; // t, y (6), lambda (m)
    let lambda = |j: usize| 7 + j;
    let (mut rows, mut cols, mut vals) = (Vec::new(), Vec::new(), Vec::new());
    let mut push = |r: usize, c: usize, v: f64| {
        rows.push(r);
        cols.push(c);
        vals.push(v);
    };
    // Zero cone: y - W lambda = 0 (rows 0..6), sum(lambda) = 1 (row 6).
    for i in 0..6 {
        push(i, 1 + i, 1.0);
        for (j, wj) in w.iter().enumerate() {
            if wj[i] != 0.0 {
                push(i, lambda(j), -wj[i]);
            }
        }
    }
    for j in 0..m {
        push(6, lambda(j), 1.0);
    }
    // Nonnegative cone: s = lambda >= 0.
    for j in 0..m {
        push(7 + j, lambda(j), -1.0);
    }
    // Second-order cone: s = (t, y).
    let soc = 7 + m;
    for k in 0..7 {
        push(soc + k, k, -1.0);
    }
    let a = CscMatrix::new_from_triplets(soc + 7, n, rows, cols, vals);
    let mut b = vec![0.0; soc + 7];
    b[6] = 1.0;
    let p = CscMatrix::zeros((n, n));
    let mut q = vec![0.0; n];
    q[0] = 1.0;
    let cones = [
        SupportedConeT::ZeroConeT(7),
        SupportedConeT::NonnegativeConeT(m),
        SupportedConeT::SecondOrderConeT(7),
    ];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .tol_gap_abs(TOLERANCE)
        .tol_gap_rel(TOLERANCE)
        .tol_feas(TOLERANCE)
        .build()
        .map_err(|e| QualityError::Solver(format!("{e:?}")))?;
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings)
        .map_err(|e| QualityError::Solver(format!("{e:?}")))?;
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {}
        other => {
            return Err(QualityError::Solver(format!(
                "distance to the hull: status {other:?}"
            )));
        }
    }
    // Report the norm of the feasible point nearest to the solver's weights.
    let x = &solver.solution.x;
    let weights: Vec<f64> = (0..m).map(|j| x[lambda(j)].max(0.0)).collect();
    let total: f64 = weights.iter().sum();
    if total.is_nan() || total <= 0.0 {
        return Err(QualityError::Solver(
            "distance to the hull: no convex weights in the solution".into(),
        ));
    }
    let y: Wrench = w.iter().zip(&weights).map(|(wj, l)| wj * (l / total)).sum();
    Ok(y.norm())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_to_a_simplex_face() {
        let w: Vec<Wrench> = (0..6)
            .map(|i| {
                let mut v = Wrench::zeros();
                v[i] = 1.0;
                v
            })
            .collect();
        let d = distance_to_hull(&w).unwrap();
        assert!((d - 1.0 / 6.0f64.sqrt()).abs() < 1e-8, "{d}");
    }

    #[test]
    fn the_distance_does_not_depend_on_the_units() {
        // A segment at distance 1 from the origin, in units from 1e-12 to 1e12: the
        // solver's absolute tolerances used to fail (PrimalInfeasible) or drift here.
        let base = [
            Wrench::new(1.0, -1.0, 0.0, 0.0, 0.0, 0.0),
            Wrench::new(1.0, 1.0, 0.0, 0.0, 0.0, 0.0),
        ];
        for s in [1e-12, 1e-6, 1.0, 1e6, 1e12] {
            let w: Vec<Wrench> = base.iter().map(|x| x * s).collect();
            let d = distance_to_hull(&w).unwrap() / s;
            assert!((d - 1.0).abs() < 1e-8, "scale {s}: {d}");
        }
    }
}
