//! `graspopt bench`: figures of the distributed pipeline ([`graspopt_runner::bench`]) and of
//! the planner ([`graspopt_planner::bench`]).

use std::process::ExitCode;

use anyhow::{Result, bail};
use clap::{Args, Subcommand};
use graspopt_planner::bench::{MAX_BENCH_POINTS, PlannerBenchSettings, planner_bench};
use graspopt_protocol::PlannerMethod;
use graspopt_runner::bench::coordinator::{BenchPath, CoordinatorSettings};
use graspopt_runner::bench::{self, PipelineSettings};

use super::setup::{count, planner_method};
use crate::out::outln;

/// The most hand workers of one throughput run.
pub const MAX_WORKERS: usize = 256;
/// The most points of one contact-cloud message.
pub const MAX_POINTS: usize = 1_000_000;
/// The most messages per path, or trials per run.
pub const MAX_MESSAGES: usize = 100_000;

#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(subcommand)]
    pub what: What,
}

#[derive(Subcommand, Debug)]
pub enum What {
    /// Throughput versus workers, and overhead per trial.
    Pipeline {
        /// Simulated trial cost for the throughput runs (milliseconds, at most 60000).
        #[arg(long, default_value_t = 200, value_parser = count::<u64>(0, 60_000))]
        trial_cost_ms: u64,
        /// Trials per worker in the throughput runs (at least 1).
        #[arg(long, default_value_t = 10, value_parser = count::<u64>(1, MAX_MESSAGES as u64))]
        trials_per_worker: u64,
        /// Worker counts, each 1 to 256.
        #[arg(long, default_value = "1,2,4", value_delimiter = ',', value_parser = count::<usize>(1, MAX_WORKERS as u64))]
        workers: Vec<usize>,
        /// Trials of the overhead run (at least 2: a cycle is the time between two).
        #[arg(long, default_value_t = 100, value_parser = count::<u64>(2, MAX_MESSAGES as u64))]
        overhead_trials: u64,
        /// How the throughput runs propose trials: bo or random.
        #[arg(long, default_value = "random", value_parser = planner_method())]
        method: PlannerMethod,
    },
    /// One coordinator and its journal with synthetic agents that answer at once: trials/s
    /// and trial latency versus workers, through the core alone and over the bus.
    Coordinator {
        /// Worker counts, each 1 to 256.
        #[arg(
            long,
            default_value = "1,2,4,8,16,32,64,128,256",
            value_delimiter = ',',
            value_parser = count::<usize>(1, MAX_WORKERS as u64)
        )]
        workers: Vec<usize>,
        /// Trials of each run (at least 1, at most 100000).
        #[arg(long, default_value_t = 10_000, value_parser = count::<u64>(1, MAX_MESSAGES as u64))]
        trials: u64,
        /// Which coordinator: core (the I/O-free core and the journal), bus (the loop over
        /// an in-process Zenoh bus), or both.
        #[arg(long, default_value = "core,bus", value_delimiter = ',', value_parser = bench_path())]
        paths: Vec<BenchPath>,
    },
    /// The planner's proposal round at many observations, through the planner agent's
    /// engine path (engine grasp) in this thread: pin it to one core with `taskset -c 0`.
    Planner {
        /// Observations at the first timed round (1 to 100000).
        #[arg(long, default_value_t = 2000, value_parser = count::<usize>(1, MAX_BENCH_POINTS as u64))]
        observations: usize,
        /// Points pending in each round, and proposals per round (1 to 100000).
        #[arg(long, default_value_t = 32, value_parser = count::<usize>(1, MAX_BENCH_POINTS as u64))]
        pending: usize,
        /// Timed rounds per dimension (1 to 1000).
        #[arg(long, default_value_t = 9, value_parser = count::<usize>(1, 1000))]
        rounds: usize,
        /// Dimensions: 2 (Branin), 6 (Hartmann6) or both.
        #[arg(long, default_value = "2,6", value_delimiter = ',')]
        dims: Vec<usize>,
    },
    /// Contact-cloud latency, shared memory versus Zenoh.
    Clouds {
        /// Points per message (at most 1000000).
        #[arg(long, default_value_t = 10_000, value_parser = count::<usize>(0, MAX_POINTS as u64))]
        points: usize,
        /// Messages per path (1 to 100000).
        #[arg(long, default_value_t = 300, value_parser = count::<usize>(1, MAX_MESSAGES as u64))]
        messages: usize,
    },
}

fn bench_path() -> impl clap::builder::TypedValueParser<Value = BenchPath> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(["core", "bus"]).map(|s| match s.as_str() {
        "core" => BenchPath::Core,
        _ => BenchPath::Bus,
    })
}

/// Checks what the flags' parsers cannot (each count's range is its parser's), before
/// anything runs.
fn validate(what: &What) -> Result<()> {
    match what {
        What::Coordinator { paths, .. } => {
            if paths.is_empty() {
                bail!("--paths: give core, bus or both");
            }
        }
        What::Pipeline {
            trials_per_worker,
            workers,
            ..
        } => {
            let max_workers = workers.iter().copied().max().unwrap_or(1) as u64;
            if trials_per_worker.saturating_mul(max_workers) > MAX_MESSAGES as u64 {
                bail!(
                    "--trials-per-worker {trials_per_worker} with {max_workers} workers is more than \
                     {MAX_MESSAGES} trials in one run"
                );
            }
        }
        What::Planner { dims, .. } => {
            if dims.is_empty() || dims.iter().any(|d| *d != 2 && *d != 6) {
                bail!("--dims: give 2, 6 or 2,6");
            }
        }
        What::Clouds { .. } => {}
    }
    Ok(())
}

pub fn run(args: &BenchArgs) -> Result<ExitCode> {
    validate(&args.what)?;
    let runtime = || tokio::runtime::Runtime::new();
    let report = match &args.what {
        What::Planner {
            observations,
            pending,
            rounds,
            dims,
        } => {
            // No async runtime: the rounds run in this thread alone.
            let settings = PlannerBenchSettings {
                dims: dims.clone(),
                observations: *observations,
                pending: *pending,
                rounds: *rounds,
                ..PlannerBenchSettings::default()
            };
            planner_bench(&settings)?.to_string()
        }
        What::Pipeline {
            trial_cost_ms,
            trials_per_worker,
            workers,
            overhead_trials,
            method,
        } => {
            let settings = PipelineSettings {
                trial_cost_ms: *trial_cost_ms,
                trials_per_worker: *trials_per_worker,
                workers: workers.clone(),
                overhead_trials: *overhead_trials,
                method: *method,
            };
            runtime()?.block_on(bench::pipeline(&settings))?.to_string()
        }
        What::Coordinator {
            workers,
            trials,
            paths,
        } => {
            let settings = CoordinatorSettings {
                workers: workers.clone(),
                trials: *trials,
                paths: paths.clone(),
            };
            let report = bench::coordinator::coordinator(&settings);
            runtime()?.block_on(report)?.to_string()
        }
        What::Clouds { points, messages } => {
            let report = bench::clouds(*points, *messages);
            runtime()?.block_on(report)?.to_string()
        }
    };
    outln!("{}", report.trim_end())?;
    Ok(ExitCode::SUCCESS)
}
