//! What a hand driver is: the one trait a real robot's integrator implements.

use graspopt_protocol::{FingerCloud, FingertipWrench, ObjectEstimate, Pose, Topic, TrialCommand};
use serde::{Deserialize, Serialize};

/// What a hand measures of its contacts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sensing {
    /// Contact clouds (points and normals) per finger: tactile skins, or the simulator.
    #[default]
    Clouds,
    /// A six-axis force/torque sensor under each fingertip: the metric agent finds the
    /// contacts from the readings. Users type `ft` (force/torque).
    #[serde(rename = "ft")]
    Wrenches,
}

impl Sensing {
    /// Every kind, in the order `--help` lists them.
    pub const ALL: [Sensing; 2] = [Sensing::Clouds, Sensing::Wrenches];

    /// The name users type (the serde name): `clouds`, `ft`.
    pub fn name(self) -> &'static str {
        match self {
            Sensing::Clouds => "clouds",
            Sensing::Wrenches => "ft",
        }
    }

    /// A kind from its name.
    pub fn parse(name: &str) -> Option<Sensing> {
        Self::ALL.into_iter().find(|s| s.name() == name.trim())
    }

    /// The topic a hand of this kind publishes its measurements on.
    pub fn topic(self) -> Topic {
        match self {
            Sensing::Clouds => Topic::Clouds,
            Sensing::Wrenches => Topic::Wrenches,
        }
    }
}

/// What a hand measured in one trial.
#[derive(Debug, Clone, PartialEq)]
pub struct HandReading {
    /// The palm pose actually reached (world).
    pub palm_pose: Pose,
    /// The raw contact cloud of each finger in finger order, then the palm's (hands that
    /// sense [`Sensing::Clouds`]).
    pub fingers: Vec<FingerCloud>,
    /// The fingertip force/torque readings (hands that sense [`Sensing::Wrenches`]).
    pub fingertips: Vec<FingertipWrench>,
    /// Smallest distance between a link and the object (metres) when nothing touches;
    /// `None` when unknown.
    pub min_gap: Option<f64>,
}

pub use crate::error::HandError;

/// A hand that executes trial commands. [`crate::serve`] does everything else: the bus,
/// filtering commands, padding each trial to its cost, tagging and sending the clouds.
pub trait HandDriver: Send + 'static {
    /// The hand this driver moves (`barrett`, ...): commands for another hand are refused
    /// without calling [`HandDriver::execute`]. `None`: the driver decides per command.
    fn hand(&self) -> Option<&str>;

    /// What the hand measures: clouds (sent as `ContactClouds`) or fingertip forces (sent as
    /// `FingertipWrenches`).
    fn sensing(&self) -> Sensing {
        Sensing::Clouds
    }

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
