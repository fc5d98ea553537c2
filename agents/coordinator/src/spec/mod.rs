//! What a run is and where it is recorded: the run spec and its trial space. Journal glue,
//! no network.
//!
//! - `resume`: resuming a run: its record, flags that contradict it, a raised budget.
//! - `journal`: opening the run in the journal, with the state rebuilt from it.
//! - `standalone`: the run a coordinator started on its own serves.

use graspopt_protocol::{ObjectEstimate, PlannerMethod};
use graspopt_sim::{ParamKind, ParamSpec, TrialSpace};
use serde::{Deserialize, Serialize};

use crate::error::CoordinatorError;

mod journal;
mod resume;
mod standalone;

pub use journal::open_run;
pub(crate) use resume::open_journal;
pub use resume::{
    Conflicts, journaled_runs, journaled_spec, quoted_runs, range_conflicts, reconcile,
    resume_conflicts, sole_run,
};
pub use standalone::{MAX_TRIALS, check_trials, standalone_run};

/// What a run is: recorded in the journal when the run is created, and taken from there when
/// it resumes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSpec {
    /// The object the run is about (perception must agree).
    pub object: String,
    pub hand: String,
    pub params: Vec<ParamKind>,
    /// `[lower, upper]` per parameter; `None`: the simulator's defaults for the object.
    pub bounds: Option<Vec<[f64; 2]>>,
    /// Number of trials.
    pub trials: u64,
    pub seed: u64,
    pub method: PlannerMethod,
    /// Size of the initial design (space-filling, not model-based) (`None`: the engine's default).
    pub initial: Option<u32>,
    /// How the tool that created the run set up the other agents (the object's mesh, the
    /// scoring, perception's noise), kept so that resuming the run restores them. Opaque to
    /// the coordinator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settings: Option<serde_json::Value>,
}

impl RunSpec {
    /// The recorded bounds as ranges of the parameters (none when the run recorded no
    /// bounds: the simulator's defaults).
    pub fn ranges(&self) -> Vec<ParamSpec> {
        let Some(bounds) = &self.bounds else {
            return Vec::new();
        };
        self.params
            .iter()
            .zip(bounds)
            .map(|(&kind, b)| ParamSpec {
                kind,
                lower: b[0],
                upper: b[1],
            })
            .collect()
    }
}

/// The bounds of a space's parameters, as a run spec records them.
pub fn bounds_of(space: &TrialSpace) -> Vec<[f64; 2]> {
    space.bounds().iter().map(|b| [b.0, b.1]).collect()
}

/// The trial space of a run on an object estimate.
pub fn trial_space(
    spec: &RunSpec,
    estimate: &ObjectEstimate,
) -> Result<(TrialSpace, Vec<[f64; 2]>), CoordinatorError> {
    let object =
        graspopt_convert::object_from_estimate(estimate).map_err(CoordinatorError::Estimate)?;
    let mut space =
        TrialSpace::with_params(&object, &spec.params).map_err(CoordinatorError::Spec)?;
    if let Some(bounds) = &spec.bounds {
        for (i, p) in space.params.iter_mut().enumerate() {
            let b = bounds.get(i).ok_or(CoordinatorError::NoBounds(i))?;
            (p.lower, p.upper) = (b[0], b[1]);
        }
        space = TrialSpace::new(space.reference, space.params).map_err(CoordinatorError::Spec)?;
    }
    let bounds = bounds_of(&space);
    Ok((space, bounds))
}

/// Parameter names, as the journal and CSV show them.
pub fn param_names(spec: &RunSpec) -> Vec<String> {
    spec.params
        .iter()
        .map(|k| {
            serde_json::to_value(k)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_else(|| format!("{k:?}"))
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests;
