//! The optimizer's benchmark on a standard test function (`graspopt optimize-function`): the
//! benchmark its settings describe, and its report, a line per seed and a summary line, as
//! text or JSON.

use graspopt_bayesopt::benchmark::{Benchmark, LevelSummary, REGRET_LEVELS, SeedSummary};
use graspopt_bayesopt::error::BoError;
use graspopt_bayesopt::{Method, TestFunction};
use serde_json::json;

/// Why a function benchmark cannot run.
#[derive(Debug, thiserror::Error)]
pub enum FunctionBenchError {
    #[error(
        "--initial {initial} is more than --budget {budget}: the initial design is part of the budget"
    )]
    Initial { initial: usize, budget: usize },
    #[error(transparent)]
    Bo(#[from] BoError),
}

/// The benchmark of `function` (by name) with `method`: `budget` evaluations per seed
/// (default: the function's), `initial` of them random (default: the function's, at most
/// the budget), `batch` per round, seeds `0..seeds`.
pub fn benchmark(
    function: &str,
    method: Method,
    seeds: u64,
    budget: Option<usize>,
    initial: Option<usize>,
    batch: usize,
) -> Result<Benchmark, FunctionBenchError> {
    let function = TestFunction::from_name(function)?;
    let budget = budget.unwrap_or_else(|| Benchmark::default_budget(function));
    let n_init = match initial {
        Some(n) if n > budget => {
            return Err(FunctionBenchError::Initial { initial: n, budget });
        }
        Some(n) => n,
        // The default design never exceeds a small explicit budget.
        None => Benchmark::default_n_init(function, budget),
    };
    Ok(Benchmark {
        function,
        method,
        seeds,
        budget,
        n_init,
        batch,
    })
}

fn fmt_opt(v: Option<usize>) -> String {
    v.map_or_else(|| "-".to_string(), |e| e.to_string())
}

fn fmt_med(v: Option<f64>) -> String {
    v.map_or_else(|| "-".to_string(), |e| format!("{e}"))
}

/// The report of seed `seed` of `b`: the best value after each evaluation (`trace`) and
/// the evaluations and rounds to each regret level; one JSON line, or two text lines.
pub fn seed_report(b: &Benchmark, json: bool, seed: u64, trace: &[f64], s: &SeedSummary) -> String {
    if json {
        return json!({
            "function": b.function.name(),
            "method": b.method.name(),
            "seed": seed,
            "budget": b.budget,
            "init": b.n_init,
            "batch": b.batch,
            "best": trace,
            "regret_levels": REGRET_LEVELS,
            "evals_to": s.evals_to,
            "rounds_to": s.rounds_to,
            "final_regret": s.final_regret,
        })
        .to_string();
    }
    let best: Vec<String> = trace.iter().map(|v| format!("{v:.6}")).collect();
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
    format!(
        "seed {seed}: best after each evaluation: {}\nseed {seed}: regret {} (final regret {:.3e})",
        best.join(" "),
        levels.join(", "),
        s.final_regret
    )
}

/// The summary of `b` over its seeds, `levels` (medians per regret level): a JSON line or
/// a text line.
pub fn summary_report(b: &Benchmark, json: bool, levels: &[LevelSummary]) -> String {
    let (function, method) = (b.function.name(), b.method.name());
    if json {
        let levels: Vec<serde_json::Value> = levels
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
        let summary = json!({
            "summary": {
                "function": function,
                "method": method,
                "seeds": b.seeds,
                "budget": b.budget,
                "init": b.n_init,
                "batch": b.batch,
                "levels": levels,
            }
        });
        return summary.to_string();
    }
    let parts: Vec<String> = levels
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
    format!(
        "summary {function} ({method}, budget {}, initial {}, batch {}): {}",
        b.budget,
        b.n_init,
        b.batch,
        parts.join("; ")
    )
}
