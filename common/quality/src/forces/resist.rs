//! The least-norm contact forces that resist an external wrench, as a second-order cone
//! program solved by Clarabel.
//!
//! Each contact `i` has a normal force `f_n`, for friction models with `mu > 0` two
//! tangential components `(a, b)` along the tangent basis `(t1, t2)` of its normal (so
//! `f_i = f_n n + a t1 + b t2`), and for soft fingers with `gamma > 0` a torsion
//! `torsion_i = gamma s_i`, where `s_i` (N) is the torsion expressed as the normal force
//! that carries it at the limit of the torsional cone. The program is
//!
//! minimise `t` subject to
//! - equilibrium: `sum_i (f_i, (p_i - c) x f_i + gamma s_i n_i) = -external`;
//! - the cones: `f_n >= 0` (frictionless or `mu = 0`), `||(a, b)|| <= mu f_n`, and
//!   `|s_i| <= f_n` (soft finger);
//! - `||x|| <= t`, `x` every contact variable stacked: `t^2 = sum_i (|f_i|^2 + s_i^2)`,
//!   the squared Euclidean norm of the contact forces plus, for soft fingers, the
//!   squared torsions divided by `gamma^2`.
//!
//! The cone on `t` makes the objective the norm itself rather than its square, so the
//! solver's tolerance applies to it directly. The solver's tolerances are absolute, so
//! lengths are first divided by a power of two near the largest of `|p_i - c|` and
//! `gamma`, and forces by a power of two near the external wrench (exact in floating
//! point): the result does not depend on the units of the input.
//!
//! An interior-point solver can stop without an answer near its tolerance on a program
//! with dozens of nearly parallel contacts (the surface model's): `InsufficientProgress` or
//! `NumericalError`, in 21 of 147,798 analyses of Barrett-hand trials on the mug, sphere and
//! rotated cuboid (issue 29). The same program is then solved again in other ways
//! ([`ATTEMPTS`]): with more regularization, scaled to a unit load (not a power of two, so
//! every number rounds differently), and last to Clarabel's default tolerance (1e-8). When
//! every way stops, the answer is [`Resisting::Unavailable`] with how each ended: the
//! program was not decided, which says nothing about the grasp.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use nalgebra::Vector3;

use super::{ContactForces, check_external, validate_grasp};
use crate::contact::{Contact, FrictionModel, tangent_basis};
use crate::error::QualityError;
use crate::hull::power_of_two_scale;
use crate::wrench::{Wrench, force, torque};

/// One way of solving the program, tried in turn while the solver stops without an answer.
#[derive(Debug, Clone, Copy)]
struct Attempt {
    /// What the attempt changes, for the reason of an unavailable answer.
    what: &'static str,
    /// Solver tolerance (gap and feasibility), relative to the scaled data (of order 1).
    tolerance: f64,
    /// The tolerance of a solution the solver reports as almost solved (Clarabel's
    /// default, 5e-5, would let the forces miss equilibrium by that much).
    reduced: f64,
    /// Clarabel's static regularization of the KKT system (its default is 1e-8).
    regularization: f64,
    /// Forces over the norm of the external wrench (a unit load) rather than over a power
    /// of two near its largest component.
    unit_load: bool,
}

/// The ways of solving the program, in order (see the module documentation). Each of the
/// retries alone gave forces on all 21 trials of the mug, sphere and rotated cuboid that
/// stopped the first (`examples/force_failures.rs` in graspopt-trial; docs/benchmarks.md).
const ATTEMPTS: [Attempt; 4] = [
    Attempt {
        what: "as posed",
        tolerance: 1e-10,
        reduced: 1e-8,
        regularization: 1e-8,
        unit_load: false,
    },
    Attempt {
        what: "with 10 times the regularization",
        tolerance: 1e-10,
        reduced: 1e-8,
        regularization: 1e-7,
        unit_load: false,
    },
    Attempt {
        what: "scaled to a unit load",
        tolerance: 1e-10,
        reduced: 1e-8,
        regularization: 1e-8,
        unit_load: true,
    },
    Attempt {
        what: "to tolerance 1e-8",
        tolerance: 1e-8,
        reduced: 1e-8,
        regularization: 1e-8,
        unit_load: true,
    },
];

/// The outcome of [`resisting_forces`].
#[derive(Debug, Clone, PartialEq)]
pub enum Resisting {
    /// The least-norm contact forces inside the friction cones that cancel the external
    /// wrench, and their norm `sqrt(sum_i |f_i|^2 + (torsion_i / gamma)^2)` (N).
    Forces { forces: ContactForces, norm: f64 },
    /// No contact forces inside the friction cones cancel the external wrench: the grasp
    /// cannot hold the object against it. `reason` says how the solver concluded so.
    CannotResist { reason: String },
    /// The solver stopped without an answer in every way the program was tried (numerical
    /// trouble, which says nothing about the grasp): `reason` names each way and how it
    /// ended.
    Unavailable { reason: String },
}

/// The contact forces of least norm, each inside its exact friction cone under `model`,
/// whose net wrench on the object about `reference_point` cancels `external` (the
/// wrench the world applies to the object, e.g. [`super::gravity_wrench`]); see the
/// module documentation for the program, its objective and how a numerical failure is
/// retried. A zero external wrench needs zero forces.
pub fn resisting_forces(
    contacts: &[Contact],
    model: &FrictionModel,
    external: &Wrench,
    reference_point: &Vector3<f64>,
) -> Result<Resisting, QualityError> {
    validate_grasp(contacts, reference_point)?;
    model.validate()?;
    check_external(external)?;
    let (mu, gamma) = match *model {
        FrictionModel::Frictionless => (0.0, 0.0),
        FrictionModel::PointFriction { mu, .. } => (mu, 0.0),
        FrictionModel::SoftFinger { mu, gamma, .. } => (mu, gamma),
    };
    if external.iter().all(|&x| x == 0.0) {
        return Ok(Resisting::Forces {
            forces: ContactForces::without_torsion(vec![Vector3::zeros(); contacts.len()]),
            norm: 0.0,
        });
    }
    // Units: lengths over `length`, forces over `unit`, torques over `unit * length`.
    let arms: Vec<Vector3<f64>> = contacts
        .iter()
        .map(|c| c.position - reference_point)
        .collect();
    let length = power_of_two_scale(
        arms.iter()
            .flat_map(|r| r.iter())
            .fold(gamma, |s, x| s.max(x.abs())),
    );
    let w_force = force(external);
    let w_torque = torque(external) / length;
    let mut problem = Problem {
        contacts,
        arms: arms.iter().map(|r| r / length).collect(),
        mu,
        gamma: gamma / length,
        external: [w_force, w_torque],
    };
    let mut stopped = Vec::new();
    for attempt in &ATTEMPTS {
        let mut unit = power_of_two_scale(w_force.amax().max(w_torque.amax()));
        if attempt.unit_load {
            // The norm of the wrench already scaled by a power of two (no underflow).
            unit *= ((w_force / unit).norm_squared() + (w_torque / unit).norm_squared()).sqrt();
        }
        problem.external = [w_force / unit, w_torque / unit];
        match problem.solve(attempt) {
            Solved::Point(x) => match problem.forces(&x, unit, gamma) {
                Some(forces) => return Ok(forces),
                None => stopped.push(format!("{}: a solution that is not finite", attempt.what)),
            },
            Solved::Infeasible(reason) => return Ok(Resisting::CannotResist { reason }),
            Solved::Stopped(why) => stopped.push(format!("{}: {why}", attempt.what)),
        }
    }
    Ok(Resisting::Unavailable {
        reason: format!(
            "the conic solver stopped without an answer in each of the {} ways it was tried ({})",
            ATTEMPTS.len(),
            stopped.join("; ")
        ),
    })
}

/// How one solve ended.
enum Solved {
    /// The solver's variables.
    Point(Vec<f64>),
    /// The solver proved the program infeasible: why, for people.
    Infeasible(String),
    /// The solver stopped without an answer (or could not start): its status.
    Stopped(String),
}

/// The program in scaled units.
struct Problem<'a> {
    contacts: &'a [Contact],
    /// `(p_i - c) / length`.
    arms: Vec<Vector3<f64>>,
    mu: f64,
    /// `gamma / length`.
    gamma: f64,
    /// The external force over `unit`, its torque over `unit * length`.
    external: [Vector3<f64>; 2],
}

/// The columns of one contact's variables.
struct Variables {
    normal: usize,
    /// `a`; `b` is the next column.
    tangent: Option<usize>,
    torsion: Option<usize>,
}

impl Problem<'_> {
    fn tangential(&self) -> bool {
        self.mu > 0.0
    }

    fn torsional(&self) -> bool {
        self.gamma > 0.0
    }

    fn per_contact(&self) -> usize {
        1 + 2 * usize::from(self.tangential()) + usize::from(self.torsional())
    }

    /// The number of variables.
    fn columns(&self) -> usize {
        1 + self.contacts.len() * self.per_contact()
    }

    /// Contact `i`'s columns; column 0 is `t`.
    fn variables(&self, i: usize) -> Variables {
        let normal = 1 + i * self.per_contact();
        let tangent = self.tangential().then_some(normal + 1);
        let torsion = self
            .torsional()
            .then_some(normal + 1 + 2 * usize::from(self.tangential()));
        Variables {
            normal,
            tangent,
            torsion,
        }
    }

    /// The contact forces of the solver's point `x` in the units of the input (`unit`: the
    /// force unit, `gamma` unscaled), or `None` if they are not finite.
    fn forces(&self, x: &[f64], unit: f64, gamma: f64) -> Option<Resisting> {
        let m = self.contacts.len();
        let mut forces = Vec::with_capacity(m);
        let mut torsions = Vec::with_capacity(m);
        let mut norm2 = 0.0;
        for (i, c) in self.contacts.iter().enumerate() {
            // The solver's point, moved onto its cones where it is outside them (by at
            // most the solver's tolerance), so that every slip margin is >= 0.
            let v = self.variables(i);
            let normal = x[v.normal].max(0.0);
            let (t1, t2) = tangent_basis(&c.normal);
            let mut f = c.normal * normal;
            if let Some(a) = v.tangent {
                let tangential = t1 * x[a] + t2 * x[a + 1];
                let (limit, magnitude) = (self.mu * normal, tangential.norm());
                f += if magnitude > limit {
                    tangential * (limit / magnitude)
                } else {
                    tangential
                };
            }
            let s = v.torsion.map_or(0.0, |s| x[s].clamp(-normal, normal));
            norm2 += f.norm_squared() + s * s;
            forces.push(f * unit);
            torsions.push(gamma * s * unit);
        }
        let norm = norm2.sqrt() * unit;
        let finite = norm.is_finite() && torsions.iter().all(|t| t.is_finite());
        finite.then(|| Resisting::Forces {
            forces: ContactForces::new(forces, torsions),
            norm,
        })
    }

    /// The constraints `A x + s = b`, `s` in the cones: equilibrium, the friction cones
    /// and the objective's cone.
    fn constraints(&self) -> (CscMatrix<f64>, Vec<f64>, Vec<SupportedConeT<f64>>) {
        let m = self.contacts.len();
        let n = self.columns();
        let mut a = Triplets::default();
        // Zero cone, rows 0..6: the contact wrenches sum to -external.
        for (i, contact) in self.contacts.iter().enumerate() {
            let v = self.variables(i);
            let nrm = &contact.normal;
            let r = &self.arms[i];
            a.wrench_column(v.normal, nrm, &r.cross(nrm));
            if let Some(t) = v.tangent {
                let (t1, t2) = tangent_basis(nrm);
                a.wrench_column(t, &t1, &r.cross(&t1));
                a.wrench_column(t + 1, &t2, &r.cross(&t2));
            }
            if let Some(s) = v.torsion {
                a.wrench_column(s, &Vector3::zeros(), &(nrm * self.gamma));
            }
        }
        let mut row = 6;
        // Nonnegative cone: f_n >= 0 without friction; f_n - s >= 0 and f_n + s >= 0
        // for the torsion.
        let mut nonnegative = 0;
        for i in 0..m {
            let v = self.variables(i);
            if v.tangent.is_none() {
                a.push(row, v.normal, -1.0);
                row += 1;
                nonnegative += 1;
            }
            if let Some(s) = v.torsion {
                for sign in [1.0, -1.0] {
                    a.push(row, v.normal, -1.0);
                    a.push(row, s, sign);
                    row += 1;
                    nonnegative += 1;
                }
            }
        }
        let mut cones = vec![
            SupportedConeT::ZeroConeT(6),
            SupportedConeT::NonnegativeConeT(nonnegative),
        ];
        // Second-order cones (mu f_n, a, b), one per contact with friction.
        for i in 0..m {
            let v = self.variables(i);
            if let Some(t) = v.tangent {
                a.push(row, v.normal, -self.mu);
                a.push(row + 1, t, -1.0);
                a.push(row + 2, t + 1, -1.0);
                row += 3;
                cones.push(SupportedConeT::SecondOrderConeT(3));
            }
        }
        // The objective's cone (t, x).
        for k in 0..n {
            a.push(row + k, k, -1.0);
        }
        row += n;
        cones.push(SupportedConeT::SecondOrderConeT(n));
        let a = CscMatrix::new_from_triplets(row, n, a.rows, a.cols, a.vals);
        let mut b = vec![0.0; row];
        for k in 0..3 {
            b[k] = -self.external[0][k];
            b[3 + k] = -self.external[1][k];
        }
        (a, b, cones)
    }

    /// Solves the program as `attempt` says.
    fn solve(&self, attempt: &Attempt) -> Solved {
        let n = self.columns();
        let (a, b, cones) = self.constraints();
        let p = CscMatrix::zeros((n, n));
        let mut q = vec![0.0; n];
        q[0] = 1.0;
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .static_regularization_constant(attempt.regularization)
            .tol_gap_abs(attempt.tolerance)
            .tol_gap_rel(attempt.tolerance)
            .tol_feas(attempt.tolerance)
            .reduced_tol_gap_abs(attempt.reduced)
            .reduced_tol_gap_rel(attempt.reduced)
            .reduced_tol_feas(attempt.reduced)
            .build();
        let solver = settings
            .map_err(|e| format!("settings {e:?}"))
            .and_then(|s| {
                DefaultSolver::new(&p, &q, &a, &b, &cones, s).map_err(|e| format!("{e:?}"))
            });
        let mut solver = match solver {
            Ok(solver) => solver,
            Err(why) => return Solved::Stopped(why),
        };
        solver.solve();
        match solver.solution.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => {
                Solved::Point(std::mem::take(&mut solver.solution.x))
            }
            SolverStatus::PrimalInfeasible => Solved::Infeasible(
                "the solver proved that no contact forces in the friction cones cancel the external wrench"
                    .into(),
            ),
            SolverStatus::AlmostPrimalInfeasible => Solved::Infeasible(
                "the solver found, to reduced accuracy, that no contact forces in the friction cones cancel the external wrench"
                    .into(),
            ),
            other => Solved::Stopped(format!("{other:?}")),
        }
    }
}

/// A sparse matrix being assembled, as (row, column, value) triplets.
#[derive(Default)]
struct Triplets {
    rows: Vec<usize>,
    cols: Vec<usize>,
    vals: Vec<f64>,
}

impl Triplets {
    /// Adds an entry (zeros are left out).
    fn push(&mut self, row: usize, col: usize, val: f64) {
        if val != 0.0 {
            self.rows.push(row);
            self.cols.push(col);
            self.vals.push(val);
        }
    }

    /// Column `col` of the equilibrium rows 0..6: the wrench `(f, t)` of a unit value of
    /// its variable.
    fn wrench_column(&mut self, col: usize, f: &Vector3<f64>, t: &Vector3<f64>) {
        for k in 0..3 {
            self.push(k, col, f[k]);
            self.push(3 + k, col, t[k]);
        }
    }
}
