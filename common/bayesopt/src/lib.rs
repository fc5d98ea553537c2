//! Bayesian optimisation engine of graspopt (thesis chapter 3): Gaussian-process regression,
//! Expected Improvement (and log-EI, UCB), DIRECT for the acquisition maximisation, an
//! ask/tell optimizer with batch proposals and serialisable state, baselines, test functions
//! and a benchmark harness. Pure algorithms: no I/O.
//!
//! Conventions: [`Optimizer`] maximises (grasp quality) unless `Settings::minimize` is set;
//! the test functions are minimised and the benchmark harness sets `minimize`.
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod acquisition;
pub mod baseline;
pub mod benchmark;
pub mod direct;
pub mod error;
pub mod fit;
pub mod gp;
pub mod kernel;
pub mod lbfgs;
pub mod linalg;
pub mod optimizer;
pub mod preset;
pub mod qei;
pub mod rng;
pub mod special;
pub mod testfunctions;

pub use acquisition::{AcquisitionKind, XiRule};
pub use baseline::{AskTell, GridSearch, RandomSearch};
pub use benchmark::run_seed;
pub use error::{BoError, Result};
pub use fit::{FitSettings, Hyperparameters};
pub use gp::Gp;
pub use kernel::{Kernel, KernelKind};
pub use optimizer::{
    BatchStrategy, GRASP_MODEL_CAP, InitialDesign, MAX_QEI_SAMPLES, MIN_MODEL_CAP, ModelCap,
    ModelPoint, Optimizer, OutputTransform, RestartRule, RoundInfo, Settings, StopReason, StopRule,
};
pub use preset::{Method, Preset};
pub use testfunctions::TestFunction;
