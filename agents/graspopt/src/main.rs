//! `graspopt`: the one command users install. Each subcommand lives in `commands/` and
//! wires a library crate to files and the terminal. Stdout is written only through
//! `out::outln!` and `out::stdout`, so that a closed pipe ends a command quietly.
#![warn(clippy::print_stdout)]

use std::process::ExitCode;

use clap::parser::ValueSource;
use clap::{ArgMatches, CommandFactory, FromArgMatches, Parser, Subcommand};

mod commands;
mod out;

#[derive(Parser, Debug)]
#[command(
    name = "graspopt",
    version,
    about = "Find good robotic grasps by trial"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Grasp-quality metrics (rank, force closure, epsilon, volume, distance, BW, isotropy) of the
    /// cases in a JSON file.
    Quality(commands::quality::QualityArgs),
    /// Run one simulated trial and print its contacts and metrics.
    Trial(commands::trial::TrialArgs),
    /// List the built-in hands (or describe one, or a URDF file).
    Hands(commands::hands::HandsArgs),
    /// Grid-scan a metric over trial parameters (CSV; SVG and PNG images for one or two).
    Scan(commands::scan::ScanArgs),
    /// Record a grid of simulated grasps' contact clouds, or fingertip readings with
    /// `--sensing ft` (for `agent hand --set replay=FILE`).
    Record(commands::record::RecordArgs),
    /// Regenerate the thesis's experiments (`metrics`: figures 4.3-4.15; `bo`: figures
    /// 4.16-4.27 and Table 4.1).
    Experiment(commands::experiment::ExperimentArgs),
    /// Run the BO engine (or random search) on a standard test function.
    OptimizeFunction(commands::optimize_function::OptimizeFunctionArgs),
    /// Optimize grasps: every agent in this process (no router needed), results in a folder.
    Run(commands::run::RunArgs),
    /// Run one agent (perception, hand, metric, planner, coordinator) as its own process.
    Agent(commands::agent::AgentArgs),
    /// A Zenoh router, for agents on several machines.
    Router(commands::router::RouterArgs),
    /// Start the agents a launch file places on this machine, each its own process.
    Launch(commands::launch::LaunchArgs),
    /// Watch the bus: list topics, echo messages, measure rate and bandwidth.
    Topic(commands::topic::TopicArgs),
    /// A live dashboard of the runs on the bus.
    Monitor(commands::monitor::MonitorArgs),
    /// A run's trials from its journal, as CSV or JSON.
    Export(commands::export::ExportArgs),
    /// Figures of the distributed pipeline (throughput, overhead, cloud latency).
    Bench(commands::bench::BenchArgs),
}

/// The command line: [`Cli`], where every flag that takes a value takes a negative number as
/// one (and a comma-separated list any text), so that `--trials -5` reaches the flag's own
/// check, which names the range it accepts, instead of being an unknown flag `-5`.
fn command() -> clap::Command {
    fn negatives(cmd: clap::Command) -> clap::Command {
        cmd.mut_subcommands(negatives).mut_args(|a| {
            match (a.get_action().takes_values(), a.get_value_delimiter()) {
                (true, Some(_)) => a.allow_hyphen_values(true),
                (true, None) => a.allow_negative_numbers(true),
                (false, _) => a,
            }
        })
    }
    negatives(Cli::command())
}

/// Whether the flag with id `name` (a field name: `trials`, `torque_scale`) was given on
/// the command line rather than left at its default.
fn given(matches: Option<&ArgMatches>, name: &str) -> bool {
    matches.is_some_and(|m| {
        m.try_get_raw(name).is_ok_and(|v| v.is_some())
            && m.value_source(name) == Some(ValueSource::CommandLine)
    })
}

/// The log filter when `RUST_LOG` is not set: warnings, but Zenoh's own connection and
/// scouting warnings only from errors up. Those name a source file of the build machine and
/// repeat what graspopt says in its own words (`cannot reach tcp/...`); `RUST_LOG=warn` or
/// `RUST_LOG=zenoh=debug` shows them. Two more Zenoh messages are silenced: "sending on a
/// closed channel" from a subscriber whose receiver a stopping agent already dropped (most
/// Ctrl-Cs printed it), and "Unable to find transport for link event" from its admin space
/// when a link closes; neither says anything a user can act on. Nor do its errors of a
/// session refused by a router (a failed login): graspopt says `authentication failed`.
const DEFAULT_LOG: &str = "warn,zenoh::net::runtime::orchestrator=error,\
                           zenoh::api::handlers::fifo=off,zenoh::api::admin=error,\
                           zenoh_transport::unicast::establishment::open=off";

/// mimalloc, not glibc's malloc. Every agent allocates each contact cloud it builds or reads
/// (10,000 points: three vectors of 187 KB) on one thread and frees it on another. glibc gave
/// those pages back to the kernel at each free, so every cloud paid them again in page faults
/// (71,084 in one `graspopt bench clouds` run, 1,373 with mimalloc): hand to metric agent over
/// shared memory took a median of 468-558 µs, against 87-155 µs with mimalloc in the same
/// alternating runs. Built without transparent huge pages (feature `no_thp`): a fresh 2 MB
/// page is zeroed whole at its first touch, which made the clouds 1.6 times slower (medians)
/// and a run's resident memory 114-127 MB instead of 66-69 MB (glibc: 46-47 MB).
/// docs/benchmarks.md, "Contact clouds", has the runs.
#[cfg(feature = "mimalloc")]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    let matches = command().get_matches();
    let cli = match Cli::from_arg_matches(&matches) {
        Ok(cli) => cli,
        Err(e) => e.exit(),
    };
    // Parsed and nothing more: the test of the docs' commands (tests/cli/doc_commands.rs).
    if std::env::var_os("GRASPOPT_PARSE_ONLY").is_some_and(|v| v == "1") {
        return ExitCode::SUCCESS;
    }
    let run_matches = matches.subcommand_matches("run");
    // Logs go to stderr; RUST_LOG overrides the default filter.
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(DEFAULT_LOG)),
        )
        .with_writer(std::io::stderr)
        // Colours only on a terminal: logs redirected to files stay plain text.
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .init();
    let result = match &cli.command {
        Command::Quality(args) => commands::quality::run(args),
        Command::Trial(args) => commands::trial::run(args),
        Command::Hands(args) => commands::hands::run(args),
        Command::Scan(args) => commands::scan::run(args),
        Command::Record(args) => commands::record::run(args),
        Command::Experiment(args) => commands::experiment::run(args),
        Command::OptimizeFunction(args) => commands::optimize_function::run(args),
        Command::Run(args) => commands::run::run(args, &|name| given(run_matches, name)),
        Command::Agent(args) => commands::agent::run(args),
        Command::Router(args) => commands::router::run(args),
        Command::Launch(args) => commands::launch::run(args),
        Command::Topic(args) => commands::topic::run(args),
        Command::Monitor(args) => commands::monitor::run(args),
        Command::Export(args) => commands::export::run(args),
        Command::Bench(args) => commands::bench::run(args),
    };
    match result {
        Ok(code) => code,
        // `graspopt ... | head -1`: the reader has what it wanted.
        Err(err) if out::reader_gone(&err) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("graspopt: {err:#}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The flags (and positional arguments) of `cmd` and its subcommands, recursively, that
    /// have no help text, as `graspopt sub --flag`; subcommands without a description too.
    fn undocumented(cmd: &clap::Command, path: &str, missing: &mut Vec<String>) {
        for arg in cmd.get_arguments() {
            let id = arg.get_id().as_str();
            if id == "help" || id == "version" {
                continue;
            }
            if arg.get_help().is_none() && arg.get_long_help().is_none() {
                let name = arg.get_long().map_or(id.to_string(), |l| format!("--{l}"));
                missing.push(format!("{path} {name}"));
            }
        }
        for sub in cmd.get_subcommands() {
            let sub_path = format!("{path} {}", sub.get_name());
            if sub.get_about().is_none() && sub.get_long_about().is_none() {
                missing.push(format!("{sub_path} (the subcommand)"));
            }
            undocumented(sub, &sub_path, missing);
        }
    }

    #[test]
    fn every_flag_of_every_subcommand_has_a_help_text() {
        let mut cmd = Cli::command();
        cmd.build();
        let mut missing = Vec::new();
        undocumented(&cmd, "graspopt", &mut missing);
        assert!(
            missing.is_empty(),
            "without a help text:\n{}",
            missing.join("\n")
        );
        // The walk sees nested subcommands and flattened flag sets.
        let agent = cmd.find_subcommand("agent").unwrap();
        let coordinator = agent.find_subcommand("coordinator").unwrap();
        assert!(coordinator.get_arguments().any(|a| a.get_id() == "trials"));
        assert!(coordinator.get_arguments().any(|a| a.get_id() == "connect"));
    }

    /// Every directive of the default filter parses (`EnvFilter::new` would skip a bad one
    /// silently), and it names the two Zenoh targets it silences.
    #[test]
    fn the_default_log_filter_parses() {
        let filter = tracing_subscriber::EnvFilter::try_new(DEFAULT_LOG).unwrap();
        let shown = filter.to_string();
        assert!(shown.contains("zenoh::api::handlers::fifo=off"), "{shown}");
        assert!(shown.contains("zenoh::api::admin=error"), "{shown}");
    }
}
