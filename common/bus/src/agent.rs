//! What an agent is: one [`Agent`] trait that the runner (`graspopt run`'s embedded agents),
//! `graspopt launch` and `graspopt agent <kind>` are written against once.
//!
//! To add an agent kind: its row in protocol's `agent_kinds!` (its [`AgentKind`], its name
//! on the bus), the crate of the agent with its `impl Agent`, and its row in the runner's
//! registry (`graspopt_runner::agents::AGENTS`), which `graspopt agent` and launch files read.

use std::future::Future;

use graspopt_protocol::{AgentKind, RunId};
use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::Bus;

/// An agent: its kind, its settings and how it runs on a bus.
pub trait Agent: Send + Sync {
    /// Its kind: the liveliness tokens it declares, `graspopt agent <kind>`, a launch file's
    /// `kind`.
    const KIND: AgentKind;
    /// What it does, in one line (`graspopt agent --help`).
    const ABOUT: &'static str;
    /// Its settings: a TOML file's keys (docs/agent-config.md) and `--set key=value`; every
    /// key has a default.
    type Config: Serialize + DeserializeOwned + Default + Clone + Send + Sync + 'static;
    /// What it returns when it ends (the serving agents end only when stopped: `()`).
    type Output: Send;
    /// Why it could not run (its crate's own error type).
    type Error: std::error::Error + Send + Sync + 'static;

    /// The id setting of `config` (unique per run and kind; `--id` sets it).
    fn id(config: &mut Self::Config) -> &mut String;

    /// Refuses settings it cannot run with, before it joins the bus; the error names the
    /// setting.
    fn validate(config: &Self::Config) -> Result<(), Self::Error>;

    /// Runs in `run` on `bus` as `config` says, until its work ends or `stop` resolves
    /// (Ctrl-C, say: it then ends cleanly, with `Ok`).
    fn run(
        &self,
        bus: &Bus,
        run: &RunId,
        config: &Self::Config,
        stop: impl Future<Output = ()> + Send,
    ) -> impl Future<Output = Result<Self::Output, Self::Error>> + Send;
}

/// `work` until it ends or `stop` resolves (then `Ok(())`): how an agent that serves until
/// stopped honours [`Agent::run`]'s `stop`.
pub async fn until<E>(
    work: impl Future<Output = Result<(), E>>,
    stop: impl Future<Output = ()>,
) -> Result<(), E> {
    tokio::select! {
        r = work => r,
        _ = stop => Ok(()),
    }
}
