//! An evaluator: one object, one hand, one trial space and the scoring settings. It maps
//! a parameter vector (hand offsets from the reference pose) to a scored trial; the
//! objective that scans and optimisers call.

use std::path::PathBuf;

use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{
    ContactModel, ContactModelSettings, Hand, Object, ParamKind, TrialOutcome, TrialSpace,
    run_trial,
};
use serde::{Deserialize, Serialize};

use crate::error::TrialError;
use crate::score::{Metric, ReferenceFrame, ScoreSettings, TrialScore, score_outcome};

/// What a simulated trial is run and scored with, as a user chooses it (the flags of
/// `graspopt trial`, `scan`, `run` and the hand agent).
#[derive(Debug, Clone, PartialEq)]
pub struct TrialSettings {
    /// A built-in object's name (ignored when `mesh` is given).
    pub object: String,
    /// A user mesh (OBJ or STL, closed) instead of a built-in object.
    pub mesh: Option<PathBuf>,
    /// Factor from the mesh file's units to metres.
    pub mesh_scale: f64,
    /// A built-in hand's name or a URDF file.
    pub hand: String,
    pub contacts: ContactModel,
    pub metric: Metric,
    pub frame: ReferenceFrame,
    /// Torque scale in metres (`None`: the object's bounding radius).
    pub torque_scale: Option<f64>,
}

impl Default for TrialSettings {
    fn default() -> Self {
        let score = ScoreSettings::default();
        Self {
            object: "mug".into(),
            mesh: None,
            mesh_scale: 1.0,
            hand: "barrett".into(),
            contacts: score.contacts,
            metric: score.metric,
            frame: score.frame,
            torque_scale: None,
        }
    }
}

impl TrialSettings {
    /// The object the settings name: the mesh if one is given, else the built-in object.
    pub fn object(&self) -> Result<Object, TrialError> {
        match &self.mesh {
            Some(path) => Object::from_file_scaled(path, self.mesh_scale).map_err(|e| {
                TrialError::Settings(format!("cannot load the mesh {}: {e}", path.display()))
            }),
            None => Ok(Object::by_name(&self.object)?),
        }
    }
}

/// One evaluated trial.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    pub params: Vec<f64>,
    pub outcome: TrialOutcome,
    pub score: TrialScore,
}

/// Parameters in, scored trial out.
#[derive(Debug)]
pub struct Evaluator {
    pub object: Object,
    pub hand: Box<dyn Hand>,
    pub space: TrialSpace,
    pub contacts: ContactModelSettings,
    pub score: ScoreSettings,
}

impl Evaluator {
    /// An evaluator with the default contact-model and score settings.
    pub fn new(object: Object, hand: Box<dyn Hand>, space: TrialSpace) -> Self {
        Self {
            object,
            hand,
            space,
            contacts: ContactModelSettings::default(),
            score: ScoreSettings::default(),
        }
    }

    /// The evaluator the settings describe, over the object's default space restricted to
    /// `kinds` ([`TrialSpace::with_params`]).
    pub fn from_settings(s: &TrialSettings, kinds: &[ParamKind]) -> Result<Self, TrialError> {
        if let Some(rho) = s.torque_scale
            && !(rho.is_finite() && rho > 0.0)
        {
            return Err(TrialError::Settings(format!(
                "the torque scale must be a positive length in metres, got {rho}"
            )));
        }
        let object = s.object()?;
        let space = TrialSpace::with_params(&object, kinds)?;
        let mut ev = Evaluator::new(object, hand_by_name(&s.hand)?, space);
        ev.score.contacts = s.contacts;
        ev.score.metric = s.metric;
        ev.score.frame = s.frame;
        ev.score.torque_scale = s.torque_scale;
        Ok(ev)
    }

    /// Runs and scores the trial at `params` (in the space's units).
    pub fn evaluate(&self, params: &[f64]) -> Result<Evaluation, TrialError> {
        let pose = self.space.palm_pose(params)?;
        let outcome = run_trial(&self.object, self.hand.as_ref(), &pose, &self.contacts)?;
        let score = score_outcome(&outcome, &self.object, &self.score)?;
        Ok(Evaluation {
            params: params.to_vec(),
            outcome,
            score,
        })
    }

    /// The score alone.
    pub fn score(&self, params: &[f64]) -> Result<f64, TrialError> {
        Ok(self.evaluate(params)?.score.score)
    }
}
