//! Contacts and contact models (thesis section 2.2, conventions in
//! `docs/metric-conventions.md`).
//!
//! A contact is a position and a unit normal that points **into** the object: the
//! direction in which the finger pushes. A contact model turns a contact into the set
//! of wrenches it can apply with unit normal force, expressed about a reference point
//! and with torques divided by a torque scale `rho` (a characteristic length).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::error::QualityError;
use crate::limits::{MAX_COORDINATE, MAX_EDGES, MAX_MU};
use crate::wrench::{Wrench, wrench};

/// How far a normal's length may be from 1 before it is rejected.
pub const UNIT_NORMAL_TOLERANCE: f64 = 1e-6;

/// A point contact: position and inward unit normal, in the frame of the grasp.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    pub position: Vector3<f64>,
    pub normal: Vector3<f64>,
}

impl Contact {
    /// A contact from a position and a normal taken as given (see [`Contact::validate`]).
    pub fn new(position: Vector3<f64>, normal: Vector3<f64>) -> Self {
        Self { position, normal }
    }

    /// A contact whose normal is normalised first; errors on a zero or non-finite normal.
    pub fn normalized(position: Vector3<f64>, normal: Vector3<f64>) -> Result<Self, QualityError> {
        let c = Self { position, normal };
        c.check_finite(0)?;
        let norm = normal.norm();
        if norm <= f64::MIN_POSITIVE {
            return Err(QualityError::ZeroNormal { index: 0 });
        }
        Ok(Self {
            position,
            normal: normal / norm,
        })
    }

    fn check_finite(&self, index: usize) -> Result<(), QualityError> {
        for (field, v) in [("position", &self.position), ("normal", &self.normal)] {
            if !v.iter().all(|x| x.is_finite()) {
                return Err(QualityError::NotFinite {
                    what: "contact",
                    index,
                    field,
                    value: [v.x, v.y, v.z],
                });
            }
        }
        Ok(())
    }

    /// Checks that the coordinates are finite, the position within
    /// [`MAX_COORDINATE`] and the normal of unit length; `index` is the contact's
    /// position in its list, used in the error.
    pub fn validate(&self, index: usize) -> Result<(), QualityError> {
        self.check_finite(index)?;
        check_range("contact", index, "position", &self.position)?;
        let norm = self.normal.norm();
        if norm <= f64::MIN_POSITIVE {
            return Err(QualityError::ZeroNormal { index });
        }
        if (norm - 1.0).abs() > UNIT_NORMAL_TOLERANCE {
            return Err(QualityError::NonUnitNormal { index, norm });
        }
        Ok(())
    }
}

/// The tangent basis `(t1, t2)` of a unit normal `n`, by the project's convention:
/// `a` is the world axis with the smallest `|a . n|` (x, y, z first on ties),
/// `t1 = normalize(a - (a . n) n)`, `t2 = n x t1`.
pub fn tangent_basis(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let mut axis = 0;
    for i in 1..3 {
        if n[i].abs() < n[axis].abs() {
            axis = i;
        }
    }
    let mut a = Vector3::zeros();
    a[axis] = 1.0;
    let t1 = (a - n * n[axis]).normalize();
    let t2 = n.cross(&t1);
    (t1, t2)
}

/// Errors when a coordinate of `v` exceeds [`MAX_COORDINATE`] in absolute value.
pub(crate) fn check_range(
    what: &'static str,
    index: usize,
    field: &'static str,
    v: &Vector3<f64>,
) -> Result<(), QualityError> {
    if v.iter().all(|x| x.abs() <= MAX_COORDINATE) {
        Ok(())
    } else {
        Err(QualityError::OutOfRange {
            what,
            index,
            field,
            value: [v.x, v.y, v.z],
            limit: MAX_COORDINATE,
        })
    }
}

/// A friction model: what one contact transmits (thesis section 2.2: frictionless, point
/// contact with friction, soft finger; the thesis calls these contact models). The friction cone is sampled on its boundary
/// with `edges` generators `f_j = n + mu (cos th_j t1 + sin th_j t2)`, `th_j = 2 pi j / edges`.
///
/// Parameter ranges (see [`crate::limits`]): `0 <= mu <= 1e6` ([`MAX_MU`]),
/// `3 <= edges <= 4096` ([`MAX_EDGES`]), `0 <= gamma <= 1e12` ([`MAX_COORDINATE`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case")]
pub enum FrictionModel {
    /// Frictionless point contact: one wrench `(n, r x n / rho)`.
    Frictionless,
    /// Point contact with Coulomb friction `mu`: `edges` wrenches `(f_j, r x f_j / rho)`.
    PointFriction { mu: f64, edges: usize },
    /// Soft finger with torsional coefficient `gamma` (a length): `2 edges` wrenches
    /// `(f_j, (r x f_j +- gamma n) / rho)` (eq. 2.11).
    SoftFinger { mu: f64, edges: usize, gamma: f64 },
}

impl FrictionModel {
    /// The number of wrenches one contact produces (saturating: an unvalidated edge
    /// count cannot overflow it).
    pub fn wrenches_per_contact(&self) -> usize {
        match *self {
            FrictionModel::Frictionless => 1,
            FrictionModel::PointFriction { edges, .. } => edges,
            FrictionModel::SoftFinger { edges, .. } => edges.saturating_mul(2),
        }
    }

    /// Checks the parameters: `0 <= mu <= `[`MAX_MU`], `3 <= edges <= `[`MAX_EDGES`],
    /// `0 <= gamma <= `[`MAX_COORDINATE`].
    pub fn validate(&self) -> Result<(), QualityError> {
        let check_mu = |mu: f64| {
            if (0.0..=MAX_MU).contains(&mu) {
                Ok(())
            } else {
                Err(QualityError::Parameter {
                    name: "mu",
                    value: mu,
                    expected: "the friction coefficient must be finite, >= 0 and <= 1e6",
                })
            }
        };
        let check_edges = |edges: usize| {
            if (3..=MAX_EDGES).contains(&edges) {
                Ok(())
            } else {
                Err(QualityError::Parameter {
                    name: "edges",
                    value: edges as f64,
                    expected: "the friction cone needs at least 3 and at most 4096 edges",
                })
            }
        };
        match *self {
            FrictionModel::Frictionless => Ok(()),
            FrictionModel::PointFriction { mu, edges } => {
                check_mu(mu)?;
                check_edges(edges)
            }
            FrictionModel::SoftFinger { mu, edges, gamma } => {
                check_mu(mu)?;
                check_edges(edges)?;
                if (0.0..=MAX_COORDINATE).contains(&gamma) {
                    Ok(())
                } else {
                    Err(QualityError::Parameter {
                        name: "gamma",
                        value: gamma,
                        expected: "the torsional coefficient must be finite, >= 0 and <= 1e12",
                    })
                }
            }
        }
    }
}

/// Everything needed to turn contacts into wrenches: the contact model, the reference
/// point about which torques are taken, and the torque scale `rho > 0`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GraspModel {
    pub contact: FrictionModel,
    pub reference_point: Vector3<f64>,
    pub torque_scale: f64,
}

impl GraspModel {
    /// A model with the reference point at the origin and `rho = 1`.
    pub fn new(contact: FrictionModel) -> Self {
        Self {
            contact,
            reference_point: Vector3::zeros(),
            torque_scale: 1.0,
        }
    }

    /// The same model with another reference point.
    pub fn with_reference_point(mut self, c: Vector3<f64>) -> Self {
        self.reference_point = c;
        self
    }

    /// The same model with another torque scale.
    pub fn with_torque_scale(mut self, rho: f64) -> Self {
        self.torque_scale = rho;
        self
    }

    /// Checks the contact model, the reference point (finite, within
    /// [`MAX_COORDINATE`]) and `rho` (finite, > 0).
    pub fn validate(&self) -> Result<(), QualityError> {
        self.contact.validate()?;
        let c = &self.reference_point;
        if !c.iter().all(|x| x.is_finite()) {
            return Err(QualityError::NotFinite {
                what: "model",
                index: 0,
                field: "reference_point",
                value: [c.x, c.y, c.z],
            });
        }
        check_range("model", 0, "reference_point", c)?;
        if !(self.torque_scale.is_finite() && self.torque_scale > 0.0) {
            return Err(QualityError::Parameter {
                name: "torque_scale",
                value: self.torque_scale,
                expected: "the torque scale must be finite and > 0",
            });
        }
        Ok(())
    }

    /// Appends the wrenches of one (validated) contact to `out`.
    pub fn push_wrenches(&self, contact: &Contact, out: &mut Vec<Wrench>) {
        let n = contact.normal;
        let r = contact.position - self.reference_point;
        let inv_rho = 1.0 / self.torque_scale;
        let cone = |mu: f64, edges: usize| {
            let (t1, t2) = tangent_basis(&n);
            (0..edges).map(move |j| {
                let th = std::f64::consts::TAU * j as f64 / edges as f64;
                n + (t1 * th.cos() + t2 * th.sin()) * mu
            })
        };
        match self.contact {
            FrictionModel::Frictionless => out.push(wrench(&n, &(r.cross(&n) * inv_rho))),
            FrictionModel::PointFriction { mu, edges } => {
                out.extend(cone(mu, edges).map(|f| wrench(&f, &(r.cross(&f) * inv_rho))));
            }
            FrictionModel::SoftFinger { mu, edges, gamma } => {
                for f in cone(mu, edges) {
                    let t = r.cross(&f);
                    out.push(wrench(&f, &((t + n * gamma) * inv_rho)));
                    out.push(wrench(&f, &((t - n * gamma) * inv_rho)));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tangent_basis_is_orthonormal_and_follows_the_convention() {
        let n = Vector3::new(0.0, 0.0, 1.0);
        let (t1, t2) = tangent_basis(&n);
        // Ties between x and y: x wins.
        assert_eq!(t1, Vector3::x());
        assert_eq!(t2, Vector3::y());
        let n = Vector3::new(0.3, -0.5, 0.2).normalize();
        let (t1, t2) = tangent_basis(&n);
        assert!(t1.dot(&n).abs() < 1e-15 && t2.dot(&n).abs() < 1e-15);
        assert!((t1.norm() - 1.0).abs() < 1e-15 && (t2.norm() - 1.0).abs() < 1e-15);
        // Smallest |component| is z: t1 lies in the plane of z and n.
        assert!(t1.dot(&Vector3::z().cross(&n)).abs() < 1e-15);
    }

    #[test]
    fn soft_finger_wrenches_have_unit_normal_force_and_torsion() {
        let model = GraspModel::new(FrictionModel::SoftFinger {
            mu: 0.5,
            edges: 8,
            gamma: 0.2,
        });
        let c = Contact::new(Vector3::zeros(), Vector3::z());
        let mut w = Vec::new();
        model.push_wrenches(&c, &mut w);
        assert_eq!(w.len(), 16);
        for (i, wi) in w.iter().enumerate() {
            assert!((wi[2] - 1.0).abs() < 1e-15);
            let tangential = (wi[0] * wi[0] + wi[1] * wi[1]).sqrt();
            assert!((tangential - 0.5).abs() < 1e-15);
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            assert!((wi[5] - sign * 0.2).abs() < 1e-15);
        }
    }

    #[test]
    fn invalid_parameters_are_named() {
        let bad = [
            FrictionModel::PointFriction { mu: -0.1, edges: 8 },
            FrictionModel::PointFriction { mu: 0.5, edges: 2 },
            FrictionModel::SoftFinger {
                mu: 0.5,
                edges: 8,
                gamma: f64::NAN,
            },
        ];
        let names: Vec<_> = bad
            .iter()
            .map(|m| match m.validate() {
                Err(QualityError::Parameter { name, .. }) => name,
                other => panic!("expected a parameter error, got {other:?}"),
            })
            .collect();
        assert_eq!(names, ["mu", "edges", "gamma"]);
        let rho = GraspModel::new(FrictionModel::Frictionless).with_torque_scale(0.0);
        assert!(matches!(
            rho.validate(),
            Err(QualityError::Parameter {
                name: "torque_scale",
                ..
            })
        ));
    }

    #[test]
    fn contact_validation_rejects_bad_normals() {
        let p = Vector3::zeros();
        assert_eq!(
            Contact::new(p, Vector3::zeros()).validate(4),
            Err(QualityError::ZeroNormal { index: 4 })
        );
        assert!(matches!(
            Contact::new(p, Vector3::new(0.0, 0.0, 2.0)).validate(1),
            Err(QualityError::NonUnitNormal { index: 1, .. })
        ));
        assert!(matches!(
            Contact::new(Vector3::new(f64::NAN, 0.0, 0.0), Vector3::z()).validate(2),
            Err(QualityError::NotFinite {
                index: 2,
                field: "position",
                ..
            })
        ));
        assert!(
            Contact::new(p, Vector3::new(f64::INFINITY, 0.0, 0.0))
                .validate(0)
                .is_err()
        );
        let c = Contact::normalized(p, Vector3::new(0.0, 3.0, 4.0)).unwrap();
        assert!((c.normal - Vector3::new(0.0, 0.6, 0.8)).norm() < 1e-15);
    }
}
