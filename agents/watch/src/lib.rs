//! Watches a graspopt bus from a terminal: the library behind `graspopt topic` and
//! `graspopt monitor`.
//!
//! - [`topic`]: topic rows of the live agents, echo formatting, rate and bandwidth windows, and
//!   the loops that list, echo and measure a topic.
//! - [`monitor`]: what the monitor knows of each run, its text and its dashboard (ratatui),
//!   and the loops that fill them from the bus.
//! - [`error`]: what the tools refuse or fail at ([`WatchError`]).
//!
//! The functions take plain settings and a `stop` future (Ctrl-C in the binary, a timer in
//! tests), never command-line flags. This crate only reads the bus: it must not know how the
//! agents decide.
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod error;
pub mod monitor;
pub mod topic;

pub use error::WatchError;
