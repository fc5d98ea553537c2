//! The hand agent: executes trial commands and sends what the fingers touched.
//!
//! This implementation drives the simulated hand: the world holds the object perception names
//! (at its true pose; `object` in the settings overrides it), the hand is put at the commanded
//! palm pose, closes until contact, and the raw contact clouds go to the metric agents
//! (shared memory on the same host, Zenoh otherwise). One trial at a time; `trial_cost_ms`
//! pads each trial to at least that long, to model a real robot's cycle time. A real hand is
//! another implementation of the same conversation (see `docs/protocol.md`).
//!
//! With `replay` set, the hand answers from recorded contact data instead ([`replay`]): each
//! trial gets the recorded grasp nearest to its parameters.
//!
//! [`SimulatedHand::execute`] is the logic (no network); [`run`] wires it to the bus.
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod replay;

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::Context;
use graspopt_bus::{Bus, CloudSender, Received, now_ms};
use graspopt_convert::{TrialTag, clouds_from_outcome, isometry};
use graspopt_protocol::{AgentKind, ContactClouds, ObjectEstimate, RunId, TrialCommand};
use graspopt_sim::{ContactModelSettings, Hand, Object, hand_by_name, run_trial};
use serde::{Deserialize, Serialize};

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
        }
    }
}

/// A simulated hand in a simulated world.
#[derive(Debug)]
pub struct SimulatedHand {
    hand: Box<dyn Hand>,
    settings: ContactModelSettings,
}

impl SimulatedHand {
    pub fn new(name: &str) -> anyhow::Result<SimulatedHand> {
        Ok(SimulatedHand {
            hand: hand_by_name(name).context("hand agent")?,
            settings: ContactModelSettings::default(),
        })
    }

    pub fn name(&self) -> &str {
        self.hand.name()
    }

    /// Executes one command on `world` (the object at its true pose). A command the hand
    /// cannot execute gives clouds with `error` set, not a failure of the agent.
    pub fn execute(&self, world: &Object, command: &TrialCommand, worker: &str) -> ContactClouds {
        let tag = TrialTag {
            run_id: command.run_id.clone(),
            trial_id: command.trial_id,
            attempt: command.attempt,
            worker: worker.to_string(),
        };
        let palm = isometry(&command.palm_pose);
        match run_trial(world, self.hand.as_ref(), &palm, &self.settings) {
            Ok(outcome) => clouds_from_outcome(&tag, &outcome, now_ms()),
            Err(e) => self.refuse(
                command,
                worker,
                format!("hand could not execute the trial: {e}"),
            ),
        }
    }

    /// The answer to a command this hand does not execute: no clouds, the reason in `error`
    /// (the coordinator records the trial as failed).
    pub fn refuse(&self, command: &TrialCommand, worker: &str, error: String) -> ContactClouds {
        ContactClouds {
            run_id: command.run_id.clone(),
            trial_id: command.trial_id,
            attempt: command.attempt,
            worker: worker.to_string(),
            hand: self.hand.name().to_string(),
            palm_pose: command.palm_pose,
            fingers: Vec::new(),
            min_gap: None,
            error: Some(error),
            executed_ms: now_ms(),
        }
    }
}

/// The world's object: the configured one, or the one the estimate names at its true pose.
pub fn world_object(config: &HandConfig, estimate: Option<&ObjectEstimate>) -> Option<Object> {
    let loaded = match (&config.mesh, &config.object, estimate) {
        (Some(path), _, _) => Object::from_file_scaled(path, config.mesh_scale),
        (None, Some(name), _) => Object::by_name(name),
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

/// The object estimate `r` carries if it is a valid one of `run`; otherwise the rejection is
/// counted in `bad` and logged.
fn estimate_of_run(
    r: Received<ObjectEstimate>,
    run: &RunId,
    id: &str,
    bad: &mut u64,
) -> Option<ObjectEstimate> {
    match r.message {
        Ok(e) if e.run_id == *run => Some(e),
        Ok(e) => {
            *bad += 1;
            tracing::warn!(
                "hand {id}: object estimate of run {:?} ignored ({bad} bad messages)",
                e.run_id
            );
            None
        }
        Err(e) => {
            *bad += 1;
            tracing::warn!(
                "hand {id}: bad object estimate on {} ({bad} bad messages): {e}",
                r.key
            );
            None
        }
    }
}

/// How long a starting hand waits for a predecessor with its id to vanish (a worker killed
/// and restarted at once) before refusing to start.
pub const UNIQUE_WAIT: std::time::Duration = std::time::Duration::from_secs(5);

/// Serves trial commands until the task is cancelled. Refuses to start while another hand
/// with the same id is alive on the run (see [`UNIQUE_WAIT`]).
pub async fn run(bus: &Bus, run: &RunId, config: &HandConfig) -> anyhow::Result<()> {
    // Two hands with one id would both execute every trial sent to that id.
    let _place = bus
        .wait_until_unique(run, AgentKind::Hand, Some(&config.id), UNIQUE_WAIT)
        .await?;
    if let Some(path) = &config.replay {
        let recording = replay::Recording::load(path)?;
        return run_replay(bus, run, config, recording).await;
    }
    let hand = Arc::new(SimulatedHand::new(&config.hand)?);
    let commands = bus
        .subscribe::<TrialCommand>(&run.command_key(&config.id))
        .await?;
    let objects = bus.subscribe::<ObjectEstimate>(&run.object_key()).await?;
    let sender = CloudSender::open(bus, run);
    let mut world: Option<Arc<Object>> = world_object(config, None).map(Arc::new);
    let mut world_name: Option<String> = None;
    // Declared last: the coordinator sends commands once it sees the token.
    let _token = bus.declare_alive(run, AgentKind::Hand, &config.id).await?;
    let mut bad = 0u64;
    loop {
        tokio::select! {
            Some(r) = objects.recv() => {
                if let Some(e) = estimate_of_run(r, run, &config.id, &mut bad)
                    && config.object.is_none()
                    && config.mesh.is_none()
                    && world_name.as_deref() != Some(&e.object)
                {
                    world = world_object(config, Some(&e)).map(Arc::new);
                    world_name = Some(e.object.clone());
                }
            },
            Some(r) = commands.recv() => {
                let command = match r.message {
                    Ok(c) if c.run_id == *run && c.worker == config.id => c,
                    Ok(c) => {
                        bad += 1;
                        tracing::warn!("hand {}: command for {}/{} ignored ({bad} bad messages)", config.id, c.run_id, c.worker);
                        continue;
                    }
                    Err(e) => {
                        bad += 1;
                        tracing::warn!("hand {}: bad command on {} ({bad} bad messages): {e}", config.id, r.key);
                        continue;
                    }
                };
                // Wait for the world's object if perception has not spoken yet.
                while world.is_none() {
                    match objects.recv().await {
                        Some(r) => {
                            if let Some(e) = estimate_of_run(r, run, &config.id, &mut bad) {
                                world = world_object(config, Some(&e)).map(Arc::new);
                                world_name = Some(e.object.clone());
                            }
                        }
                        None => return Ok(()),
                    }
                }
                let Some(object) = world.clone() else { continue };
                let started = Instant::now();
                let h = hand.clone();
                let id = config.id.clone();
                let mut clouds = if command.hand != hand.name() {
                    let why = format!("worker {id} has a {} hand, the trial asks for {}", hand.name(), command.hand);
                    hand.refuse(&command, &id, why)
                } else {
                    tokio::task::spawn_blocking(move || h.execute(&object, &command, &id))
                        .await
                        .context("hand: trial thread panicked")?
                };
                let cost = Duration::from_millis(config.trial_cost_ms);
                if let Some(rest) = cost.checked_sub(started.elapsed()) {
                    tokio::time::sleep(rest).await;
                }
                clouds.executed_ms = now_ms();
                if let Err(e) = sender.send(&clouds).await {
                    tracing::warn!("hand {}: cannot send the clouds of trial {}: {e}", config.id, clouds.trial_id);
                }
            },
            else => return Ok(()),
        }
    }
}

/// Serves trial commands from a recording until the task is cancelled.
async fn run_replay(
    bus: &Bus,
    run: &RunId,
    config: &HandConfig,
    recording: replay::Recording,
) -> anyhow::Result<()> {
    let commands = bus
        .subscribe::<TrialCommand>(&run.command_key(&config.id))
        .await?;
    let sender = CloudSender::open(bus, run);
    let _token = bus.declare_alive(run, AgentKind::Hand, &config.id).await?;
    tracing::info!(
        "hand {}: answering from {} ({} grasps)",
        config.id,
        recording.path.display(),
        recording.trials.len()
    );
    let mut bad = 0u64;
    while let Some(r) = commands.recv().await {
        let command = match r.message {
            Ok(c) if c.run_id == *run && c.worker == config.id => c,
            Ok(c) => {
                bad += 1;
                tracing::warn!(
                    "hand {}: command for {}/{} ignored ({bad} bad messages)",
                    config.id,
                    c.run_id,
                    c.worker
                );
                continue;
            }
            Err(e) => {
                bad += 1;
                tracing::warn!(
                    "hand {}: bad command on {} ({bad} bad messages): {e}",
                    config.id,
                    r.key
                );
                continue;
            }
        };
        let started = Instant::now();
        let mut clouds = recording.answer(&command, &config.id);
        if let Some(rest) =
            Duration::from_millis(config.trial_cost_ms).checked_sub(started.elapsed())
        {
            tokio::time::sleep(rest).await;
        }
        clouds.executed_ms = now_ms();
        if let Err(e) = sender.send(&clouds).await {
            tracing::warn!(
                "hand {}: cannot send the clouds of trial {}: {e}",
                config.id,
                clouds.trial_id
            );
        }
    }
    Ok(())
}
