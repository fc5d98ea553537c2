//! Bayesian optimisation and its baselines run on simulated grasp trials: the experiments
//! of thesis sections 4.6-4.8 (1D runs with the model at each step, 2D sample maps, trials
//! to within 5/10/20% of the grid maximum, BO versus random search over seeds) as data.
//!
//! This crate joins the trial evaluator (`graspopt-trial`: parameters in, score out) and the
//! optimisation engine (`graspopt-bayesopt`). The scores are maximised. It knows nothing of
//! files, plots or the bus: graspopt-report writes what it returns.
//!
//! - [`search`]: one seeded run of a method on an evaluator, as a [`Trace`].
//! - [`target`]: trials to within a fraction of a reference value, medians over seeds.
//! - [`compare`]: many seeds of several methods in parallel, summarised per method.
//! - [`snapshot`]: the GP mean, its standard deviation and EI along a 1D space after each step.
//! - [`scans`]: grid scans of a built-in object for the studies.
//! - [`metric_study`]: the metric figures 4.3-4.15 (which scans, what is read off them).
//! - [`sensing_study`]: the force-sensing round trip (fingertip contacts to sensor readings and
//!   back) on the seven objects.
//! - [`bo_study`]: the BO figures 4.16-4.27 and Table 4.1 (the checked plan, the results of
//!   each part per object).
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod bo_study;
pub mod compare;
pub mod error;
pub mod metric_study;
pub mod scans;
pub mod search;
pub mod sensing_study;
pub mod snapshot;
pub mod target;

pub use compare::{Comparison, MethodSummary, compare};
pub use error::ExperimentError;
pub use search::{SearchSettings, Trace, run};
pub use snapshot::{Snapshot, run_with_snapshots};
pub use target::{TARGET_FRACTIONS, median, trials_to_within};
