//! Sequential-greedy q-Expected-Improvement for batch proposals: point `j` of a round maximises
//! the joint qEI of the points already chosen (pending ones and the `j - 1` earlier ones of the
//! round) plus the candidate `x`, under the GP's joint posterior of the latent function.
//!
//! The chosen points `C` are fixed while `x` varies. With fixed base samples `z_C`, the chosen
//! points' values are `f_C = m_C + L_C z_C`, and given them `f_x` is Gaussian with mean
//! `m_x + l . z_C` and variance `d^2 = var_x - |l|^2`, where `l = L_C^{-1} S_Cx` (`S_Cx`: the
//! posterior covariances of `x` with `C`, `L_C`: the Cholesky factor of `C`'s). Since
//! `l . z_C = S_Cx . u` with `u = L_C^{-T} z_C`, only `S_Cx` and `d` are computed per
//! candidate.
//!
//! Per sample the joint improvement over `best` is `max(0, max f_C - best, f_x - best)`, which
//! is `b + max(0, f_x - t)` with `b = max(0, max f_C - best)` and the threshold
//! `t = best + b`; `b` does not depend on `x`. So maximising qEI over `x` is maximising the
//! mean over samples of `E[max(0, f_x - t) | z_C]`, an EI per sample, which is computed exactly
//! (no sampling of `f_x` itself, so the acquisition has no flat regions).

use std::sync::OnceLock;

use crate::acquisition::LOG_EI_FLOOR;
use crate::error::Result;
use crate::gp::Gp;
use crate::linalg;
use crate::rng::Rng;
use crate::special::{dlog_h, log_h};

/// The fixed part of one sequential-greedy qEI maximisation. See the module documentation.
pub(crate) struct QeiContext<'a> {
    gp: &'a Gp,
    /// Chosen points (unit cube).
    points: Vec<Vec<f64>>,
    /// `L^{-1} k(X, c)` of each chosen point (`L`: the GP's factor).
    v: Vec<Vec<f64>>,
    /// Cholesky factor of the chosen points' posterior covariance (m x m, row-major).
    lc: Vec<f64>,
    /// Per sample: `L_C^{-T} z_C`.
    u: Vec<Vec<f64>>,
    /// Per sample: the threshold `best + max(0, max f_C - best)`.
    thresh: Vec<f64>,
    // Scratch.
    k_row: Vec<f64>,
    v_row: Vec<f64>,
    s: Vec<f64>,
    l: Vec<f64>,
    zs: Vec<f64>,
}

impl<'a> QeiContext<'a> {
    /// Context for the points `chosen` (unit cube, at least one) on `gp` (conditioned on the
    /// observations only), improvement over `best` (incumbent plus xi), `samples` base samples
    /// drawn from `rng`.
    pub(crate) fn new(
        gp: &'a Gp,
        chosen: &[Vec<f64>],
        best: f64,
        samples: usize,
        rng: &mut Rng,
    ) -> Result<Self> {
        let m = chosen.len();
        let samples = samples.max(1);
        let kern = gp.kernel();
        let mut v = Vec::with_capacity(m);
        let mut means = Vec::with_capacity(m);
        let (mut k_row, mut v_row) = (Vec::new(), Vec::new());
        for c in chosen {
            let (mean, _) = gp.predict_extending(c, 0, &mut k_row, &mut v_row);
            means.push(mean);
            v.push(v_row.clone());
        }
        let mut cov = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..=i {
                let c = kern.eval(&chosen[i], &chosen[j]) - linalg::dot(&v[i], &v[j]);
                cov[i * m + j] = c;
                cov[j * m + i] = c;
            }
            cov[i * m + i] = cov[i * m + i].max(1e-12 * kern.signal_variance);
        }
        let (lc, _) = linalg::cholesky_jitter(&cov, m)?;
        let mut u = Vec::with_capacity(samples);
        let mut thresh = Vec::with_capacity(samples);
        for _ in 0..samples {
            let z: Vec<f64> = (0..m).map(|_| rng.normal()).collect();
            let top = (0..m)
                .map(|i| means[i] + linalg::dot(&lc[i * m..i * m + i + 1], &z[..i + 1]))
                .fold(f64::NEG_INFINITY, f64::max);
            let mut us = z;
            linalg::solve_upper_t_in_place(&lc, m, &mut us);
            u.push(us);
            thresh.push(best.max(top));
        }
        Ok(QeiContext {
            gp,
            points: chosen.to_vec(),
            v,
            lc,
            u,
            thresh,
            k_row,
            v_row,
            s: vec![0.0; m],
            l: vec![0.0; m],
            zs: Vec::with_capacity(samples),
        })
    }

    /// Log of the qEI gain of adding `x` (unit cube); [`LOG_EI_FLOOR`] when 0.
    pub(crate) fn log_gain(&mut self, x: &[f64]) -> f64 {
        let m = self.points.len();
        let (mx, var) = self
            .gp
            .predict_extending(x, 0, &mut self.k_row, &mut self.v_row);
        let kern = self.gp.kernel();
        for i in 0..m {
            self.s[i] = kern.eval(&self.points[i], x) - linalg::dot(&self.v[i], &self.v_row);
        }
        self.l.copy_from_slice(&self.s);
        linalg::solve_lower_in_place(&self.lc, m, &mut self.l);
        let d2 = var - linalg::dot(&self.l, &self.l);
        if d2.is_nan() || d2 <= 0.0 {
            return LOG_EI_FLOOR;
        }
        let d = d2.sqrt();
        // Mean over samples of d h(z_s): log d + log-sum-exp of log h(z_s). log h is concave,
        // so it lies below its tangent at the largest z: a sample whose z is far enough below
        // adds less than e^-40 of the largest term and is skipped.
        self.zs.clear();
        let mut zmax = f64::NEG_INFINITY;
        for (us, t) in self.u.iter().zip(&self.thresh) {
            let z = (mx + linalg::dot(&self.s, us) - t) / d;
            zmax = zmax.max(z);
            self.zs.push(z);
        }
        let top = tabulated_log_h(zmax);
        let slope = dlog_h(zmax);
        let sum: f64 = self
            .zs
            .iter()
            .filter(|&&z| slope * (zmax - z) < 40.0)
            .map(|&z| (tabulated_log_h(z) - top).exp())
            .sum();
        let v = d.ln() + top + (sum / self.u.len() as f64).ln();
        if v.is_finite() {
            v.max(LOG_EI_FLOOR)
        } else {
            LOG_EI_FLOOR
        }
    }
}

/// Range and spacing of the `log h` table.
const TABLE_LO: f64 = -40.0;
const TABLE_HI: f64 = 10.0;
const TABLE_STEPS_PER_UNIT: f64 = 64.0;

/// `log h(z)` ([`crate::special::log_h`]) by cubic Hermite interpolation of a table of its
/// values and slopes on `[-40, 10]` in steps of 1/64 (error below 1e-9); outside, the exact
/// function. The qEI gain evaluates it once per sample per candidate, and the exact one's
/// continued fraction would take most of the time.
fn tabulated_log_h(z: f64) -> f64 {
    static TABLE: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    if !(TABLE_LO..TABLE_HI).contains(&z) {
        return log_h(z);
    }
    let h = 1.0 / TABLE_STEPS_PER_UNIT;
    let table = TABLE.get_or_init(|| {
        let n = ((TABLE_HI - TABLE_LO) * TABLE_STEPS_PER_UNIT) as usize;
        (0..=n)
            .map(|i| {
                let z = TABLE_LO + i as f64 * h;
                (log_h(z), dlog_h(z))
            })
            .collect()
    });
    let x = (z - TABLE_LO) * TABLE_STEPS_PER_UNIT;
    let i = (x.floor() as usize).min(table.len() - 2);
    let t = x - i as f64;
    let (y0, d0) = table[i];
    let (y1, d1) = table[i + 1];
    let t2 = t * t;
    let t3 = t2 * t;
    (2.0 * t3 - 3.0 * t2 + 1.0) * y0
        + (t3 - 2.0 * t2 + t) * h * d0
        + (-2.0 * t3 + 3.0 * t2) * y1
        + (t3 - t2) * h * d1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::{Kernel, KernelKind};

    #[test]
    fn the_table_matches_log_h() {
        let mut worst: f64 = 0.0;
        let mut z = -60.0;
        while z < 15.0 {
            worst = worst.max((tabulated_log_h(z) - log_h(z)).abs());
            z += 0.00137;
        }
        assert!(worst < 1e-9, "{worst}");
    }

    /// The gain equals a brute-force Monte-Carlo estimate of qEI(C + x) - qEI(C) under the
    /// joint posterior of the three points.
    #[test]
    fn the_gain_matches_brute_force_joint_sampling() {
        let k = Kernel {
            kind: KernelKind::Matern52,
            length_scales: vec![0.3, 0.4],
            signal_variance: 1.0,
        };
        let mut r = Rng::new(3);
        let x: Vec<Vec<f64>> = (0..8).map(|_| r.unit_point(2)).collect();
        let y: Vec<f64> = x.iter().map(|p| (3.0 * p[0]).sin() + p[1]).collect();
        let gp = Gp::new(x, y.clone(), k, 1e-6).expect("gp");
        let best = y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let chosen = vec![vec![0.2, 0.7], vec![0.8, 0.9]];
        let cand = [0.5, 0.95];
        let mut ctx = QeiContext::new(&gp, &chosen, best, 4000, &mut Rng::new(2)).expect("ctx");
        let gain = ctx.log_gain(&cand).exp();
        let pts = [chosen[0].clone(), chosen[1].clone(), cand.to_vec()];
        let (mut kr, mut vs, mut means) = (Vec::new(), Vec::new(), Vec::new());
        for p in &pts {
            let mut v = Vec::new();
            means.push(gp.predict_extending(p, 0, &mut kr, &mut v).0);
            vs.push(v);
        }
        let mut cov = vec![0.0; 9];
        for i in 0..3 {
            for j in 0..3 {
                cov[i * 3 + j] = gp.kernel().eval(&pts[i], &pts[j]) - linalg::dot(&vs[i], &vs[j]);
            }
        }
        let (l, _) = linalg::cholesky_jitter(&cov, 3).expect("chol");
        let mut rr = Rng::new(9);
        let n = 200_000;
        let (mut with, mut without) = (0.0, 0.0);
        for _ in 0..n {
            let z = [rr.normal(), rr.normal(), rr.normal()];
            let f: Vec<f64> = (0..3)
                .map(|i| means[i] + (0..=i).map(|j| l[i * 3 + j] * z[j]).sum::<f64>())
                .collect();
            without += (f[0].max(f[1]) - best).max(0.0);
            with += (f[0].max(f[1]).max(f[2]) - best).max(0.0);
        }
        let brute = (with - without) / n as f64;
        assert!(brute > 1e-3, "{brute}");
        assert!((gain - brute).abs() < 0.05 * brute, "{gain} {brute}");
    }

    /// A candidate at a chosen point adds (almost) nothing: its value is known given the
    /// samples of the chosen points.
    #[test]
    fn a_chosen_point_adds_nothing() {
        let k = Kernel {
            kind: KernelKind::Matern32,
            length_scales: vec![0.3, 0.3],
            signal_variance: 1.0,
        };
        let x = vec![vec![0.1, 0.1], vec![0.9, 0.2], vec![0.4, 0.8]];
        let gp = Gp::new(x, vec![0.0, 0.5, -0.2], k, 1e-6).expect("gp");
        let chosen = vec![vec![0.6, 0.6]];
        let mut ctx = QeiContext::new(&gp, &chosen, 0.5, 256, &mut Rng::new(1)).expect("ctx");
        let near = ctx.log_gain(&[0.6, 0.6]).exp();
        let far = ctx.log_gain(&[0.1, 0.9]).exp();
        assert!(far > 1e-2, "{far}");
        assert!(near < 1e-3 * far, "{near} {far}");
    }
}
