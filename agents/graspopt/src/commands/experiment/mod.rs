//! `graspopt experiment`: regenerate the thesis's chapter-4 figures in the simulator, into a
//! folder of CSV and SVG (and PNG) files with a short markdown report. The studies are
//! computed by `graspopt_experiment::{metric_study, bo_study}` and written by
//! `graspopt_report::experiment`.
//!
//! - [`metrics`]: the metric figures 4.3-4.15;
//! - [`bo`]: the Bayesian-optimisation figures 4.16-4.27 and Table 4.1, and the same in 6D;
//! - [`sensing`]: the force-sensing round trip (issue #20's tables).

mod bo;
mod metrics;
mod sensing;

use anyhow::Result;
use clap::{Args, Subcommand};

#[derive(Args, Debug)]
pub struct ExperimentArgs {
    #[command(subcommand)]
    pub which: Experiment,
}

#[derive(Subcommand, Debug)]
pub enum Experiment {
    /// The metric figures of thesis chapter 4 (4.3-4.15).
    Metrics(metrics::MetricsArgs),
    /// The Bayesian-optimisation figures of thesis chapter 4 (4.16-4.27, Table 4.1), BO
    /// versus random search over seeds on all seven objects, in 2D and 6D.
    Bo(bo::BoArgs),
    /// The force-sensing round trip: fingertip contacts to force/torque readings and back,
    /// on the seven objects with barrett_ft, without and with sensor noise.
    Sensing(sensing::SensingArgs),
}

pub fn run(args: &ExperimentArgs) -> Result<std::process::ExitCode> {
    match &args.which {
        Experiment::Metrics(m) => metrics::metrics(m)?,
        Experiment::Bo(b) => bo::bo(b)?,
        Experiment::Sensing(s) => sensing::sensing(s)?,
    }
    Ok(std::process::ExitCode::SUCCESS)
}
