//! What a hand touched in a trial ([`ContactClouds`], the `clouds` topic): a cloud of raw
//! contact points per finger.

use serde::{Deserialize, Serialize};

use super::{AttemptRef, Message, Pose, finite, validate_measurement_header};
use crate::error::{Problem, ValidationError};
use crate::keys::RunId;

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

impl CloudPoint {
    /// Finite `p` and `n`, `n` of norm 1 within 1e-3, `w` finite and > 0. The error names
    /// the point as `fingers[finger].points[index]`.
    #[inline]
    pub fn validate(&self, finger: usize, index: usize) -> Result<(), ValidationError> {
        if self.is_valid() {
            return Ok(());
        }
        const TYPE: &str = ContactClouds::TYPE;
        let (f, i) = (finger, index);
        // Field names are formatted only for the error: this runs on every point.
        let ok = self.p.iter().chain(&self.n).all(|v| v.is_finite());
        if !ok {
            finite(TYPE, &format!("fingers[{f}].points[{i}].p"), &self.p)?;
            finite(TYPE, &format!("fingers[{f}].points[{i}].n"), &self.n)?;
        }
        if !(self.w.is_finite() && self.w > 0.0) {
            let problem = Problem::OutOfRange {
                requirement: "finite and > 0",
                value: self.w,
            };
            return Err(ValidationError::new(
                TYPE,
                format!("fingers[{f}].points[{i}].w"),
                problem,
            ));
        }
        Err(ValidationError::new(
            TYPE,
            format!("fingers[{f}].points[{i}].n"),
            Problem::NotUnitNormal(self.normal_norm2().sqrt()),
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
    pub fn validate_header(&self) -> Result<(), ValidationError> {
        validate_measurement_header(Self::TYPE, &self.worker, &self.palm_pose, self.min_gap)
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
    fn validate(&self) -> Result<(), ValidationError> {
        self.validate_header()?;
        for (f, finger) in self.fingers.iter().enumerate() {
            for (i, pt) in finger.points.iter().enumerate() {
                pt.validate(f, i)?;
            }
        }
        Ok(())
    }
}
