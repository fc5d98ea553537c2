//! A trial's score ([`TrialResult`], the `result` topic): its metrics and its force analysis.

use serde::{Deserialize, Serialize};

use super::forces::ForceAnalysisBeforeUnavailable;
use super::{ForceAnalysis, Message, MetricValues, finite};
use crate::error::{Problem, ValidationError};
use crate::keys::RunId;

/// metric -> coordinator: the score of one trial.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialResult {
    pub run_id: RunId,
    pub trial_id: u64,
    pub attempt: u32,
    /// The hand worker that executed the trial.
    pub worker: String,
    /// The metric agent that scored it.
    pub scorer: String,
    /// The objective the planner maximises.
    pub score: f64,
    /// The metrics, when anything was touched.
    pub metrics: Option<MetricValues>,
    /// Modelled contact points scored.
    pub contacts: u32,
    pub fingers_in_contact: u32,
    /// Raw cloud points received.
    pub cloud_points: u32,
    /// How the clouds reached the scorer: `shm`, `zenoh` (empty when unknown).
    pub cloud_transport: String,
    /// Set when the trial failed (the hand's error, or a scoring error): the trial is
    /// recorded as failed and not re-issued.
    pub error: Option<String>,
    /// The contact-force analysis, when anything was touched. Added last, within wire
    /// version 3: a result without it (an older metric agent's) decodes with none (see
    /// [`TrialResult::decode_older`]).
    #[serde(default)]
    pub forces: Option<ForceAnalysis>,
}

/// [`TrialResult`] as wire version 3 first had it, before `forces`.
#[derive(Deserialize)]
struct TrialResultBeforeForces {
    run_id: RunId,
    trial_id: u64,
    attempt: u32,
    worker: String,
    scorer: String,
    score: f64,
    metrics: Option<MetricValues>,
    contacts: u32,
    fingers_in_contact: u32,
    cloud_points: u32,
    cloud_transport: String,
    error: Option<String>,
}

impl Message for TrialResult {
    const TYPE: &'static str = "TrialResult";
    fn run_id(&self) -> &RunId {
        &self.run_id
    }
    fn validate(&self) -> Result<(), ValidationError> {
        crate::keys::check_agent_id(&self.worker)
            .map_err(|e| ValidationError::new(Self::TYPE, "worker", Problem::InvalidId(e)))?;
        if self.error.is_none() {
            finite(Self::TYPE, "score", &[self.score])?;
        }
        if let Some(m) = &self.metrics {
            m.validate_in(Self::TYPE, "metrics")?;
        }
        if let Some(f) = &self.forces {
            f.validate_in(Self::TYPE, "forces")?;
        }
        Ok(())
    }
    /// Two older layouts: before `forces.unavailable` (the fields up to `forces`, which
    /// bincode writes as the pair below), and before `forces`.
    fn decode_older(body: &[u8]) -> Option<(Self, usize)> {
        type BeforeUnavailable = (
            TrialResultBeforeForces,
            Option<ForceAnalysisBeforeUnavailable>,
        );
        let (r, forces, read) = match crate::codec::decode_bincode_body::<BeforeUnavailable>(body)
            .ok()
            .filter(|(_, read)| *read == body.len())
        {
            Some(((r, forces), read)) => (r, forces.map(ForceAnalysis::from), read),
            None => {
                let (r, read) =
                    crate::codec::decode_bincode_body::<TrialResultBeforeForces>(body).ok()?;
                (r, None, read)
            }
        };
        let result = TrialResult {
            run_id: r.run_id,
            trial_id: r.trial_id,
            attempt: r.attempt,
            worker: r.worker,
            scorer: r.scorer,
            score: r.score,
            metrics: r.metrics,
            contacts: r.contacts,
            fingers_in_contact: r.fingers_in_contact,
            cloud_points: r.cloud_points,
            cloud_transport: r.cloud_transport,
            error: r.error,
            forces,
        };
        Some((result, read))
    }
}
