//! The folders of `graspopt experiment metrics` ([`metrics`]) and `graspopt experiment bo`
//! ([`bo`]): CSV files, SVG (and PNG) figures and a markdown report, laid out from what the
//! studies of `graspopt-experiment` return.

pub mod bo;
pub mod metrics;
