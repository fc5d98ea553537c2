//! Stationary covariance functions with ARD (one length scale per dimension) and a signal
//! variance: Matern 3/2 (the thesis default, eq. 3.4), Matern 5/2, squared exponential, and
//! the product of one-dimensional Matern 3/2 factors.
//!
//! With `r = sqrt(sum_d ((a_d - b_d) / l_d)^2)` the radial kernels are `k = s * rho(r)`. They
//! also give `g(r) = -rho'(r) / r` (finite at r = 0), from which the derivatives follow:
//! `dk/d(log l_d) = s g(r) ((a_d - b_d)/l_d)^2` and `dk/da_d = -s g(r) (a_d - b_d) / l_d^2`.
//!
//! The product kernel ([`KernelKind::ProductMatern32`]) is `k = s prod_d (1 + sqrt3 t_d)
//! exp(-sqrt3 t_d)` with `t_d = |a_d - b_d| / l_d`; its derivatives are
//! `dk/d(log l_d) = k 3 t_d^2 / (1 + sqrt3 t_d)` and
//! `dk/da_d = -k 3 (a_d - b_d) / (l_d^2 (1 + sqrt3 t_d))`.

use serde::{Deserialize, Serialize};

const SQRT3: f64 = 1.732_050_807_568_877_2;
const SQRT5: f64 = 2.236_067_977_499_79;

/// Which stationary kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum KernelKind {
    /// Matern nu = 3/2: `(1 + sqrt3 r) exp(-sqrt3 r)` (thesis eq. 3.4).
    #[default]
    Matern32,
    /// Matern nu = 5/2: `(1 + sqrt5 r + 5 r^2 / 3) exp(-sqrt5 r)`.
    Matern52,
    /// Squared exponential: `exp(-r^2 / 2)`.
    SquaredExponential,
    /// Product of one-dimensional Matern 3/2 factors, `prod_d (1 + sqrt3 t_d) exp(-sqrt3 t_d)`
    /// with `t_d = |a_d - b_d| / l_d` (not radial: the correlation falls with the sum of the
    /// scaled coordinate distances; the form of egobox's and SMT's Matern 3/2). Its
    /// [`KernelKind::profile`] and [`KernelKind::rho`] are those of one factor.
    ProductMatern32,
}

/// The product Matern 3/2 correlation of the scaled coordinate differences `t_d` (any sign).
#[inline]
pub fn product_matern32(t: impl Iterator<Item = f64>) -> f64 {
    let (mut prod, mut sum) = (1.0, 0.0);
    for v in t {
        let a = v.abs();
        prod *= 1.0 + SQRT3 * a;
        sum += a;
    }
    prod * (-SQRT3 * sum).exp()
}

/// `d ln k / d(log l_d)` of the product Matern 3/2 kernel for the scaled difference `t_d`:
/// `3 t_d^2 / (1 + sqrt3 |t_d|)`.
#[inline]
pub fn product_matern32_dlog_l(t: f64) -> f64 {
    3.0 * t * t / (1.0 + SQRT3 * t.abs())
}

impl KernelKind {
    /// `(rho(r), g(r))` with `g = -rho'(r) / r`.
    #[inline]
    pub fn profile(self, r: f64) -> (f64, f64) {
        match self {
            KernelKind::Matern32 | KernelKind::ProductMatern32 => {
                let e = (-SQRT3 * r).exp();
                ((1.0 + SQRT3 * r) * e, 3.0 * e)
            }
            KernelKind::Matern52 => {
                let e = (-SQRT5 * r).exp();
                (
                    (1.0 + SQRT5 * r + 5.0 / 3.0 * r * r) * e,
                    5.0 / 3.0 * (1.0 + SQRT5 * r) * e,
                )
            }
            KernelKind::SquaredExponential => {
                let e = (-0.5 * r * r).exp();
                (e, e)
            }
        }
    }

    /// `rho(r)` only.
    #[inline]
    pub fn rho(self, r: f64) -> f64 {
        match self {
            KernelKind::Matern32 | KernelKind::ProductMatern32 => {
                (1.0 + SQRT3 * r) * (-SQRT3 * r).exp()
            }
            KernelKind::Matern52 => (1.0 + SQRT5 * r + 5.0 / 3.0 * r * r) * (-SQRT5 * r).exp(),
            KernelKind::SquaredExponential => (-0.5 * r * r).exp(),
        }
    }
}

/// A kernel with its hyperparameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Kernel {
    /// Kernel family.
    pub kind: KernelKind,
    /// One length scale per input dimension (> 0).
    pub length_scales: Vec<f64>,
    /// Signal variance `s = sigma_f^2` (> 0).
    pub signal_variance: f64,
}

impl Kernel {
    /// Scaled distance `r` between `a` and `b`.
    #[inline]
    pub fn scaled_distance(&self, a: &[f64], b: &[f64]) -> f64 {
        let mut s = 0.0;
        for ((x, y), l) in a.iter().zip(b).zip(&self.length_scales) {
            let t = (x - y) / l;
            s += t * t;
        }
        s.sqrt()
    }

    /// `k(a, b)`.
    #[inline]
    pub fn eval(&self, a: &[f64], b: &[f64]) -> f64 {
        if self.kind == KernelKind::ProductMatern32 {
            return self.signal_variance
                * product_matern32(
                    a.iter()
                        .zip(b)
                        .zip(&self.length_scales)
                        .map(|((x, y), l)| (x - y) / l),
                );
        }
        self.signal_variance * self.kind.rho(self.scaled_distance(a, b))
    }

    /// `k(a, b)` and its gradient with respect to `a`, written into `grad`.
    pub fn eval_with_grad(&self, a: &[f64], b: &[f64], grad: &mut [f64]) -> f64 {
        if self.kind == KernelKind::ProductMatern32 {
            let k = self.eval(a, b);
            for (((gd, x), y), l) in grad.iter_mut().zip(a).zip(b).zip(&self.length_scales) {
                let t = (x - y) / l;
                *gd = -k * 3.0 * t / (l * (1.0 + SQRT3 * t.abs()));
            }
            return k;
        }
        let r = self.scaled_distance(a, b);
        let (rho, g) = self.kind.profile(r);
        for (((gd, x), y), l) in grad.iter_mut().zip(a).zip(b).zip(&self.length_scales) {
            *gd = -self.signal_variance * g * (x - y) / (l * l);
        }
        self.signal_variance * rho
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_at_zero_and_one() {
        for kind in [
            KernelKind::Matern32,
            KernelKind::Matern52,
            KernelKind::SquaredExponential,
            KernelKind::ProductMatern32,
        ] {
            let k = Kernel {
                kind,
                length_scales: vec![1.0, 2.0],
                signal_variance: 2.0,
            };
            assert!((k.eval(&[0.3, 0.1], &[0.3, 0.1]) - 2.0).abs() < 1e-15);
        }
        let k = Kernel {
            kind: KernelKind::Matern32,
            length_scales: vec![1.0],
            signal_variance: 1.0,
        };
        let expect = (1.0 + 3f64.sqrt()) * (-(3f64.sqrt())).exp();
        assert!((k.eval(&[0.0], &[1.0]) - expect).abs() < 1e-15);
        // The product kernel: one factor per coordinate, so (0, 0) to (1, 2) with length
        // scales (1, 2) is the square of one unit factor (the radial kernel's r is sqrt 2).
        let p = Kernel {
            kind: KernelKind::ProductMatern32,
            length_scales: vec![1.0, 2.0],
            signal_variance: 1.0,
        };
        assert!((p.eval(&[0.0, 0.0], &[1.0, 2.0]) - expect * expect).abs() < 1e-15);
        assert!((p.eval(&[0.0, 0.0], &[-1.0, 0.0]) - expect).abs() < 1e-15);
    }

    #[test]
    fn gradient_and_g_match_finite_differences() {
        for kind in [
            KernelKind::Matern32,
            KernelKind::Matern52,
            KernelKind::SquaredExponential,
            KernelKind::ProductMatern32,
        ] {
            let k = Kernel {
                kind,
                length_scales: vec![0.3, 0.7, 1.5],
                signal_variance: 1.3,
            };
            let a = [0.2, 0.5, 0.9];
            let b = [0.4, 0.1, 0.3];
            let mut g = [0.0; 3];
            k.eval_with_grad(&a, &b, &mut g);
            for d in 0..3 {
                let e = 1e-6;
                let mut ap = a;
                ap[d] += e;
                let mut am = a;
                am[d] -= e;
                let fd = (k.eval(&ap, &b) - k.eval(&am, &b)) / (2.0 * e);
                assert!((fd - g[d]).abs() < 1e-7, "{kind:?} {d} {fd} {}", g[d]);
                // dk/dlog l_d
                let mut kp = k.clone();
                kp.length_scales[d] *= (e).exp();
                let mut km = k.clone();
                km.length_scales[d] *= (-e).exp();
                let fd = (kp.eval(&a, &b) - km.eval(&a, &b)) / (2.0 * e);
                let r = k.scaled_distance(&a, &b);
                let t = (a[d] - b[d]) / k.length_scales[d];
                let an = if kind == KernelKind::ProductMatern32 {
                    k.eval(&a, &b) * product_matern32_dlog_l(t)
                } else {
                    k.signal_variance * kind.profile(r).1 * t * t
                };
                assert!((fd - an).abs() < 1e-7, "{kind:?} {d} {fd} {an}");
            }
        }
    }
}
