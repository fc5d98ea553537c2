//! The folders of `graspopt experiment metrics` ([`metrics`]) and `graspopt experiment bo`
//! ([`bo`]): CSV files, SVG (and PNG) figures and a markdown report, laid out from what the
//! studies of `graspopt-experiment` return.

pub mod bo;
pub mod metrics;

use crate::error::Result;
use graspopt_experiment::ExperimentError;

/// The hand of a study (`--hand`, a built-in name or a URDF file) as its report names it:
/// the hand's own name (a URDF's robot name) and, for a file, the file it was read from.
/// A hand that cannot be loaded is refused as the study refuses it.
pub(crate) fn hand_description(hand: &str) -> Result<String> {
    let loaded =
        graspopt_sim::hand::hand_by_name(hand).map_err(|source| ExperimentError::Hand {
            name: hand.to_string(),
            source,
        })?;
    let from_file = std::path::Path::new(hand.trim())
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("urdf"));
    Ok(if from_file {
        format!("Hand `{}` (read from `{}`)", loaded.name(), hand.trim())
    } else {
        format!("Hand `{}` (built in)", loaded.name())
    })
}
