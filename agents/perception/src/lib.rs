//! The perception agent: publishes the object estimate every trial is planned against.
//!
//! In simulation the estimate is the scene's object at its true pose perturbed once by seeded
//! Gaussian noise (a calibration error that stays for the whole run). It is published at
//! start and then every `period_ms`, so agents that start later or restart learn it.
//!
//! [`estimate`] is the logic (no network); [`run`] wires it to the bus, and
//! [`PerceptionAgent`] is it as an [`Agent`].
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

mod error;

use std::path::PathBuf;
use std::time::Duration;

pub use error::PerceptionError;
use graspopt_bus::{Agent, Bus, now_ms};
use graspopt_protocol::keys::OBJECT;
use graspopt_protocol::{AgentKind, Encoding, ObjectEstimate, RunId};
use graspopt_sim::Object;
use graspopt_sim::noise::gaussian;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Perception settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PerceptionConfig {
    pub id: String,
    /// A built-in object name, unless `mesh` is given.
    pub object: String,
    /// A user mesh (OBJ or STL) instead of a built-in object.
    pub mesh: Option<PathBuf>,
    /// Factor from the mesh file's units to metres (0.001 for millimetres).
    pub mesh_scale: f64,
    /// Standard deviation of the position error, per axis (metres).
    pub position_noise: f64,
    /// Standard deviation of the orientation error, per axis of a rotation vector (radians).
    pub rotation_noise: f64,
    pub seed: u64,
    pub period_ms: u64,
}

impl Default for PerceptionConfig {
    fn default() -> Self {
        PerceptionConfig {
            id: "perception".into(),
            object: "mug".into(),
            mesh: None,
            mesh_scale: 1.0,
            position_noise: 0.0,
            rotation_noise: 0.0,
            seed: 0,
            period_ms: 1000,
        }
    }
}

impl PerceptionConfig {
    /// Checks the settings: the noise levels must be finite and non-negative (an infinite
    /// one would put the object nowhere).
    pub fn validate(&self) -> Result<(), PerceptionError> {
        // Beyond these an estimate means nothing (a rotation's standard deviation past a half
        // turn, a position's past a metre around objects of centimetres), and the pose of a
        // huge one is not even finite.
        for (name, v, max, unit) in [
            (
                "position_noise",
                self.position_noise,
                MAX_POSITION_NOISE,
                "m",
            ),
            (
                "rotation_noise",
                self.rotation_noise,
                MAX_ROTATION_NOISE,
                "rad",
            ),
        ] {
            if !(v.is_finite() && (0.0..=max).contains(&v)) {
                return Err(PerceptionError::Noise {
                    name,
                    max,
                    unit,
                    value: v,
                });
            }
        }
        Ok(())
    }
}

/// The largest accepted `position_noise` (m).
pub const MAX_POSITION_NOISE: f64 = 1.0;
/// The largest accepted `rotation_noise` (rad): half a turn.
pub const MAX_ROTATION_NOISE: f64 = std::f64::consts::PI;

/// The scene's object (at its true pose).
pub fn scene_object(config: &PerceptionConfig) -> Result<Object, PerceptionError> {
    match &config.mesh {
        Some(path) => Object::from_file_scaled(path, config.mesh_scale).map_err(|source| {
            PerceptionError::Mesh {
                path: path.clone(),
                source,
            }
        }),
        None => Object::by_name(&config.object).map_err(PerceptionError::Object),
    }
}

/// The noisy pose estimate of `truth`: the same for the same seed.
pub fn noisy_pose(truth: &Isometry3<f64>, config: &PerceptionConfig) -> Isometry3<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    let mut v = || Vector3::new(gaussian(&mut rng), gaussian(&mut rng), gaussian(&mut rng));
    let dt = v() * config.position_noise;
    let dr = v() * config.rotation_noise;
    Isometry3::from_parts(Translation3::from(dt), UnitQuaternion::from_scaled_axis(dr)) * truth
}

/// The estimate to publish.
pub fn estimate(run: &RunId, config: &PerceptionConfig) -> Result<ObjectEstimate, PerceptionError> {
    config.validate()?;
    let object = scene_object(config)?;
    let pose = noisy_pose(object.pose(), config);
    Ok(ObjectEstimate {
        run_id: run.clone(),
        object: object.name().to_string(),
        mesh: config
            .mesh
            .as_ref()
            .map(|_| graspopt_convert::mesh_data(&object)),
        pose: graspopt_convert::pose(&pose),
        seq: 1,
        stamp_ms: now_ms(),
        source: config.id.clone(),
    })
}

/// Publishes the estimate until the task is cancelled.
pub async fn run(bus: &Bus, run: &RunId, config: &PerceptionConfig) -> Result<(), PerceptionError> {
    let mut estimate = estimate(run, config)?;
    let _token = bus
        .declare_alive(run, AgentKind::Perception, &config.id)
        .await?;
    let key = OBJECT.key(run.into());
    let period = Duration::from_millis(config.period_ms.max(10));
    loop {
        estimate.stamp_ms = now_ms();
        if let Err(e) = bus.put(&key, &estimate, Encoding::Bincode).await {
            tracing::warn!("perception: cannot publish the estimate: {e}");
        }
        tokio::time::sleep(period).await;
    }
}

/// The perception agent (`graspopt agent perception`).
pub struct PerceptionAgent;

impl Agent for PerceptionAgent {
    const KIND: AgentKind = AgentKind::Perception;
    const ABOUT: &'static str = "Publishes the object estimate";
    type Config = PerceptionConfig;
    type Output = ();
    type Error = PerceptionError;

    fn id(config: &mut PerceptionConfig) -> &mut String {
        &mut config.id
    }

    fn validate(config: &PerceptionConfig) -> Result<(), PerceptionError> {
        config.validate()
    }

    async fn run(
        &self,
        bus: &Bus,
        run_id: &RunId,
        config: &PerceptionConfig,
        stop: impl Future<Output = ()> + Send,
    ) -> Result<(), PerceptionError> {
        graspopt_bus::agent::until(run(bus, run_id, config), stop).await
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_is_seeded_and_scaled() {
        let truth = Isometry3::identity();
        let config = PerceptionConfig {
            position_noise: 0.002,
            rotation_noise: 0.01,
            seed: 7,
            ..PerceptionConfig::default()
        };
        let a = noisy_pose(&truth, &config);
        let b = noisy_pose(&truth, &config);
        assert_eq!(a, b);
        let t = a.translation.vector.norm();
        assert!(t > 0.0 && t < 0.002 * 6.0, "{t}");
        let exact = noisy_pose(&truth, &PerceptionConfig::default());
        assert_eq!(exact, truth);
        let other = noisy_pose(&truth, &PerceptionConfig { seed: 8, ..config });
        assert_ne!(a, other);
    }

    #[test]
    fn noise_not_finite_negative_or_meaningless_is_refused_by_name() {
        let run = RunId::new("r").unwrap();
        for (position_noise, rotation_noise, name) in [
            (f64::INFINITY, 0.0, "position_noise"),
            (0.0, f64::NAN, "rotation_noise"),
            (0.0, -0.1, "rotation_noise"),
            (0.0, f64::MAX * 2.0, "rotation_noise"),
            // Finite but past any meaning: a rotation of 1e300 rad is not even a pose.
            (0.0, 1e300, "rotation_noise"),
            (1.5, 0.0, "position_noise"),
        ] {
            let config = PerceptionConfig {
                position_noise,
                rotation_noise,
                ..PerceptionConfig::default()
            };
            let e = estimate(&run, &config).unwrap_err().to_string();
            assert!(e.contains(name), "{e}");
        }
        assert!(PerceptionConfig::default().validate().is_ok());
        let widest = PerceptionConfig {
            position_noise: MAX_POSITION_NOISE,
            rotation_noise: MAX_ROTATION_NOISE,
            ..PerceptionConfig::default()
        };
        assert!(widest.validate().is_ok());
        assert!(estimate(&run, &widest).is_ok());
    }
}
