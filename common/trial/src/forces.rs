//! The contact-force analysis of a trial (the thesis's "contact force analysis"), beside its
//! metrics: for any grasp, the least-norm contact forces inside the friction cones that resist
//! the object's weight (or "cannot resist"); for forces a hand measured, also the net wrench
//! they apply to the object and how far each is inside its friction cone.
//!
//! The contacts are the ones the metric scores: the score's contact model (the surface model by
//! default, a few dozen points per finger) for a simulated or cloud-measured trial, the sensed
//! contact of each fingertip for a hand with force sensors. The same contacts keep "cannot
//! resist" consistent with force closure: a grasp in force closure resists any load. (One mean
//! contact per finger would be cheaper, but it loses a finger wrapped around a handle.)
//!
//! Frames: the contacts' frame (world), torques about the score's reference point
//! ([`crate::score::grasp_model`]), gravity along world `-z` by default.

use graspopt_quality::forces::{
    ContactForces, Resisting, SlipMargin, gravity_wrench, net_wrench, resisting_forces,
    slip_margins,
};
use graspopt_quality::{Contact, FrictionModel, Wrench};
use graspopt_sim::{Object, TrialOutcome};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::error::TrialError;
use crate::score::{ScoreSettings, grasp_model};

/// What the grasp must resist.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ForceSettings {
    /// The object's mass (kg). Default 0.5 kg.
    pub object_mass: f64,
    /// Gravity in the world frame (m/s^2). Default `[0, 0, -9.81]`.
    pub gravity: [f64; 3],
}

impl Default for ForceSettings {
    fn default() -> Self {
        ForceSettings {
            object_mass: 0.5,
            gravity: [0.0, 0.0, -9.81],
        }
    }
}

impl ForceSettings {
    /// Checks the mass (finite, >= 0) and gravity (finite); the error names the field.
    pub fn validate(&self) -> Result<(), TrialError> {
        if !(self.object_mass.is_finite() && self.object_mass >= 0.0) {
            return Err(TrialError::Settings(format!(
                "object_mass must be finite and >= 0 kg, got {}",
                self.object_mass
            )));
        }
        if let Some(g) = self.gravity.iter().find(|g| !g.is_finite()) {
            return Err(TrialError::Settings(format!(
                "gravity must be finite, got {g} in {:?}",
                self.gravity
            )));
        }
        Ok(())
    }
}

/// Forces a hand measured: per contact, the force on the object and the moment about the
/// contact normal, with their net wrench and slip margins.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredForces {
    pub forces: ContactForces,
    /// The net wrench of the measured forces on the object.
    pub net: Wrench,
    /// Per contact, how far its force is inside its friction cone.
    pub margins: Vec<SlipMargin>,
}

/// The force analysis of one grasp.
#[derive(Debug, Clone, PartialEq)]
pub struct GraspForces {
    /// The wrench the world applies to the object (its weight).
    pub external: Wrench,
    /// The least-norm forces that resist it, or why none can, or why they are unknown.
    pub resisting: Resisting,
    /// What the hand measured, if it measures forces.
    pub measured: Option<MeasuredForces>,
}

impl GraspForces {
    /// The largest single contact force of the resisting solution (N).
    pub fn resisting_max(&self) -> Option<f64> {
        match &self.resisting {
            Resisting::Forces { forces, .. } => {
                forces.forces.iter().map(|f| f.norm()).reduce(f64::max)
            }
            Resisting::CannotResist { .. } | Resisting::Unavailable { .. } => None,
        }
    }
}

/// The force analysis of `contacts` (world frame, normals into the object) under `model`,
/// torques about `reference`, against the weight of `object` (centre of mass from the object)
/// per `settings`; with `measured` forces (one per contact) when the hand measured them.
/// No contacts: nothing resists, every force is zero. Errors: settings or a load out of
/// range, or measured forces that do not fit the contacts; the least resisting forces
/// themselves never fail it ([`Resisting::Unavailable`], with the reason, when they are not
/// found).
pub fn analyse_contacts(
    contacts: &[Contact],
    model: &FrictionModel,
    reference: &Vector3<f64>,
    object: &Object,
    settings: &ForceSettings,
    measured: Option<ContactForces>,
) -> Result<GraspForces, TrialError> {
    settings.validate()?;
    let g = Vector3::from(settings.gravity);
    let external = gravity_wrench(
        settings.object_mass,
        &g,
        &object.centre_of_mass().coords,
        reference,
    )?;
    if contacts.is_empty() {
        let resisting = if external.iter().all(|&x| x == 0.0) {
            Resisting::Forces {
                forces: ContactForces::without_torsion(Vec::new()),
                norm: 0.0,
            }
        } else {
            Resisting::CannotResist {
                reason: "nothing touches the object".into(),
            }
        };
        return Ok(GraspForces {
            external,
            resisting,
            measured: None,
        });
    }
    // Past the settings and the load, the least forces never fail the analysis: a solver
    // that stops is `Unavailable` already, and so is contact data it refused.
    let resisting = resisting_forces(contacts, model, &external, reference).unwrap_or_else(|e| {
        Resisting::Unavailable {
            reason: e.to_string(),
        }
    });
    let measured = match measured {
        Some(forces) => Some(MeasuredForces {
            net: net_wrench(contacts, &forces, reference)?,
            margins: slip_margins(contacts, model, &forces)?,
            forces,
        }),
        None => None,
    };
    Ok(GraspForces {
        external,
        resisting,
        measured,
    })
}

/// The force analysis of a simulated or cloud-measured trial: the contacts of the score's
/// contact model (the palm's too when the score counts it), its friction model and reference
/// point.
pub fn analyse_outcome(
    outcome: &TrialOutcome,
    object: &Object,
    score: &ScoreSettings,
    settings: &ForceSettings,
) -> Result<GraspForces, TrialError> {
    let contacts = outcome
        .contacts(score.contacts, score.include_palm)
        .iter()
        .map(|c| Contact::normalized(c.position.coords, c.normal))
        .collect::<Result<Vec<_>, _>>()?;
    let model = grasp_model(outcome, object, score)?;
    analyse_contacts(
        &contacts,
        &score.model,
        &model.reference_point,
        object,
        settings,
        None,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_forces_never_fail_the_analysis_bad_settings_do() {
        let object = Object::by_name("sphere").unwrap();
        let c = object.centre_of_mass().coords;
        let model = FrictionModel::PointFriction { mu: 0.5, edges: 8 };
        // A normal of length 2 (no simulated contact has one): the least forces refuse it,
        // the analysis reports them unavailable with that reason, the load still known.
        let contacts = [
            Contact::new(c + Vector3::x() * 0.04, -Vector3::x() * 2.0),
            Contact::new(c - Vector3::x() * 0.04, Vector3::x()),
        ];
        let settings = ForceSettings::default();
        let g = analyse_contacts(&contacts, &model, &c, &object, &settings, None).unwrap();
        let Resisting::Unavailable { reason } = &g.resisting else {
            panic!("{g:?}");
        };
        assert!(reason.contains("normal"), "{reason}");
        assert_eq!(g.external[2], -0.5 * 9.81);
        assert_eq!(g.resisting_max(), None);
        // A mass that is not one is the caller's error.
        let negative = ForceSettings {
            object_mass: -1.0,
            ..settings
        };
        let e = analyse_contacts(&contacts, &model, &c, &object, &negative, None).unwrap_err();
        assert!(e.to_string().contains("object_mass"), "{e}");
    }
}
