//! `graspopt agent <kind>`: one agent as its own process, on the bus the flags describe. A
//! subcommand per row of the runner's registry ([`graspopt_runner::AGENTS`]); settings come
//! from `--config FILE` (TOML, the agent's settings struct) and `--set key=value` overrides
//! (docs/agent-config.md). The coordinator also takes the run's spec as flags.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::parser::ValueSource;
use clap::{ArgMatches, Args, Command, FromArgMatches};
use graspopt_protocol::AgentKind;
use graspopt_runner::{AGENTS, SpecSettings, Standalone};

use super::bus::BusArgs;
use super::setup::SpecArgs;
use crate::out::outln;

/// `graspopt agent <kind> [flags]`.
#[derive(Debug)]
pub struct AgentArgs {
    pub kind: AgentKind,
    pub common: Common,
    /// The coordinator's run spec.
    pub spec: Option<SpecArgs>,
    /// The ids of the flags given on the command line.
    pub explicit: Vec<String>,
}

/// The flags of every agent.
#[derive(Args, Debug, Clone)]
pub struct Common {
    /// The run to join.
    #[arg(long, default_value = "run")]
    pub run: String,
    /// Settings file (TOML; its keys, with an example per agent: docs/agent-config.md).
    /// `--set` wins over it.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// One setting, over the settings file: KEY=VALUE, a dotted key for a key of a table
    /// (`--set table.key=value`); repeatable. The keys are listed below.
    #[arg(long, value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Agent id (unique per run and kind).
    #[arg(long)]
    pub id: Option<String>,
    #[command(flatten)]
    pub bus: BusArgs,
}

impl Args for AgentArgs {
    fn augment_args(cmd: Command) -> Command {
        let kinds = AGENTS.iter().map(|row| {
            let sub = Common::augment_args(Command::new(row.kind.as_str()));
            let sub = match row.kind {
                AgentKind::Coordinator => SpecArgs::augment_args(sub),
                _ => sub,
            };
            // After the flags: a flattened struct's doc comment would be its description.
            let keys = (row.keys)().join(", ");
            let settings = format!(
                "Settings (--set KEY=VALUE, or in --config FILE; docs/agent-config.md): {keys}"
            );
            sub.about(row.about).long_about(None).after_help(settings)
        });
        cmd.subcommands(kinds).subcommand_required(true)
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl FromArgMatches for AgentArgs {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let missing = || clap::Error::new(clap::error::ErrorKind::MissingSubcommand);
        let (name, sub) = m.subcommand().ok_or_else(missing)?;
        let kind = AgentKind::parse(name).ok_or_else(missing)?;
        let spec = match kind {
            AgentKind::Coordinator => Some(SpecArgs::from_arg_matches(sub)?),
            _ => None,
        };
        let given =
            |id: &&clap::Id| sub.value_source(id.as_str()) == Some(ValueSource::CommandLine);
        Ok(AgentArgs {
            kind,
            common: Common::from_arg_matches(sub)?,
            spec,
            explicit: sub.ids().filter(given).map(|id| id.to_string()).collect(),
        })
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl AgentArgs {
    /// What the runner needs to run this agent.
    pub fn standalone(&self) -> Standalone {
        let c = &self.common;
        Standalone {
            run: c.run.clone(),
            id: c.id.clone(),
            config: c.config.clone(),
            set: c.set.clone(),
            bus: c.bus.config(),
            spec: self.spec.as_ref().map(|s| SpecSettings {
                trial: s.sim.settings(),
                trials: s.trials,
                params: s.params.clone(),
                method: s.method,
                initial: s.initial,
                seed: s.seed,
                resume: s.resume,
                explicit: self.explicit.clone(),
            }),
        }
    }
}

/// `graspopt agent`: the agent runs until a shutdown signal (the coordinator until its
/// run ends, then prints its final status).
pub fn run(args: &AgentArgs) -> Result<ExitCode> {
    let runtime = tokio::runtime::Runtime::new()?;
    let standalone = args.standalone();
    let row = graspopt_runner::agents::agent_row(args.kind);
    let Some(end) = runtime.block_on((row.run)(&standalone))? else {
        return Ok(ExitCode::SUCCESS);
    };
    outln!("{}", end.json()?)?;
    for line in end.lines(" (stopped)") {
        eprintln!("coordinator: {line}");
    }
    Ok(ExitCode::from(end.exit_code()))
}
