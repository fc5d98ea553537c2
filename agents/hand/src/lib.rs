//! The hand agent: executes trial commands and sends what the fingers touched.
//!
//! A hand is a [`HandDriver`]: it executes one trial command (move the palm to the commanded
//! pose, close, read the contacts) and returns the raw contact clouds per finger, or why it
//! could not. [`serve`] is the bus loop, written once for every driver: it claims the
//! worker id, declares the hand alive, takes the commands of its run and worker (counting
//! and logging any other message), runs the driver on a thread of its own, pads each trial to
//! at least `trial_cost_ms` (to model a robot's cycle time), tags the clouds with the trial
//! and sends them to the metric agents (shared memory on the same host, Zenoh otherwise).
//! One trial at a time.
//!
//! Two drivers come with it: [`SimulatedHand`] (the grasp simulator; its world holds the
//! object perception names at its true pose, or the configured one) and [`ReplayHand`]
//! (each trial gets the recorded grasp nearest to its parameters, see [`replay`]). [`run`]
//! picks one from the [`HandConfig`] and serves it; [`HandAgent`] is that as an [`Agent`].
//!
//! # A real hand
//!
//! A robot's integrator implements [`HandDriver`] and calls [`serve`]; nothing else of the
//! conversation (`docs/protocol.md`) needs writing:
//!
//! ```no_run
//! use std::time::Duration;
//! use graspopt_hand::{HandDriver, HandError, HandReading, serve};
//! use graspopt_protocol::{CloudPoint, FingerCloud, RunId, TrialCommand};
//!
//! /// A gripper that touches the object with one point per finger, and faults on odd trials.
//! struct MyGripper;
//!
//! impl HandDriver for MyGripper {
//!     fn hand(&self) -> Option<&str> {
//!         Some("parallel_jaw")
//!     }
//!     fn execute(&mut self, command: &TrialCommand) -> Result<HandReading, HandError> {
//!         if !command.trial_id.is_multiple_of(2) {
//!             return Err(HandError::Fault("gripper fault".into()));
//!         }
//!         // Move the arm to command.palm_pose, close, read the tactile sensors...
//!         let finger = |i: u32, side: f64| FingerCloud {
//!             finger: Some(i),
//!             links: vec![format!("finger{i}")],
//!             points: vec![CloudPoint { p: [0.0, side * 0.02, 0.1], n: [0.0, -side, 0.0], w: 1.0 }],
//!         };
//!         Ok(HandReading {
//!             palm_pose: command.palm_pose,
//!             fingers: vec![finger(0, 1.0), finger(1, -1.0)],
//!             fingertips: Vec::new(),
//!             min_gap: None,
//!         })
//!     }
//! }
//!
//! # async fn example() -> Result<(), Box<dyn std::error::Error>> {
//! let bus = graspopt_bus::Bus::open(&graspopt_bus::BusConfig::default()).await?;
//! let run = RunId::new("lab-1")?;
//! serve(&bus, &run, "gripper-1", Duration::ZERO, MyGripper).await?;
//! # Ok(())
//! # }
//! ```
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod driver;
mod error;
pub mod replay;
pub mod serve;
pub mod simulated;

use std::path::PathBuf;
use std::time::Duration;

use graspopt_bus::{Agent, Bus};
use graspopt_protocol::{AgentKind, RunId};
use graspopt_trial::fingertips::FingertipSettings;
use graspopt_trial::forces::ForceSettings;
use serde::{Deserialize, Serialize};

pub use driver::{HandDriver, HandError, HandReading, Sensing};
pub use error::HandAgentError;
pub use replay::ReplayHand;
pub use serve::{UNIQUE_WAIT, serve};
pub use simulated::{SimulatedHand, world_object};

/// Hand settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HandConfig {
    pub id: String,
    /// A built-in hand (`barrett`, `parallel_jaw`, `franka_hand`) or a URDF file.
    pub hand: String,
    /// The world's object; `None`: the one perception names.
    pub object: Option<String>,
    /// A user mesh as the world's object.
    pub mesh: Option<PathBuf>,
    /// Factor from the mesh file's units to metres (0.001 for millimetres).
    pub mesh_scale: f64,
    /// Minimum duration of a trial (milliseconds), to model a robot's cycle time.
    pub trial_cost_ms: u64,
    /// Answer trials from this recording (JSON lines, see [`replay`]) instead of simulating.
    pub replay: Option<PathBuf>,
    /// What the simulated hand measures: contact clouds, or fingertip force/torque readings
    /// (a hand with spherical fingertips, `barrett_ft`).
    pub sensing: Sensing,
    /// The simulated fingertip sensors (with `sensing = "ft"`).
    pub fingertips: FingertipSettings,
    /// The simulated world's object: its mass and gravity, which the fingertips' forces hold.
    pub forces: ForceSettings,
}

impl Default for HandConfig {
    fn default() -> Self {
        HandConfig {
            id: "hand-1".into(),
            hand: "barrett".into(),
            object: None,
            mesh: None,
            mesh_scale: 1.0,
            trial_cost_ms: 0,
            replay: None,
            sensing: Sensing::Clouds,
            fingertips: FingertipSettings::default(),
            forces: ForceSettings::default(),
        }
    }
}

/// Checks what `config` asks for before anything joins the bus: the hand exists, and with
/// `sensing = "ft"` it has spherical fingertips and the sensor settings are valid (a replay
/// hand's recording is checked when it loads).
pub fn check(config: &HandConfig) -> Result<(), HandAgentError> {
    if config.replay.is_none() {
        SimulatedHand::new(config)?;
    }
    Ok(())
}

/// Serves trial commands with the hand `config` describes (the replay hand when `replay`
/// is set, else the simulated one, measuring clouds or fingertip forces per `sensing`) until
/// the task is cancelled.
pub async fn run(bus: &Bus, run: &RunId, config: &HandConfig) -> Result<(), HandAgentError> {
    let cost = Duration::from_millis(config.trial_cost_ms);
    if let Some(path) = &config.replay {
        let recording = replay::Recording::load(path)?;
        tracing::info!(
            "hand {}: answering from {} ({} grasps)",
            config.id,
            recording.path.display(),
            recording.trials.len()
        );
        return serve(bus, run, &config.id, cost, ReplayHand { recording }).await;
    }
    let hand = SimulatedHand::new(config)?;
    serve(bus, run, &config.id, cost, hand).await
}

/// The hand agent (`graspopt agent hand`).
pub struct HandAgent;

impl Agent for HandAgent {
    const KIND: AgentKind = AgentKind::Hand;
    const ABOUT: &'static str = "Executes trials on the simulated hand";
    type Config = HandConfig;
    type Output = ();
    type Error = HandAgentError;

    fn id(config: &mut HandConfig) -> &mut String {
        &mut config.id
    }

    fn validate(config: &HandConfig) -> Result<(), HandAgentError> {
        check(config)
    }

    async fn run(
        &self,
        bus: &Bus,
        run_id: &RunId,
        config: &HandConfig,
        stop: impl Future<Output = ()> + Send,
    ) -> Result<(), HandAgentError> {
        graspopt_bus::agent::until(run(bus, run_id, config), stop).await
    }
}
