//! The settings of a simulated trial as a user states them: which object (built-in or a mesh
//! file), hand, contact model, metric, reference frame and torque scale. The CLI builds them
//! from its flags; [`Evaluator::from_settings`] turns them into an evaluator.

use std::path::PathBuf;

use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{ContactModel, Object, ParamKind, ParamSpec, TrialSpace};
use serde::{Deserialize, Serialize};

use crate::error::TrialError;
use crate::evaluator::Evaluator;
use crate::score::{Metric, ReferenceFrame};

/// Which object, hand and scoring choices a trial uses.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialSettings {
    /// A built-in object's name (used when `mesh` is None).
    pub object: String,
    /// A closed mesh (OBJ or STL) instead of a built-in object.
    pub mesh: Option<PathBuf>,
    /// Factor from the mesh file's units to metres.
    pub mesh_scale: f64,
    /// A built-in hand's name or a URDF file.
    pub hand: String,
    pub contacts: ContactModel,
    pub metric: Metric,
    pub frame: ReferenceFrame,
    /// Torque scale in metres (None: the object's bounding radius).
    pub torque_scale: Option<f64>,
    /// Bounds that replace the object's defaults for these parameters (each one of the
    /// trial's parameters; see [`TrialSpace::with_ranges`]).
    #[serde(default)]
    pub ranges: Vec<ParamSpec>,
}

impl Default for TrialSettings {
    /// The mug, the Barrett hand and the default scoring (surface contacts, BW, object frame).
    fn default() -> Self {
        let score = crate::score::ScoreSettings::default();
        Self {
            object: "mug".into(),
            mesh: None,
            mesh_scale: 1.0,
            hand: "barrett".into(),
            contacts: score.contacts,
            metric: score.metric,
            frame: score.frame,
            torque_scale: None,
            ranges: Vec::new(),
        }
    }
}

impl TrialSettings {
    /// The object named by the settings.
    pub fn object(&self) -> Result<Object, TrialError> {
        match &self.mesh {
            Some(path) => {
                Object::from_file_scaled(path, self.mesh_scale).map_err(|source| TrialError::Mesh {
                    path: path.clone(),
                    source: Box::new(source),
                })
            }
            None => Ok(Object::by_name(&self.object)?),
        }
    }
}

impl Evaluator {
    /// The evaluator of `settings` over the parameters `kinds` (in that order, each with its
    /// default bounds or its range in `settings.ranges`).
    pub fn from_settings(
        settings: &TrialSettings,
        kinds: &[ParamKind],
    ) -> Result<Self, TrialError> {
        let object = settings.object()?;
        let space = TrialSpace::with_ranges(&object, kinds, &settings.ranges)?;
        let hand = hand_by_name(&settings.hand)?;
        let mut ev = Evaluator::new(object, hand, space);
        ev.score.contacts = settings.contacts;
        ev.score.metric = settings.metric;
        ev.score.frame = settings.frame;
        if let Some(rho) = settings.torque_scale {
            if !(rho.is_finite() && rho > 0.0) {
                return Err(TrialError::Settings(format!(
                    "the torque scale must be a positive length in metres, got {rho}"
                )));
            }
            ev.score.torque_scale = Some(rho);
        }
        Ok(ev)
    }
}
