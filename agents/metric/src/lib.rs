//! The metric agent: turns each trial's contact clouds, or its fingertip force/torque
//! readings, into a quality result with its contact-force analysis.
//!
//! Contact models are built from the raw clouds on the *estimated* object (perception's), as
//! a real system must, then scored with the configured contact model, frame and metric (the
//! thesis's defaults: surface model, soft fingers, object frame, BW). Clouds arrive over
//! shared memory from hands on this host and over Zenoh from the others. A hand with
//! force/torque sensors in its fingertips sends readings instead: each fingertip's contact is
//! found from its reading (intrinsic contact sensing), and the contacts are scored as one-point
//! clouds; a reading that admits no contact is left out, with the reason in the log.
//!
//! Every result carries a force analysis (`TrialResult::forces`): the least forces in the
//! friction cones that hold the object's weight (or why they are unavailable, when the
//! solver found no answer: the score stands), and for measured forces their net wrench and
//! slip margins (`graspopt_trial::forces`).
//!
//! [`score_clouds`] and [`score_wrenches`] are the logic (no network); [`run`] wires them to
//! the bus, and [`MetricAgent`] is it as an [`Agent`].
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

mod error;

use std::collections::VecDeque;
use std::sync::Arc;

pub use error::MetricError;
use graspopt_bus::{Agent, Bus, CloudReceiver, Received, ReceivedClouds};
use graspopt_convert::{
    force_analysis, isometry, measured_from_clouds, metric_values, object_from_estimate,
    sensor_reading,
};
use graspopt_protocol::keys::{Key, OBJECT, RESULT, WRENCHES};
use graspopt_protocol::{
    AgentKind, AttemptRef, ContactClouds, DecodeError, Encoding, FingertipWrenches, ForceAnalysis,
    ObjectEstimate, RunId, TrialResult,
};
use graspopt_quality::forces::ContactForces;
use graspopt_sensing::SensingSettings;
use graspopt_sim::{ContactModelSettings, Object};
use graspopt_trial::ScoreSettings;
use graspopt_trial::fingertips::{
    FingertipContact, fingertip_model, fingertip_score, sense, soft_finger_sensing,
};
use graspopt_trial::forces::{ForceSettings, GraspForces, analyse_contacts, analyse_outcome};
use graspopt_trial::measured::{MeasuredTrial, score_measured};
use graspopt_trial::score::grasp_model;
use graspopt_trial::{TrialError, TrialScore};
use serde::{Deserialize, Serialize};

/// Metric settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MetricConfig {
    pub id: String,
    /// How contact models are built from the clouds.
    pub contacts: ContactModelSettings,
    /// Contact model, frame, torque scale and metric of the score.
    pub score: ScoreSettings,
    /// How fingertip force/torque readings are turned into contacts (soft fingers by
    /// default, as the score's contact model).
    pub sensing: SensingSettings,
    /// What the force analysis holds the grasp against (the object's weight).
    pub forces: ForceSettings,
}

impl Default for MetricConfig {
    fn default() -> Self {
        MetricConfig {
            id: "metric".into(),
            contacts: ContactModelSettings::default(),
            score: ScoreSettings::default(),
            sensing: soft_finger_sensing(),
            forces: ForceSettings::default(),
        }
    }
}

/// Scores one trial's clouds on the estimated object. Errors (the hand's, or a scoring
/// failure) become a result with `error` set: the coordinator records the trial as failed.
pub fn score_clouds(clouds: &ContactClouds, object: &Object, config: &MetricConfig) -> TrialResult {
    let mut result = TrialResult {
        run_id: clouds.run_id.clone(),
        trial_id: clouds.trial_id,
        attempt: clouds.attempt,
        worker: clouds.worker.clone(),
        scorer: config.id.clone(),
        score: 0.0,
        metrics: None,
        contacts: 0,
        fingers_in_contact: 0,
        cloud_points: clouds.point_count() as u32,
        cloud_transport: String::new(),
        error: clouds.error.clone(),
        forces: None,
    };
    if result.error.is_some() {
        return result;
    }
    let measured = measured_from_clouds(clouds);
    match score_measured(&measured, object, &config.contacts, &config.score) {
        Ok((s, outcome)) => {
            result.score = s.score;
            result.metrics = s.metrics.as_ref().map(metric_values);
            result.contacts = s.contacts as u32;
            result.fingers_in_contact = s.fingers_in_contact as u32;
            let forces = analyse_outcome(&outcome, object, &config.score, &config.forces);
            result.forces = analysed(forces, &result);
        }
        Err(e) => result.error = Some(format!("scoring failed: {e}")),
    }
    result
}

/// Scores one trial's fingertip readings on the estimated object: each reading's contact
/// (intrinsic contact sensing), scored as a one-point cloud per fingertip with the mean-point
/// model (`graspopt_trial::fingertips::fingertip_score`), and the measured forces analysed. A reading that admits no contact is left out and its reason returned
/// (`finger: reason`). Errors become a result with `error` set, as for clouds.
pub fn score_wrenches(
    readings: &FingertipWrenches,
    object: &Object,
    config: &MetricConfig,
) -> (TrialResult, Vec<String>) {
    let mut result = TrialResult {
        run_id: readings.run_id.clone(),
        trial_id: readings.trial_id,
        attempt: readings.attempt,
        worker: readings.worker.clone(),
        scorer: config.id.clone(),
        score: 0.0,
        metrics: None,
        contacts: 0,
        fingers_in_contact: 0,
        cloud_points: readings.fingertips.len() as u32,
        cloud_transport: String::new(),
        error: readings.error.clone(),
        forces: None,
    };
    let mut refused = Vec::new();
    if result.error.is_some() {
        return (result, refused);
    }
    let mut contacts = Vec::new();
    for tip in &readings.fingertips {
        match sense(&sensor_reading(tip), &config.sensing) {
            Ok(c) => contacts.push((tip.finger as usize, tip.link.clone(), c)),
            Err(why) => refused.push(format!("finger {} ({}): {why}", tip.finger, tip.link)),
        }
    }
    let measured = MeasuredTrial::from_fingertips(
        &readings.hand,
        isometry(&readings.palm_pose),
        &contacts,
        readings.min_gap,
    );
    match score_sensed(&measured, &contacts, object, config) {
        Ok((s, forces)) => {
            result.score = s.score;
            result.metrics = s.metrics.as_ref().map(metric_values);
            result.contacts = s.contacts as u32;
            result.fingers_in_contact = s.fingers_in_contact as u32;
            result.forces = analysed(forces, &result);
        }
        Err(e) => result.error = Some(format!("scoring failed: {e}")),
    }
    (result, refused)
}

/// The force analysis for the result. Least forces the solver found no answer for are
/// reported unavailable in it, with the reason (`ForceAnalysis::unavailable`), not logged.
/// None when no analysis could be made (measured forces it refused): the score stands
/// without it, and the log says why.
fn analysed(
    forces: Result<GraspForces, TrialError>,
    result: &TrialResult,
) -> Option<ForceAnalysis> {
    match forces {
        Ok(f) => Some(force_analysis(&f)),
        Err(e) => {
            tracing::warn!(
                "{}: trial {}: no force analysis, the score stands without it: {e}",
                result.scorer,
                result.trial_id
            );
            None
        }
    }
}

/// A score, and the force analysis beside it (which may fail on its own).
type ScoreAndForces = (TrialScore, Result<GraspForces, TrialError>);

/// The score of sensed fingertip contacts, and the analysis of their measured forces.
fn score_sensed(
    measured: &MeasuredTrial,
    contacts: &[(usize, String, FingertipContact)],
    object: &Object,
    config: &MetricConfig,
) -> Result<ScoreAndForces, TrialError> {
    let score = fingertip_score(&config.score);
    let (s, outcome) = score_measured(measured, object, &config.contacts, &score)?;
    let reference = grasp_model(&outcome, object, &score)?.reference_point;
    let quality: Vec<_> = contacts.iter().map(|(_, _, c)| c.contact()).collect();
    let forces = ContactForces::new(
        contacts.iter().map(|(_, _, c)| c.force).collect(),
        contacts.iter().map(|(_, _, c)| c.torsion).collect(),
    );
    let model = fingertip_model(config.sensing.kind, &config.score.model);
    let analysis = analyse_contacts(
        &quality,
        &model,
        &reference,
        object,
        &config.forces,
        (!contacts.is_empty()).then_some(forces),
    );
    Ok((s, analysis))
}

/// The failed result of an attempt whose clouds (`what`: "contact clouds") or fingertip
/// readings ("fingertip readings") were invalid (a NaN, a normal that is not unit length, a
/// surface of radius 0): the error names the field.
pub fn invalid_measurement_result(
    about: &AttemptRef,
    what: &str,
    detail: &str,
    scorer: &str,
    transport: &str,
) -> TrialResult {
    TrialResult {
        run_id: about.run_id.clone(),
        trial_id: about.trial_id,
        attempt: about.attempt,
        worker: about.worker.clone(),
        scorer: scorer.to_string(),
        score: 0.0,
        metrics: None,
        contacts: 0,
        fingers_in_contact: 0,
        cloud_points: 0,
        cloud_transport: transport.to_string(),
        error: Some(format!("invalid {what}: {detail}")),
        forces: None,
    }
}

/// Scores clouds until the task is cancelled.
pub async fn run(bus: &Bus, run: &RunId, config: &MetricConfig) -> Result<(), MetricError> {
    validate(config)?;
    let mut clouds = CloudReceiver::open(bus, run).await?;
    let wrenches = bus.subscribe(&WRENCHES.key(run.into())).await?;
    let objects = bus.subscribe(&OBJECT.key(run.into())).await?;
    let _token = bus
        .declare_alive(run, AgentKind::Metric, &config.id)
        .await?;
    let mut scorer = Scorer {
        bus,
        run,
        key: RESULT.key(run.into()),
        config: Arc::new(config.clone()),
        object: None,
        waiting: VecDeque::new(),
        bad: 0,
    };
    loop {
        tokio::select! {
            Some(r) = objects.recv() => scorer.on_object(r),
            Some(r) = clouds.recv() => scorer.on_clouds(r).await,
            Some(r) = wrenches.recv() => scorer.on_wrenches(r).await,
            else => return Ok(()),
        }
        scorer.score_waiting().await?;
    }
}

/// Refuses settings the metric agent cannot score with, naming them.
pub fn validate(config: &MetricConfig) -> Result<(), MetricError> {
    config
        .contacts
        .validate()
        .map_err(|e| MetricError::Settings(e.into()))?;
    config
        .forces
        .validate()
        .map_err(|e| MetricError::Settings(e.into()))
}

/// The metric agent's loop state: the run's object, the measurements waiting for it, and
/// the count of bad messages.
struct Scorer<'a> {
    bus: &'a Bus,
    run: &'a RunId,
    key: Key<TrialResult>,
    config: Arc<MetricConfig>,
    /// The estimate's sequence number, object name and object.
    object: Option<(u64, String, Arc<Object>)>,
    waiting: VecDeque<Measured>,
    bad: u64,
}

impl Scorer<'_> {
    fn on_object(&mut self, r: Received<ObjectEstimate>) {
        let id = &self.config.id;
        match r.message {
            Ok(e) if e.run_id == *self.run => {
                let same = self
                    .object
                    .as_ref()
                    .is_some_and(|(seq, name, _)| *seq == e.seq && *name == e.object);
                if !same {
                    match object_from_estimate(&e) {
                        Ok(o) => self.object = Some((e.seq, e.object.clone(), Arc::new(o))),
                        Err(err) => {
                            self.bad += 1;
                            let bad = self.bad;
                            tracing::warn!(
                                "metric {id}: unusable object estimate ({bad} bad messages): {err}"
                            );
                        }
                    }
                }
            }
            Ok(e) => {
                self.bad += 1;
                let bad = self.bad;
                tracing::warn!(
                    "metric {id}: object estimate of run {:?} ignored ({bad} bad messages)",
                    e.run_id
                );
            }
            Err(e) => {
                self.bad += 1;
                let bad = self.bad;
                tracing::warn!(
                    "metric {id}: bad object estimate on {} ({bad} bad messages): {e}",
                    r.key
                );
            }
        }
    }

    async fn on_clouds(&mut self, r: ReceivedClouds) {
        let id = self.config.id.clone();
        match r.message {
            Ok(c) if c.run_id == *self.run => {
                self.waiting.push_back(Measured::Clouds(c, r.path.as_str()))
            }
            Ok(c) => {
                self.bad += 1;
                let bad = self.bad;
                tracing::warn!(
                    "metric {id}: clouds of run {:?} ignored ({bad} bad messages)",
                    c.run_id
                );
            }
            Err(e) => {
                self.bad += 1;
                let bad = self.bad;
                tracing::warn!(
                    "metric {id}: bad clouds via {} ({bad} bad messages): {e}",
                    r.path.as_str()
                );
                // Clouds that name an attempt of this run fail it with the reason, so the
                // trial does not wait for its lease (the coordinator accepts it only from
                // the worker the attempt was issued to).
                self.fail_invalid(&e, "contact clouds", r.path.as_str())
                    .await;
            }
        }
    }

    async fn on_wrenches(&mut self, r: Received<FingertipWrenches>) {
        let id = self.config.id.clone();
        match r.message {
            Ok(w) if w.run_id == *self.run => self.waiting.push_back(Measured::Wrenches(w)),
            Ok(w) => {
                self.bad += 1;
                let bad = self.bad;
                tracing::warn!(
                    "metric {id}: fingertip readings of run {:?} ignored ({bad} bad messages)",
                    w.run_id
                );
            }
            Err(e) => {
                self.bad += 1;
                let bad = self.bad;
                tracing::warn!(
                    "metric {id}: bad fingertip readings on {} ({bad} bad messages): {e}",
                    r.key
                );
                self.fail_invalid(&e, "fingertip readings", "zenoh").await;
            }
        }
    }

    /// Publishes the failure of the attempt an invalid measurement names, if it is of this
    /// run.
    async fn fail_invalid(&self, e: &DecodeError, what: &str, transport: &str) {
        if let DecodeError::Invalid {
            detail,
            about: Some(a),
            ..
        } = e
            && a.run_id == *self.run
        {
            let id = &self.config.id;
            let detail = detail.to_string();
            let failed = invalid_measurement_result(a, what, &detail, id, transport);
            if let Err(e) = self.bus.put(&self.key, &failed, Encoding::Bincode).await {
                tracing::warn!(
                    "metric {id}: cannot publish the failure of trial {}: {e}",
                    a.trial_id
                );
            }
        }
    }

    /// Scores and publishes the waiting measurements, once the object is known.
    async fn score_waiting(&mut self) -> Result<(), MetricError> {
        let Some((_, _, o)) = &self.object else {
            return Ok(());
        };
        while let Some(measured) = self.waiting.pop_front() {
            let (o, cfg) = (o.clone(), self.config.clone());
            let result = tokio::task::spawn_blocking(move || measured.score(&o, &cfg))
                .await
                .map_err(MetricError::Panicked)?;
            if let Err(e) = self.bus.put(&self.key, &result, Encoding::Bincode).await {
                tracing::warn!(
                    "metric {}: cannot publish result of trial {}: {e}",
                    self.config.id,
                    result.trial_id
                );
            }
        }
        Ok(())
    }
}

/// The metric agent (`graspopt agent metric`).
pub struct MetricAgent;

impl Agent for MetricAgent {
    const KIND: AgentKind = AgentKind::Metric;
    const ABOUT: &'static str = "Scores contact clouds and fingertip force readings";
    type Config = MetricConfig;
    type Output = ();
    type Error = MetricError;

    fn id(config: &mut MetricConfig) -> &mut String {
        &mut config.id
    }

    fn validate(config: &MetricConfig) -> Result<(), MetricError> {
        validate(config)
    }

    async fn run(
        &self,
        bus: &Bus,
        run_id: &RunId,
        config: &MetricConfig,
        stop: impl Future<Output = ()> + Send,
    ) -> Result<(), MetricError> {
        graspopt_bus::agent::until(run(bus, run_id, config), stop).await
    }
}

/// What a hand sent for one trial, waiting for the object estimate.
enum Measured {
    /// Clouds and how they came (`shm`, `zenoh`).
    Clouds(ContactClouds, &'static str),
    Wrenches(FingertipWrenches),
}

impl Measured {
    /// Its result; refused fingertip readings are logged.
    fn score(self, object: &Object, config: &MetricConfig) -> TrialResult {
        match self {
            Measured::Clouds(c, path) => {
                let mut result = score_clouds(&c, object, config);
                result.cloud_transport = path.to_string();
                result
            }
            Measured::Wrenches(w) => {
                let (mut result, refused) = score_wrenches(&w, object, config);
                for why in refused {
                    tracing::info!(
                        "metric {}: trial {}: no contact from fingertip reading of {why}",
                        config.id,
                        w.trial_id
                    );
                }
                result.cloud_transport = "zenoh".to_string();
                result
            }
        }
    }
}
