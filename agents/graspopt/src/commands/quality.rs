//! `graspopt quality --input FILE [--format json|table] [--timing]`: the metrics of
//! every case of a JSON file shaped like `tests/data/metric-cases.json`: an object
//! with `cases`, each with `params` + `contacts`, or `wrenches`, or both (contacts win).
//!
//! One output row per case, in order. A bad case prints an error naming the case index
//! and the field (on stderr, and as `{"error": ...}` in its JSON row) and the others are
//! still evaluated; the exit status is then 1. The metrics are the metric table's
//! (`graspopt_quality::metrics::TABLE`), in its order. A metric is never printed as `null`
//! (only `volume`, with `--no-volume`) nor as `-0.0` (`evaluate` guarantees both).
//!
//! Keys (any other key is an error naming it, so a misspelling is not silently replaced
//! by a default): see [`graspopt_quality::cases`].
//! - case: `params`, `contacts`, `wrenches`, and the descriptive keys `kind`, `name`,
//!   `description`, `notes`, `comment`, `expected`, which are ignored.
//! - `params`: `model` (`frictionless`, `point_friction` or `soft_finger`), `mu`
//!   (`0..=1e6`), `edges` (`3..=4096`), `gamma` (`0..=1e12`), `reference_point` (default
//!   the origin), `torque_scale` (default 1, `> 0`). A key the model does not use (`gamma`
//!   of a point contact) is accepted and ignored.
//! - each contact: `position`, `normal` (unit length).
//!
//! Limits (`graspopt_quality::limits`): at most 2,000,000 wrenches per case (contacts x
//! wrenches per contact, or given), every coordinate and every wrench component (given
//! or generated) at most 1e12 in absolute value.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use graspopt_quality::cases::Case;
use graspopt_quality::metrics::{
    DistanceSolver, Metrics, MetricsOptions, TABLE, Value as MetricValue, evaluate,
};
use graspopt_quality::{GraspMap, QualityError};
use serde::Serialize;
use serde_json::{Value, json};

#[derive(Args, Debug)]
pub struct QualityArgs {
    /// JSON file with a `cases` array.
    #[arg(long)]
    pub input: PathBuf,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Json)]
    pub format: Format,
    /// Add `micros`: the median microseconds per evaluation over repeated runs.
    #[arg(long)]
    pub timing: bool,
    /// Skip the Grasp Wrench Volume (it needs the full hull, slow for surface models).
    #[arg(long)]
    pub no_volume: bool,
    /// Solver for the distance from the origin to the wrench hull.
    #[arg(long, value_enum, default_value_t = Solver::MinNorm)]
    pub solver: Solver,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// One JSON object per line.
    Json,
    /// An aligned text table.
    Table,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Solver {
    /// Wolfe's minimum-norm-point algorithm (default).
    MinNorm,
    /// The conic program solved by Clarabel.
    Clarabel,
}

pub fn run(args: &QualityArgs) -> Result<ExitCode> {
    let text = std::fs::read_to_string(&args.input)
        .with_context(|| format!("cannot read {}", args.input.display()))?;
    let doc: Value = serde_json::from_str(&text)
        .with_context(|| format!("{} is not valid JSON", args.input.display()))?;
    let Some(cases) = doc.get("cases").and_then(Value::as_array) else {
        bail!(
            "{}: expected an object with a `cases` array",
            args.input.display()
        );
    };
    let options = MetricsOptions {
        volume: !args.no_volume,
        distance_solver: match args.solver {
            Solver::MinNorm => DistanceSolver::MinNorm,
            Solver::Clarabel => DistanceSolver::Clarabel,
        },
    };
    let mut out = crate::out::stdout();
    let mut failed = 0;
    let written = (|| -> std::io::Result<()> {
        if args.format == Format::Table {
            write_table_header(&mut out, args.timing)?;
        }
        for (i, case) in cases.iter().enumerate() {
            let row = parse_case(case)
                .and_then(|grasp| {
                    let metrics = evaluate(&grasp, &options).map_err(|e| match e {
                        QualityError::HullTooLarge {
                            metric: "volume", ..
                        } => anyhow::anyhow!("{e}, or pass --no-volume"),
                        e => e.into(),
                    })?;
                    let micros = args.timing.then(|| median_micros(&grasp, &options));
                    Ok((metrics, micros))
                })
                .map_err(|e| format!("case {i}: {e:#}"));
            if let Err(message) = &row {
                eprintln!("graspopt: {message}");
                failed += 1;
            }
            match args.format {
                Format::Json => writeln!(out, "{}", json_row(&row))?,
                Format::Table => write_table_row(&mut out, i, &row)?,
            }
        }
        out.flush()
    })();
    written.context("cannot write the results")?;
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        eprintln!("graspopt: {failed} of {} cases failed", cases.len());
        ExitCode::FAILURE
    })
}

type Row = std::result::Result<(Metrics, Option<f64>), String>;

/// One JSON output row: the metrics in their documented order, then `micros`.
#[derive(Serialize)]
struct JsonRow {
    #[serde(flatten)]
    metrics: Metrics,
    #[serde(skip_serializing_if = "Option::is_none")]
    micros: Option<f64>,
}

fn json_row(row: &Row) -> String {
    match row {
        Ok((m, micros)) => serde_json::to_string(&JsonRow {
            metrics: *m,
            micros: *micros,
        })
        .unwrap_or_else(|e| json!({ "error": e.to_string() }).to_string()),
        Err(message) => json!({ "error": message }).to_string(),
    }
}

/// `case`, then each metric's short name in its column (the metric table's), then `micros`.
fn write_table_header(out: &mut impl Write, timing: bool) -> std::io::Result<()> {
    write!(out, "{:>5}", "case")?;
    for def in &TABLE {
        write!(out, " {:>w$}", def.short, w = def.width)?;
    }
    if timing {
        write!(out, " {:>10}", "micros")?;
    }
    writeln!(out)
}

/// One row: the metrics as `evaluate` returns them (finite, no negative zero), reals in
/// scientific notation, `-` for one not computed.
fn write_table_row(out: &mut impl Write, i: usize, row: &Row) -> std::io::Result<()> {
    match row {
        Ok((m, micros)) => {
            write!(out, "{i:>5}")?;
            for (def, value) in m.iter() {
                let w = def.width;
                match value {
                    Some(MetricValue::Real(x)) => write!(out, " {x:>w$.9e}")?,
                    Some(v) => write!(out, " {v:>w$}")?,
                    None => write!(out, " {:>w$}", "-")?,
                }
            }
            if let Some(us) = micros {
                write!(out, " {us:>10.1}")?;
            }
            writeln!(out)
        }
        Err(message) => writeln!(out, "{i:>5} error: {message}"),
    }
}

/// The median time of one evaluation, over repeated runs (at least 5, and at least
/// 50 ms in total, at most 1,000 runs).
fn median_micros(grasp: &GraspMap, options: &MetricsOptions) -> f64 {
    let mut samples = Vec::new();
    let started = Instant::now();
    while samples.len() < 5
        || (started.elapsed() < Duration::from_millis(50) && samples.len() < 1000)
    {
        let t = Instant::now();
        let _ = std::hint::black_box(evaluate(std::hint::black_box(grasp), options));
        samples.push(t.elapsed().as_secs_f64() * 1e6);
    }
    graspopt_bayesopt::benchmark::median(&samples).unwrap_or(f64::NAN)
}

/// The grasp map of one case of the file ([`graspopt_quality::cases::Case`]); an error names
/// the field at fault by its path (`contacts[0].position`).
fn parse_case(case: &Value) -> Result<GraspMap> {
    let case: Case = serde_path_to_error::deserialize(case).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        if path == "." {
            anyhow::anyhow!("{inner}")
        } else {
            anyhow::anyhow!("{path}: {inner}")
        }
    })?;
    Ok(case.grasp_map()?)
}
