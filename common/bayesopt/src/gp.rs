//! Gaussian-process regression with a zero prior mean and Gaussian observation noise
//! (thesis eq. 3.8): Cholesky factorisation with jitter retry, posterior mean and variance of the
//! latent function (with gradients for the acquisition polish), the log marginal likelihood, and
//! O(n^2) appends used for batch "fantasy" observations.
//!
//! This layer works on whatever data it is given: the optimizer scales inputs to the unit cube
//! and standardises outputs before building a [`Gp`].

use crate::error::{BoError, Result};
use crate::kernel::{Kernel, KernelKind, product_matern32};
use crate::linalg;

const LN_2PI: f64 = 1.837_877_066_409_345_3;

/// A conditioned Gaussian process.
#[derive(Debug, Clone)]
pub struct Gp {
    kernel: Kernel,
    noise: f64,
    dim: usize,
    x: Vec<Vec<f64>>,
    /// Inputs scaled by the inverse length scales, flat row-major n x d (fast predictions).
    xs_scaled: Vec<f64>,
    inv_ls: Vec<f64>,
    y: Vec<f64>,
    /// Lower Cholesky factor of K + (noise + jitter) I, row-major n x n.
    l: Vec<f64>,
    alpha: Vec<f64>,
    jitter: f64,
}

impl Gp {
    /// Condition a GP with `kernel` and noise variance `noise` on observations `(x, y)`.
    pub fn new(x: Vec<Vec<f64>>, y: Vec<f64>, kernel: Kernel, noise: f64) -> Result<Self> {
        let dim = kernel.length_scales.len();
        if dim == 0 {
            return Err(BoError::EmptyBounds);
        }
        if x.len() != y.len() {
            return Err(BoError::DimensionMismatch {
                expected: x.len(),
                got: y.len(),
            });
        }
        if !(noise >= 0.0 && noise.is_finite()) {
            return Err(BoError::InvalidSetting(format!("noise variance {noise}")));
        }
        if !(kernel.signal_variance > 0.0 && kernel.signal_variance.is_finite())
            || kernel
                .length_scales
                .iter()
                .any(|l| !(*l > 0.0 && l.is_finite()))
        {
            return Err(BoError::InvalidSetting(
                "kernel hyperparameters must be positive and finite".into(),
            ));
        }
        for p in &x {
            if p.len() != dim {
                return Err(BoError::DimensionMismatch {
                    expected: dim,
                    got: p.len(),
                });
            }
            if p.iter().any(|v| !v.is_finite()) {
                return Err(BoError::NonFinite { what: "GP input" });
            }
        }
        if y.iter().any(|v| !v.is_finite()) {
            return Err(BoError::NonFinite {
                what: "GP observation",
            });
        }
        let n = x.len();
        let mut k = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..i {
                // lower triangle only: all that the factorisation reads
                k[i * n + j] = kernel.eval(&x[i], &x[j]);
            }
            k[i * n + i] = kernel.signal_variance + noise;
        }
        let (l, jitter) = linalg::cholesky_jitter(&k, n)?;
        let mut alpha = y.clone();
        linalg::solve_lower_in_place(&l, n, &mut alpha);
        linalg::solve_upper_t_in_place(&l, n, &mut alpha);
        let inv_ls: Vec<f64> = kernel.length_scales.iter().map(|l| 1.0 / l).collect();
        let xs_scaled = x
            .iter()
            .flat_map(|p| p.iter().zip(&inv_ls).map(|(a, b)| a * b))
            .collect();
        Ok(Gp {
            kernel,
            noise,
            dim,
            x,
            xs_scaled,
            inv_ls,
            y,
            l,
            alpha,
            jitter,
        })
    }

    /// Number of conditioning points.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True when conditioned on no point (the prior).
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Input dimension.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The kernel.
    pub fn kernel(&self) -> &Kernel {
        &self.kernel
    }

    /// Observation noise variance.
    pub fn noise(&self) -> f64 {
        self.noise
    }

    /// Jitter that had to be added to the diagonal (0 when none).
    pub fn jitter(&self) -> f64 {
        self.jitter
    }

    /// Posterior mean and variance (of the latent f, variance >= 0) at `xs`.
    /// `xs` must have the GP's dimension (checked by the caller layers; extra coordinates are
    /// ignored and missing ones treated as absent terms).
    pub fn predict(&self, xs: &[f64]) -> (f64, f64) {
        self.predict_with_buffer(xs, &mut Vec::new())
    }

    /// [`Gp::predict`] using `v` as scratch (no allocation once it has the capacity; for
    /// callers that predict at many points).
    pub fn predict_with_buffer(&self, xs: &[f64], v: &mut Vec<f64>) -> (f64, f64) {
        v.clear();
        self.kernel_row_from(xs, 0, v);
        let mean = linalg::dot(v, &self.alpha);
        linalg::solve_lower_in_place(&self.l, self.x.len(), v);
        let var = self.kernel.signal_variance - linalg::dot(v, v);
        (mean, var.max(0.0))
    }

    /// [`Gp::predict`] that also leaves the kernel row `k(xs, x_i)` in `k` and `L^{-1} k` in
    /// `v`, reusing their first `from` entries: these must be those of a GP whose first
    /// `from` conditioning points are this one's (with the same kernel), e.g. the GP this one
    /// was extended from by [`Gp::push`], so only the rows of the appended points are
    /// computed. The result is bit-identical to [`Gp::predict`].
    pub fn predict_extending(
        &self,
        xs: &[f64],
        from: usize,
        k: &mut Vec<f64>,
        v: &mut Vec<f64>,
    ) -> (f64, f64) {
        let n = self.x.len();
        let from = from.min(n).min(k.len()).min(v.len());
        k.truncate(from);
        v.truncate(from);
        self.kernel_row_from(xs, from, k);
        v.extend_from_slice(&k[from..]);
        linalg::solve_lower_rows_from(&self.l, n, v, from);
        let mean = linalg::dot(k, &self.alpha);
        let var = self.kernel.signal_variance - linalg::dot(v, v);
        (mean, var.max(0.0))
    }

    /// Append `k(xs, x_i)` for the conditioning points `i >= from` to `out`.
    fn kernel_row_from(&self, xs: &[f64], from: usize, out: &mut Vec<f64>) {
        let d = self.dim;
        out.reserve(self.x.len().saturating_sub(from));
        if d <= 16 && xs.len() == d {
            let mut p = [0.0f64; 16];
            for k in 0..d {
                p[k] = xs[k] * self.inv_ls[k];
            }
            let (kind, sv) = (self.kernel.kind, self.kernel.signal_variance);
            if kind == KernelKind::ProductMatern32 {
                for row in self.xs_scaled.chunks_exact(d).skip(from) {
                    out.push(sv * product_matern32((0..d).map(|k| p[k] - row[k])));
                }
                return;
            }
            for row in self.xs_scaled.chunks_exact(d).skip(from) {
                let mut r2 = 0.0;
                for k in 0..d {
                    let t = p[k] - row[k];
                    r2 += t * t;
                }
                out.push(sv * kind.rho(r2.sqrt()));
            }
        } else {
            out.extend(self.x[from..].iter().map(|xi| self.kernel.eval(xs, xi)));
        }
    }

    /// Posterior mean and variance with their gradients with respect to `xs`.
    pub fn predict_with_grad(&self, xs: &[f64], dmean: &mut [f64], dvar: &mut [f64]) -> (f64, f64) {
        let n = self.x.len();
        let d = self.dim;
        let mut dk = vec![0.0; n * d];
        let mut v = vec![0.0; n];
        for (i, xi) in self.x.iter().enumerate() {
            v[i] = self
                .kernel
                .eval_with_grad(xs, xi, &mut dk[i * d..(i + 1) * d]);
        }
        let mean: f64 = v.iter().zip(&self.alpha).map(|(a, b)| a * b).sum();
        linalg::solve_lower_in_place(&self.l, n, &mut v);
        let var = self.kernel.signal_variance - v.iter().map(|t| t * t).sum::<f64>();
        let mut w = v;
        linalg::solve_upper_t_in_place(&self.l, n, &mut w);
        dmean.iter_mut().for_each(|g| *g = 0.0);
        dvar.iter_mut().for_each(|g| *g = 0.0);
        for i in 0..n {
            let row = &dk[i * d..(i + 1) * d];
            for k in 0..d.min(dmean.len()).min(dvar.len()) {
                dmean[k] += self.alpha[i] * row[k];
                dvar[k] -= 2.0 * w[i] * row[k];
            }
        }
        if var <= 0.0 {
            dvar.iter_mut().for_each(|g| *g = 0.0);
        }
        (mean, var.max(0.0))
    }

    /// Log marginal likelihood `log p(y | X, theta)`.
    pub fn log_marginal_likelihood(&self) -> f64 {
        let n = self.x.len();
        let fit: f64 = self.y.iter().zip(&self.alpha).map(|(a, b)| a * b).sum();
        let logdet: f64 = (0..n).map(|i| self.l[i * n + i].ln()).sum();
        -0.5 * fit - logdet - 0.5 * n as f64 * LN_2PI
    }

    /// Condition additionally on `(x, y)` in O(n^2) (rank-one extension of the Cholesky factor).
    pub fn push(&mut self, x: Vec<f64>, y: f64) -> Result<()> {
        if x.len() != self.dim {
            return Err(BoError::DimensionMismatch {
                expected: self.dim,
                got: x.len(),
            });
        }
        if !y.is_finite() || x.iter().any(|v| !v.is_finite()) {
            return Err(BoError::NonFinite { what: "GP append" });
        }
        let n = self.x.len();
        let mut v: Vec<f64> = self.x.iter().map(|xi| self.kernel.eval(&x, xi)).collect();
        linalg::solve_lower_in_place(&self.l, n, &mut v);
        let diag2 = self.kernel.signal_variance + self.noise + self.jitter
            - v.iter().map(|t| t * t).sum::<f64>();
        let floor = 1e-10 * self.kernel.signal_variance;
        let diag = diag2.max(floor).sqrt();
        let m = n + 1;
        let mut l = vec![0.0; m * m];
        for i in 0..n {
            l[i * m..i * m + i + 1].copy_from_slice(&self.l[i * n..i * n + i + 1]);
        }
        l[n * m..n * m + n].copy_from_slice(&v);
        l[n * m + n] = diag;
        self.l = l;
        self.xs_scaled
            .extend(x.iter().zip(&self.inv_ls).map(|(a, b)| a * b));
        self.x.push(x);
        self.y.push(y);
        let mut alpha = self.y.clone();
        linalg::solve_lower_in_place(&self.l, m, &mut alpha);
        linalg::solve_upper_t_in_place(&self.l, m, &mut alpha);
        self.alpha = alpha;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::KernelKind;

    fn se(l: f64) -> Kernel {
        Kernel {
            kind: KernelKind::SquaredExponential,
            length_scales: vec![l],
            signal_variance: 1.0,
        }
    }

    /// Hand-computed 3-point example: SE kernel, l = 1, s = 1, noise 0, X = {0, 1, 2},
    /// y = {0, 1, 0}. With a = e^{-1/2}, b = e^{-2}: K = [[1,a,b],[a,1,a],[b,a,1]].
    /// At x* = 1 (a training point) mean = 1 and variance = 0. At x* = 0.5,
    /// k* = (e^{-1/8}, e^{-1/8}, e^{-9/8}) and mean = k*^T K^{-1} y, var = 1 - k*^T K^{-1} k*,
    /// solved by hand with Cramer's rule below.
    #[test]
    fn three_point_posterior_by_hand() {
        let gp = Gp::new(
            vec![vec![0.0], vec![1.0], vec![2.0]],
            vec![0.0, 1.0, 0.0],
            se(1.0),
            0.0,
        )
        .unwrap();
        let (m, v) = gp.predict(&[1.0]);
        assert!((m - 1.0).abs() < 1e-9 && v < 1e-9, "{m} {v}");

        let a = (-0.5f64).exp();
        let b = (-2.0f64).exp();
        // K^{-1} y with y = e2: by symmetry alpha = (p, q, p) solving
        // p + a q + b p = 0, a p + q + a p = 1  =>  p = -a q / (1 + b), q = 1 / (1 - 2a^2/(1+b)).
        let q = 1.0 / (1.0 - 2.0 * a * a / (1.0 + b));
        let p = -a * q / (1.0 + b);
        let k1 = (-0.125f64).exp();
        let k3 = (-1.125f64).exp();
        let mean_expected = k1 * p + k1 * q + k3 * p;
        // Variance: solve K z = k* by Cramer's rule.
        let det3 = |m: [[f64; 3]; 3]| {
            m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
        };
        let kmat = [[1.0, a, b], [a, 1.0, a], [b, a, 1.0]];
        let ks = [k1, k1, k3];
        let dk = det3(kmat);
        let mut z = [0.0; 3];
        for (c, zc) in z.iter_mut().enumerate() {
            let mut mm = kmat;
            for r in 0..3 {
                mm[r][c] = ks[r];
            }
            *zc = det3(mm) / dk;
        }
        let var_expected = 1.0 - (ks[0] * z[0] + ks[1] * z[1] + ks[2] * z[2]);
        let (m, v) = gp.predict(&[0.5]);
        assert!((m - mean_expected).abs() < 1e-12, "{m} {mean_expected}");
        assert!((v - var_expected).abs() < 1e-12, "{v} {var_expected}");
        // Numerical values, for the record.
        assert!(
            (mean_expected - 0.675_106_854).abs() < 1e-8,
            "{mean_expected}"
        );
        // log marginal likelihood: -0.5 y^T K^{-1} y - 0.5 log|K| - 1.5 log(2 pi)
        let lml = -0.5 * q - 0.5 * dk.ln() - 1.5 * LN_2PI;
        assert!((gp.log_marginal_likelihood() - lml).abs() < 1e-10);
    }

    #[test]
    fn gradients_match_finite_differences() {
        // `predict` takes the fast kernel rows, `predict_with_grad` `Kernel::eval_with_grad`:
        // the finite differences of one match the gradients of the other.
        for kind in [KernelKind::Matern52, KernelKind::ProductMatern32] {
            let k = Kernel {
                kind,
                length_scales: vec![0.3, 0.6],
                signal_variance: 1.2,
            };
            let x = vec![
                vec![0.1, 0.2],
                vec![0.8, 0.4],
                vec![0.5, 0.9],
                vec![0.3, 0.6],
            ];
            let gp = Gp::new(x, vec![0.3, -1.0, 0.5, 1.1], k, 1e-4).unwrap();
            let p = [0.42, 0.37];
            let mut dm = [0.0; 2];
            let mut dv = [0.0; 2];
            let (m0, v0) = gp.predict_with_grad(&p, &mut dm, &mut dv);
            let (m1, v1) = gp.predict(&p);
            assert!(
                (m0 - m1).abs() < 1e-12 && (v0 - v1).abs() < 1e-12,
                "{kind:?}"
            );
            for d in 0..2 {
                let e = 1e-6;
                let mut a = p;
                a[d] += e;
                let mut b = p;
                b[d] -= e;
                let (ma, va) = gp.predict(&a);
                let (mb, vb) = gp.predict(&b);
                assert!(((ma - mb) / (2.0 * e) - dm[d]).abs() < 1e-6, "{kind:?}");
                assert!(((va - vb) / (2.0 * e) - dv[d]).abs() < 1e-6, "{kind:?}");
            }
        }
    }

    #[test]
    fn push_matches_full_refit() {
        let k = se(0.4);
        let x = vec![vec![0.1], vec![0.5], vec![0.9]];
        let mut gp = Gp::new(x.clone(), vec![1.0, -0.5, 0.2], k.clone(), 1e-6).unwrap();
        gp.push(vec![0.3], 0.7).unwrap();
        let mut x2 = x;
        x2.push(vec![0.3]);
        let full = Gp::new(x2, vec![1.0, -0.5, 0.2, 0.7], k, 1e-6).unwrap();
        for t in [0.0, 0.2, 0.45, 0.77, 1.0] {
            let (a, b) = gp.predict(&[t]);
            let (c, d) = full.predict(&[t]);
            assert!((a - c).abs() < 1e-8 && (b - d).abs() < 1e-8);
        }
    }

    #[test]
    fn predict_variants_are_bit_identical() {
        let k = Kernel {
            kind: KernelKind::Matern32,
            length_scales: vec![0.3, 0.5, 0.8],
            signal_variance: 1.3,
        };
        let mut r = crate::rng::Rng::new(4);
        let x: Vec<Vec<f64>> = (0..23).map(|_| r.unit_point(3)).collect();
        let y: Vec<f64> = x.iter().map(|p| p[0].sin() - p[1] * p[2]).collect();
        let gp = Gp::new(x, y, k, 1e-4).unwrap();
        let mut g2 = gp.clone();
        g2.push(vec![0.2, 0.4, 0.6], -1.0).unwrap();
        g2.push(vec![0.7, 0.1, 0.3], 0.5).unwrap();
        let (mut buf, mut kr, mut vr) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..20 {
            let p = r.unit_point(3);
            let (m, v) = gp.predict(&p);
            assert_eq!(gp.predict_with_buffer(&p, &mut buf), (m, v));
            assert_eq!(gp.predict_extending(&p, 0, &mut kr, &mut vr), (m, v));
            // rows of `gp` reused for the GP extended by two fantasy points
            assert_eq!(
                g2.predict_extending(&p, gp.len(), &mut kr, &mut vr),
                g2.predict(&p)
            );
        }
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(Gp::new(vec![vec![0.0]], vec![f64::NAN], se(1.0), 0.0).is_err());
        assert!(Gp::new(vec![vec![0.0, 1.0]], vec![1.0], se(1.0), 0.0).is_err());
        assert!(Gp::new(vec![vec![0.0]], vec![1.0, 2.0], se(1.0), 0.0).is_err());
        assert!(Gp::new(vec![vec![0.0]], vec![1.0], se(-1.0), 0.0).is_err());
        // duplicates are fine thanks to the jitter
        let gp = Gp::new(vec![vec![0.2], vec![0.2]], vec![1.0, 1.0], se(1.0), 0.0).unwrap();
        assert!(gp.jitter() > 0.0);
    }
}
