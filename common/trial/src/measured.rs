//! Scoring contact clouds measured by a hand, real or simulated: what a metric agent does
//! with the clouds a hand sends. The contact models are built from the raw clouds here (the
//! surface model on the estimated object), then scored exactly as [`score_outcome`] scores a
//! simulated trial, so a trial scored from its clouds equals the same trial scored whole.

use graspopt_sim::{
    ContactCloud, ContactModelSettings, ContactPoint, FingerOutcome, Grasp, Object, TrialOutcome,
};
use nalgebra::Isometry3;

use crate::error::TrialError;
use crate::fingertips::FingertipContact;
use crate::score::{ScoreSettings, TrialScore, closest_gap, score_outcome};

/// One finger's raw cloud as measured (`finger: None` for the palm).
#[derive(Debug, Clone, PartialEq)]
pub struct FingerCloud {
    pub finger: Option<usize>,
    pub links: Vec<String>,
    pub points: Vec<ContactPoint>,
}

/// What a hand measured in one trial.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredTrial {
    pub hand: String,
    /// The palm pose reached (world).
    pub palm_pose: Isometry3<f64>,
    /// Fingers in order, then the palm.
    pub fingers: Vec<FingerCloud>,
    /// Smallest link-object distance when nothing touches.
    pub min_gap: Option<f64>,
}

impl MeasuredTrial {
    /// The measurement of a simulated trial (its raw clouds only).
    pub fn from_outcome(outcome: &TrialOutcome) -> MeasuredTrial {
        let finger = |f: &FingerOutcome| FingerCloud {
            finger: f.finger,
            links: f.links.clone(),
            points: f.cloud.points.clone(),
        };
        MeasuredTrial {
            hand: outcome.grasp.hand.clone(),
            palm_pose: outcome.grasp.palm_pose,
            fingers: outcome
                .fingers
                .iter()
                .chain(std::iter::once(&outcome.palm))
                .map(finger)
                .collect(),
            min_gap: closest_gap(outcome),
        }
    }

    /// What a force-sensing hand measured, as contacts: one point per sensed fingertip, on
    /// the fingertip (`contacts`: `(finger, fingertip name, contact)`), scored as clouds are.
    pub fn from_fingertips(
        hand: &str,
        palm_pose: Isometry3<f64>,
        contacts: &[(usize, String, FingertipContact)],
        min_gap: Option<f64>,
    ) -> MeasuredTrial {
        MeasuredTrial {
            hand: hand.to_string(),
            palm_pose,
            fingers: contacts
                .iter()
                .map(|(finger, link, c)| FingerCloud {
                    finger: Some(*finger),
                    links: vec![link.clone()],
                    points: vec![ContactPoint {
                        position: c.point,
                        normal: c.normal,
                        weight: 1.0,
                    }],
                })
                .collect(),
            min_gap,
        }
    }

    /// Rebuilds a trial outcome on `object`: contact models from the raw clouds.
    pub fn to_outcome(&self, object: &Object, settings: &ContactModelSettings) -> TrialOutcome {
        let model = |m: &FingerCloud| {
            let cloud = ContactCloud {
                points: m.points.clone(),
            };
            FingerOutcome::from_cloud(m.finger, m.links.clone(), cloud, object, settings)
        };
        let fingers: Vec<FingerOutcome> = self
            .fingers
            .iter()
            .filter(|f| f.finger.is_some())
            .map(model)
            .collect();
        let palm = self
            .fingers
            .iter()
            .find(|f| f.finger.is_none())
            .map(model)
            .unwrap_or_default();
        let touched = self.fingers.iter().any(|f| !f.points.is_empty());
        TrialOutcome {
            object: object.name().to_string(),
            grasp: Grasp {
                hand: self.hand.clone(),
                requested_palm_pose: self.palm_pose,
                palm_pose: self.palm_pose,
                retreat: 0.0,
                joints: Vec::new(),
                link_poses: Vec::new(),
                link_touching: Vec::new(),
                link_distances: self.min_gap.into_iter().collect(),
            },
            fingers,
            palm,
            touched,
        }
    }
}

/// Scores measured clouds on `object` (the object estimate the trials are planned against).
pub fn score_measured(
    measured: &MeasuredTrial,
    object: &Object,
    contacts: &ContactModelSettings,
    score: &ScoreSettings,
) -> Result<(TrialScore, TrialOutcome), TrialError> {
    contacts.validate()?;
    let outcome = measured.to_outcome(object, contacts);
    let s = score_outcome(&outcome, object, score)?;
    Ok((s, outcome))
}
