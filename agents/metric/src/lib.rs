//! The metric agent: turns each trial's contact clouds into a quality result.
//!
//! Contact models are built from the raw clouds on the *estimated* object (perception's), as
//! a real system must, then scored with the configured contact model, frame and metric (the
//! thesis's defaults: surface model, soft fingers, object frame, BW). Clouds arrive over
//! shared memory from hands on this host and over Zenoh from the others.
//!
//! [`score_clouds`] is the logic (no network); [`run`] wires it to the bus.
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

use std::collections::VecDeque;
use std::sync::Arc;

use anyhow::Context;
use graspopt_bus::{Bus, CloudReceiver};
use graspopt_convert::{measured_from_clouds, metric_values, object_from_estimate};
use graspopt_protocol::keys::{OBJECT, RESULT};
use graspopt_protocol::{
    AgentKind, AttemptRef, ContactClouds, DecodeError, Encoding, RunId, TrialResult,
};
use graspopt_sim::{ContactModelSettings, Object};
use graspopt_trial::ScoreSettings;
use graspopt_trial::measured::score_measured;
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
}

impl Default for MetricConfig {
    fn default() -> Self {
        MetricConfig {
            id: "metric".into(),
            contacts: ContactModelSettings::default(),
            score: ScoreSettings::default(),
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
        Ok((s, _)) => {
            result.score = s.score;
            result.metrics = s.metrics.as_ref().map(metric_values);
            result.contacts = s.contacts as u32;
            result.fingers_in_contact = s.fingers_in_contact as u32;
        }
        Err(e) => result.error = Some(format!("scoring failed: {e}")),
    }
    result
}

/// The failed result of an attempt whose clouds were invalid (a NaN, a normal that is not
/// unit length): the error names the field.
pub fn invalid_clouds_result(
    about: &AttemptRef,
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
        error: Some(format!("invalid contact clouds: {detail}")),
        forces: None,
    }
}

/// Scores clouds until the task is cancelled.
pub async fn run(bus: &Bus, run: &RunId, config: &MetricConfig) -> anyhow::Result<()> {
    config
        .contacts
        .validate()
        .context("metric agent settings")?;
    let mut clouds = CloudReceiver::open(bus, run).await?;
    let objects = bus.subscribe(&OBJECT.key(run.into())).await?;
    let _token = bus
        .declare_alive(run, AgentKind::Metric, &config.id)
        .await?;
    let config = Arc::new(config.clone());
    let mut object: Option<(u64, String, Arc<Object>)> = None;
    let mut waiting: VecDeque<(ContactClouds, &'static str)> = VecDeque::new();
    let mut bad = 0u64;
    let key = RESULT.key(run.into());
    loop {
        tokio::select! {
            Some(r) = objects.recv() => match r.message {
                Ok(e) if e.run_id == *run => {
                    let same = object.as_ref().is_some_and(|(seq, name, _)| *seq == e.seq && *name == e.object);
                    if !same {
                        match object_from_estimate(&e) {
                            Ok(o) => object = Some((e.seq, e.object.clone(), Arc::new(o))),
                            Err(err) => {
                                bad += 1;
                                tracing::warn!("metric {}: unusable object estimate ({bad} bad messages): {err}", config.id);
                            }
                        }
                    }
                }
                Ok(e) => {
                    bad += 1;
                    tracing::warn!("metric {}: object estimate of run {:?} ignored ({bad} bad messages)", config.id, e.run_id);
                }
                Err(e) => {
                    bad += 1;
                    tracing::warn!("metric {}: bad object estimate on {} ({bad} bad messages): {e}", config.id, r.key);
                }
            },
            Some(r) = clouds.recv() => match r.message {
                Ok(c) if c.run_id == *run => waiting.push_back((c, r.path.as_str())),
                Ok(c) => {
                    bad += 1;
                    tracing::warn!("metric {}: clouds of run {:?} ignored ({bad} bad messages)", config.id, c.run_id);
                }
                Err(e) => {
                    bad += 1;
                    tracing::warn!("metric {}: bad clouds via {} ({bad} bad messages): {e}", config.id, r.path.as_str());
                    // Clouds that name an attempt of this run fail it with the reason, so
                    // the trial does not wait for its lease (the coordinator accepts it only
                    // from the worker the attempt was issued to).
                    if let DecodeError::Invalid { detail, about: Some(a), .. } = &e
                        && a.run_id == *run
                    {
                        let failed = invalid_clouds_result(a, detail, &config.id, r.path.as_str());
                        if let Err(e) = bus.put(&key, &failed, Encoding::Bincode).await {
                            tracing::warn!("metric {}: cannot publish the failure of trial {}: {e}", config.id, a.trial_id);
                        }
                    }
                }
            },
            else => return Ok(()),
        }
        if let Some((_, _, o)) = &object {
            while let Some((c, path)) = waiting.pop_front() {
                let (o, cfg) = (o.clone(), config.clone());
                let mut result = tokio::task::spawn_blocking(move || score_clouds(&c, &o, &cfg))
                    .await
                    .context("metric: scoring thread panicked")?;
                result.cloud_transport = path.to_string();
                if let Err(e) = bus.put(&key, &result, Encoding::Bincode).await {
                    tracing::warn!(
                        "metric {}: cannot publish result of trial {}: {e}",
                        config.id,
                        result.trial_id
                    );
                }
            }
        }
    }
}
