//! Standard test functions (to be minimised) with their known optimum `f_min`, a normaliser
//! `f_max` (the maximum over the box, or the conventional normaliser) and the normalised regret
//! `(best - f_min) / (f_max - f_min)`.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use crate::error::{BoError, Result};

/// A benchmark function. The optima are the published ones (the source is given for each);
/// `f_max` is the maximum over the box, found here on a fine grid refined by a coordinate
/// search, except where a conventional normaliser is named.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum TestFunction {
    /// Branin-Hoo on [-5, 10] x [0, 15]; f* = 0.397887 at (-pi, 12.275), (pi, 2.275) and
    /// (9.42478, 2.475) (Dixon and Szegö 1978; Surjanovic and Bingham, Virtual Library of
    /// Simulation Experiments, "Branin function"), f_max = 308.129.
    Branin,
    /// Hartmann 3D on [0, 1]^3; f* = -3.86278 at (0.114614, 0.555649, 0.852547) (Dixon and
    /// Szegö 1978; Surjanovic and Bingham, "Hartmann 3-D"), normaliser f_max = 0.
    Hartmann3,
    /// Hartmann 6D on [0, 1]^6; f* = -3.32237 at (0.20169, 0.150011, 0.476874, 0.275332,
    /// 0.311652, 0.6573) (Dixon and Szegö 1978; Surjanovic and Bingham, "Hartmann 6-D"),
    /// f_max = 0 (local minimum at -3.2032).
    Hartmann6,
    /// Rosenbrock 2D on [-2, 2]^2; f* = 0 at (1, 1) (Rosenbrock 1960), f_max = 3609 at
    /// (-2, -2).
    Rosenbrock2,
    /// Six-hump camel on [-3, 3] x [-2, 2]; f* = -1.0316285 at (0.0898420, -0.7126564) and
    /// (-0.0898420, 0.7126564) (Dixon and Szegö 1978; Molga and Smutnicki 2005, "Test
    /// functions for optimization needs"), f_max = 162.9 at (3, 2) and (-3, -2).
    SixHumpCamel,
    /// Goldstein-Price in the log form ln(GP(x)) on [-2, 2]^2 (the raw function spans six
    /// orders of magnitude); GP* = 3 at (0, -1) (Goldstein and Price 1971; Surjanovic and
    /// Bingham, "Goldstein-Price function"), so f* = ln 3; f_max = 13.831079 at
    /// (-1.73737, 2).
    GoldsteinPriceLog,
    /// Michalewicz 2D (m = 10) on [0, pi]^2; f* = -1.8013034 at (2.202906, 1.570796)
    /// (Michalewicz 1996; Surjanovic and Bingham, "Michalewicz function"), f_max = 0 at
    /// (0, 0).
    Michalewicz2,
    /// Ackley 3D (a = 20, b = 0.2, c = 2 pi) on [-32.768, 32.768]^3; f* = 0 at the origin
    /// (Ackley 1987; Surjanovic and Bingham, "Ackley function"), f_max = 22.320335 near
    /// (32.5, 32.5, -32.5).
    Ackley3,
    /// Levy 4D on [-10, 10]^4; f* = 0 at (1, 1, 1, 1) (Laguna and Martí 2005; Surjanovic and
    /// Bingham, "Levy function"), f_max = 254.89843 at (-10, -10, -10, -10).
    Levy4,
    /// Styblinski-Tang 4D on [-5, 5]^4; f* = -39.16617 d = -156.66466 at x_i = -2.903534
    /// (Styblinski and Tang 1990; Surjanovic and Bingham, "Styblinski-Tang function"),
    /// f_max = 125 d = 500 at (5, 5, 5, 5).
    StyblinskiTang4,
}

const H6_A: [[f64; 6]; 4] = [
    [10.0, 3.0, 17.0, 3.5, 1.7, 8.0],
    [0.05, 10.0, 17.0, 0.1, 8.0, 14.0],
    [3.0, 3.5, 1.7, 10.0, 17.0, 8.0],
    [17.0, 8.0, 0.05, 10.0, 0.1, 14.0],
];
const H6_P: [[f64; 6]; 4] = [
    [0.1312, 0.1696, 0.5569, 0.0124, 0.8283, 0.5886],
    [0.2329, 0.4135, 0.8307, 0.3736, 0.1004, 0.9991],
    [0.2348, 0.1451, 0.3522, 0.2883, 0.3047, 0.6650],
    [0.4047, 0.8828, 0.8732, 0.5743, 0.1091, 0.0381],
];
const H3_A: [[f64; 3]; 4] = [
    [3.0, 10.0, 30.0],
    [0.1, 10.0, 35.0],
    [3.0, 10.0, 30.0],
    [0.1, 10.0, 35.0],
];
const H3_P: [[f64; 3]; 4] = [
    [0.3689, 0.1170, 0.2673],
    [0.4699, 0.4387, 0.7470],
    [0.1091, 0.8732, 0.5547],
    [0.0381, 0.5743, 0.8828],
];
const H_ALPHA: [f64; 4] = [1.0, 1.2, 3.0, 3.2];

impl TestFunction {
    /// All functions.
    pub const ALL: [TestFunction; 10] = [
        TestFunction::Branin,
        TestFunction::Hartmann3,
        TestFunction::Hartmann6,
        TestFunction::Rosenbrock2,
        TestFunction::SixHumpCamel,
        TestFunction::GoldsteinPriceLog,
        TestFunction::Michalewicz2,
        TestFunction::Ackley3,
        TestFunction::Levy4,
        TestFunction::StyblinskiTang4,
    ];

    /// Parse a name as given by [`TestFunction::name`] (any case; `rosenbrock2` too).
    pub fn from_name(name: &str) -> Result<Self> {
        let lower = name.to_ascii_lowercase();
        if lower == "rosenbrock2" {
            return Ok(TestFunction::Rosenbrock2);
        }
        Self::ALL
            .into_iter()
            .find(|f| f.name() == lower)
            .ok_or_else(|| {
                let known: Vec<&str> = Self::ALL.iter().map(|f| f.name()).collect();
                BoError::InvalidSetting(format!(
                    "unknown test function '{lower}' (known: {})",
                    known.join(", ")
                ))
            })
    }

    /// Lowercase name.
    pub fn name(self) -> &'static str {
        match self {
            TestFunction::Branin => "branin",
            TestFunction::Hartmann3 => "hartmann3",
            TestFunction::Hartmann6 => "hartmann6",
            TestFunction::Rosenbrock2 => "rosenbrock",
            TestFunction::SixHumpCamel => "sixhumpcamel",
            TestFunction::GoldsteinPriceLog => "goldsteinprice",
            TestFunction::Michalewicz2 => "michalewicz",
            TestFunction::Ackley3 => "ackley",
            TestFunction::Levy4 => "levy",
            TestFunction::StyblinskiTang4 => "styblinskitang",
        }
    }

    /// Input dimension.
    pub fn dim(self) -> usize {
        match self {
            TestFunction::Branin
            | TestFunction::Rosenbrock2
            | TestFunction::SixHumpCamel
            | TestFunction::GoldsteinPriceLog
            | TestFunction::Michalewicz2 => 2,
            TestFunction::Hartmann3 | TestFunction::Ackley3 => 3,
            TestFunction::Levy4 | TestFunction::StyblinskiTang4 => 4,
            TestFunction::Hartmann6 => 6,
        }
    }

    /// Box `(lower, upper)`.
    pub fn bounds(self) -> (Vec<f64>, Vec<f64>) {
        let d = self.dim();
        let (lo, hi) = match self {
            TestFunction::Branin => return (vec![-5.0, 0.0], vec![10.0, 15.0]),
            TestFunction::SixHumpCamel => return (vec![-3.0, -2.0], vec![3.0, 2.0]),
            TestFunction::Hartmann3 | TestFunction::Hartmann6 => (0.0, 1.0),
            TestFunction::Rosenbrock2 | TestFunction::GoldsteinPriceLog => (-2.0, 2.0),
            TestFunction::Michalewicz2 => (0.0, PI),
            TestFunction::Ackley3 => (-32.768, 32.768),
            TestFunction::Levy4 => (-10.0, 10.0),
            TestFunction::StyblinskiTang4 => (-5.0, 5.0),
        };
        (vec![lo; d], vec![hi; d])
    }

    /// Global minimum value.
    pub fn f_min(self) -> f64 {
        match self {
            TestFunction::Branin => 0.397_887,
            TestFunction::Hartmann3 => -3.862_78,
            TestFunction::Hartmann6 => -3.322_37,
            TestFunction::Rosenbrock2 | TestFunction::Ackley3 | TestFunction::Levy4 => 0.0,
            TestFunction::SixHumpCamel => -1.031_628_5,
            TestFunction::GoldsteinPriceLog => 3.0_f64.ln(),
            TestFunction::Michalewicz2 => -1.801_303_4,
            TestFunction::StyblinskiTang4 => -39.166_165_7 * 4.0,
        }
    }

    /// Regret normaliser: the maximum over the box, or 0 for Hartmann (conventional).
    pub fn f_max(self) -> f64 {
        match self {
            TestFunction::Branin => 308.129,
            TestFunction::Hartmann3 | TestFunction::Hartmann6 | TestFunction::Michalewicz2 => 0.0,
            TestFunction::Rosenbrock2 => 3609.0,
            TestFunction::SixHumpCamel => 162.9,
            TestFunction::GoldsteinPriceLog => 13.831_079,
            TestFunction::Ackley3 => 22.320_335,
            TestFunction::Levy4 => 254.898_43,
            TestFunction::StyblinskiTang4 => 500.0,
        }
    }

    /// Normalised regret of a best-so-far value (clamped at 0 from below).
    pub fn regret(self, best: f64) -> f64 {
        ((best - self.f_min()) / (self.f_max() - self.f_min())).max(0.0)
    }

    /// Evaluate (no bounds check; `x` must have `dim()` coordinates, missing ones count as 0).
    pub fn eval(self, x: &[f64]) -> f64 {
        let d = self.dim();
        let at = |i: usize| x.get(i).copied().unwrap_or(0.0);
        let xs = || (0..d).map(at);
        match self {
            TestFunction::Branin => {
                let (x1, x2) = (at(0), at(1));
                let b = 5.1 / (4.0 * PI * PI);
                let c = 5.0 / PI;
                let t = 1.0 / (8.0 * PI);
                (x2 - b * x1 * x1 + c * x1 - 6.0).powi(2) + 10.0 * (1.0 - t) * x1.cos() + 10.0
            }
            TestFunction::Hartmann3 => -(0..4)
                .map(|i| {
                    let s: f64 = (0..3)
                        .map(|j| H3_A[i][j] * (at(j) - H3_P[i][j]).powi(2))
                        .sum();
                    H_ALPHA[i] * (-s).exp()
                })
                .sum::<f64>(),
            TestFunction::Hartmann6 => -(0..4)
                .map(|i| {
                    let s: f64 = (0..6)
                        .map(|j| H6_A[i][j] * (at(j) - H6_P[i][j]).powi(2))
                        .sum();
                    H_ALPHA[i] * (-s).exp()
                })
                .sum::<f64>(),
            TestFunction::Rosenbrock2 => {
                let (a, b) = (at(0), at(1));
                (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2)
            }
            TestFunction::SixHumpCamel => {
                let (a, b) = (at(0), at(1));
                (4.0 - 2.1 * a * a + a.powi(4) / 3.0) * a * a + a * b + (4.0 * b * b - 4.0) * b * b
            }
            TestFunction::GoldsteinPriceLog => {
                let (a, b) = (at(0), at(1));
                let p = 1.0
                    + (a + b + 1.0).powi(2)
                        * (19.0 - 14.0 * a + 3.0 * a * a - 14.0 * b + 6.0 * a * b + 3.0 * b * b);
                let q = 30.0
                    + (2.0 * a - 3.0 * b).powi(2)
                        * (18.0 - 32.0 * a + 12.0 * a * a + 48.0 * b - 36.0 * a * b + 27.0 * b * b);
                (p * q).ln()
            }
            TestFunction::Michalewicz2 => -xs()
                .enumerate()
                .map(|(i, v)| v.sin() * ((i + 1) as f64 * v * v / PI).sin().powi(20))
                .sum::<f64>(),
            TestFunction::Ackley3 => {
                let n = d as f64;
                let sq = xs().map(|v| v * v).sum::<f64>() / n;
                let cs = xs().map(|v| (2.0 * PI * v).cos()).sum::<f64>() / n;
                -20.0 * (-0.2 * sq.sqrt()).exp() - cs.exp() + 20.0 + std::f64::consts::E
            }
            TestFunction::Levy4 => {
                let w = |i: usize| 1.0 + (at(i) - 1.0) / 4.0;
                let inner: f64 = (0..d - 1)
                    .map(|i| (w(i) - 1.0).powi(2) * (1.0 + 10.0 * (PI * w(i) + 1.0).sin().powi(2)))
                    .sum();
                let last = w(d - 1);
                (PI * w(0)).sin().powi(2)
                    + inner
                    + (last - 1.0).powi(2) * (1.0 + (2.0 * PI * last).sin().powi(2))
            }
            TestFunction::StyblinskiTang4 => {
                0.5 * xs()
                    .map(|v| v.powi(4) - 16.0 * v * v + 5.0 * v)
                    .sum::<f64>()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn known_optima() {
        let b = TestFunction::Branin;
        assert!((b.eval(&[PI, 2.275]) - 0.397_887).abs() < 1e-6);
        assert!((b.eval(&[-PI, 12.275]) - 0.397_887).abs() < 1e-6);
        assert!((b.eval(&[-5.0, 0.0]) - 308.129).abs() < 1e-3);
        let h6 = TestFunction::Hartmann6;
        let xs = [0.20169, 0.150011, 0.476874, 0.275332, 0.311652, 0.6573];
        assert!((h6.eval(&xs) - (-3.32237)).abs() < 1e-5);
        let h3 = TestFunction::Hartmann3;
        assert!((h3.eval(&[0.114614, 0.555649, 0.852547]) - (-3.86278)).abs() < 1e-5);
        assert_eq!(TestFunction::Rosenbrock2.eval(&[1.0, 1.0]), 0.0);
        assert_eq!(TestFunction::Rosenbrock2.eval(&[-2.0, -2.0]), 3609.0);
        assert!((h6.regret(-3.2032) - 0.0359).abs() < 1e-3);
    }

    /// Each function at its published minimiser gives its f_min (to the literature's
    /// precision), at the point named in its doc its f_max, and nowhere on a grid of the box
    /// less than f_min or more than f_max.
    #[test]
    fn the_suite_functions_reach_their_published_optima() {
        let cases: [(TestFunction, &[f64], f64); 8] = [
            (
                TestFunction::SixHumpCamel,
                &[0.089_842_0, -0.712_656_4],
                1e-7,
            ),
            (
                TestFunction::SixHumpCamel,
                &[-0.089_842_0, 0.712_656_4],
                1e-7,
            ),
            (TestFunction::GoldsteinPriceLog, &[0.0, -1.0], 1e-12),
            (TestFunction::Michalewicz2, &[2.202_906, FRAC_PI_2], 1e-6),
            (TestFunction::Ackley3, &[0.0; 3], 1e-12),
            (TestFunction::Levy4, &[1.0; 4], 1e-12),
            (TestFunction::StyblinskiTang4, &[-2.903_534; 4], 1e-4),
            (TestFunction::Branin, &[9.424_78, 2.475], 1e-5),
        ];
        for (f, x, tol) in cases {
            let v = f.eval(x);
            assert!(
                (v - f.f_min()).abs() < tol,
                "{}: {v} vs {}",
                f.name(),
                f.f_min()
            );
            assert!(f.regret(v) < 1e-6, "{}", f.name());
        }
        assert!((TestFunction::GoldsteinPriceLog.f_min() - 1.098_612).abs() < 1e-6);
        let maxima: [(TestFunction, &[f64]); 5] = [
            (TestFunction::SixHumpCamel, &[3.0, 2.0]),
            (TestFunction::GoldsteinPriceLog, &[-1.737_37, 2.0]),
            (
                TestFunction::Ackley3,
                &[32.500_414, 32.500_414, -32.500_414],
            ),
            (TestFunction::Levy4, &[-10.0; 4]),
            (TestFunction::StyblinskiTang4, &[5.0; 4]),
        ];
        for (f, x) in maxima {
            let v = f.eval(x);
            assert!(
                (v - f.f_max()).abs() < 1e-5,
                "{}: {v} vs {}",
                f.name(),
                f.f_max()
            );
        }
        for f in TestFunction::ALL {
            let (lo, hi) = f.bounds();
            let d = f.dim();
            assert_eq!((lo.len(), hi.len()), (d, d));
            let n: usize = if d <= 2 { 61 } else { 9 };
            for k in 0..n.pow(d as u32) {
                let x: Vec<f64> = (0..d)
                    .map(|j| {
                        let i = (k / n.pow(j as u32)) % n;
                        lo[j] + (hi[j] - lo[j]) * i as f64 / (n - 1) as f64
                    })
                    .collect();
                let v = f.eval(&x);
                assert!(v >= f.f_min() - 1e-6, "{} at {x:?}: {v}", f.name());
                assert!(v <= f.f_max() + 1e-4, "{} at {x:?}: {v}", f.name());
            }
        }
    }

    #[test]
    fn names_round_trip() {
        for f in TestFunction::ALL {
            assert_eq!(TestFunction::from_name(f.name()).unwrap(), f);
            assert_eq!(
                TestFunction::from_name(&f.name().to_uppercase()).unwrap(),
                f
            );
        }
        assert_eq!(
            TestFunction::from_name("rosenbrock2").unwrap(),
            TestFunction::Rosenbrock2
        );
        let names: std::collections::HashSet<&str> =
            TestFunction::ALL.iter().map(|f| f.name()).collect();
        assert_eq!(names.len(), TestFunction::ALL.len());
        let e = TestFunction::from_name("nope").unwrap_err().to_string();
        assert!(e.contains("'nope'") && e.contains("styblinskitang"), "{e}");
    }
}
