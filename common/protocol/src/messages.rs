//! Every message between agents. Plain data: arrays for vectors and poses, so an agent in
//! another language (a real hand, say) can produce them from `docs/protocol.md` alone.
//!
//! Each message type implements [`Message`]: its name, its run id and a validity check that
//! decoders run on every payload (finite numbers, unit normals, consistent sizes), so an agent
//! never acts on a message it could not have meant.

use serde::{Deserialize, Serialize};

use crate::keys::RunId;

mod forces;
mod metrics;

pub use forces::ForceAnalysis;
use forces::ForceAnalysisBeforeUnavailable;
pub use metrics::{MAX_METRIC_KEY, MAX_METRICS, MetricValue, MetricValues};

/// Implemented by every message type.
pub trait Message: Serialize + for<'de> Deserialize<'de> {
    /// The type name used in documents and tools.
    const TYPE: &'static str;
    /// The run this message belongs to.
    fn run_id(&self) -> &RunId;
    /// Checks the content; the error names the field.
    fn validate(&self) -> Result<(), String>;
    /// The trial attempt this message reports on, for messages that report on one (a hand's
    /// clouds): an invalid one can then fail that attempt with the reason instead of
    /// leaving it to its lease.
    fn attempt_ref(&self) -> Option<AttemptRef> {
        None
    }
    /// A bincode body of this message as an earlier layout of the same wire version wrote it
    /// (before fields were appended), and the bytes it took: for messages that grew a field
    /// at the end (`None`: this one never did). JSON needs no such help: an appended field
    /// is `#[serde(default)]`.
    fn decode_older(_body: &[u8]) -> Option<(Self, usize)>
    where
        Self: Sized,
    {
        None
    }
}

/// One attempt of one trial, as named by a message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AttemptRef {
    pub run_id: RunId,
    pub trial_id: u64,
    pub attempt: u32,
    pub worker: String,
}

fn finite(field: &str, values: &[f64]) -> Result<(), String> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(format!("{field}[{i}] is not finite ({})", values[i])),
        None => Ok(()),
    }
}

/// A rigid pose: translation (metres) and a unit quaternion `[w, x, y, z]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    pub translation: [f64; 3],
    pub rotation: [f64; 4],
}

impl Pose {
    pub const IDENTITY: Pose = Pose {
        translation: [0.0; 3],
        rotation: [1.0, 0.0, 0.0, 0.0],
    };

    /// Finite, with a quaternion of norm 1 within 1e-6.
    pub fn validate(&self, field: &str) -> Result<(), String> {
        finite(&format!("{field}.translation"), &self.translation)?;
        finite(&format!("{field}.rotation"), &self.rotation)?;
        let n = self.rotation.iter().map(|v| v * v).sum::<f64>().sqrt();
        if (n - 1.0).abs() > 1e-6 {
            return Err(format!(
                "{field}.rotation is not a unit quaternion (norm {n})"
            ));
        }
        Ok(())
    }
}

/// A triangle mesh sent with an object (user meshes; built-in objects are sent by name).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeshData {
    pub vertices: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

/// perception -> everyone: the object the trials are planned against, in the world frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObjectEstimate {
    pub run_id: RunId,
    /// A built-in object name (`mug`, `sphere`, ...) or the user mesh's name.
    pub object: String,
    /// The mesh, for objects that are not built in.
    pub mesh: Option<MeshData>,
    /// The estimated pose of the object's frame in the world.
    pub pose: Pose,
    /// Increases with every new estimate.
    pub seq: u64,
    pub stamp_ms: i64,
    /// Who estimated it (an agent id).
    pub source: String,
}

impl Message for ObjectEstimate {
    const TYPE: &'static str = "ObjectEstimate";
    fn run_id(&self) -> &RunId {
        &self.run_id
    }
    fn validate(&self) -> Result<(), String> {
        if self.object.trim().is_empty() {
            return Err("object is empty".into());
        }
        self.pose.validate("pose")?;
        if let Some(mesh) = &self.mesh {
            for (i, v) in mesh.vertices.iter().enumerate() {
                finite(&format!("mesh.vertices[{i}]"), v)?;
            }
            let n = mesh.vertices.len();
            for (i, t) in mesh.triangles.iter().enumerate() {
                if t.iter().any(|&k| k as usize >= n) {
                    return Err(format!("mesh.triangles[{i}] refers to a missing vertex"));
                }
            }
        }
        Ok(())
    }
}

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
    fn validate(&self) -> Result<(), String> {
        finite("params", &self.params)?;
        self.palm_pose.validate("palm_pose")?;
        if self.attempt == 0 {
            return Err("attempt must be >= 1".into());
        }
        Ok(())
    }
}

/// One raw contact point: a position on the object's surface, the unit normal pointing
/// into the object (world frame) and the area it stands for (`w`, > 0; 1 when absent, so that
/// clouds of equal points need not send it).
///
/// `repr(C)`, seven `f64` without padding: on a little-endian host a point's 56 bytes in
/// memory are its 56 bytes in the shared-memory layout ([`crate::layout`]), which copies a
/// finger's points as one block. The derives (zerocopy's, which check that the type has no
/// padding) are what make that copy sound; this crate itself has no `unsafe`.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Serialize,
    Deserialize,
    zerocopy::FromBytes,
    zerocopy::IntoBytes,
    zerocopy::Immutable,
    zerocopy::KnownLayout,
)]
#[repr(C)]
pub struct CloudPoint {
    pub p: [f64; 3],
    pub n: [f64; 3],
    #[serde(default = "unit_weight")]
    pub w: f64,
}

fn unit_weight() -> f64 {
    1.0
}

/// The raw contact cloud of one finger (`finger: None` for the palm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FingerCloud {
    pub finger: Option<u32>,
    pub links: Vec<String>,
    pub points: Vec<CloudPoint>,
}

/// hand -> metric: what the hand touched in one trial.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactClouds {
    pub run_id: RunId,
    pub trial_id: u64,
    pub attempt: u32,
    /// The hand worker that executed the trial.
    pub worker: String,
    pub hand: String,
    /// The palm pose actually reached (world).
    pub palm_pose: Pose,
    /// One cloud per finger in finger order, then the palm's.
    pub fingers: Vec<FingerCloud>,
    /// Smallest distance between a link and the object (metres) when nothing touches; the
    /// metric's no-contact score uses it. `None` when unknown.
    pub min_gap: Option<f64>,
    /// Set when the hand could not execute the trial (unreachable pose, hardware fault); the
    /// clouds are then empty.
    pub error: Option<String>,
    pub executed_ms: i64,
}

impl ContactClouds {
    /// Total number of points.
    pub fn point_count(&self) -> usize {
        self.fingers.iter().map(|f| f.points.len()).sum()
    }

    /// What [`Message::validate`] checks except the points: the worker id, the palm pose and
    /// `min_gap`. Decoders that check each point as they read it (the shared-memory layout)
    /// call this and [`CloudPoint::validate`].
    pub fn validate_header(&self) -> Result<(), String> {
        validate_measurement_header(&self.worker, &self.palm_pose, self.min_gap)
    }
}

impl Message for ContactClouds {
    const TYPE: &'static str = "ContactClouds";
    fn run_id(&self) -> &RunId {
        &self.run_id
    }
    fn attempt_ref(&self) -> Option<AttemptRef> {
        Some(AttemptRef {
            run_id: self.run_id.clone(),
            trial_id: self.trial_id,
            attempt: self.attempt,
            worker: self.worker.clone(),
        })
    }
    fn validate(&self) -> Result<(), String> {
        self.validate_header()?;
        for (f, finger) in self.fingers.iter().enumerate() {
            for (i, pt) in finger.points.iter().enumerate() {
                pt.validate(f, i)?;
            }
        }
        Ok(())
    }
}

/// The fingertip surface a force/torque sensor carries, in the sensor frame: a sphere, an
/// ellipsoid or a capsule (`{"shape": "sphere", "center": [0, 0, 0.015], "radius": 0.012}`).
pub use graspopt_sensing::FingertipSurface;

/// One fingertip force/torque sensor's reading in a trial.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FingertipWrench {
    /// The finger (0-based, in the hand's finger order).
    pub finger: u32,
    /// The fingertip's name (a link of the hand), for people and logs.
    pub link: String,
    /// The sensor frame in the world when it read.
    pub sensor_pose: Pose,
    /// The fingertip's surface, in the sensor frame.
    pub surface: FingertipSurface,
    /// The force the object applies to the fingertip, sensor frame (N).
    pub force: [f64; 3],
    /// The torque of that contact about the sensor frame's origin, sensor frame (N m).
    pub torque: [f64; 3],
    /// When the sensor read (milliseconds since the Unix epoch).
    pub stamp_ms: i64,
}

/// hand -> metric: what a hand's fingertip force/torque sensors read in one trial (a hand that
/// senses forces instead of contact clouds). The metric agent finds each fingertip's contact
/// from its reading (intrinsic contact sensing) and scores the contacts as it scores clouds.
/// Fingertips that read nothing may be left out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FingertipWrenches {
    pub run_id: RunId,
    pub trial_id: u64,
    pub attempt: u32,
    /// The hand worker that executed the trial.
    pub worker: String,
    pub hand: String,
    /// The palm pose actually reached (world).
    pub palm_pose: Pose,
    pub fingertips: Vec<FingertipWrench>,
    /// Smallest distance between the hand and the object (metres) when nothing touches;
    /// `None` when unknown (a real hand does not know it).
    pub min_gap: Option<f64>,
    /// Set when the hand could not execute the trial; `fingertips` is then empty.
    pub error: Option<String>,
    pub executed_ms: i64,
}

impl Message for FingertipWrenches {
    const TYPE: &'static str = "FingertipWrenches";
    fn run_id(&self) -> &RunId {
        &self.run_id
    }
    fn attempt_ref(&self) -> Option<AttemptRef> {
        Some(AttemptRef {
            run_id: self.run_id.clone(),
            trial_id: self.trial_id,
            attempt: self.attempt,
            worker: self.worker.clone(),
        })
    }
    fn validate(&self) -> Result<(), String> {
        validate_measurement_header(&self.worker, &self.palm_pose, self.min_gap)?;
        for (i, tip) in self.fingertips.iter().enumerate() {
            tip.sensor_pose
                .validate(&format!("fingertips[{i}].sensor_pose"))?;
            tip.surface
                .validate()
                .map_err(|e| format!("fingertips[{i}].surface: {e}"))?;
            finite(&format!("fingertips[{i}].force"), &tip.force)?;
            finite(&format!("fingertips[{i}].torque"), &tip.torque)?;
        }
        Ok(())
    }
}

/// What a hand's measurement of one trial (clouds or fingertip readings) must hold besides the
/// measurement: a valid worker id, a valid palm pose, and `min_gap` finite and >= 0.
fn validate_measurement_header(
    worker: &str,
    palm_pose: &Pose,
    min_gap: Option<f64>,
) -> Result<(), String> {
    crate::keys::check_agent_id(worker).map_err(|e| format!("worker: {e}"))?;
    palm_pose.validate("palm_pose")?;
    if let Some(g) = min_gap
        && !(g.is_finite() && g >= 0.0)
    {
        return Err(format!("min_gap must be finite and >= 0, got {g}"));
    }
    Ok(())
}

impl CloudPoint {
    /// Finite `p` and `n`, `n` of norm 1 within 1e-3, `w` finite and > 0. The error names
    /// the point as `fingers[finger].points[index]`.
    #[inline]
    pub fn validate(&self, finger: usize, index: usize) -> Result<(), String> {
        if self.is_valid() {
            return Ok(());
        }
        let (f, i) = (finger, index);
        // Field names are formatted only for the error: this runs on every point.
        let ok = self.p.iter().chain(&self.n).all(|v| v.is_finite());
        if !ok {
            finite(&format!("fingers[{f}].points[{i}].p"), &self.p)?;
            finite(&format!("fingers[{f}].points[{i}].n"), &self.n)?;
        }
        if !(self.w.is_finite() && self.w > 0.0) {
            return Err(format!(
                "fingers[{f}].points[{i}].w must be finite and > 0, got {}",
                self.w
            ));
        }
        Err(format!(
            "fingers[{f}].points[{i}].n is not a unit normal (norm {})",
            self.normal_norm2().sqrt()
        ))
    }

    /// Whether [`CloudPoint::validate`] accepts the point, without a branch per condition
    /// (`&` rather than `&&`), so that a loop over a cloud compiles to straight-line code;
    /// bulk readers check every point with it and format an error only for the first one
    /// that fails.
    #[inline]
    pub fn is_valid(&self) -> bool {
        const LOW: f64 = (1.0 - 1e-3) * (1.0 - 1e-3);
        const HIGH: f64 = (1.0 + 1e-3) * (1.0 + 1e-3);
        // A NaN or an infinity in n makes n2 NaN or infinite, which fails the range; one in
        // p makes the sum of p times zero NaN, which it is only then.
        let p = self.p[0] * 0.0 + self.p[1] * 0.0 + self.p[2] * 0.0;
        let n2 = self.normal_norm2();
        (p == 0.0) & (LOW..=HIGH).contains(&n2) & (self.w > 0.0) & (self.w < f64::INFINITY)
    }

    /// `|n|²`: |n| is within 1e-3 of 1 when this is within the squared bounds (no square
    /// root per point).
    #[inline]
    fn normal_norm2(&self) -> f64 {
        self.n[0] * self.n[0] + self.n[1] * self.n[1] + self.n[2] * self.n[2]
    }
}

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
    fn validate(&self) -> Result<(), String> {
        crate::keys::check_agent_id(&self.worker).map_err(|e| format!("worker: {e}"))?;
        if self.error.is_none() {
            finite("score", &[self.score])?;
        }
        if let Some(m) = &self.metrics {
            m.validate("metrics")?;
        }
        if let Some(f) = &self.forces {
            f.validate("forces")?;
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

/// One observation for the planner.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Observation {
    pub x: Vec<f64>,
    pub y: f64,
}

/// How the planner proposes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum PlannerMethod {
    /// Bayesian optimization (GP + EI + DIRECT).
    #[default]
    Bo,
    /// Uniform random search.
    Random,
}

impl PlannerMethod {
    /// Every method, in the order `--help` lists them.
    pub const ALL: [PlannerMethod; 2] = [PlannerMethod::Bo, PlannerMethod::Random];

    /// The name users type and see (the serde name): `bo`, `random`.
    pub fn name(self) -> &'static str {
        match self {
            PlannerMethod::Bo => "bo",
            PlannerMethod::Random => "random",
        }
    }

    /// A method from its name.
    pub fn parse(name: &str) -> Option<PlannerMethod> {
        Self::ALL.into_iter().find(|m| m.name() == name.trim())
    }
}

/// coordinator -> planner (query): propose `count` trials.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SuggestRequest {
    pub run_id: RunId,
    pub request_id: u64,
    pub method: PlannerMethod,
    /// `[lower, upper]` per parameter.
    pub bounds: Vec<[f64; 2]>,
    pub seed: u64,
    /// Size of the initial design (space-filling, not model-based) (`None`: the engine's default).
    pub initial: Option<u32>,
    /// Every completed trial, in completion order.
    pub observations: Vec<Observation>,
    /// Trials issued and not yet completed.
    pub pending: Vec<Vec<f64>>,
    pub count: u32,
    /// The engine state of the run's last reply ([`SuggestReply::engine_state`]), as the
    /// coordinator keeps it in its journal. Opaque to everyone but the planner: a planner
    /// that does not hold the run's engine (it was restarted) continues from it exactly,
    /// instead of rebuilding a model from `observations` that would propose slightly
    /// different points.
    #[serde(default)]
    pub engine_state: Option<Vec<u8>>,
}

impl Message for SuggestRequest {
    const TYPE: &'static str = "SuggestRequest";
    fn run_id(&self) -> &RunId {
        &self.run_id
    }
    fn validate(&self) -> Result<(), String> {
        let d = self.bounds.len();
        if d == 0 {
            return Err("bounds is empty".into());
        }
        for (i, b) in self.bounds.iter().enumerate() {
            finite(&format!("bounds[{i}]"), b)?;
            if b[0] >= b[1] {
                return Err(format!("bounds[{i}] is empty ({} >= {})", b[0], b[1]));
            }
        }
        for (i, o) in self.observations.iter().enumerate() {
            if o.x.len() != d {
                return Err(format!(
                    "observations[{i}].x has {} values, not {d}",
                    o.x.len()
                ));
            }
            // Field names are formatted only for the error: a request carries the run's
            // whole history, and formatting them per observation was a tenth of a run's CPU
            // in `graspopt bench coordinator`.
            if !(o.x.iter().all(|v| v.is_finite()) && o.y.is_finite()) {
                finite(&format!("observations[{i}].x"), &o.x)?;
                finite(&format!("observations[{i}].y"), &[o.y])?;
            }
        }
        for (i, p) in self.pending.iter().enumerate() {
            if p.len() != d {
                return Err(format!("pending[{i}] has {} values, not {d}", p.len()));
            }
            if !p.iter().all(|v| v.is_finite()) {
                finite(&format!("pending[{i}]"), p)?;
            }
        }
        if self.count == 0 || self.count > 1024 {
            return Err(format!("count must be 1..=1024, got {}", self.count));
        }
        Ok(())
    }
}

/// planner -> coordinator (reply).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SuggestReply {
    pub run_id: RunId,
    pub request_id: u64,
    pub points: Vec<Vec<f64>>,
    /// Set when the planner could not propose.
    pub error: Option<String>,
    /// The planner's engine after this proposal (see [`SuggestRequest::engine_state`]).
    #[serde(default)]
    pub engine_state: Option<Vec<u8>>,
}

impl Message for SuggestReply {
    const TYPE: &'static str = "SuggestReply";
    fn run_id(&self) -> &RunId {
        &self.run_id
    }
    fn validate(&self) -> Result<(), String> {
        for (i, p) in self.points.iter().enumerate() {
            finite(&format!("points[{i}]"), p)?;
        }
        Ok(())
    }
}

/// The phase of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RunPhase {
    /// Waiting for the object estimate, a planner or workers.
    Waiting,
    Running,
    Finished,
    /// Stopped before its end (Ctrl-C, SIGTERM): the journal records it stopped, and
    /// `--resume` continues it. Added last, within wire version 3.
    Stopped,
}

/// `name=value` for each parameter of a trial (5 decimals), joined by `sep`: how the
/// tools print a trial's parameters with [`RunStatus::param_names`].
pub fn named_params(names: &[String], values: &[f64], sep: &str) -> String {
    let parts: Vec<String> = names
        .iter()
        .zip(values)
        .map(|(n, v)| format!("{n}={v:.5}"))
        .collect();
    parts.join(sep)
}

/// The best trial so far.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BestTrial {
    pub trial_id: u64,
    pub score: f64,
    pub params: Vec<f64>,
    pub force_closure: Option<bool>,
}

/// A live hand worker.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorkerStatus {
    pub id: String,
    pub host: String,
    /// The trial it holds, if any.
    pub trial: Option<u64>,
}

/// Counters of what the coordinator refused or repaired.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub struct ErrorCounts {
    /// Payloads that did not decode or failed validation.
    pub bad_messages: u64,
    /// Results for trials this run does not know.
    pub unknown_trial: u64,
    /// Second and later results for a completed trial.
    pub duplicates: u64,
    /// Results naming a trial of this run with an attempt or worker it was never issued to.
    pub not_issued: u64,
    /// Trials re-issued after a lost worker or an expired lease.
    pub reissued: u64,
    /// Trials that failed.
    pub failed: u64,
}

/// What a run can be waiting for before trials go out (or go on).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WaitReason {
    /// No object estimate yet: no perception agent publishes on the run.
    ObjectEstimate,
    /// No metric agent alive: trials are held back, their clouds would not be scored.
    MetricAgent,
    /// No hand worker alive.
    Hand,
    /// No answer from the planner (none running, or it has not answered yet).
    Planner,
}

impl WaitReason {
    /// Every reason, in the order they are shown.
    pub const ALL: [WaitReason; 4] = [
        WaitReason::ObjectEstimate,
        WaitReason::MetricAgent,
        WaitReason::Hand,
        WaitReason::Planner,
    ];

    /// What is missing, for people: "no metric agent".
    pub fn describe(self) -> &'static str {
        match self {
            WaitReason::ObjectEstimate => "no object estimate yet",
            WaitReason::MetricAgent => "no metric agent",
            WaitReason::Hand => "no hand",
            WaitReason::Planner => "no planner answer",
        }
    }
}

/// One thing a run waits for, and since when (milliseconds since the Unix epoch).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Waiting {
    pub reason: WaitReason,
    pub since_ms: i64,
}

/// `waits` for people, with how long each has lasted at `now_ms`: "no metric agent (12 s), no
/// hand (3 s)" (the coordinator's log, the monitor).
pub fn describe_waits(waits: &[Waiting], now_ms: i64) -> String {
    waits
        .iter()
        .map(|w| {
            format!(
                "{} ({:.0} s)",
                w.reason.describe(),
                (now_ms - w.since_ms).max(0) as f64 / 1000.0
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// coordinator -> monitors: the state of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunStatus {
    pub run_id: RunId,
    pub phase: RunPhase,
    pub object: String,
    pub param_names: Vec<String>,
    pub budget: u64,
    pub completed: u64,
    pub running: u64,
    pub failed: u64,
    pub best: Option<BestTrial>,
    /// Best score after each completed trial.
    pub best_history: Vec<f64>,
    pub workers: Vec<WorkerStatus>,
    pub errors: ErrorCounts,
    pub stamp_ms: i64,
    /// What the run has been waiting for, for a second or more (empty: nothing). Added last,
    /// within wire version 3: a status without it (an older coordinator's) decodes with none
    /// (see [`RunStatus::decode_older`]).
    #[serde(default)]
    pub waiting: Vec<Waiting>,
    /// The best trial's force analysis, if its result had one. Added last, within wire
    /// version 3 (see [`RunStatus::decode_older`]).
    #[serde(default)]
    pub best_forces: Option<ForceAnalysis>,
}

/// [`RunStatus`] as wire version 3 first had it, before `waiting`.
#[derive(Deserialize)]
struct RunStatusBeforeWaiting {
    run_id: RunId,
    phase: RunPhase,
    object: String,
    param_names: Vec<String>,
    budget: u64,
    completed: u64,
    running: u64,
    failed: u64,
    best: Option<BestTrial>,
    best_history: Vec<f64>,
    workers: Vec<WorkerStatus>,
    errors: ErrorCounts,
    stamp_ms: i64,
}

impl Message for RunStatus {
    const TYPE: &'static str = "RunStatus";
    fn run_id(&self) -> &RunId {
        &self.run_id
    }
    /// The best trial's forces are checked as a result's are (the coordinator copies them
    /// from a validated result); the rest is left as sent.
    fn validate(&self) -> Result<(), String> {
        if let Some(f) = &self.best_forces {
            f.validate("best_forces")?;
        }
        Ok(())
    }
    /// Three older layouts: before `best_forces.unavailable` (the fields up to
    /// `best_forces`, which bincode writes as the triple below), before `best_forces` (the
    /// pair), and before `waiting`.
    fn decode_older(body: &[u8]) -> Option<(Self, usize)> {
        type BeforeUnavailable = (
            RunStatusBeforeWaiting,
            Vec<Waiting>,
            Option<ForceAnalysisBeforeUnavailable>,
        );
        let whole = |read: &usize| *read == body.len();
        let decoded = crate::codec::decode_bincode_body::<BeforeUnavailable>(body)
            .ok()
            .filter(|(_, read)| whole(read))
            .or_else(|| {
                crate::codec::decode_bincode_body::<(RunStatusBeforeWaiting, Vec<Waiting>)>(body)
                    .ok()
                    .filter(|(_, read)| whole(read))
                    .map(|((s, waiting), read)| ((s, waiting, None), read))
            })
            .or_else(|| {
                crate::codec::decode_bincode_body::<RunStatusBeforeWaiting>(body)
                    .ok()
                    .map(|(s, read)| ((s, Vec::new(), None), read))
            });
        let ((s, waiting, best_forces), read) = decoded?;
        let status = RunStatus {
            run_id: s.run_id,
            phase: s.phase,
            object: s.object,
            param_names: s.param_names,
            budget: s.budget,
            completed: s.completed,
            running: s.running,
            failed: s.failed,
            best: s.best,
            best_history: s.best_history,
            workers: s.workers,
            errors: s.errors,
            stamp_ms: s.stamp_ms,
            waiting,
            best_forces: best_forces.map(ForceAnalysis::from),
        };
        Some((status, read))
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn named_params_pairs_names_and_values() {
        let names = ["a".to_string(), "b".to_string()];
        assert_eq!(
            super::named_params(&names, &[0.5, -1.0], ","),
            "a=0.50000,b=-1.00000"
        );
        // Extra values (or names) are left out, not paired with nothing.
        assert_eq!(
            super::named_params(&names[..1], &[0.5, -1.0], ","),
            "a=0.50000"
        );
    }
}
