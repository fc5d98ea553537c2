//! Runs graspopt's agents: every agent of a run in this process ([`embedded`]), and the
//! signals that stop them ([`signal`]).
//!
//! Tests call it in-process. It knows nothing of command-line flags: the `graspopt` binary
//! resolves them into an [`Embedded`] run.

pub mod embedded;
pub mod signal;

pub use embedded::{Embedded, placeholder, run_embedded};
