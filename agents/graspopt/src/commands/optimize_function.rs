//! `graspopt optimize-function`: run the Bayesian optimisation engine (or random search) on a
//! standard test function over several seeds and report the best value after each evaluation
//! and the evaluations (and rounds, for batches) needed to reach normalised regret 5%, 1% and
//! 0.1%, then medians over the seeds.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use graspopt_bayesopt::Method;
use graspopt_runner::bench::functions;

use super::setup::count;
use crate::out::outln;

/// The most seeds one command runs.
pub const MAX_SEEDS: u64 = 1000;
/// The most evaluations per seed.
pub const MAX_BUDGET: usize = 100_000;

/// `--method`: one of [`Method::NAMED`], parsed by [`Method::from_name`].
pub fn method_parser() -> impl TypedValueParser<Value = Method> {
    PossibleValuesParser::new(
        Method::NAMED.map(|m| PossibleValue::new(m.name()).help(m.description())),
    )
    .try_map(|name| Method::from_name(&name))
}

/// Output format.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum FormatArg {
    /// Human-readable lines.
    Text,
    /// One JSON object per line (per seed, then a summary).
    Json,
}

/// Arguments of `graspopt optimize-function`.
#[derive(clap::Args, Debug)]
pub struct OptimizeFunctionArgs {
    /// Test function: branin, hartmann3, hartmann6, rosenbrock, sixhumpcamel, goldsteinprice
    /// (log form), michalewicz, ackley, levy or styblinskitang.
    pub function: String,
    /// Number of seeds, 1 to 1000 (seeds 0..N).
    #[arg(long, default_value_t = 10, value_parser = count::<u64>(1, MAX_SEEDS))]
    pub seeds: u64,
    /// Evaluations per seed, 1 to 100000 (default: 50 in 2D, 100 otherwise).
    #[arg(long, value_parser = count::<usize>(1, MAX_BUDGET as u64))]
    pub budget: Option<usize>,
    /// Random initial points, at most the budget (default: 5 in 2D, 10 in 6D, otherwise 2 d;
    /// capped at the budget).
    #[arg(long = "initial", alias = "init", value_name = "N", value_parser = count::<usize>(0, u64::MAX))]
    pub init: Option<usize>,
    /// Points proposed per round (parallel workers).
    #[arg(long, default_value_t = 1, value_parser = count::<usize>(1, u64::MAX))]
    pub batch: usize,
    /// Method.
    #[arg(long, default_value = "bo", value_parser = method_parser())]
    pub method: Method,
    /// Output format.
    #[arg(long, value_enum, default_value_t = FormatArg::Text)]
    pub format: FormatArg,
}

/// Run the command.
pub fn run(args: &OptimizeFunctionArgs) -> anyhow::Result<std::process::ExitCode> {
    let b = functions::benchmark(
        &args.function,
        args.method,
        args.seeds,
        args.budget,
        args.init,
        args.batch,
    )?;
    let json = args.format == FormatArg::Json;
    let levels = b.run(|seed, trace, s| -> anyhow::Result<()> {
        outln!("{}", functions::seed_report(&b, json, seed, trace, s))?;
        Ok(())
    })?;
    outln!("{}", functions::summary_report(&b, json, &levels))?;
    Ok(std::process::ExitCode::SUCCESS)
}
