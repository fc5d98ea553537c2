//! Hyperparameter fitting: maximum a posteriori estimate of the log length scales, log signal
//! variance and log noise variance, with weak log-normal priors, box bounds, analytic gradients
//! of the log marginal likelihood, projected L-BFGS, a warm start and random restarts.
//!
//! Parameter vector layout: `theta = [ln l_1, ..., ln l_d, ln s, ln noise]`.

use serde::{Deserialize, Serialize};

use crate::error::{BoError, Result};
use crate::kernel::{Kernel, KernelKind, product_matern32, product_matern32_dlog_l};
use crate::lbfgs;
use crate::linalg;
use crate::rng::Rng;

const LN_2PI: f64 = 1.837_877_066_409_345_3;

/// Priors, bounds and effort of the fit. All on the unit-cube / standardised-output scale.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitSettings {
    /// Mean of the normal prior on `ln l` (default `ln 0.3`).
    pub length_scale_log_mean: f64,
    /// Standard deviation of the normal prior on `ln l` (default 1.0).
    pub length_scale_log_sd: f64,
    /// Bounds on each length scale (default [0.01, 10]).
    pub length_scale_bounds: (f64, f64),
    /// Mean of the normal prior on `ln s` (default 0: s ~ 1 for standardised outputs).
    pub signal_log_mean: f64,
    /// Standard deviation of the normal prior on `ln s` (default 1.5).
    pub signal_log_sd: f64,
    /// Bounds on the signal variance (default [0.01, 100]).
    pub signal_bounds: (f64, f64),
    /// Mean of the normal prior on `ln noise` (default `ln 1e-4`).
    pub noise_log_mean: f64,
    /// Standard deviation of the normal prior on `ln noise` (default 2.0).
    pub noise_log_sd: f64,
    /// Bounds on the noise variance; the lower one is the noise floor (default [1e-6, 1]).
    pub noise_bounds: (f64, f64),
    /// Random restarts drawn from the prior, in addition to the warm start.
    pub restarts: usize,
    /// L-BFGS iterations per start.
    pub max_iter: usize,
    /// L-BFGS iterations when only the warm start is run (rounds without restarts).
    pub warm_max_iter: usize,
}

impl Default for FitSettings {
    fn default() -> Self {
        FitSettings {
            length_scale_log_mean: 0.3f64.ln(),
            length_scale_log_sd: 1.0,
            length_scale_bounds: (0.01, 10.0),
            signal_log_mean: 0.0,
            signal_log_sd: 1.5,
            signal_bounds: (0.01, 100.0),
            noise_log_mean: 1e-4f64.ln(),
            noise_log_sd: 2.0,
            noise_bounds: (1e-6, 1.0),
            restarts: 2,
            max_iter: 50,
            warm_max_iter: 6,
        }
    }
}

impl FitSettings {
    /// Check ranges.
    pub fn validate(&self) -> Result<()> {
        let ok = |b: (f64, f64)| b.0 > 0.0 && b.0 < b.1 && b.1.is_finite();
        if !ok(self.length_scale_bounds) || !ok(self.signal_bounds) || !ok(self.noise_bounds) {
            return Err(BoError::InvalidSetting(
                "hyperparameter bounds must satisfy 0 < lower < upper < inf".into(),
            ));
        }
        if !(self.length_scale_log_sd > 0.0 && self.signal_log_sd > 0.0 && self.noise_log_sd > 0.0)
        {
            return Err(BoError::InvalidSetting("prior sd must be > 0".into()));
        }
        Ok(())
    }

    fn bounds(&self, d: usize) -> (Vec<f64>, Vec<f64>) {
        let mut lo = vec![self.length_scale_bounds.0.ln(); d];
        let mut hi = vec![self.length_scale_bounds.1.ln(); d];
        lo.push(self.signal_bounds.0.ln());
        hi.push(self.signal_bounds.1.ln());
        lo.push(self.noise_bounds.0.ln());
        hi.push(self.noise_bounds.1.ln());
        (lo, hi)
    }

    /// Prior mean of theta (the default start).
    pub fn prior_mean(&self, d: usize) -> Vec<f64> {
        let mut t = vec![self.length_scale_log_mean; d];
        t.push(self.signal_log_mean);
        t.push(self.noise_log_mean);
        t
    }
}

/// Fitted hyperparameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Hyperparameters {
    /// Length scales (unit-cube scale).
    pub length_scales: Vec<f64>,
    /// Signal variance (standardised-output scale).
    pub signal_variance: f64,
    /// Noise variance (standardised-output scale).
    pub noise: f64,
}

impl Hyperparameters {
    /// From the log-parameter vector.
    pub fn from_theta(theta: &[f64]) -> Self {
        let d = theta.len().saturating_sub(2);
        Hyperparameters {
            length_scales: theta[..d].iter().map(|v| v.exp()).collect(),
            signal_variance: theta.get(d).map_or(1.0, |v| v.exp()),
            noise: theta.get(d + 1).map_or(1e-6, |v| v.exp()),
        }
    }

    /// To the log-parameter vector.
    pub fn to_theta(&self) -> Vec<f64> {
        let mut t: Vec<f64> = self.length_scales.iter().map(|v| v.ln()).collect();
        t.push(self.signal_variance.ln());
        t.push(self.noise.ln());
        t
    }

    /// The kernel these hyperparameters define.
    pub fn kernel(&self, kind: KernelKind) -> Kernel {
        Kernel {
            kind,
            length_scales: self.length_scales.clone(),
            signal_variance: self.signal_variance,
        }
    }
}

/// The negative log posterior and its gradient for a fixed data set (pairwise squared
/// differences cached once).
pub struct Objective<'a> {
    kind: KernelKind,
    settings: &'a FitSettings,
    y: &'a [f64],
    n: usize,
    d: usize,
    /// Packed lower triangle (i > j), per dimension: `diff2[p * d + k]`.
    diff2: Vec<f64>,
    /// The same, `|a_k - b_k|` (product kernel only, else empty).
    diff_abs: Vec<f64>,
}

impl<'a> Objective<'a> {
    /// Prepare the objective for data `(x, y)`.
    pub fn new(
        kind: KernelKind,
        settings: &'a FitSettings,
        x: &'a [Vec<f64>],
        y: &'a [f64],
    ) -> Self {
        let n = x.len();
        let d = x.first().map_or(0, |p| p.len());
        let mut diff2 = Vec::with_capacity(n * n.saturating_sub(1) / 2 * d);
        for i in 0..n {
            for j in 0..i {
                for (a, b) in x[i].iter().zip(&x[j]).take(d) {
                    diff2.push((a - b) * (a - b));
                }
            }
        }
        let diff_abs = if kind == KernelKind::ProductMatern32 {
            diff2.iter().map(|v| v.sqrt()).collect()
        } else {
            Vec::new()
        };
        Objective {
            kind,
            settings,
            y,
            n,
            d,
            diff2,
            diff_abs,
        }
    }

    /// Negative log posterior (up to a constant) at `theta`; gradient into `grad`.
    /// Returns +inf when the kernel matrix cannot be factorised.
    pub fn value_grad(&self, theta: &[f64], grad: &mut [f64]) -> f64 {
        let mut ws = Workspace::default();
        let v = self.value(theta, &mut ws);
        self.gradient(theta, &mut ws, grad);
        v
    }

    /// Negative log posterior at `theta`, leaving in `ws` the factorisation that
    /// [`Objective::gradient`] at the same `theta` reuses. +inf when the kernel matrix cannot
    /// be factorised.
    fn value(&self, theta: &[f64], ws: &mut Workspace) -> f64 {
        let (n, d) = (self.n, self.d);
        ws.inv_l2.clear();
        ws.inv_l2
            .extend(theta[..d].iter().map(|t| (-2.0 * t).exp()));
        let s = theta[d].exp();
        let noise = theta[d + 1].exp();
        // Every entry read below is written first (the strict upper triangle of K is never
        // read), so the buffers are only resized, not cleared.
        ws.k.resize(n * n, 0.0);
        ws.gmat.resize(n * n.saturating_sub(1) / 2, 0.0);
        let (k, gmat) = (&mut ws.k, &mut ws.gmat);
        let product = self.kind == KernelKind::ProductMatern32;
        if product {
            ws.inv_l.clear();
            ws.inv_l.extend(theta[..d].iter().map(|t| (-t).exp()));
        }
        let mut p = 0;
        for i in 0..n {
            for j in 0..i {
                if product {
                    let row = &self.diff_abs[p * d..(p + 1) * d];
                    k[i * n + j] =
                        s * product_matern32(row.iter().zip(&ws.inv_l).map(|(a, b)| a * b));
                    p += 1;
                    continue;
                }
                let row = &self.diff2[p * d..(p + 1) * d];
                let r2: f64 = row.iter().zip(&ws.inv_l2).map(|(a, b)| a * b).sum();
                let (rho, g) = self.kind.profile(r2.sqrt());
                k[i * n + j] = s * rho; // lower triangle only: all that is read
                gmat[p] = s * g;
                p += 1;
            }
            k[i * n + i] = s + noise;
        }
        ws.factorised = linalg::cholesky_jitter_into(k, n, &mut ws.l).is_ok();
        if !ws.factorised {
            return f64::INFINITY;
        }
        let l = &ws.l;
        ws.alpha.clear();
        ws.alpha.extend_from_slice(self.y);
        linalg::solve_lower_in_place(l, n, &mut ws.alpha);
        linalg::solve_upper_t_in_place(l, n, &mut ws.alpha);
        let fit: f64 = self.y.iter().zip(&ws.alpha).map(|(a, b)| a * b).sum();
        let logdet: f64 = (0..n).map(|i| l[i * n + i].ln()).sum();
        let nll = 0.5 * fit + logdet + 0.5 * n as f64 * LN_2PI;
        // Priors: normal on each log parameter.
        let mut prior = 0.0;
        for (idx, &t) in theta[..d + 2].iter().enumerate() {
            let (mean, sd) = self.prior(idx);
            let z = (t - mean) / sd;
            prior += 0.5 * z * z;
        }
        nll + prior
    }

    /// Gradient of the negative log posterior at `theta`, the point of the last
    /// [`Objective::value`] call with `ws` (zero where that failed).
    fn gradient(&self, theta: &[f64], ws: &mut Workspace, grad: &mut [f64]) {
        let (n, d) = (self.n, self.d);
        grad.iter_mut().for_each(|g| *g = 0.0);
        if !ws.factorised {
            return;
        }
        let s = theta[d].exp();
        let noise = theta[d + 1].exp();
        // W = alpha alpha^T - K^{-1}; dLML/dtheta = 0.5 tr(W dK/dtheta).
        linalg::inverse_lower_from_cholesky_into(&ws.l, n, &mut ws.lt, &mut ws.kinv);
        let (alpha, kinv, k, gmat, inv_l2) = (&ws.alpha, &ws.kinv, &ws.k, &ws.gmat, &ws.inv_l2);
        let (product, inv_l) = (self.kind == KernelKind::ProductMatern32, &ws.inv_l);
        let mut trace_w = 0.0;
        let mut wsum = 0.0; // sum W_ij K_ij without noise (signal part)
        let mut p = 0;
        for i in 0..n {
            for j in 0..i {
                let w = alpha[i] * alpha[j] - kinv[i * n + j];
                wsum += 2.0 * w * k[i * n + j];
                if product {
                    let row = &self.diff_abs[p * d..(p + 1) * d];
                    let kw = 2.0 * w * k[i * n + j];
                    for kk in 0..d {
                        grad[kk] += kw * product_matern32_dlog_l(row[kk] * inv_l[kk]);
                    }
                    p += 1;
                    continue;
                }
                let gw = 2.0 * w * gmat[p];
                let row = &self.diff2[p * d..(p + 1) * d];
                for kk in 0..d {
                    grad[kk] += gw * row[kk] * inv_l2[kk];
                }
                p += 1;
            }
            let wii = alpha[i] * alpha[i] - kinv[i * n + i];
            trace_w += wii;
            wsum += wii * s;
        }
        // grad holds d(LML); convert to d(NLL) = -0.5 * ...
        for g in grad[..d].iter_mut() {
            *g *= -0.5;
        }
        grad[d] = -0.5 * wsum;
        grad[d + 1] = -0.5 * noise * trace_w;
        // Priors: normal on each log parameter.
        for (idx, &t) in theta[..d + 2].iter().enumerate() {
            let (mean, sd) = self.prior(idx);
            grad[idx] += (t - mean) / sd / sd;
        }
    }

    /// Mean and standard deviation of the normal prior on `theta[idx]`.
    fn prior(&self, idx: usize) -> (f64, f64) {
        let st = self.settings;
        if idx < self.d {
            (st.length_scale_log_mean, st.length_scale_log_sd)
        } else if idx == self.d {
            (st.signal_log_mean, st.signal_log_sd)
        } else {
            (st.noise_log_mean, st.noise_log_sd)
        }
    }
}

/// Buffers of one evaluation of an [`Objective`], kept between evaluations (no allocation per
/// call), with the factorisation computed for the value that the gradient reuses.
#[derive(Default)]
struct Workspace {
    inv_l2: Vec<f64>,
    /// Inverse length scales (product kernel only).
    inv_l: Vec<f64>,
    /// Kernel matrix K (noise on the diagonal), n x n.
    k: Vec<f64>,
    /// `s g(r)` per pair (packed lower triangle).
    gmat: Vec<f64>,
    /// Cholesky factor of K.
    l: Vec<f64>,
    /// K^{-1} y.
    alpha: Vec<f64>,
    /// Scratch and lower triangle of K^{-1} (gradient only).
    lt: Vec<f64>,
    kinv: Vec<f64>,
    /// Whether `l` and `alpha` are valid (the factorisation succeeded).
    factorised: bool,
}

/// An [`Objective`] with its workspace, for the two-step L-BFGS interface.
struct FitProblem<'o, 'a> {
    obj: &'o Objective<'a>,
    ws: Workspace,
}

impl lbfgs::Problem for FitProblem<'_, '_> {
    fn value(&mut self, theta: &[f64]) -> f64 {
        self.obj.value(theta, &mut self.ws)
    }
    fn gradient(&mut self, theta: &[f64], g: &mut [f64]) {
        self.obj.gradient(theta, &mut self.ws, g);
    }
}

/// MAP fit: the best of a local optimisation from `warm` (or the prior mean) and
/// `settings.restarts` starts drawn from the prior. Returns the hyperparameters and the
/// negative log posterior reached.
pub fn fit_map(
    kind: KernelKind,
    settings: &FitSettings,
    x: &[Vec<f64>],
    y: &[f64],
    warm: Option<&Hyperparameters>,
    restarts: usize,
    rng: &mut Rng,
) -> Result<(Hyperparameters, f64)> {
    settings.validate()?;
    let d = x.first().map_or(0, |p| p.len());
    if x.is_empty() || d == 0 {
        return Err(BoError::NotEnoughData(
            "fit needs at least one point".into(),
        ));
    }
    if x.len() != y.len() {
        return Err(BoError::DimensionMismatch {
            expected: x.len(),
            got: y.len(),
        });
    }
    if y.iter().any(|v| !v.is_finite()) || x.iter().flatten().any(|v| !v.is_finite()) {
        return Err(BoError::NonFinite { what: "fit data" });
    }
    let obj = Objective::new(kind, settings, x, y);
    let (lo, hi) = settings.bounds(d);
    let mut starts = Vec::new();
    match warm {
        Some(h) if h.length_scales.len() == d => starts.push(h.to_theta()),
        _ => starts.push(settings.prior_mean(d)),
    }
    for _ in 0..restarts {
        let mut t = settings.prior_mean(d);
        for v in t[..d].iter_mut() {
            *v += settings.length_scale_log_sd * rng.normal();
        }
        t[d] += 0.5 * settings.signal_log_sd * rng.normal();
        starts.push(t);
    }
    let iters = if restarts == 0 && warm.is_some() {
        settings.warm_max_iter.min(settings.max_iter)
    } else {
        settings.max_iter
    };
    let mut best: Option<(Vec<f64>, f64)> = None;
    let mut problem = FitProblem {
        obj: &obj,
        ws: Workspace::default(),
    };
    for s in starts {
        let m = lbfgs::minimize_problem(&mut problem, &s, &lo, &hi, iters, 1e-5);
        if m.f.is_finite() && best.as_ref().is_none_or(|b| m.f < b.1) {
            best = Some((m.x, m.f));
        }
    }
    match best {
        Some((t, f)) => Ok((Hyperparameters::from_theta(&t), f)),
        None => Err(BoError::CholeskyFailed {
            jitter: linalg::JITTER_MAX,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gp::Gp;

    fn data() -> (Vec<Vec<f64>>, Vec<f64>) {
        let mut r = Rng::new(3);
        let x: Vec<Vec<f64>> = (0..15).map(|_| r.unit_point(2)).collect();
        let y: Vec<f64> = x
            .iter()
            .map(|p| (6.0 * p[0]).sin() + 0.3 * p[1] * p[1])
            .collect();
        (x, y)
    }

    #[test]
    fn objective_matches_gp_lml_and_gradient_matches_fd() {
        let (x, y) = data();
        let st = FitSettings::default();
        for kind in [
            KernelKind::Matern32,
            KernelKind::Matern52,
            KernelKind::SquaredExponential,
            KernelKind::ProductMatern32,
        ] {
            let obj = Objective::new(kind, &st, &x, &y);
            let theta = vec![(0.4f64).ln(), (0.9f64).ln(), 0.2, (1e-3f64).ln()];
            let mut g = vec![0.0; 4];
            let f = obj.value_grad(&theta, &mut g);
            let h = Hyperparameters::from_theta(&theta);
            let gp = Gp::new(x.clone(), y.clone(), h.kernel(kind), h.noise).unwrap();
            let prior: f64 = [
                (theta[0] - st.length_scale_log_mean) / st.length_scale_log_sd,
                (theta[1] - st.length_scale_log_mean) / st.length_scale_log_sd,
                (theta[2] - st.signal_log_mean) / st.signal_log_sd,
                (theta[3] - st.noise_log_mean) / st.noise_log_sd,
            ]
            .iter()
            .map(|z| 0.5 * z * z)
            .sum();
            assert!((f - (-gp.log_marginal_likelihood() + prior)).abs() < 1e-8);
            for i in 0..4 {
                let e = 1e-6;
                let mut tp = theta.clone();
                tp[i] += e;
                let mut tm = theta.clone();
                tm[i] -= e;
                let mut dummy = vec![0.0; 4];
                let fd =
                    (obj.value_grad(&tp, &mut dummy) - obj.value_grad(&tm, &mut dummy)) / (2.0 * e);
                assert!(
                    (fd - g[i]).abs() < 1e-4 * fd.abs().max(1.0),
                    "{kind:?} {i} {fd} {}",
                    g[i]
                );
            }
        }
    }

    #[test]
    fn map_fit_improves_on_prior_mean_and_respects_bounds() {
        let (x, y) = data();
        let st = FitSettings::default();
        let mut rng = Rng::new(1);
        let (h, f) = fit_map(KernelKind::Matern52, &st, &x, &y, None, 2, &mut rng).unwrap();
        let obj = Objective::new(KernelKind::Matern52, &st, &x, &y);
        let mut g = vec![0.0; 4];
        let f0 = obj.value_grad(&st.prior_mean(2), &mut g);
        assert!(f <= f0);
        assert!(h.noise >= 1e-6 * 0.999 && h.noise <= 1.0);
        for l in &h.length_scales {
            assert!(*l >= 0.01 * 0.999 && *l <= 10.0 * 1.001);
        }
        // the x1 direction varies more than x2: shorter length scale
        assert!(h.length_scales[0] < h.length_scales[1], "{h:?}");
    }

    #[test]
    fn fit_rejects_bad_data() {
        let st = FitSettings::default();
        let mut rng = Rng::new(1);
        let x = vec![vec![0.1], vec![0.2]];
        assert!(
            fit_map(
                KernelKind::Matern32,
                &st,
                &x,
                &[1.0, f64::NAN],
                None,
                0,
                &mut rng
            )
            .is_err()
        );
        assert!(fit_map(KernelKind::Matern32, &st, &x, &[1.0], None, 0, &mut rng).is_err());
        assert!(fit_map(KernelKind::Matern32, &st, &[], &[], None, 0, &mut rng).is_err());
    }
}
