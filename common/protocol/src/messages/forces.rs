//! A trial's contact-force analysis as results carry it ([`ForceAnalysis`]), and its layout
//! before a field was appended (for [`super::TrialResult`] and [`super::RunStatus`] written by
//! older agents).

use serde::{Deserialize, Serialize};

use super::finite;
use crate::error::{Problem, ValidationError};

/// The contact-force analysis of a trial (the thesis's "contact force analysis"), reported
/// beside its metrics. Wrenches are `[fx, fy, fz, tx, ty, tz]` in newtons and newton-metres,
/// world axes, torques about the reference point of the metrics (the object's centre of
/// mass by default).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ForceAnalysis {
    /// The wrench the world applies to the object that the grasp must resist: the object's
    /// weight by default.
    pub external: [f64; 6],
    /// The contact forces of least Euclidean norm, each inside its friction cone, that resist
    /// `external`: the 2-norm of the vector of every contact's force (N). `None`: no forces
    /// in the cones can ("cannot resist"), or, with `unavailable` set, unknown.
    pub resisting_norm: Option<f64>,
    /// The largest single contact force of that solution, at its most loaded contact (N).
    pub resisting_max: Option<f64>,
    /// Measured forces only (a hand with force sensors): the net wrench the measured contact
    /// forces apply to the object.
    pub net_wrench: Option<[f64; 6]>,
    /// Measured forces only: per sensed contact, `mu f_n - |f_t|` (N), how much more
    /// tangential force the contact takes before it slips (negative: outside its cone).
    pub slip_margins: Vec<f64>,
    /// Set when the least resisting forces are unavailable: why (the conic solver stopped
    /// without an answer however it was tried). `resisting_norm` and `resisting_max` are then
    /// `None` without meaning "cannot resist"; the score and the measured forces stand.
    /// Added last, within wire version 3: an analysis without it (an older metric agent's)
    /// decodes with none (see [`super::TrialResult::decode_older`]).
    #[serde(default)]
    pub unavailable: Option<String>,
}

impl ForceAnalysis {
    /// Whether forces in the friction cones can resist the external wrench; `None` when
    /// the analysis could not tell ([`ForceAnalysis::unavailable`]).
    pub fn can_resist(&self) -> Option<bool> {
        match self.unavailable {
            Some(_) => None,
            None => Some(self.resisting_norm.is_some()),
        }
    }

    /// The smallest slip margin of the measured contacts (N), if any were measured.
    pub fn min_slip_margin(&self) -> Option<f64> {
        self.slip_margins.iter().copied().reduce(f64::min)
    }

    /// The norm of the net measured force (N), if forces were measured.
    pub fn net_force(&self) -> Option<f64> {
        self.net_wrench
            .map(|w| (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt())
    }

    /// The analysis for people, as the tools print it: "holds the load (4.905 N): least
    /// contact forces 6.250 N in all (2-norm over the contacts), 3.500 N at the most loaded
    /// contact", "cannot hold the load (4.905 N)" or "least contact forces unavailable (load
    /// 4.905 N): REASON", then for measured forces "; measured: net force 0.012 N, smallest
    /// slip margin 0.840 N".
    pub fn describe(&self) -> String {
        let e = &self.external;
        let load = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
        let mut text = match (&self.unavailable, self.resisting_norm, self.resisting_max) {
            (Some(why), _, _) => {
                format!("least contact forces unavailable (load {load:.3} N): {why}")
            }
            (None, Some(norm), max) => format!(
                "holds the load ({load:.3} N): least contact forces {norm:.3} N in all (2-norm over the contacts){}",
                max.map_or(String::new(), |m| format!(
                    ", {m:.3} N at the most loaded contact"
                ))
            ),
            (None, None, _) => format!("cannot hold the load ({load:.3} N)"),
        };
        if let Some(net) = self.net_force() {
            text.push_str(&format!("; measured: net force {net:.3} N"));
            if let Some(m) = self.min_slip_margin() {
                text.push_str(&format!(", smallest slip margin {m:.3} N"));
            }
        }
        text
    }

    /// Checks that every number is finite and the norms are >= 0; the error names the field
    /// (`field` of a `ForceAnalysis`).
    pub fn validate(&self, field: &str) -> Result<(), ValidationError> {
        self.validate_in("ForceAnalysis", field)
    }

    /// [`ForceAnalysis::validate`] for the analysis at `field` of a message of type
    /// `message_type`.
    pub(crate) fn validate_in(
        &self,
        message_type: &'static str,
        field: &str,
    ) -> Result<(), ValidationError> {
        let invalid = |name: &str, problem| {
            ValidationError::new(message_type, format!("{field}.{name}"), problem)
        };
        finite(message_type, &format!("{field}.external"), &self.external)?;
        for (name, v) in [
            ("resisting_norm", self.resisting_norm),
            ("resisting_max", self.resisting_max),
        ] {
            if let Some(v) = v
                && !(v.is_finite() && v >= 0.0)
            {
                let problem = Problem::OutOfRange {
                    requirement: "finite and >= 0",
                    value: v,
                };
                return Err(invalid(name, problem));
            }
        }
        if let Some(w) = &self.net_wrench {
            finite(message_type, &format!("{field}.net_wrench"), w)?;
        }
        if self.unavailable.is_some() && self.resisting_norm.is_some() {
            let problem = Problem::Contradicts(format!("{field}.resisting_norm"));
            return Err(invalid("unavailable", problem));
        }
        finite(
            message_type,
            &format!("{field}.slip_margins"),
            &self.slip_margins,
        )
    }
}

/// [`ForceAnalysis`] before `unavailable`.
#[derive(Deserialize)]
pub(super) struct ForceAnalysisBeforeUnavailable {
    external: [f64; 6],
    resisting_norm: Option<f64>,
    resisting_max: Option<f64>,
    net_wrench: Option<[f64; 6]>,
    slip_margins: Vec<f64>,
}

impl From<ForceAnalysisBeforeUnavailable> for ForceAnalysis {
    fn from(f: ForceAnalysisBeforeUnavailable) -> Self {
        ForceAnalysis {
            external: f.external,
            resisting_norm: f.resisting_norm,
            resisting_max: f.resisting_max,
            net_wrench: f.net_wrench,
            slip_margins: f.slip_margins,
            unavailable: None,
        }
    }
}
