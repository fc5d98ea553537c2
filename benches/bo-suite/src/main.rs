//! The BO suite of issue 19: graspopt's recommended settings (`Preset::Benchmark`) and
//! egobox-ego side by side on the standard test functions of `TestFunction::ALL`, with the
//! same budget (20 d evaluations, the initial design included) and the same initial design
//! (uniform points drawn from the seed, given to both engines already evaluated).
//!
//! `run` appends one JSON line per (engine, function, seed) to the output file as each
//! finishes, and skips those already there, so an interrupted run resumes where it stopped.
//! `table` reads such files and prints the Markdown table of docs/benchmarks.md (of the
//! seeds FIRST to LAST, both included, with `--seeds`; of all seeds otherwise).
//!
//! Usage:
//!   graspopt-bo-suite run --engine ours|egobox [--functions a,b,..] [--seeds N] --out FILE
//!   graspopt-bo-suite table [--seeds FIRST-LAST] FILE...
//!   graspopt-bo-suite tuned
//!
//! `tuned` runs issue 4's figures for the settings (with `BO_SUITE_VARIANT` applied): Branin
//! seeds 0-9 (50 evaluations, 5 initial; target a median of at most 8 evaluations to 1%)
//! and Hartmann6 seeds 0-9 (100 evaluations, 10 initial; target 1% in every seed), each with
//! the engine's own initial design, as `bo_bench` does.

use std::collections::BTreeMap;
use std::io::{BufRead, Write};
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use anyhow::{Context, bail, ensure};
use egobox_ego::{CorrelationSpec, EgorBuilder, InfillStrategy};
use graspopt_bayesopt::benchmark::{
    Benchmark, LevelSummary, SeedSummary, aggregate, median, recommended_settings, summarize,
};
use graspopt_bayesopt::rng::Rng;
use graspopt_bayesopt::{
    KernelKind, Optimizer, OutputTransform, RestartRule, Settings, TestFunction, XiRule,
};
use ndarray::{Array2, ArrayView2};
use serde::{Deserialize, Serialize};

/// Budget per seed: 20 evaluations per dimension, the initial design included.
fn budget(f: TestFunction) -> usize {
    20 * f.dim()
}

/// Initial design size: graspopt's benchmark default (5 in 2D, 10 in 6D, else 2 d).
fn n_init(f: TestFunction) -> usize {
    Benchmark::default_n_init(f, budget(f))
}

/// The seed's initial design: `n_init(f)` uniform points in the box.
fn initial_design(f: TestFunction, seed: u64) -> Vec<Vec<f64>> {
    let (lo, hi) = f.bounds();
    let mut rng = Rng::new(seed);
    (0..n_init(f))
        .map(|_| {
            lo.iter()
                .zip(&hi)
                .map(|(l, h)| rng.uniform_range(*l, *h))
                .collect()
        })
        .collect()
}

/// One engine on one function and seed.
#[derive(Debug, Serialize, Deserialize)]
struct Record {
    engine: String,
    function: String,
    seed: u64,
    budget: usize,
    n_init: usize,
    /// Best value after each evaluation (the initial design included).
    trace: Vec<f64>,
    /// Wall time of each proposal, seconds.
    proposal_s: Vec<f64>,
}

/// Best-so-far values of `ys`.
fn best_so_far(ys: &[f64]) -> Vec<f64> {
    ys.iter()
        .scan(f64::INFINITY, |b, y| {
            *b = b.min(*y);
            Some(*b)
        })
        .collect()
}

/// Our engine for `f` and `seed` as the suite runs it: the settings under test, minimising,
/// with the suite's initial-design size.
fn suite_optimizer(f: TestFunction, seed: u64) -> anyhow::Result<Optimizer> {
    let (lo, hi) = f.bounds();
    let bounds: Vec<(f64, f64)> = lo.into_iter().zip(hi).collect();
    let mut settings = settings_under_test()?;
    settings.minimize = true;
    settings.n_init = Some(n_init(f));
    Ok(Optimizer::new(&bounds, settings, seed)?)
}

/// graspopt with `recommended_settings()`: the design observed first, then one proposal at
/// a time.
fn run_ours(f: TestFunction, seed: u64) -> anyhow::Result<Record> {
    let mut opt = suite_optimizer(f, seed)?;
    let mut ys = Vec::with_capacity(budget(f));
    for x in initial_design(f, seed) {
        let y = f.eval(&x);
        opt.observe(&x, y)?;
        ys.push(y);
    }
    let mut proposal_s = Vec::new();
    while ys.len() < budget(f) {
        let t = Instant::now();
        let pts = opt.suggest(1)?;
        proposal_s.push(t.elapsed().as_secs_f64());
        for x in pts {
            let y = f.eval(&x);
            opt.observe(&x, y)?;
            ys.push(y);
        }
    }
    Ok(record("ours", f, seed, &ys, proposal_s))
}

/// Changes to `recommended_settings()` for a comparison run, comma-separated (environment
/// `BO_SUITE_VARIANT`): `norestart`, `nodiv`, `notail`, `nopm`, `rank`, `m52`, `se`, `pm32`, and
/// `winN`, `tolX`, `tabuX`, `rinitN`, `reiX` / `norei` (restart rule; `rei` its
/// `max_relative_ei`), `pmqX`, `divN`, `lsX` (length-scale
/// prior median), `lssdX`, `directN`, `refitN`, `fitrN`, `xiX`, `nfixX` (noise held near X),
/// `nfloorX` (noise floor), `sigsdX`, `lsminX`, `lsmaxX`, `itersN` (fit iterations),
/// `polishN` (polish starts), `piterN` (polish iterations).
fn apply_variant(s: &mut Settings, variant: &str) -> anyhow::Result<()> {
    for part in variant.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let num = |prefix: &str| -> anyhow::Result<f64> {
            part[prefix.len()..]
                .parse()
                .with_context(|| format!("variant {part}: not a number after {prefix}"))
        };
        match part {
            "norestart" => s.restart = None,
            "nodiv" => s.diversify_every = 0,
            "notail" => s.output_transform = OutputTransform::None,
            "nopm" => s.prior_mean_quantile = None,
            "rank" => s.output_transform = OutputTransform::Rank,
            "m52" => s.kernel = KernelKind::Matern52,
            "se" => s.kernel = KernelKind::SquaredExponential,
            "pm32" => s.kernel = KernelKind::ProductMatern32,
            p if p.starts_with("win") => rule(s, part)?.window = num("win")? as usize,
            p if p.starts_with("tol") => rule(s, part)?.tol = num("tol")?,
            p if p.starts_with("tabu") => rule(s, part)?.tabu_radius = num("tabu")?,
            p if p.starts_with("rinit") => rule(s, part)?.init = num("rinit")? as usize,
            p if p.starts_with("pmq") => s.prior_mean_quantile = Some(num("pmq")?),
            p if p.starts_with("div") => s.diversify_every = num("div")? as usize,
            p if p.starts_with("lssd") => s.fit.length_scale_log_sd = num("lssd")?,
            p if p.starts_with("ls") => s.fit.length_scale_log_mean = num("ls")?.ln(),
            p if p.starts_with("direct") => s.direct_evals_per_dim = num("direct")? as usize,
            p if p.starts_with("refit") => s.full_refit_every = num("refit")? as usize,
            p if p.starts_with("fitr") => s.fit.restarts = num("fitr")? as usize,
            p if p.starts_with("xi") => s.xi = XiRule::Fixed(num("xi")?),
            p if p.starts_with("nfix") => {
                let v = num("nfix")?;
                s.fit.noise_bounds = (v, 2.0 * v);
                s.fit.noise_log_mean = v.ln();
            }
            p if p.starts_with("nfloor") => s.fit.noise_bounds.0 = num("nfloor")?,
            p if p.starts_with("sigsd") => s.fit.signal_log_sd = num("sigsd")?,
            p if p.starts_with("lsmax") => s.fit.length_scale_bounds.1 = num("lsmax")?,
            p if p.starts_with("lsmin") => s.fit.length_scale_bounds.0 = num("lsmin")?,
            p if p.starts_with("polish") => s.polish_starts = num("polish")? as usize,
            p if p.starts_with("piter") => s.polish_iters = num("piter")? as usize,
            p if p.starts_with("iters") => s.fit.max_iter = num("iters")? as usize,
            "norei" => rule(s, part)?.max_relative_ei = None,
            p if p.starts_with("rei") => rule(s, part)?.max_relative_ei = Some(num("rei")?),
            other => bail!("unknown variant {other}"),
        }
    }
    Ok(())
}

fn rule<'a>(s: &'a mut Settings, part: &str) -> anyhow::Result<&'a mut RestartRule> {
    s.restart
        .as_mut()
        .with_context(|| format!("variant {part}: the restart rule is off"))
}

/// egobox-ego's `Egor` (LogEI, Matern 3/2, constant trend, its defaults otherwise) given the
/// same design with its values, for `budget - n_init` iterations of one point. A proposal's
/// time is the wall time from the end of one evaluation (or the start of the run) to the
/// start of the next.
fn run_egobox(f: TestFunction, seed: u64) -> anyhow::Result<Record> {
    let design = initial_design(f, seed);
    let d = f.dim();
    let mut doe = Array2::zeros((design.len(), d + 1));
    let mut ys = Vec::with_capacity(budget(f));
    for (i, x) in design.iter().enumerate() {
        for (j, v) in x.iter().enumerate() {
            doe[[i, j]] = *v;
        }
        let y = f.eval(x);
        doe[[i, d]] = y;
        ys.push(y);
    }
    let (lo, hi) = f.bounds();
    let mut xlimits = Array2::zeros((d, 2));
    for j in 0..d {
        xlimits[[j, 0]] = lo[j];
        xlimits[[j, 1]] = hi[j];
    }
    // (evaluated values, proposal times, end of the last evaluation)
    let log = Arc::new(Mutex::new((
        Vec::<f64>::new(),
        Vec::<f64>::new(),
        Instant::now(),
    )));
    let objective = {
        let log = Arc::clone(&log);
        move |x: &ArrayView2<f64>| -> Array2<f64> {
            let mut out = Array2::zeros((x.nrows(), 1));
            let mut l = log.lock().unwrap_or_else(|e| e.into_inner());
            let waited = l.2.elapsed().as_secs_f64();
            l.1.push(waited);
            for (i, row) in x.rows().into_iter().enumerate() {
                let p: Vec<f64> = row.to_vec();
                let y = f.eval(&p);
                out[[i, 0]] = y;
                l.0.push(y);
            }
            l.2 = Instant::now();
            out
        }
    };
    let iters = budget(f) - design.len();
    log.lock().unwrap_or_else(|e| e.into_inner()).2 = Instant::now();
    EgorBuilder::optimize(objective)
        .configure(|c| {
            c.doe(&doe)
                .max_iters(iters)
                .seed(seed)
                .infill_strategy(InfillStrategy::LogEI)
                .configure_gp(|g| g.correlation_spec(egobox_correlation()))
        })
        .min_within(&xlimits)?
        .run()?;
    let mut l = log.lock().unwrap_or_else(|e| e.into_inner());
    ys.extend(std::mem::take(&mut l.0));
    let proposal_s = std::mem::take(&mut l.1);
    drop(l);
    ys.truncate(budget(f));
    Ok(record("egobox", f, seed, &ys, proposal_s))
}

/// egobox-ego's correlation: Matern 3/2 unless `BO_SUITE_EGOBOX_CORR` says `se` or `m52`
/// (for a comparison of kernels).
fn egobox_correlation() -> CorrelationSpec {
    match std::env::var("BO_SUITE_EGOBOX_CORR").as_deref() {
        Ok("se") => CorrelationSpec::SQUAREDEXPONENTIAL,
        Ok("m52") => CorrelationSpec::MATERN52,
        _ => CorrelationSpec::MATERN32,
    }
}

fn record(engine: &str, f: TestFunction, seed: u64, ys: &[f64], proposal_s: Vec<f64>) -> Record {
    Record {
        engine: engine.to_string(),
        function: f.name().to_string(),
        seed,
        budget: budget(f),
        n_init: n_init(f),
        trace: best_so_far(ys),
        proposal_s,
    }
}

fn read_records(path: &Path) -> anyhow::Result<Vec<Record>> {
    if !path.exists() {
        return Ok(Vec::new());
    }
    let file =
        std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let mut out = Vec::new();
    for (i, line) in std::io::BufReader::new(file).lines().enumerate() {
        let line = line?;
        if line.trim().is_empty() {
            continue;
        }
        out.push(
            serde_json::from_str(&line)
                .with_context(|| format!("{} line {}: not a record", path.display(), i + 1))?,
        );
    }
    Ok(out)
}

fn run(args: &[String]) -> anyhow::Result<()> {
    let mut engine = None;
    let mut functions: Vec<TestFunction> = TestFunction::ALL.to_vec();
    let mut seeds = 20u64;
    let mut out = None;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().with_context(|| format!("{a} needs a value"));
        match a.as_str() {
            "--engine" => engine = Some(value()?.clone()),
            "--functions" => {
                functions = value()?
                    .split(',')
                    .map(TestFunction::from_name)
                    .collect::<Result<_, _>>()?
            }
            "--seeds" => seeds = value()?.parse().context("--seeds: not a whole number")?,
            "--out" => out = Some(value()?.clone()),
            other => bail!("unknown argument {other}"),
        }
    }
    let engine = engine.context("--engine ours|egobox is required")?;
    ensure!(
        engine == "ours" || engine == "egobox",
        "--engine must be ours or egobox, got {engine}"
    );
    let out = out.context("--out FILE is required")?;
    let done: Vec<(String, String, u64)> = read_records(Path::new(&out))?
        .into_iter()
        .map(|r| (r.engine, r.function, r.seed))
        .collect();
    for f in functions {
        for seed in 0..seeds {
            if done.contains(&(engine.clone(), f.name().to_string(), seed)) {
                continue;
            }
            let t = Instant::now();
            let rec = if engine == "ours" {
                run_ours(f, seed)
            } else {
                run_egobox(f, seed)
            }
            .with_context(|| format!("{engine} on {} seed {seed}", f.name()))?;
            let s = summarize(f, seed, &rec.trace, 1);
            eprintln!(
                "{engine} {} seed {seed}: evals to 1% {:?}, final regret {:.2e}, {:.1} s",
                f.name(),
                s.evals_to[1],
                s.final_regret,
                t.elapsed().as_secs_f64()
            );
            let mut file = std::fs::OpenOptions::new()
                .create(true)
                .append(true)
                .open(&out)
                .with_context(|| format!("cannot open {out}"))?;
            writeln!(file, "{}", serde_json::to_string(&rec)?)?;
        }
    }
    Ok(())
}

fn fmt_med(v: Option<f64>) -> String {
    v.map_or_else(|| "-".into(), |m| format!("{m}"))
}

/// One engine's records on one function.
#[derive(Default)]
struct Group {
    seeds: Vec<SeedSummary>,
    proposal_s: Vec<f64>,
    budget: usize,
}

fn table(args: &[String]) -> anyhow::Result<()> {
    let (seeds, paths) = match args {
        [flag, range, rest @ ..] if flag == "--seeds" => {
            let (a, b) = range
                .split_once('-')
                .with_context(|| format!("--seeds FIRST-LAST, got {range}"))?;
            let first: u64 = a.parse().context("--seeds: not a whole number")?;
            let last: u64 = b.parse().context("--seeds: not a whole number")?;
            (first..=last, rest)
        }
        _ => (0..=u64::MAX, args),
    };
    ensure!(!paths.is_empty(), "table needs at least one results file");
    let mut by: BTreeMap<(String, String), Group> = BTreeMap::new();
    for p in paths {
        for r in read_records(Path::new(p))?
            .into_iter()
            .filter(|r| seeds.contains(&r.seed))
        {
            let f = TestFunction::from_name(&r.function)?;
            let e = by
                .entry((r.function.clone(), r.engine.clone()))
                .or_default();
            e.seeds.push(summarize(f, r.seed, &r.trace, 1));
            e.proposal_s.extend(&r.proposal_s);
            e.budget = r.budget;
        }
    }
    println!(
        "| function | d | budget (initial) | ours: seeds at 1% | egobox: seeds at 1% | ours: median evals to 1% | egobox: median evals to 1% | ours: seeds at 0.1% | egobox: seeds at 0.1% | ours: ms per proposal | egobox: ms per proposal |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for f in TestFunction::ALL {
        let get = |e: &str| by.get(&(f.name().to_string(), e.to_string()));
        // A function run by one engine only gets "-" in the other's columns.
        let (o, g) = (get("ours"), get("egobox"));
        let Some(budget) = o.or(g).map(|e| e.budget) else {
            continue;
        };
        let levels = |e: Option<&Group>| e.map(|e| aggregate(&e.seeds, e.budget, 1));
        let (lo, lg) = (levels(o), levels(g));
        let reached = |l: &Option<Vec<LevelSummary>>, i: usize| {
            l.as_ref().map_or_else(
                || "-".to_string(),
                |l| format!("{}/{}", l[i].reached, l[i].seeds),
            )
        };
        let med = |l: &Option<Vec<LevelSummary>>| {
            l.as_ref()
                .map_or_else(|| "-".into(), |l| fmt_med(l[1].median_evals))
        };
        let t = |e: Option<&Group>| {
            e.and_then(|e| median(&e.proposal_s))
                .map_or_else(|| "-".into(), |m| format!("{:.1}", 1e3 * m))
        };
        println!(
            "| {} | {} | {} ({}) | {} | {} | {} | {} | {} | {} | {} | {} |",
            f.name(),
            f.dim(),
            budget,
            n_init(f),
            reached(&lo, 1),
            reached(&lg, 1),
            med(&lo),
            med(&lg),
            reached(&lo, 2),
            reached(&lg, 2),
            t(o),
            t(g),
        );
    }
    Ok(())
}

/// One seed of ours on one function, printed evaluation by evaluation: the value, the best
/// regret so far and the epoch (restarts), to see where a seed stops.
fn trace(args: &[String]) -> anyhow::Result<()> {
    let f = TestFunction::from_name(args.first().context("trace FUNCTION SEED")?)?;
    let seed: u64 = args.get(1).context("trace FUNCTION SEED")?.parse()?;
    let mut opt = suite_optimizer(f, seed)?;
    let mut best = f64::INFINITY;
    let mut n = 0;
    let show = |opt: &Optimizer, x: &[f64], y: f64, best: f64, n: usize| {
        let xs: Vec<String> = x.iter().map(|v| format!("{v:.2}")).collect();
        println!(
            "{n:3} epoch@{:3} y {y:12.5} best regret {:.2e} x [{}] rel_ei {:.1e}",
            opt.epoch_start(),
            f.regret(best),
            xs.join(", "),
            opt.last_round().relative_ei.unwrap_or(f64::NAN)
        );
    };
    for x in initial_design(f, seed) {
        let y = f.eval(&x);
        opt.observe(&x, y)?;
        best = best.min(y);
        n += 1;
        show(&opt, &x, y, best, n);
    }
    while n < budget(f) {
        for x in opt.suggest(1)? {
            let y = f.eval(&x);
            opt.observe(&x, y)?;
            best = best.min(y);
            n += 1;
            show(&opt, &x, y, best, n);
        }
    }
    Ok(())
}

/// The settings of a run: `recommended_settings()` with `BO_SUITE_VARIANT` applied.
fn settings_under_test() -> anyhow::Result<Settings> {
    let mut settings = recommended_settings();
    if let Ok(v) = std::env::var("BO_SUITE_VARIANT") {
        apply_variant(&mut settings, &v)?;
    }
    Ok(settings)
}

/// Issue 4's figures for the settings under test (see the module doc).
fn tuned() -> anyhow::Result<()> {
    for (f, budget, init) in [
        (TestFunction::Branin, 50, 5),
        (TestFunction::Hartmann6, 100, 10),
    ] {
        let mut settings = settings_under_test()?;
        settings.n_init = Some(init);
        let handles: Vec<_> = (0..2u64)
            .map(|t| {
                let s = settings.clone();
                std::thread::spawn(move || {
                    (0..10u64)
                        .filter(|seed| seed % 2 == t)
                        .map(|seed| {
                            graspopt_bayesopt::benchmark::run_seed_with(
                                f,
                                seed,
                                budget,
                                1,
                                s.clone(),
                            )
                            .map(|trace| summarize(f, seed, &trace, 1))
                        })
                        .collect::<Result<Vec<_>, _>>()
                })
            })
            .collect();
        let mut seeds = Vec::new();
        for h in handles {
            let part = h
                .join()
                .map_err(|_| anyhow::anyhow!("a seed's thread panicked"))??;
            seeds.extend(part);
        }
        seeds.sort_by_key(|s| s.seed);
        let l = aggregate(&seeds, budget, 1);
        let missed: Vec<String> = seeds
            .iter()
            .filter(|s| s.evals_to[1].is_none())
            .map(|s| format!("{} ({:.1}%)", s.seed, 100.0 * s.final_regret))
            .collect();
        println!(
            "{}: 1% in {}/{} seeds, median evals {}; missed: {}",
            f.name(),
            l[1].reached,
            l[1].seeds,
            fmt_med(l[1].median_evals),
            if missed.is_empty() {
                "none".into()
            } else {
                missed.join(", ")
            }
        );
    }
    Ok(())
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("run") => run(&args[1..]),
        Some("table") => table(&args[1..]),
        Some("tuned") => tuned(),
        Some("trace") => trace(&args[1..]),
        _ => bail!(
            "usage: graspopt-bo-suite run --engine ours|egobox [--functions a,b] [--seeds N] --out FILE\n       graspopt-bo-suite table [--seeds FIRST-LAST] FILE...\n       graspopt-bo-suite tuned"
        ),
    }
}
