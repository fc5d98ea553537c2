//! Acquisition functions (maximisation convention): Expected Improvement with an exploration
//! margin `xi` (thesis eq. 3.14-3.15), a numerically stable log-EI with gradient (finite on
//! plateaus where EI underflows to 0), and the upper confidence bound.
//!
//! EI is exactly 0 where the posterior variance is 0 (thesis eq. 3.14), and log-EI is then
//! [`LOG_EI_FLOOR`], a large finite negative number.

use serde::{Deserialize, Serialize};

use crate::special::{dlog_h, h, log_h};

/// Value of log-EI where the posterior variance is 0 (EI = 0): finite, below any attainable
/// log-EI of a positive variance.
pub const LOG_EI_FLOOR: f64 = -1e200;

/// Which acquisition the optimizer maximises.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum AcquisitionKind {
    /// Expected improvement, maximised through its logarithm (log-EI) for numerical
    /// robustness: the same maximiser as EI.
    #[default]
    ExpectedImprovement,
    /// Upper confidence bound `mu + sqrt(beta) sigma`.
    Ucb {
        /// Exploration weight (on the variance).
        beta: f64,
    },
}

/// How `xi` is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum XiRule {
    /// Thesis eq. 3.16: `xi = sigma_f^2 / 100` (sigma_f^2 the fitted signal variance of the
    /// standardised outputs).
    #[default]
    ThesisSignalVariance,
    /// `xi = sigma_f^2 * factor` (factor 0.01 reproduces the thesis rule).
    SignalVarianceTimes(f64),
    /// A fixed `xi` on the standardised-output scale (0 = plain EI).
    Fixed(f64),
}

impl XiRule {
    /// The margin for a fitted signal variance.
    pub fn xi(&self, signal_variance: f64) -> f64 {
        match *self {
            XiRule::ThesisSignalVariance => signal_variance / 100.0,
            XiRule::SignalVarianceTimes(f) => signal_variance * f,
            XiRule::Fixed(x) => x,
        }
    }
}

/// `EI_xi = (mu - best - xi) Phi(z) + sigma phi(z)`, `z = (mu - best - xi) / sigma`;
/// exactly 0 when `var <= 0`.
pub fn expected_improvement(mean: f64, var: f64, best: f64, xi: f64) -> f64 {
    if var.is_nan() || var <= 0.0 {
        return 0.0;
    }
    let sigma = var.sqrt();
    let z = (mean - best - xi) / sigma;
    sigma * h(z)
}

/// `log EI_xi`, computed without underflow; [`LOG_EI_FLOOR`] when `var <= 0`.
pub fn log_expected_improvement(mean: f64, var: f64, best: f64, xi: f64) -> f64 {
    if var.is_nan() || var <= 0.0 {
        return LOG_EI_FLOOR;
    }
    let sigma = var.sqrt();
    let z = (mean - best - xi) / sigma;
    let v = sigma.ln() + log_h(z);
    if v.is_finite() {
        v.max(LOG_EI_FLOOR)
    } else {
        LOG_EI_FLOOR
    }
}

/// log-EI and its gradient from the posterior mean/variance and their gradients.
pub fn log_ei_with_grad(
    mean: f64,
    var: f64,
    dmean: &[f64],
    dvar: &[f64],
    best: f64,
    xi: f64,
    grad: &mut [f64],
) -> f64 {
    if var.is_nan() || var <= 1e-300 {
        grad.iter_mut().for_each(|g| *g = 0.0);
        return LOG_EI_FLOOR;
    }
    let sigma = var.sqrt();
    let z = (mean - best - xi) / sigma;
    let dl = dlog_h(z);
    let d_mu = dl / sigma;
    let d_sigma = (1.0 - dl * z) / sigma;
    for ((g, dm), dv) in grad.iter_mut().zip(dmean).zip(dvar) {
        *g = d_mu * dm + d_sigma * dv / (2.0 * sigma);
    }
    let v = sigma.ln() + log_h(z);
    if v.is_finite() {
        v.max(LOG_EI_FLOOR)
    } else {
        LOG_EI_FLOOR
    }
}

/// Upper confidence bound `mu + sqrt(beta * var)`.
pub fn ucb(mean: f64, var: f64, beta: f64) -> f64 {
    mean + (beta * var.max(0.0)).sqrt()
}

/// UCB and its gradient.
pub fn ucb_with_grad(
    mean: f64,
    var: f64,
    dmean: &[f64],
    dvar: &[f64],
    beta: f64,
    grad: &mut [f64],
) -> f64 {
    let sigma = var.max(0.0).sqrt();
    let k = beta.sqrt();
    for ((g, dm), dv) in grad.iter_mut().zip(dmean).zip(dvar) {
        *g = dm
            + if sigma > 1e-150 {
                k * dv / (2.0 * sigma)
            } else {
                0.0
            };
    }
    mean + k * sigma
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ei_zero_where_variance_zero() {
        assert_eq!(expected_improvement(5.0, 0.0, 1.0, 0.0), 0.0);
        assert_eq!(expected_improvement(-5.0, 0.0, 1.0, 0.01), 0.0);
        assert_eq!(log_expected_improvement(5.0, 0.0, 1.0, 0.0), LOG_EI_FLOOR);
        assert!(expected_improvement(5.0, 1e-12, 1.0, 0.0) > 3.9);
    }

    #[test]
    fn ei_known_value_and_xi_effect() {
        // mu = best, sigma = 1: EI = phi(0) = 0.398942...
        let ei = expected_improvement(0.0, 1.0, 0.0, 0.0);
        assert!((ei - 0.398_942_280_401_432_7).abs() < 1e-12);
        // mu - best = 1, sigma = 2: z = 0.5, EI = Phi(.5) + 2 phi(.5)
        let ei = expected_improvement(1.0, 4.0, 0.0, 0.0);
        let expect = 0.691_462_461_274_013_1 + 2.0 * 0.352_065_326_764_299_5;
        assert!((ei - expect).abs() < 1e-12, "{ei} {expect}");
        assert!(expected_improvement(1.0, 4.0, 0.0, 0.1) < ei);
    }

    #[test]
    fn log_ei_finite_and_consistent() {
        for &(m, v) in &[
            (0.0, 1.0),
            (-3.0, 0.25),
            (2.0, 0.01),
            (-8.0, 1.0),
            (-1.0, 0.04),
        ] {
            let ei = expected_improvement(m, v, 0.0, 0.01);
            let lei = log_expected_improvement(m, v, 0.0, 0.01);
            assert!(ei > 0.0);
            assert!(
                (lei - ei.ln()).abs() < 1e-8 * ei.ln().abs().max(1.0),
                "{m} {v}"
            );
        }
        // plateau: EI underflows to 0, log-EI still finite and ordered
        let a = log_expected_improvement(-100.0, 1e-4, 0.0, 0.0);
        let b = log_expected_improvement(-100.0, 2e-4, 0.0, 0.0);
        assert_eq!(expected_improvement(-100.0, 1e-4, 0.0, 0.0), 0.0);
        assert!(a.is_finite() && b.is_finite() && b > a && a > LOG_EI_FLOOR);
    }

    #[test]
    fn log_ei_gradient_matches_chain_rule_fd() {
        // mean(x) = 2x - 1, var(x) = 0.1 + x^2 in 1D
        let f = |x: f64| log_expected_improvement(2.0 * x - 1.0, 0.1 + x * x, 0.3, 0.01);
        for &x in &[-3.0, -0.5, 0.2, 1.5] {
            let mut g = [0.0];
            log_ei_with_grad(
                2.0 * x - 1.0,
                0.1 + x * x,
                &[2.0],
                &[2.0 * x],
                0.3,
                0.01,
                &mut g,
            );
            let e = 1e-6;
            let fd = (f(x + e) - f(x - e)) / (2.0 * e);
            assert!(
                (fd - g[0]).abs() < 1e-5 * fd.abs().max(1.0),
                "{x} {fd} {}",
                g[0]
            );
        }
    }

    #[test]
    fn ucb_values() {
        assert!((ucb(1.0, 4.0, 4.0) - 5.0).abs() < 1e-15);
        assert_eq!(ucb(1.0, -1.0, 4.0), 1.0);
    }
}
