//! What a hand's fingertip force/torque sensors read in a trial ([`FingertipWrenches`], the
//! `wrenches` topic).

use serde::{Deserialize, Serialize};

use super::{AttemptRef, Message, Pose, finite, validate_measurement_header};
use crate::error::{Problem, ValidationError};
use crate::keys::RunId;

/// The fingertip surface a force/torque sensor carries, in the sensor frame: a sphere, an
/// ellipsoid or a capsule (`{"shape": "sphere", "center": [0, 0, 0.015], "radius": 0.012}`).
pub use graspopt_sensing::FingertipSurface;

/// One fingertip force/torque sensor's reading in a trial.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FingertipWrench {
    /// The finger (0-based, in the hand's finger order).
    pub finger: u32,
    /// The fingertip's name (a link of the hand), for people and logs.
    pub link: String,
    /// The sensor frame in the world when it read.
    pub sensor_pose: Pose,
    /// The fingertip's surface, in the sensor frame.
    pub surface: FingertipSurface,
    /// The force the object applies to the fingertip, sensor frame (N).
    pub force: [f64; 3],
    /// The torque of that contact about the sensor frame's origin, sensor frame (N m).
    pub torque: [f64; 3],
    /// When the sensor read (milliseconds since the Unix epoch).
    pub stamp_ms: i64,
}

/// hand -> metric: what a hand's fingertip force/torque sensors read in one trial (a hand that
/// senses forces instead of contact clouds). The metric agent finds each fingertip's contact
/// from its reading (intrinsic contact sensing) and scores the contacts as it scores clouds.
/// Fingertips that read nothing may be left out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FingertipWrenches {
    pub run_id: RunId,
    pub trial_id: u64,
    pub attempt: u32,
    /// The hand worker that executed the trial.
    pub worker: String,
    pub hand: String,
    /// The palm pose actually reached (world).
    pub palm_pose: Pose,
    pub fingertips: Vec<FingertipWrench>,
    /// Smallest distance between the hand and the object (metres) when nothing touches;
    /// `None` when unknown (a real hand does not know it).
    pub min_gap: Option<f64>,
    /// Set when the hand could not execute the trial; `fingertips` is then empty.
    pub error: Option<String>,
    pub executed_ms: i64,
}

impl Message for FingertipWrenches {
    const TYPE: &'static str = "FingertipWrenches";
    fn run_id(&self) -> &RunId {
        &self.run_id
    }
    fn attempt_ref(&self) -> Option<AttemptRef> {
        Some(AttemptRef {
            run_id: self.run_id.clone(),
            trial_id: self.trial_id,
            attempt: self.attempt,
            worker: self.worker.clone(),
        })
    }
    fn validate(&self) -> Result<(), ValidationError> {
        const TYPE: &str = FingertipWrenches::TYPE;
        validate_measurement_header(TYPE, &self.worker, &self.palm_pose, self.min_gap)?;
        for (i, tip) in self.fingertips.iter().enumerate() {
            tip.sensor_pose
                .validate_in(TYPE, &format!("fingertips[{i}].sensor_pose"))?;
            tip.surface.validate().map_err(|e| {
                let field = format!("fingertips[{i}].surface");
                ValidationError::new(TYPE, field, Problem::Surface(e))
            })?;
            finite(TYPE, &format!("fingertips[{i}].force"), &tip.force)?;
            finite(TYPE, &format!("fingertips[{i}].torque"), &tip.torque)?;
        }
        Ok(())
    }
}
