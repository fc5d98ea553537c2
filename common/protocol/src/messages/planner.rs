//! The planner's query: a request for trials to propose ([`SuggestRequest`], with the run's
//! observations) and its reply ([`SuggestReply`]).

use serde::{Deserialize, Serialize};

use super::{Message, finite};
use crate::error::{Problem, ValidationError};
use crate::keys::RunId;

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
    fn validate(&self) -> Result<(), ValidationError> {
        const TYPE: &str = SuggestRequest::TYPE;
        let invalid = |field: String, problem| ValidationError::new(TYPE, field, problem);
        let d = self.bounds.len();
        if d == 0 {
            return Err(invalid("bounds".into(), Problem::Empty));
        }
        for (i, b) in self.bounds.iter().enumerate() {
            finite(TYPE, &format!("bounds[{i}]"), b)?;
            if b[0] >= b[1] {
                let problem = Problem::EmptyRange {
                    lower: b[0],
                    upper: b[1],
                };
                return Err(invalid(format!("bounds[{i}]"), problem));
            }
        }
        let wrong_length = |len: usize| Problem::WrongLength { len, expected: d };
        for (i, o) in self.observations.iter().enumerate() {
            if o.x.len() != d {
                let field = format!("observations[{i}].x");
                return Err(invalid(field, wrong_length(o.x.len())));
            }
            // Field names are formatted only for the error: a request carries the run's
            // whole history, and formatting them per observation was a tenth of a run's CPU
            // in `graspopt bench coordinator`.
            if !(o.x.iter().all(|v| v.is_finite()) && o.y.is_finite()) {
                finite(TYPE, &format!("observations[{i}].x"), &o.x)?;
                finite(TYPE, &format!("observations[{i}].y"), &[o.y])?;
            }
        }
        for (i, p) in self.pending.iter().enumerate() {
            if p.len() != d {
                return Err(invalid(format!("pending[{i}]"), wrong_length(p.len())));
            }
            if !p.iter().all(|v| v.is_finite()) {
                finite(TYPE, &format!("pending[{i}]"), p)?;
            }
        }
        if self.count == 0 || self.count > 1024 {
            let problem = Problem::OutOfRange {
                requirement: "1..=1024",
                value: f64::from(self.count),
            };
            return Err(invalid("count".into(), problem));
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
    fn validate(&self) -> Result<(), ValidationError> {
        for (i, p) in self.points.iter().enumerate() {
            finite(Self::TYPE, &format!("points[{i}]"), p)?;
        }
        Ok(())
    }
}
