//! `graspopt`: the one command users install. Each subcommand lives in `commands/` and
//! wires a library crate to files and the terminal.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod commands;
mod export;
mod render;

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
    /// Grasp-quality metrics (rank, force closure, epsilon, volume, distance, BW) of the
    /// cases in a JSON file.
    Quality(commands::quality::QualityArgs),
    /// Run one simulated trial and print its contacts and metrics.
    Trial(commands::trial::TrialArgs),
    /// Grid-scan a metric over one or two trial parameters (CSV and SVG).
    Scan(commands::scan::ScanArgs),
    /// Regenerate the thesis's experiments (`metrics`: figures 4.3-4.15).
    Experiment(commands::experiment::ExperimentArgs),
    /// Run the BO engine (or random search) on a standard test function.
    OptimizeFunction(commands::optimize_function::OptimizeFunctionArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Quality(args) => commands::quality::run(args),
        Command::Trial(args) => commands::trial::run(args),
        Command::Scan(args) => commands::scan::run(args),
        Command::Experiment(args) => commands::experiment::run(args),
        Command::OptimizeFunction(args) => {
            commands::optimize_function::run(args).map(|()| ExitCode::SUCCESS)
        }
    };
    match result {
        Ok(code) => code,
        Err(err) => {
            eprintln!("graspopt: {err:#}");
            ExitCode::FAILURE
        }
    }
}
