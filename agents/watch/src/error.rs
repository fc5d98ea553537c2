//! The watch tools' error type. The messages are the ones users see (tests quote them).

use graspopt_bus::BusError;
use graspopt_protocol::Topic;
use graspopt_protocol::keys::KeyError;

use crate::topic::{MIN_INTERVALS, MIN_WINDOW};

/// Everything the watch tools refuse or fail at.
#[derive(Debug, thiserror::Error)]
pub enum WatchError {
    /// `--duration` not a positive number of seconds.
    #[error("--duration must be a positive number of seconds, got {0}")]
    Duration(f64),
    /// `--duration` beyond what a [`std::time::Duration`] holds.
    #[error("--duration {0} is too long")]
    DurationTooLong(f64),
    /// `--window` too small to measure a rate.
    #[error(
        "--window must be at least {MIN_WINDOW} messages (a rate needs {MIN_INTERVALS} intervals), got {0}"
    )]
    Window(usize),
    /// `--run` given with a key expression (it only goes with a topic name).
    #[error("--run goes with a topic name, not with a key expression ({0})")]
    RunWithKey(String),
    /// A `KEY` argument that is neither a key expression nor a topic of the key table.
    #[error(
        "unknown topic {key:?}: give a key expression (graspopt/<run>/result) or one of {}",
        Topic::ALL.map(|t| t.entry().name).join(", ")
    )]
    UnknownTopic { key: String },
    /// The dashboard cannot take this terminal.
    #[error("cannot use this terminal for the dashboard: {0} (try --once)")]
    Terminal(std::io::Error),
    /// Drawing on the terminal failed.
    #[error(transparent)]
    Draw(#[from] std::io::Error),
    #[error(transparent)]
    Key(#[from] KeyError),
    #[error(transparent)]
    Bus(#[from] BusError),
}
