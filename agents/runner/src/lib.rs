//! Runs graspopt's agents: the registry of agent kinds and one agent as its own process
//! ([`agents`]); every agent of a run in this process ([`embedded`]), from
//! settings resolved for a new or a resumed run ([`run_settings`]); the pipeline
//! benchmarks ([`bench`]); launch files and their processes ([`launch`]); recordings for
//! the replay hand ([`record`]); an agent's settings file ([`config`]); and the signals
//! that stop them ([`signal`]).
//!
//! Tests call it in-process. It knows nothing of command-line flags: the `graspopt` binary
//! fills a [`RunSettings`] or a [`Standalone`] from them.

pub mod agents;
pub mod bench;
pub mod config;
pub mod embedded;
pub mod ending;
pub mod error;
pub mod launch;
pub mod open_files;
pub mod record;
pub mod run_settings;
pub mod signal;

pub use agents::{AGENTS, AgentRow, SpecSettings, Standalone};
pub use embedded::{Embedded, placeholder, run_embedded};
pub use error::RunnerError;
pub use run_settings::RunSettings;
