//! Watching topics: `graspopt topic list|echo|hz|bw`.
//!
//! - [`list`]: the topics of the live agents (from their liveliness tokens), with each topic's
//!   message type and publishers ([`rows`]).
//! - [`echo`]: every message on a topic, decoded ([`text`] for people, or one JSON object per
//!   line).
//! - [`rate`]: the message rate or the bandwidth over a sliding [`Window`].
//!
//! A key is a key expression (`graspopt/mug/result`, `graspopt/*/status`) or a topic name
//! (`object`, `command`, `clouds`, `result`, `status`) completed with a run (default: every
//! run): [`resolve_key`]. Subscriptions go through ring buffers: a slow terminal loses the
//! oldest messages and never slows the agents. Clouds that travel through shared memory (hand
//! and metric agent on one host) are not on Zenoh and so are not seen here.

pub mod event;
pub mod rows;
pub mod text;
pub mod window;

use crate::error::WatchError;
use graspopt_protocol::{RunId, Runs, Topic};

pub use event::{EchoSettings, Measure, RateSettings, check_duration, echo, list, rate};
pub use rows::{Row, rows_json, rows_table, topic_rows};
pub use text::{human_bytes, render_text};
pub use window::{MIN_INTERVALS, MIN_WINDOW, Window, WindowStats, check_window};

/// How a command prints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// For people.
    Text,
    /// One JSON document per line (per message for echo).
    Json,
}

/// The key expression a `KEY` argument means: a key expression as it is, or a topic name of
/// the key table in `run` (every run if `None`).
pub fn resolve_key(key: &str, run: Option<&str>) -> Result<String, WatchError> {
    if key.contains('/') {
        if run.is_some() {
            return Err(WatchError::RunWithKey(key.to_string()));
        }
        return Ok(key.to_string());
    }
    let run = run.map(RunId::new).transpose()?;
    let runs = run.as_ref().map_or(Runs::All, Runs::One);
    match Topic::named(key) {
        Some(topic) => Ok(topic.entry().key_expr(runs)),
        None => Err(WatchError::UnknownTopic {
            key: key.to_string(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topic_names_become_key_expressions() {
        assert_eq!(
            resolve_key("result", Some("mug")).unwrap(),
            "graspopt/mug/result"
        );
        assert_eq!(
            resolve_key("command", None).unwrap(),
            "graspopt/*/hand/*/command"
        );
        assert_eq!(resolve_key("graspopt/x/**", None).unwrap(), "graspopt/x/**");
        let e = resolve_key("results", None).unwrap_err().to_string();
        assert!(e.contains("results") && e.contains("status"), "{e}");
        assert!(resolve_key("result", Some("a/b")).is_err());
        assert!(resolve_key("graspopt/x/result", Some("x")).is_err());
    }
}
