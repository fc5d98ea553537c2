//! Standard test functions (to be minimised) with their known optimum `f_min`, a normaliser
//! `f_max` (the maximum over the box, or the conventional normaliser) and the normalised regret
//! `(best - f_min) / (f_max - f_min)`.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use crate::error::{BoError, Result};

/// A benchmark function.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum TestFunction {
    /// Branin-Hoo on [-5, 10] x [0, 15]; f* = 0.397887, f_max = 308.129.
    Branin,
    /// Hartmann 3D on [0, 1]^3; f* = -3.86278, normaliser f_max = 0.
    Hartmann3,
    /// Hartmann 6D on [0, 1]^6; f* = -3.32237, f_max = 0 (local minimum at -3.2032).
    Hartmann6,
    /// Rosenbrock 2D on [-2, 2]^2; f* = 0 at (1, 1), f_max = 3609 at (-2, -2).
    Rosenbrock2,
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
    pub const ALL: [TestFunction; 4] = [
        TestFunction::Branin,
        TestFunction::Hartmann3,
        TestFunction::Hartmann6,
        TestFunction::Rosenbrock2,
    ];

    /// Parse a lowercase name (`branin`, `hartmann3`, `hartmann6`, `rosenbrock`).
    pub fn from_name(name: &str) -> Result<Self> {
        match name.to_ascii_lowercase().as_str() {
            "branin" => Ok(TestFunction::Branin),
            "hartmann3" => Ok(TestFunction::Hartmann3),
            "hartmann6" => Ok(TestFunction::Hartmann6),
            "rosenbrock" | "rosenbrock2" => Ok(TestFunction::Rosenbrock2),
            other => Err(BoError::InvalidSetting(format!(
                "unknown test function '{other}' (known: branin, hartmann3, hartmann6, rosenbrock)"
            ))),
        }
    }

    /// Lowercase name.
    pub fn name(self) -> &'static str {
        match self {
            TestFunction::Branin => "branin",
            TestFunction::Hartmann3 => "hartmann3",
            TestFunction::Hartmann6 => "hartmann6",
            TestFunction::Rosenbrock2 => "rosenbrock",
        }
    }

    /// Input dimension.
    pub fn dim(self) -> usize {
        match self {
            TestFunction::Branin | TestFunction::Rosenbrock2 => 2,
            TestFunction::Hartmann3 => 3,
            TestFunction::Hartmann6 => 6,
        }
    }

    /// Box `(lower, upper)`.
    pub fn bounds(self) -> (Vec<f64>, Vec<f64>) {
        match self {
            TestFunction::Branin => (vec![-5.0, 0.0], vec![10.0, 15.0]),
            TestFunction::Hartmann3 => (vec![0.0; 3], vec![1.0; 3]),
            TestFunction::Hartmann6 => (vec![0.0; 6], vec![1.0; 6]),
            TestFunction::Rosenbrock2 => (vec![-2.0; 2], vec![2.0; 2]),
        }
    }

    /// Global minimum value.
    pub fn f_min(self) -> f64 {
        match self {
            TestFunction::Branin => 0.397_887,
            TestFunction::Hartmann3 => -3.862_78,
            TestFunction::Hartmann6 => -3.322_37,
            TestFunction::Rosenbrock2 => 0.0,
        }
    }

    /// Regret normaliser (maximum over the box for Branin and Rosenbrock, 0 for Hartmann).
    pub fn f_max(self) -> f64 {
        match self {
            TestFunction::Branin => 308.129,
            TestFunction::Hartmann3 | TestFunction::Hartmann6 => 0.0,
            TestFunction::Rosenbrock2 => 3609.0,
        }
    }

    /// Normalised regret of a best-so-far value (clamped at 0 from below).
    pub fn regret(self, best: f64) -> f64 {
        ((best - self.f_min()) / (self.f_max() - self.f_min())).max(0.0)
    }

    /// Evaluate (no bounds check; `x` must have `dim()` coordinates, missing ones count as 0).
    pub fn eval(self, x: &[f64]) -> f64 {
        let at = |i: usize| x.get(i).copied().unwrap_or(0.0);
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
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        for f in TestFunction::ALL {
            assert_eq!(TestFunction::from_name(f.name()).unwrap(), f);
        }
        assert!(TestFunction::from_name("nope").is_err());
    }
}
