//! The run monitor: a live dashboard of the runs on the bus.
//!
//! Runs are found from the coordinators' liveliness tokens; each run's current state is
//! asked from its coordinator (so the monitor works when started after the run began), then
//! followed through the status topic. For the focused run it shows the trials by state, the
//! workers alive with their current trial, the best grasp so far, a sparkline of the best
//! score so far and the error counters. `q` or Esc quits, Tab switches runs. [`once`] gives
//! the same as text (for scripts).
//!
//! - [`app`]: the state ([`Monitor`], [`RunView`]) and its text ([`run_lines`]).
//! - [`ui`]: drawing the dashboard.
//! - [`event`]: the bus and keyboard loops.

pub mod app;
pub mod event;
pub mod ui;

pub use app::{Monitor, RunView, run_lines, spark_data};
pub use event::{dashboard, once};
pub use ui::draw;
