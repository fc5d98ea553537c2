//! The simulated hand: a [`HandDriver`] on the grasp simulator. It measures contact clouds, or
//! with [`Sensing::Wrenches`] the readings of force/torque sensors under its spherical fingertips
//! (`graspopt_trial::fingertips`), with sensor noise drawn from a generator seeded by the
//! trial and attempt, so a trial reads the same each time it is executed.

use graspopt_convert::{TrialTag, clouds_from_outcome, fingertip_wrench, isometry};
use graspopt_protocol::{ObjectEstimate, TrialCommand};
use graspopt_sim::{ContactModelSettings, Hand, Object, hand_by_name, run_trial};
use graspopt_trial::ScoreSettings;
use graspopt_trial::fingertips::{fingertips, simulate_wrenches};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::HandConfig;
use crate::driver::{HandDriver, HandError, HandReading, Sensing};
use crate::error::HandAgentError;

/// A simulated hand in a simulated world: the world holds the configured object, or the one
/// perception names at its true pose.
#[derive(Debug)]
pub struct SimulatedHand {
    hand: Box<dyn Hand>,
    settings: ContactModelSettings,
    config: HandConfig,
    world: Option<Object>,
    /// The object the estimate that built `world` named.
    world_name: Option<String>,
}

impl SimulatedHand {
    /// The hand `config.hand` in the world of `config` (empty until an object estimate
    /// arrives when no object is configured). Sensing forces needs a hand with spherical
    /// fingertips.
    pub fn new(config: &HandConfig) -> Result<SimulatedHand, HandAgentError> {
        let hand = hand_by_name(&config.hand).map_err(|source| HandAgentError::Hand {
            context: "hand agent",
            source,
        })?;
        if config.sensing == Sensing::Wrenches {
            let sensing = |context, source: Box<dyn std::error::Error + Send + Sync>| {
                HandAgentError::Sensing { context, source }
            };
            fingertips(hand.as_ref())
                .map_err(|e| sensing("hand agent with sensing = ft", e.into()))?;
            let noise = &config.fingertips.noise;
            noise
                .validate()
                .map_err(|e| sensing("hand agent: fingertip sensor noise", e.into()))?;
            config
                .forces
                .validate()
                .map_err(|e| sensing("hand agent", e.into()))?;
        }
        Ok(SimulatedHand {
            hand,
            settings: ContactModelSettings::default(),
            config: config.clone(),
            world: world_object(config, None),
            world_name: None,
        })
    }

    /// Executes one command on `world` (the object at its true pose).
    pub fn execute_on(
        &self,
        world: &Object,
        command: &TrialCommand,
    ) -> Result<HandReading, HandError> {
        let palm = isometry(&command.palm_pose);
        let outcome = run_trial(world, self.hand.as_ref(), &palm, &self.settings)
            .map_err(|e| HandError::Simulation(e.to_string()))?;
        let tag = TrialTag {
            run_id: command.run_id.clone(),
            trial_id: command.trial_id,
            attempt: command.attempt,
            worker: command.worker.clone(),
        };
        let clouds = clouds_from_outcome(&tag, &outcome, 0);
        if self.config.sensing == Sensing::Clouds {
            return Ok(HandReading {
                palm_pose: clouds.palm_pose,
                fingers: clouds.fingers,
                fingertips: Vec::new(),
                min_gap: clouds.min_gap,
            });
        }
        let mut rng =
            ChaCha8Rng::seed_from_u64(command.trial_id ^ (u64::from(command.attempt) << 48));
        let tips = simulate_wrenches(
            &outcome,
            self.hand.as_ref(),
            world,
            &ScoreSettings::default(),
            &self.config.forces,
            &self.config.fingertips,
            &mut rng,
        )
        .map_err(|e| HandError::Fingertips(e.to_string()))?;
        let stamp_ms = graspopt_bus::now_ms();
        Ok(HandReading {
            palm_pose: clouds.palm_pose,
            fingers: Vec::new(),
            fingertips: tips
                .iter()
                .map(|t| fingertip_wrench(&t.sensor, stamp_ms))
                .collect(),
            min_gap: clouds.min_gap,
        })
    }
}

impl HandDriver for SimulatedHand {
    fn hand(&self) -> Option<&str> {
        Some(self.hand.name())
    }

    fn sensing(&self) -> Sensing {
        self.config.sensing
    }

    fn needs_object(&self) -> bool {
        self.world.is_none()
    }

    /// Builds the world from the estimate when it has none yet, or when no object is
    /// configured and the estimate names another object.
    fn set_object(&mut self, estimate: &ObjectEstimate) {
        let follows = self.config.object.is_none() && self.config.mesh.is_none();
        if self.world.is_none() || (follows && self.world_name.as_deref() != Some(&estimate.object))
        {
            self.world = world_object(&self.config, Some(estimate));
            self.world_name = Some(estimate.object.clone());
        }
    }

    fn execute(&mut self, command: &TrialCommand) -> Result<HandReading, HandError> {
        match &self.world {
            Some(world) => self.execute_on(world, command),
            None => Err(HandError::NoObject),
        }
    }
}

/// The world's object: the configured one, or the one the estimate names at its true pose.
pub fn world_object(config: &HandConfig, estimate: Option<&ObjectEstimate>) -> Option<Object> {
    let loaded = match (&config.mesh, &config.object, estimate) {
        (Some(path), _, _) => Object::from_file_scaled(path, config.mesh_scale),
        (None, Some(name), _) => Object::by_name(name),
        // A built-in object at its own pose (the rotated cuboid's is turned 45 degrees: an
        // identity pose made it the plain cuboid, and every trial of a run on it scored
        // another grasp than `graspopt trial`); a mesh's own frame is the world's.
        (None, None, Some(e)) if e.mesh.is_none() => Object::by_name(&e.object),
        (None, None, Some(e)) => {
            let mut truth = e.clone();
            truth.pose = graspopt_protocol::Pose::IDENTITY;
            graspopt_convert::object_from_estimate(&truth)
        }
        (None, None, None) => return None,
    };
    match loaded {
        Ok(o) => Some(o),
        Err(e) => {
            tracing::error!("hand {}: cannot build the world's object: {e}", config.id);
            None
        }
    }
}
