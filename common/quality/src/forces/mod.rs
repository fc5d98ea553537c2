//! Force analysis of a grasp (issue 20, the thesis title's "contact force analysis").
//!
//! Given contacts (position, unit normal pointing into the object) and, for measured
//! grasps, the force each contact applies to the object:
//! - [`net_wrench`]: the total wrench the contacts apply to the object;
//! - [`slip_margins`]: how far each contact force is inside its friction cone;
//! - [`resisting_forces`]: for any grasp, the least-norm contact forces inside the
//!   friction cones that cancel an external wrench, such as [`gravity_wrench`].
//!
//! Units are SI by convention (N, N m, m), but nothing depends on them: forces, torques
//! and lengths may be in any consistent units. Friction cones here are the exact
//! second-order cones of the friction model (its `edges` are not used):
//! - frictionless: `f = f_n n`, `f_n >= 0`;
//! - point friction: `||f_t|| <= mu f_n`, where `f_n = f . n` and `f_t = f - f_n n`;
//! - soft finger: the same, and `|torsion| <= gamma f_n` (thesis eq. 2.11, `gamma` a
//!   length).

mod resist;

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::contact::{Contact, FrictionModel, check_range};
use crate::error::QualityError;
use crate::limits::MAX_COORDINATE;
use crate::wrench::{Wrench, wrench};

pub use resist::{Resisting, resisting_forces};

/// Contact forces of a grasp: per contact, the force it applies to the object (in the
/// frame of the contacts, N) and the moment about the contact normal (N m; 0 unless
/// the contact is a soft finger), positive counter-clockwise about the inward normal.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactForces {
    pub forces: Vec<Vector3<f64>>,
    pub torsions: Vec<f64>,
}

impl ContactForces {
    /// Forces and torsions, one of each per contact.
    pub fn new(forces: Vec<Vector3<f64>>, torsions: Vec<f64>) -> Self {
        Self { forces, torsions }
    }

    /// Forces with no torsion (point contacts).
    pub fn without_torsion(forces: Vec<Vector3<f64>>) -> Self {
        let torsions = vec![0.0; forces.len()];
        Self { forces, torsions }
    }

    /// Checks one force and one torsion per contact, each finite and within
    /// [`MAX_COORDINATE`].
    fn validate(&self, contacts: usize) -> Result<(), QualityError> {
        if self.forces.len() != contacts || self.torsions.len() != contacts {
            return Err(QualityError::ForceCount {
                contacts,
                forces: self.forces.len(),
                torsions: self.torsions.len(),
            });
        }
        for (i, (f, &t)) in self.forces.iter().zip(&self.torsions).enumerate() {
            if !f.iter().all(|x| x.is_finite()) {
                return Err(QualityError::NotFinite {
                    what: "contact",
                    index: i,
                    field: "force",
                    value: [f.x, f.y, f.z],
                });
            }
            check_range("contact", i, "force", f)?;
            if !t.is_finite() || t.abs() > MAX_COORDINATE {
                return Err(QualityError::TorsionOutOfRange {
                    index: i,
                    value: t,
                    limit: MAX_COORDINATE,
                });
            }
        }
        Ok(())
    }
}

/// How one contact force sits in its friction cone. Each margin is negative when the
/// force is outside the cone.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SlipMargin {
    /// The normal force `f_n = f . n` (N): negative when the contact would have to pull,
    /// which it cannot (the finger would separate).
    pub normal: f64,
    /// `mu f_n - ||f_t||` (N, `mu = 0` for a frictionless contact): negative when the
    /// contact would slip.
    pub friction: f64,
    /// For a soft finger, `gamma f_n - |torsion|` (N m): negative when the contact would
    /// twist. `None` for the other models.
    pub torsion: Option<f64>,
}

impl SlipMargin {
    /// Whether the force is inside its cone, every margin at least `-tolerance` (in the
    /// margin's unit).
    pub fn holds(&self, tolerance: f64) -> bool {
        self.normal >= -tolerance
            && self.friction >= -tolerance
            && self.torsion.is_none_or(|t| t >= -tolerance)
    }
}

/// The total wrench the contact forces apply to the object, about `reference_point`:
/// the sum of `(f_i, (p_i - c) x f_i + torsion_i n_i)`.
pub fn net_wrench(
    contacts: &[Contact],
    forces: &ContactForces,
    reference_point: &Vector3<f64>,
) -> Result<Wrench, QualityError> {
    validate_grasp(contacts, reference_point)?;
    forces.validate(contacts.len())?;
    Ok(contacts
        .iter()
        .zip(forces.forces.iter().zip(&forces.torsions))
        .map(|(c, (f, &t))| {
            let r = c.position - reference_point;
            wrench(f, &(r.cross(f) + c.normal * t))
        })
        .sum())
}

/// The slip margin of each contact force under `model` (see [`SlipMargin`]). A nonzero
/// torsion on a contact that is not a soft finger is an error.
pub fn slip_margins(
    contacts: &[Contact],
    model: &FrictionModel,
    forces: &ContactForces,
) -> Result<Vec<SlipMargin>, QualityError> {
    validate_contacts(contacts)?;
    model.validate()?;
    forces.validate(contacts.len())?;
    let (mu, gamma) = match *model {
        FrictionModel::Frictionless => (0.0, None),
        FrictionModel::PointFriction { mu, .. } => (mu, None),
        FrictionModel::SoftFinger { mu, gamma, .. } => (mu, Some(gamma)),
    };
    contacts
        .iter()
        .zip(forces.forces.iter().zip(&forces.torsions))
        .enumerate()
        .map(|(i, (c, (f, &t)))| {
            let normal = f.dot(&c.normal);
            let tangential = (f - c.normal * normal).norm();
            let torsion = match gamma {
                Some(gamma) => Some(gamma * normal - t.abs()),
                None if t == 0.0 => None,
                None => {
                    return Err(QualityError::TorsionWithoutSoftFinger { index: i, value: t });
                }
            };
            Ok(SlipMargin {
                normal,
                friction: mu * normal - tangential,
                torsion,
            })
        })
        .collect()
}

/// The wrench gravity applies to an object of `mass` (kg) with centre of mass `com`,
/// about `reference_point`: `(m g, (com - c) x m g)`. `g` is the gravitational
/// acceleration in the frame of the contacts (m/s^2, e.g. `[0, 0, -9.81]`).
pub fn gravity_wrench(
    mass: f64,
    g: &Vector3<f64>,
    com: &Vector3<f64>,
    reference_point: &Vector3<f64>,
) -> Result<Wrench, QualityError> {
    if !(0.0..=MAX_COORDINATE).contains(&mass) {
        return Err(QualityError::Parameter {
            name: "mass",
            value: mass,
            expected: "the mass must be finite, >= 0 and <= 1e12",
        });
    }
    for (field, v) in [("g", g), ("com", com), ("reference_point", reference_point)] {
        check_point("gravity", field, v)?;
    }
    let weight = g * mass;
    let w = wrench(&weight, &(com - reference_point).cross(&weight));
    check_external(&w)?;
    Ok(w)
}

/// Checks the contacts (at least one, each valid: see [`Contact::validate`]).
fn validate_contacts(contacts: &[Contact]) -> Result<(), QualityError> {
    if contacts.is_empty() {
        return Err(QualityError::Empty("contacts"));
    }
    for (i, c) in contacts.iter().enumerate() {
        c.validate(i)?;
    }
    Ok(())
}

/// Checks the contacts and the reference point.
fn validate_grasp(
    contacts: &[Contact],
    reference_point: &Vector3<f64>,
) -> Result<(), QualityError> {
    validate_contacts(contacts)?;
    check_point("grasp", "reference_point", reference_point)
}

/// Checks that a point or vector is finite and within [`MAX_COORDINATE`].
fn check_point(
    what: &'static str,
    field: &'static str,
    v: &Vector3<f64>,
) -> Result<(), QualityError> {
    if !v.iter().all(|x| x.is_finite()) {
        return Err(QualityError::NotFinite {
            what,
            index: 0,
            field,
            value: [v.x, v.y, v.z],
        });
    }
    check_range(what, 0, field, v)
}

/// Checks that an external wrench is finite and within [`MAX_COORDINATE`].
fn check_external(w: &Wrench) -> Result<(), QualityError> {
    if w.iter().all(|x| x.abs() <= MAX_COORDINATE) {
        Ok(())
    } else {
        Err(QualityError::ExternalWrench {
            value: [w[0], w[1], w[2], w[3], w[4], w[5]],
            limit: MAX_COORDINATE,
        })
    }
}
