//! Tests of graspopt-sensing: analytic contacts, noise-free round trips, refusals,
//! validation, serde and the noise model.

mod analytic;
mod inputs;
mod noise;
mod properties;
mod refusals;
mod round_trip;
mod support;
