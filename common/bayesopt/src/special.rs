//! Special functions needed by the acquisition functions: `erfc`, the scaled `erfcx`, the
//! standard normal pdf/cdf and a numerically stable `log(phi(z) + z Phi(z))` (the core of log-EI).

use std::f64::consts::PI;

const SQRT_2: f64 = std::f64::consts::SQRT_2;
/// ln(sqrt(2 pi)).
const LN_SQRT_2PI: f64 = 0.918_938_533_204_672_8;

/// Below this `erfc` uses the Taylor series of `erf`, above it a continued fraction.
const SERIES_LIMIT: f64 = 2.0;

fn erf_series(x: f64) -> f64 {
    // erf(x) = 2/sqrt(pi) * sum_n (-1)^n x^(2n+1) / (n! (2n+1))
    let x2 = x * x;
    let mut term = x; // (-1)^n x^(2n+1) / n!
    let mut sum = x;
    let mut n = 0.0;
    loop {
        n += 1.0;
        term *= -x2 / n;
        let add = term / (2.0 * n + 1.0);
        sum += add;
        if add.abs() <= 1e-17 * sum.abs() || n > 200.0 {
            break;
        }
    }
    sum * 2.0 / PI.sqrt()
}

/// `erfcx(x) = exp(x^2) erfc(x)` for `x >= SERIES_LIMIT`, by the Laplace continued fraction
/// evaluated with the modified Lentz method.
fn erfcx_cf(x: f64) -> f64 {
    // erfc(x) = exp(-x^2)/sqrt(pi) * 1/(x + (1/2)/(x + 1/(x + (3/2)/(x + 2/(x + ...)))))
    if x > 1e8 {
        return 1.0 / (x * PI.sqrt());
    }
    let tiny = 1e-300;
    let mut f = x;
    let mut c = x;
    let mut d = 0.0;
    for k in 1..500 {
        let a = k as f64 * 0.5;
        d = x + a * d;
        if d.abs() < tiny {
            d = tiny;
        }
        c = x + a / c;
        if c.abs() < tiny {
            c = tiny;
        }
        d = 1.0 / d;
        let delta = c * d;
        f *= delta;
        if (delta - 1.0).abs() < 1e-16 {
            break;
        }
    }
    1.0 / (f * PI.sqrt())
}

/// Complementary error function, relative accuracy about 1e-13 or better over the real line.
pub fn erfc(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x < 0.0 {
        return 2.0 - erfc(-x);
    }
    if x < SERIES_LIMIT {
        1.0 - erf_series(x)
    } else if x > 27.3 {
        0.0
    } else {
        (-x * x).exp() * erfcx_cf(x)
    }
}

/// Scaled complementary error function `exp(x^2) erfc(x)`, finite for all x >= 0 (it is used
/// only for non-negative arguments here; negative arguments are computed directly).
pub fn erfcx(x: f64) -> f64 {
    if x < SERIES_LIMIT {
        (x * x).exp() * erfc(x)
    } else {
        erfcx_cf(x)
    }
}

/// Standard normal density.
pub fn norm_pdf(z: f64) -> f64 {
    (-0.5 * z * z - LN_SQRT_2PI).exp()
}

/// Log of the standard normal density.
pub fn log_norm_pdf(z: f64) -> f64 {
    -0.5 * z * z - LN_SQRT_2PI
}

/// Standard normal cumulative distribution.
pub fn norm_cdf(z: f64) -> f64 {
    0.5 * erfc(-z / SQRT_2)
}

/// Mills-type ratio `Phi(z) / phi(z)` for `z <= 0`, finite however negative z is.
fn cdf_over_pdf_neg(z: f64) -> f64 {
    (PI / 2.0).sqrt() * erfcx(-z / SQRT_2)
}

/// `h(z) = phi(z) + z Phi(z)`, the standardised expected improvement (>= 0).
pub fn h(z: f64) -> f64 {
    if z < -40.0 {
        0.0
    } else {
        (norm_pdf(z) + z * norm_cdf(z)).max(0.0)
    }
}

/// `log h(z)` computed without underflow: finite for every finite z (about `-z^2/2 - 2 ln|z|`
/// for very negative z), so log-EI keeps a slope on plateaus where EI itself is 0.
pub fn log_h(z: f64) -> f64 {
    if z > -1.0 {
        return h(z).ln();
    }
    if z < -1e6 {
        // Asymptotic: h(z) ~ phi(z) / z^2.
        return log_norm_pdf(z) - 2.0 * (-z).ln();
    }
    // h(z) = phi(z) (1 + z m(z)), m = Phi/phi; 1 + z m > 0 but suffers some cancellation.
    let r = 1.0 + z * cdf_over_pdf_neg(z);
    let r = if r > 0.0 { r } else { 1.0 / (z * z) };
    log_norm_pdf(z) + r.ln()
}

/// Derivatives of `log h(z)` with respect to z: `Phi(z) / h(z)`, computed stably.
pub fn dlog_h(z: f64) -> f64 {
    if z > -1.0 {
        let hz = h(z);
        if hz > 0.0 {
            return norm_cdf(z) / hz;
        }
        return -z;
    }
    if z < -1e6 {
        return -z;
    }
    let m = cdf_over_pdf_neg(z);
    let r = 1.0 + z * m;
    if r > 0.0 { m / r } else { -z }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    #[test]
    fn erfc_known_values() {
        assert!(rel(erfc(0.5), 0.479_500_122_186_953_5) < 1e-13);
        assert!(rel(erfc(1.0), 0.157_299_207_050_285_13) < 1e-13);
        assert!(rel(erfc(1.9), 0.007_209_570_764_742_524) < 1e-11);
        assert!(rel(erfc(2.0), 0.004_677_734_981_047_266) < 1e-12);
        assert!(rel(erfc(3.0), 2.209_049_699_858_544e-5) < 1e-12);
        assert!(rel(erfc(5.0), 1.537_459_794_428_035e-12) < 1e-12);
        assert!(rel(erfc(-1.0), 1.842_700_792_949_715) < 1e-14);
        assert_eq!(erfc(0.0), 1.0);
    }

    #[test]
    fn cdf_symmetry_and_values() {
        assert!((norm_cdf(0.0) - 0.5).abs() < 1e-15);
        assert!(rel(norm_cdf(1.96), 0.975_002_104_851_780) < 1e-12);
        assert!(rel(norm_cdf(-3.0), 0.001_349_898_031_630_094_6) < 1e-11);
    }

    #[test]
    fn log_h_matches_direct_and_stays_finite() {
        for &z in &[-30.0, -10.0, -5.0, -2.0, -1.0001, -0.5, 0.0, 1.0, 3.0] {
            let direct = h(z).ln();
            assert!(
                (log_h(z) - direct).abs() < 1e-9 * direct.abs().max(1.0),
                "z={z}"
            );
        }
        for &z in &[-50.0, -1e3, -1e5, -1e7, -1e150] {
            let l = log_h(z);
            assert!(l.is_finite() && l < 0.0, "z={z} {l}");
        }
        // monotone increasing
        let mut prev = f64::NEG_INFINITY;
        for i in 0..200 {
            let z = -100.0 + i as f64;
            let l = log_h(z);
            assert!(l > prev);
            prev = l;
        }
    }

    #[test]
    fn dlog_h_matches_finite_difference() {
        for &z in &[-40.0, -8.0, -2.0, -0.5, 0.3, 2.0] {
            let e = 1e-6;
            let fd = (log_h(z + e) - log_h(z - e)) / (2.0 * e);
            assert!(
                (fd - dlog_h(z)).abs() < 1e-5 * fd.abs().max(1.0),
                "z={z} {fd} {}",
                dlog_h(z)
            );
        }
    }
}
