//! Every message between agents. Plain data: arrays for vectors and poses, so an agent in
//! another language (a real hand, say) can produce them from `docs/protocol.md` alone.
//!
//! Each message type implements [`Message`]: its name, its run id and a validity check that
//! decoders run on every payload (finite numbers, unit normals, consistent sizes), so an agent
//! never acts on a message it could not have meant. One module per concept, each re-exported
//! here: the object (`object.rs`), a trial's command (`command.rs`), what a hand measured
//! (`clouds.rs`, `wrenches.rs`), a trial's score (`result.rs`, `forces.rs`), the planner's
//! query (`planner.rs`) and the run's state (`status.rs`); `pose.rs` is shared.
//!
//! To add a message: its struct and `impl Message` in the module of its concept (a new module
//! for a new concept, declared and re-exported below), then, for a topic, its row in the key
//! table ([`crate::keys`]).

use serde::{Deserialize, Serialize};

use crate::error::{Problem, ValidationError};
use crate::keys::RunId;

mod clouds;
mod command;
mod forces;
mod metrics;
mod object;
mod planner;
mod pose;
mod result;
mod status;
mod wrenches;

pub use clouds::*;
pub use command::*;
pub use forces::*;
pub use metrics::{MAX_METRIC_KEY, MAX_METRICS, MetricValue, MetricValues};
pub use object::*;
pub use planner::*;
pub use pose::*;
pub use result::*;
pub use status::*;
pub use wrenches::*;

/// Implemented by every message type.
pub trait Message: Serialize + for<'de> Deserialize<'de> {
    /// The type name used in documents and tools.
    const TYPE: &'static str;
    /// The run this message belongs to.
    fn run_id(&self) -> &RunId;
    /// Checks the content; the error names the field.
    fn validate(&self) -> Result<(), ValidationError>;
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

/// `Ok` when every value is finite, else the error naming the first that is not:
/// `field[i] is not finite (NaN)`.
fn finite(message_type: &'static str, field: &str, values: &[f64]) -> Result<(), ValidationError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(ValidationError::new(
            message_type,
            format!("{field}[{i}]"),
            Problem::NotFinite(values[i]),
        )),
        None => Ok(()),
    }
}

/// What a hand's measurement of one trial (clouds or fingertip readings) must hold besides the
/// measurement: a valid worker id, a valid palm pose, and `min_gap` finite and >= 0.
fn validate_measurement_header(
    message_type: &'static str,
    worker: &str,
    palm_pose: &Pose,
    min_gap: Option<f64>,
) -> Result<(), ValidationError> {
    crate::keys::check_agent_id(worker)
        .map_err(|e| ValidationError::new(message_type, "worker", Problem::InvalidId(e)))?;
    palm_pose.validate_in(message_type, "palm_pose")?;
    if let Some(g) = min_gap
        && !(g.is_finite() && g >= 0.0)
    {
        let problem = Problem::OutOfRange {
            requirement: "finite and >= 0",
            value: g,
        };
        return Err(ValidationError::new(message_type, "min_gap", problem));
    }
    Ok(())
}
