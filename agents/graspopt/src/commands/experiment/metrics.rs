//! `graspopt experiment metrics`: regenerate the thesis's metric figures (4.3-4.15) in
//! the simulator, into a folder of CSV + SVG files with a short markdown report (see
//! `graspopt_experiment::metric_study` for the figures).

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use graspopt_experiment::metric_study::{MAX_STEPS, MAX_STEPS_2D, MetricStudy};

use crate::commands::setup::count;

use crate::out::outln;

#[derive(Args, Debug)]
pub struct MetricsArgs {
    /// Output folder.
    #[arg(long, default_value = "results/experiment-metrics")]
    pub out: PathBuf,
    /// Points of each 1D scan (2 to 100000).
    #[arg(long, default_value_t = 61, value_parser = count::<usize>(2, MAX_STEPS as u64))]
    pub steps: usize,
    /// Points per axis of each 2D scan (2 to 3000).
    #[arg(long, default_value_t = 31, value_parser = count::<usize>(2, MAX_STEPS_2D as u64))]
    pub steps_2d: usize,
    /// Worker threads (0: all cores).
    #[arg(long, default_value_t = 0, value_parser = count::<usize>(0, u64::MAX))]
    pub threads: usize,
    /// Hand: a built-in name (see `graspopt hands`) or a URDF file.
    #[arg(long, default_value = "barrett")]
    pub hand: String,
}

pub(super) fn metrics(args: &MetricsArgs) -> Result<()> {
    let study = MetricStudy {
        hand: args.hand.clone(),
        steps: args.steps,
        steps_2d: args.steps_2d,
        threads: args.threads,
    };
    let path = graspopt_report::experiment::metrics::write_metric_study(&args.out, &study)?;
    outln!("{}", path.display())?;
    Ok(())
}
