//! An evaluator: one object, one hand, one trial space and the scoring settings. It maps
//! a parameter vector (hand offsets from the reference pose) to a scored trial; the
//! objective that scans and optimisers call.

use graspopt_sim::{ContactModelSettings, Hand, Object, TrialOutcome, TrialSpace, run_trial};
use serde::{Deserialize, Serialize};

use crate::error::TrialError;
use crate::score::{ScoreSettings, TrialScore, score_outcome};

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
