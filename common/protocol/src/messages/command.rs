//! A trial for a hand to carry out ([`TrialCommand`], the `command` topic).

use serde::{Deserialize, Serialize};

use super::{Message, Pose, finite};
use crate::error::{Problem, ValidationError};
use crate::keys::RunId;

/// coordinator -> one hand worker: execute this trial.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialCommand {
    pub run_id: RunId,
    pub trial_id: u64,
    /// 1 for the first issue, incremented on every re-issue.
    pub attempt: u32,
    /// The worker the trial is leased to.
    pub worker: String,
    /// The hand model the trial was planned for (`barrett`, `parallel_jaw`).
    pub hand: String,
    /// The trial parameters (the run's parameter names, in order).
    pub params: Vec<f64>,
    /// Where to put the palm (world frame), computed from the parameters and the object
    /// estimate.
    pub palm_pose: Pose,
    /// The lease: the coordinator re-issues the trial if no result arrives within this time.
    pub lease_ms: u64,
    pub issued_ms: i64,
}

impl Message for TrialCommand {
    const TYPE: &'static str = "TrialCommand";
    fn run_id(&self) -> &RunId {
        &self.run_id
    }
    fn validate(&self) -> Result<(), ValidationError> {
        finite(Self::TYPE, "params", &self.params)?;
        self.palm_pose.validate_in(Self::TYPE, "palm_pose")?;
        if self.attempt == 0 {
            let problem = Problem::Unmet(">= 1");
            return Err(ValidationError::new(Self::TYPE, "attempt", problem));
        }
        Ok(())
    }
}
