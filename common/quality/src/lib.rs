//! Grasp quality from contacts: wrenches, contact models, the grasp map and the
//! metrics of its wrench hull (thesis chapter 2).
//!
//! This crate owns the mathematics only. It knows nothing of files, the bus or the
//! simulator: callers hand it contacts (positions and unit normals pointing into the
//! object) or wrenches, and get metrics back.
//!
//! - [`cases`]: grasp cases as data (the case file's serde types).
//! - [`wrench`]: wrench vectors and frame changes (eq. 2.1-2.3).
//! - [`contact`]: contacts, contact models (frictionless, friction cone, soft finger)
//!   and the wrenches each produces (eq. 2.4-2.11).
//! - [`cloud`]: preprocessing of a raw contact cloud into its mean contact (eq. 2.12).
//! - [`grasp_map`]: the grasp map, the set of all contact wrenches (eq. 2.13-2.14).
//! - [`hull`]: convex-hull queries in wrench space (affine rank, minimum-norm point,
//!   expanding polytope, full hull).
//! - [`limits`]: bounds on edge counts, wrench counts and magnitudes, so bad input is an
//!   error naming the field rather than an allocation failure or an overflowed metric.
//! - [`forces`]: force analysis: the net wrench of contact forces, their slip margins,
//!   and the least-norm forces in the friction cones that resist an external wrench.
//! - [`metrics`]: force closure, Largest Sphere, Grasp Wrench Volume, distance and the
//!   Bimodal Wrench metric (section 2.6).
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod cases;
pub mod cloud;
pub mod contact;
pub mod error;
pub mod forces;
pub mod grasp_map;
pub mod hull;
pub mod limits;
pub mod metrics;
pub mod wrench;

pub use cloud::{MeanContact, mean_contact};
pub use contact::{Contact, FrictionModel, GraspModel};
pub use error::QualityError;
pub use forces::{
    ContactForces, Resisting, SlipMargin, gravity_wrench, net_wrench, resisting_forces,
    slip_margins,
};
pub use grasp_map::GraspMap;
pub use metrics::{DistanceSolver, Metric, Metrics, MetricsOptions, evaluate};
pub use wrench::Wrench;
