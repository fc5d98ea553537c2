//! `graspopt optimize-function`: run the Bayesian optimisation engine (or random search) on a
//! standard test function over several seeds and report the best value after each evaluation
//! and the evaluations (and rounds, for batches) needed to reach normalised regret 5%, 1% and
//! 0.1%, then medians over the seeds.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use graspopt_bayesopt::benchmark::{Benchmark, REGRET_LEVELS};
use graspopt_bayesopt::{Method, TestFunction};
use serde_json::json;

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

fn fmt_opt(v: Option<usize>) -> String {
    v.map_or_else(|| "-".to_string(), |e| e.to_string())
}

fn fmt_med(v: Option<f64>) -> String {
    v.map_or_else(|| "-".to_string(), |e| format!("{e}"))
}

/// Run the command.
pub fn run(args: &OptimizeFunctionArgs) -> anyhow::Result<std::process::ExitCode> {
    let function = TestFunction::from_name(&args.function)?;
    let budget = args
        .budget
        .unwrap_or_else(|| Benchmark::default_budget(function));
    let n_init = match args.init {
        Some(n) => {
            anyhow::ensure!(
                n <= budget,
                "--initial {n} is more than --budget {budget}: the initial design is part of the budget"
            );
            n
        }
        // The default design never exceeds a small explicit budget.
        None => Benchmark::default_n_init(function, budget),
    };
    let method = args.method;
    let q = args.batch;
    let benchmark = Benchmark {
        function,
        method,
        seeds: args.seeds,
        budget,
        n_init,
        batch: q,
    };
    let agg = benchmark.run(|seed, trace, s| -> anyhow::Result<()> {
        match args.format {
            FormatArg::Json => {
                let line = json!({
                    "function": function.name(),
                    "method": method.name(),
                    "seed": seed,
                    "budget": budget,
                    "init": n_init,
                    "batch": q,
                    "best": trace,
                    "regret_levels": REGRET_LEVELS,
                    "evals_to": s.evals_to,
                    "rounds_to": s.rounds_to,
                    "final_regret": s.final_regret,
                });
                outln!("{line}")?;
            }
            FormatArg::Text => {
                let best: Vec<String> = trace.iter().map(|v| format!("{v:.6}")).collect();
                outln!(
                    "seed {seed}: best after each evaluation: {}",
                    best.join(" ")
                )?;
                let levels: Vec<String> = REGRET_LEVELS
                    .iter()
                    .enumerate()
                    .map(|(k, l)| {
                        format!(
                            "{}%: {} evals / {} rounds",
                            l * 100.0,
                            fmt_opt(s.evals_to[k]),
                            fmt_opt(s.rounds_to[k])
                        )
                    })
                    .collect();
                outln!(
                    "seed {seed}: regret {} (final regret {:.3e})",
                    levels.join(", "),
                    s.final_regret
                )?;
            }
        }
        Ok(())
    })?;
    match args.format {
        FormatArg::Json => {
            let levels: Vec<serde_json::Value> = agg
                .iter()
                .map(|l| {
                    json!({
                        "level": l.level,
                        "reached": l.reached,
                        "seeds": l.seeds,
                        "median_evals": l.median_evals,
                        "median_rounds": l.median_rounds,
                        "max_evals": l.max_evals,
                    })
                })
                .collect();
            outln!(
                "{}",
                json!({
                    "summary": {
                        "function": function.name(),
                        "method": method.name(),
                        "seeds": args.seeds,
                        "budget": budget,
                        "init": n_init,
                        "batch": q,
                        "levels": levels,
                    }
                })
            )?;
        }
        FormatArg::Text => {
            let parts: Vec<String> = agg
                .iter()
                .map(|l| {
                    format!(
                        "{}%: {}/{} seeds, median {} evals / {} rounds",
                        l.level * 100.0,
                        l.reached,
                        l.seeds,
                        fmt_med(l.median_evals),
                        fmt_med(l.median_rounds)
                    )
                })
                .collect();
            outln!(
                "summary {} ({}, budget {budget}, initial {n_init}, batch {q}): {}",
                function.name(),
                method.name(),
                parts.join("; ")
            )?;
        }
    }
    Ok(std::process::ExitCode::SUCCESS)
}
