//! A scored grasp trial: place a simulated hand, close it on the object, turn the
//! contacts into wrenches and score them with a grasp-quality metric (thesis chapter 4).
//!
//! This crate joins the simulator (`graspopt-sim`, geometry only) and the quality core
//! (`graspopt-quality`, mathematics only). It owns the choices between them: which
//! contact model, which reference frame and torque scale, which metric, and the score of
//! a trial that touches nothing. It knows nothing of files or the bus.
//!
//! - [`score`]: settings and scoring of one trial outcome.
//! - [`evaluator`]: an object, a hand and a trial space: parameters in, score out.
//! - [`measured`]: scoring clouds a hand measured (the metric agent's side).
//! - [`fingertips`]: simulated fingertip force/torque sensors, and contacts from their
//!   readings.
//! - [`forces`]: the contact-force analysis of a trial (least forces resisting the object's
//!   weight; measured forces' net wrench and slip margins).
//! - [`point`]: a trial point as users write it (`x=-0.08,y=0.01`), checked against a space.
//! - [`scan`]: 1D/2D (any-D) grid scans over the trial space, in parallel, and their grids.
//! - [`settings`]: a trial's settings as a user states them ([`Evaluator::from_settings`]).
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod error;
pub mod evaluator;
pub mod fingertips;
pub mod forces;
pub mod measured;
pub mod point;
pub mod scan;
pub mod score;
pub mod settings;

pub use error::TrialError;
pub use evaluator::{Evaluation, Evaluator};
pub use point::NamedPoint;
pub use scan::{ScanPoint, scan_grid};
pub use score::{Metric, ReferenceFrame, ScoreSettings, TrialScore, score_outcome};
pub use settings::TrialSettings;
