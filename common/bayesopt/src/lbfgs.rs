//! A compact projected L-BFGS minimiser for smooth functions on a box (used for the
//! hyperparameter MAP fit and the acquisition polish). Variables at a bound whose gradient
//! points outwards are frozen for the step; steps are projected onto the box and accepted by a
//! backtracking Armijo search. Non-finite objective values are treated as +infinity.

/// Result of a minimisation.
#[derive(Debug, Clone)]
pub struct Minimum {
    /// Best point found.
    pub x: Vec<f64>,
    /// Objective there.
    pub f: f64,
    /// Objective evaluations used.
    pub evals: usize,
}

fn project(x: &mut [f64], lo: &[f64], hi: &[f64]) {
    for ((v, l), h) in x.iter_mut().zip(lo).zip(hi) {
        *v = v.clamp(*l, *h);
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// An objective for [`minimize_problem`], evaluated in two steps so that trial points of the
/// line search that are rejected cost only a value: [`Problem::gradient`] is only called at
/// the point of the immediately preceding [`Problem::value`] call (so it may reuse work
/// cached by it).
pub trait Problem {
    /// Objective at `x` (non-finite: treated as +infinity).
    fn value(&mut self, x: &[f64]) -> f64;
    /// Gradient at `x`, the point of the last [`Problem::value`] call, written into `g`.
    fn gradient(&mut self, x: &[f64], g: &mut [f64]);
}

/// A closure returning the value and writing the gradient, as a [`Problem`].
struct Joint<F> {
    f: F,
    g: Vec<f64>,
}

impl<F: FnMut(&[f64], &mut [f64]) -> f64> Problem for Joint<F> {
    fn value(&mut self, x: &[f64]) -> f64 {
        (self.f)(x, &mut self.g)
    }
    fn gradient(&mut self, _x: &[f64], g: &mut [f64]) {
        g.copy_from_slice(&self.g);
    }
}

/// Minimise `f` (which returns the value and writes the gradient) over `[lo, hi]` from `x0`.
pub fn minimize_box<F>(
    f: F,
    x0: &[f64],
    lo: &[f64],
    hi: &[f64],
    max_iter: usize,
    gtol: f64,
) -> Minimum
where
    F: FnMut(&[f64], &mut [f64]) -> f64,
{
    let mut p = Joint {
        f,
        g: vec![0.0; x0.len()],
    };
    minimize_problem(&mut p, x0, lo, hi, max_iter, gtol)
}

/// Minimise `p` over `[lo, hi]` from `x0`; the same iterates as [`minimize_box`] with the
/// closure `|x, g| { let v = p.value(x); p.gradient(x, g); v }`, but the gradient is only
/// evaluated where it is used (the start and accepted steps).
pub fn minimize_problem<P: Problem + ?Sized>(
    p: &mut P,
    x0: &[f64],
    lo: &[f64],
    hi: &[f64],
    max_iter: usize,
    gtol: f64,
) -> Minimum {
    let n = x0.len();
    let mut x = x0.to_vec();
    project(&mut x, lo, hi);
    let mut g = vec![0.0; n];
    let mut fx = p.value(&x);
    let mut evals = 1;
    if fx.is_finite() {
        p.gradient(&x, &mut g);
    }
    if !fx.is_finite() || g.iter().any(|v| !v.is_finite()) {
        return Minimum {
            x,
            f: if fx.is_finite() { fx } else { f64::INFINITY },
            evals,
        };
    }
    let mut s_hist: Vec<Vec<f64>> = Vec::new();
    let mut y_hist: Vec<Vec<f64>> = Vec::new();
    let mut xn = vec![0.0; n];
    let mut gn = vec![0.0; n];
    for iter in 0..max_iter {
        let free: Vec<bool> = (0..n)
            .map(|i| !((x[i] <= lo[i] && g[i] > 0.0) || (x[i] >= hi[i] && g[i] < 0.0)))
            .collect();
        let pg: Vec<f64> = (0..n).map(|i| if free[i] { g[i] } else { 0.0 }).collect();
        let pg_norm = pg.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if pg_norm <= gtol {
            break;
        }
        let q = two_loop(&pg, &s_hist, &y_hist, iter);
        let mut d: Vec<f64> = (0..n).map(|i| if free[i] { -q[i] } else { 0.0 }).collect();
        if dot(&d, &pg) >= 0.0 {
            d = pg.iter().map(|v| -v).collect();
            s_hist.clear();
            y_hist.clear();
        }
        let step = line_search(p, &x, &d, fx, &g, (lo, hi), (&mut xn, &mut gn));
        evals += step.evals;
        let Some(fnew) = step.value else {
            if s_hist.is_empty() {
                break;
            }
            s_hist.clear();
            y_hist.clear();
            continue;
        };
        let s: Vec<f64> = (0..n).map(|i| xn[i] - x[i]).collect();
        let yv: Vec<f64> = (0..n).map(|i| gn[i] - g[i]).collect();
        let sy = dot(&s, &yv);
        if sy > 1e-12 * dot(&yv, &yv).max(1e-300) {
            s_hist.push(s);
            y_hist.push(yv);
            if s_hist.len() > MEMORY {
                s_hist.remove(0);
                y_hist.remove(0);
            }
        }
        let improvement = fx - fnew;
        x.copy_from_slice(&xn);
        g.copy_from_slice(&gn);
        fx = fnew;
        if improvement.abs() <= 1e-12 * fx.abs().max(1.0) {
            break;
        }
    }
    Minimum { x, f: fx, evals }
}

/// How many steps the L-BFGS memory keeps.
const MEMORY: usize = 6;

/// The two-loop recursion on the free variables' gradient `pg`: the quasi-Newton step (before
/// its sign), scaled to unit-ish length at the first iteration.
fn two_loop(pg: &[f64], s_hist: &[Vec<f64>], y_hist: &[Vec<f64>], iter: usize) -> Vec<f64> {
    let n = pg.len();
    let mut q = pg.to_vec();
    let k = s_hist.len();
    let mut alphas = vec![0.0; k];
    for j in (0..k).rev() {
        let rho = 1.0 / dot(&y_hist[j], &s_hist[j]);
        alphas[j] = rho * dot(&s_hist[j], &q);
        for i in 0..n {
            q[i] -= alphas[j] * y_hist[j][i];
        }
    }
    if k > 0 {
        let gamma = dot(&s_hist[k - 1], &y_hist[k - 1]) / dot(&y_hist[k - 1], &y_hist[k - 1]);
        q.iter_mut().for_each(|v| *v *= gamma);
    } else {
        // First step: unit-ish length.
        let norm = dot(pg, pg).sqrt();
        let scale = if iter == 0 {
            (1.0 / norm).min(1.0)
        } else {
            1.0
        };
        q.iter_mut().for_each(|v| *v *= scale);
    }
    for j in 0..k {
        let rho = 1.0 / dot(&y_hist[j], &s_hist[j]);
        let beta = rho * dot(&y_hist[j], &q);
        for i in 0..n {
            q[i] += s_hist[j][i] * (alphas[j] - beta);
        }
    }
    q
}

/// A line search's outcome: the accepted value (`None`: no acceptable step) and the
/// evaluations it used.
struct Step {
    value: Option<f64>,
    evals: usize,
}

/// Backtracking line search from `x` (value `fx`, gradient `g`) along `d` on the path
/// projected onto the box; writes the accepted point and its gradient into `(xn, gn)`.
fn line_search<P: Problem + ?Sized>(
    p: &mut P,
    x: &[f64],
    d: &[f64],
    fx: f64,
    g: &[f64],
    (lo, hi): (&[f64], &[f64]),
    (xn, gn): (&mut [f64], &mut [f64]),
) -> Step {
    let n = x.len();
    let mut evals = 0;
    let mut t = 1.0;
    for _ in 0..30 {
        for i in 0..n {
            xn[i] = x[i] + t * d[i];
        }
        project(xn, lo, hi);
        let step: Vec<f64> = (0..n).map(|i| xn[i] - x[i]).collect();
        if step.iter().all(|v| *v == 0.0) {
            break;
        }
        let fnew = p.value(xn);
        evals += 1;
        // Armijo condition first: the gradient is only needed at an accepted point.
        if fnew.is_finite() && fnew <= fx + 1e-4 * dot(g, &step) {
            p.gradient(xn, gn);
            if gn.iter().all(|v| v.is_finite()) {
                return Step {
                    value: Some(fnew),
                    evals,
                };
            }
        }
        t *= 0.5;
    }
    Step { value: None, evals }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rosenbrock_unconstrained_and_boxed() {
        let rosen = |x: &[f64], g: &mut [f64]| {
            let (a, b) = (x[0], x[1]);
            g[0] = -2.0 * (1.0 - a) - 400.0 * a * (b - a * a);
            g[1] = 200.0 * (b - a * a);
            (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2)
        };
        let m = minimize_box(rosen, &[-1.2, 1.0], &[-5.0, -5.0], &[5.0, 5.0], 500, 1e-10);
        assert!(
            (m.x[0] - 1.0).abs() < 1e-5 && (m.x[1] - 1.0).abs() < 1e-5,
            "{:?}",
            m
        );
        // optimum of a quadratic outside the box lands on the bound
        let q = |x: &[f64], g: &mut [f64]| {
            g[0] = 2.0 * (x[0] - 3.0);
            g[1] = 2.0 * (x[1] + 0.5);
            (x[0] - 3.0).powi(2) + (x[1] + 0.5).powi(2)
        };
        let m = minimize_box(q, &[0.5, 0.5], &[0.0, 0.0], &[1.0, 1.0], 100, 1e-10);
        assert!(
            (m.x[0] - 1.0).abs() < 1e-12 && m.x[1].abs() < 1e-12,
            "{:?}",
            m
        );
    }

    #[test]
    fn two_step_problem_follows_the_same_iterates() {
        // Rosenbrock as a Problem that counts gradient evaluations.
        struct Rosen {
            grads: usize,
        }
        impl Problem for Rosen {
            fn value(&mut self, x: &[f64]) -> f64 {
                (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2)
            }
            fn gradient(&mut self, x: &[f64], g: &mut [f64]) {
                self.grads += 1;
                let (a, b) = (x[0], x[1]);
                g[0] = -2.0 * (1.0 - a) - 400.0 * a * (b - a * a);
                g[1] = 200.0 * (b - a * a);
            }
        }
        let (lo, hi) = ([-5.0, -5.0], [5.0, 5.0]);
        let mut p = Rosen { grads: 0 };
        let joint = minimize_box(
            |x, g| {
                let v = p.value(x);
                p.gradient(x, g);
                v
            },
            &[-1.2, 1.0],
            &lo,
            &hi,
            40,
            1e-10,
        );
        let mut q = Rosen { grads: 0 };
        let split = minimize_problem(&mut q, &[-1.2, 1.0], &lo, &hi, 40, 1e-10);
        assert_eq!(joint.x, split.x);
        assert_eq!(joint.f.to_bits(), split.f.to_bits());
        assert_eq!(joint.evals, split.evals);
        // the gradient is skipped at rejected trial points
        assert!(q.grads < p.grads, "{} {}", q.grads, p.grads);
    }
}
