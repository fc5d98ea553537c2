//! What a hand driver is: the one trait a real robot's integrator implements.

use graspopt_protocol::{FingerCloud, ObjectEstimate, Pose, TrialCommand};

/// What a hand measured in one trial.
#[derive(Debug, Clone, PartialEq)]
pub struct HandReading {
    /// The palm pose actually reached (world).
    pub palm_pose: Pose,
    /// The raw contact cloud of each finger in finger order, then the palm's.
    pub fingers: Vec<FingerCloud>,
    /// Smallest distance between a link and the object (metres) when nothing touches;
    /// `None` when unknown.
    pub min_gap: Option<f64>,
}

/// Why a hand could not execute a trial: the trial fails with this reason, the agent goes on.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct HandError(pub String);

/// A hand that executes trial commands. [`crate::serve`] does everything else: the bus,
/// filtering commands, padding each trial to its cost, tagging and sending the clouds.
pub trait HandDriver: Send + 'static {
    /// The hand this driver moves (`barrett`, ...): commands for another hand are refused
    /// without calling [`HandDriver::execute`]. `None`: the driver decides per command.
    fn hand(&self) -> Option<&str>;

    /// Whether it cannot execute yet for want of the run's object estimate (the simulated
    /// hand builds its world from it): a command then waits for an estimate.
    fn needs_object(&self) -> bool {
        false
    }

    /// Perception's object estimate of the run, each time one arrives.
    fn set_object(&mut self, _estimate: &ObjectEstimate) {}

    /// Moves to `command.palm_pose`, closes the hand, reads the contacts. May block: it runs
    /// on a thread of its own.
    fn execute(&mut self, command: &TrialCommand) -> Result<HandReading, HandError>;
}
