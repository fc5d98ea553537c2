//! `graspopt experiment bo`: the thesis's Bayesian-optimisation experiments (sections 4.6-4.8)
//! in the simulator, over seeds, into a folder of CSV and SVG files with a markdown report:
//!
//! - 4.16-4.17: 1D runs on the sphere and the star prism with the chosen engine (two random
//!   points, stop when EI vanishes): the model that chose each trial (samples, GP mean,
//!   two-sigma band, EI), four of them drawn;
//! - 4.18-4.24: the samples of a 2D run on each object over the grid scan;
//! - Table 4.1: grid size against BO trials, in total (until the engine's stopping rule) and
//!   to within 5/10/20% of the grid maximum, medians over seeds, beside random search and the
//!   thesis's figures;
//! - 4.25-4.27: best so far against trials, BO against random search, mean and spread over
//!   seeds, on every object; and the same in the 6D pose space (no grid in 6D).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use graspopt_bayesopt::{InitialDesign, Method, Settings};
use graspopt_experiment::{
    Comparison, Engine, MethodSummary, SearchSettings, Snapshot, TARGET_FRACTIONS, compare, median,
    run_with_snapshots,
};
use graspopt_sim::ParamKind;
use graspopt_trial::Evaluator;

use super::{argmax, evaluator, scan, touched_grid, write};
use crate::commands::setup::Contacts;
use crate::out::outln;
use graspopt_pictures::chart;

/// Thesis Table 4.1 (total, 5%, 10%, 20%), its rows read as shifted by one line (the text's
/// table starts with an unnamed row and ends with an empty one).
const THESIS_TABLE_4_1: [(&str, [u32; 4]); 7] = [
    ("sphere", [551, 14, 14, 14]),
    ("wine_glass", [306, 31, 19, 19]),
    ("cylinder", [485, 39, 20, 20]),
    ("mug", [331, 55, 55, 1]),
    ("cuboid", [564, 1, 1, 1]),
    ("rotated_cuboid", [388, 59, 59, 59]),
    ("star_prism", [402, 105, 105, 31]),
];

/// Largest accepted values of the size flags (beyond them a run takes hours or the grid does
/// not fit in memory).
const MAX_SEEDS: u64 = 1000;
const MAX_BUDGET: usize = 2000;
const MAX_STEPS: usize = 1000;

#[derive(Args, Debug)]
pub struct BoArgs {
    /// Output folder.
    #[arg(long, default_value = "results/experiment-bo")]
    pub out: PathBuf,
    /// Hand: a built-in name (see `graspopt hands`) or a URDF file.
    #[arg(long, default_value = "barrett")]
    pub hand: String,
    /// Seeds per method and object.
    #[arg(long, default_value_t = 10)]
    pub seeds: u64,
    /// The first seed (seeds run from it upwards).
    #[arg(long, default_value_t = 0)]
    pub first_seed: u64,
    /// Trials per 2D run (the thesis compared over 100).
    #[arg(long, default_value_t = 100)]
    pub budget: usize,
    /// Trials per 6D run.
    #[arg(long, default_value_t = 100)]
    pub budget_6d: usize,
    /// Grid of the 2D reference scan, approach x vertical (the thesis's 2,211 points); one
    /// count is used for both axes, as in `graspopt scan`.
    #[arg(long, default_value = "67,33")]
    pub steps: String,
    /// Objects of the 2D and 6D parts, comma-separated (default: the seven of the thesis);
    /// the 1D part always runs on the sphere and the star prism, as the thesis's figures.
    #[arg(long, value_delimiter = ',')]
    pub objects: Vec<String>,
    /// Parts to run: 1d (figs 4.16-4.17), 2d (4.18-4.27, Table 4.1), 6d.
    #[arg(long, value_delimiter = ',', default_values_t = [Part::OneD, Part::TwoD, Part::SixD])]
    pub parts: Vec<Part>,
    /// The engine's settings: grasp (the thesis's with the misses' scores compressed),
    /// benchmark (tuned on Branin and Hartmann6) or thesis (as written).
    #[arg(long, value_enum, default_value_t = EngineArg::Grasp)]
    pub engine: EngineArg,
    /// Contact model scored.
    #[arg(long, value_enum, default_value_t = Contacts::Surface)]
    pub contacts: Contacts,
    /// Worker threads (0: all cores).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Part {
    #[value(name = "1d")]
    OneD,
    #[value(name = "2d")]
    TwoD,
    #[value(name = "6d")]
    SixD,
}

impl std::fmt::Display for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Part::OneD => "1d",
            Part::TwoD => "2d",
            Part::SixD => "6d",
        })
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum EngineArg {
    Grasp,
    Benchmark,
    Thesis,
}

impl From<EngineArg> for Engine {
    fn from(e: EngineArg) -> Self {
        match e {
            EngineArg::Grasp => Engine::Grasp,
            EngineArg::Benchmark => Engine::Benchmark,
            EngineArg::Thesis => Engine::Thesis,
        }
    }
}

fn method_name(m: Method) -> &'static str {
    match m {
        Method::Bo | Method::BoThesis => "bo",
        Method::Random => "random",
    }
}

/// `star_prism` as a reader writes it: `star prism`.
fn display(object: &str) -> String {
    object.replace('_', " ")
}

/// The evaluator of `object` over `kinds` with the chosen contact model.
fn object_evaluator(
    hand: &str,
    object: &str,
    kinds: &[ParamKind],
    contacts: Contacts,
) -> Result<Evaluator> {
    let mut ev = evaluator(hand, object, kinds)?;
    ev.score.contacts = contacts.into();
    Ok(ev)
}

/// The checked flags of a run.
struct Plan {
    engine: Engine,
    steps: [usize; 2],
    objects: Vec<String>,
    seeds: Vec<u64>,
}

fn plan(args: &BoArgs) -> Result<Plan> {
    if !(1..=MAX_SEEDS).contains(&args.seeds) {
        bail!(
            "--seeds must be between 1 and {MAX_SEEDS}, got {}",
            args.seeds
        );
    }
    let Some(end) = args.first_seed.checked_add(args.seeds) else {
        bail!("--first-seed + --seeds must stay below 2^64");
    };
    let steps: Vec<usize> = args
        .steps
        .split(',')
        .map(|s| s.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--steps {:?}: expected counts like 67,33", args.steps))?;
    let [nx, ny] = match steps[..] {
        [n] => [n, n],
        [nx, ny] => [nx, ny],
        _ => bail!(
            "--steps {:?}: expected one count or two, like 67,33",
            args.steps
        ),
    };
    if ![nx, ny].iter().all(|n| (2..=MAX_STEPS).contains(n)) {
        bail!(
            "--steps {:?}: each count must be between 2 and {MAX_STEPS}",
            args.steps
        );
    }
    // A run no longer than the engine's initial design never uses the model.
    for (flag, budget, dim, part) in [
        ("--budget", args.budget, 2, Part::TwoD),
        ("--budget-6d", args.budget_6d, 6, Part::SixD),
    ] {
        let init = Settings::default_n_init(dim);
        if args.parts.contains(&part) && !(init < budget && budget <= MAX_BUDGET) {
            bail!(
                "{flag} must be more than the engine's {init} initial-design trials in {dim}D and at most {MAX_BUDGET}, got {budget}"
            );
        }
    }
    let mut objects: Vec<String> = Vec::new();
    let named: Vec<String> = if args.objects.is_empty() {
        graspopt_sim::Object::names()
            .into_iter()
            .map(String::from)
            .collect()
    } else {
        args.objects.iter().map(|s| s.trim().to_string()).collect()
    };
    for o in named {
        if o.is_empty() {
            bail!("--objects has an empty name (two commas in a row?)");
        }
        graspopt_sim::Object::by_name(&o)?;
        if !objects.contains(&o) {
            objects.push(o);
        }
    }
    Ok(Plan {
        engine: args.engine.into(),
        steps: [nx, ny],
        objects,
        seeds: (args.first_seed..end).collect(),
    })
}

/// How BO's initial design relates to random search's points, for the report.
fn pairing(settings: &Settings) -> &'static str {
    match settings.initial_design {
        InitialDesign::Random => {
            "for each seed, BO's random initial design draws the same first points as random \
             search, so each seed is a paired comparison."
        }
        InitialDesign::MaximinLatinHypercube { .. } => {
            "BO's initial design is a maximin Latin hypercube (one point in each slice of every \
             axis), random search's points are independent and uniform."
        }
    }
}

pub(super) fn bo(args: &BoArgs) -> Result<()> {
    let plan = plan(args)?;
    let dir = &args.out;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let parts: Vec<String> = args.parts.iter().map(Part::to_string).collect();
    let contacts = format!("{:?}", args.contacts).to_lowercase();
    let mut report = format!(
        "# Bayesian-optimisation experiments (thesis 4.6-4.8)\n\n\
         Regenerated by `graspopt experiment bo --seeds {} --first-seed {} --budget {} --budget-6d {} --steps {},{} \
         --objects {} --parts {} --contacts {contacts} --engine {}`.\n\n\
         Barrett hand, {contacts} contact model without noise (the thesis's 2D runs used mean-point contacts and noisy \
         observations: `--contacts mean`), BW score; a trial that touches nothing scores below every grasp, by how \
         far it missed. Engine settings `{}`; random search is uniform over the same box. Seeds {}-{}: {} \
         \"Within p%\" of a reference means a best score of at least `reference - p |reference|`.\n",
        args.seeds,
        args.first_seed,
        args.budget,
        args.budget_6d,
        plan.steps[0],
        plan.steps[1],
        plan.objects.join(","),
        parts.join(","),
        plan.engine.name(),
        plan.engine.name(),
        args.first_seed,
        args.first_seed + (args.seeds - 1),
        pairing(&plan.engine.settings()),
    );
    let started = std::time::Instant::now();
    if args.parts.contains(&Part::OneD) {
        one_d(dir, args, plan.engine, &mut report)?;
    }
    if args.parts.contains(&Part::TwoD) {
        two_d(dir, args, &plan, &mut report)?;
    }
    if args.parts.contains(&Part::SixD) {
        six_d(dir, args, &plan, &mut report)?;
    }
    let _ = writeln!(
        report,
        "\nWall time: {:.0} s.",
        started.elapsed().as_secs_f64()
    );
    let path = dir.join("report.md");
    std::fs::write(&path, &report).with_context(|| format!("cannot write {}", path.display()))?;
    outln!("{}", path.display())?;
    Ok(())
}

/// Figures 4.16-4.17: a 1D run on the sphere and on the star prism (two random points, stop
/// when EI vanishes), the model that chose each trial, four of them drawn.
fn one_d(dir: &Path, args: &BoArgs, engine: Engine, report: &mut String) -> Result<()> {
    report.push_str(
        "\n## Figures 4.16-4.17: 1D runs along the approach axis (2 random points, stop when EI vanishes)\n\n\
         Each figure shows the model that chose the next trial (green line): posterior mean and two-sigma band \
         (red), the samples so far (dots), the score along a 201-point scan (grey, misses left out) and, below, the \
         expected improvement the engine maximised (its own standardised units).\n\n\
         | object | trials until the engine stopped | best found | scan maximum | files |\n|---|---|---|---|---|\n",
    );
    for (fig, object) in [("4.16", "sphere"), ("4.17", "star_prism")] {
        let ev = object_evaluator(&args.hand, object, &[ParamKind::Approach], args.contacts)?;
        let (_, truth) = scan(&ev, &[201], args.threads)?;
        let settings = SearchSettings {
            method: Method::Bo,
            budget: 40,
            n_init: Some(2),
            stop_on_small_ei: true,
            engine: Some(engine.settings()),
            workers: 1,
        };
        let (trace, snaps) = run_with_snapshots(&ev, &settings, args.first_seed, 201)?;
        let mut csv = String::from("trials,approach,mean,sd,ei\n");
        for s in &snaps {
            for i in 0..s.grid.len() {
                let _ = writeln!(
                    csv,
                    "{},{},{},{},{}",
                    s.trials, s.grid[i], s.mean[i], s.sd[i], s.ei[i]
                );
            }
        }
        let mut files = vec![write(dir, &format!("fig{fig}-{object}-model.csv"), &csv)?];
        let mut samples_csv = String::from("trial,approach,score,ei_when_chosen\n");
        for (i, (p, y)) in trace.params.iter().zip(&trace.scores).enumerate() {
            let ei = snaps
                .iter()
                .find(|s| s.trials == i)
                .map_or(String::new(), |s| s.next_ei.to_string());
            let _ = writeln!(samples_csv, "{},{},{y},{ei}", i + 1, p[0]);
        }
        files.push(write(
            dir,
            &format!("fig{fig}-{object}-samples.csv"),
            &samples_csv,
        )?);
        let truth_scores: Vec<f64> = truth
            .iter()
            .map(crate::commands::scan::touched_score)
            .collect();
        for snap in pick_four(&snaps) {
            let samples: Vec<(f64, f64)> = trace.params[..snap.trials]
                .iter()
                .zip(&trace.scores)
                .map(|(p, y)| (p[0], *y))
                .collect();
            let title = format!(
                "Fig. {fig}: {}, model after {} trials",
                display(object),
                snap.trials
            );
            files.push(write(
                dir,
                &format!("fig{fig}-{object}-after-{:02}.svg", snap.trials),
                &chart::model_plot(&chart::ModelPlot {
                    title: &title,
                    xlabel: "approach offset (m)",
                    xs: &snap.grid,
                    mean: &snap.mean,
                    sd: &snap.sd,
                    ei: &snap.ei,
                    truth: Some(&truth_scores),
                    samples: &samples,
                    next: Some(snap.next),
                }),
            )?);
        }
        let best = trace.best().map_or(f64::NAN, |b| b.1);
        let top = argmax(&truth);
        let _ = writeln!(
            report,
            "| {} | {}{} | {best:.4} | {:.4} at {:.3} m | {} |",
            display(object),
            trace.scores.len(),
            if trace.ei_stop_at.is_some() {
                ""
            } else {
                " (budget)"
            },
            top.score.score,
            top.params[0],
            files.join(", ")
        );
    }
    Ok(())
}

/// Four snapshots like the thesis's panels: the first model, two steps later, halfway, last.
fn pick_four(snaps: &[Snapshot]) -> Vec<&Snapshot> {
    let n = snaps.len();
    let mut idx = vec![0, 2.min(n.saturating_sub(1)), n / 2, n.saturating_sub(1)];
    idx.sort_unstable();
    idx.dedup();
    idx.into_iter().filter_map(|i| snaps.get(i)).collect()
}

/// A median trial count with the seeds that got there ("-" unless more than half did).
fn fmt_median(m: Option<f64>, reached: usize, seeds: usize) -> String {
    match m {
        Some(v) => format!("{v} ({reached}/{seeds})"),
        None => format!("- ({reached}/{seeds})"),
    }
}

/// Writes the per-seed counts and the mean/spread curves of a comparison, and its plot.
fn comparison_files(
    dir: &Path,
    stem: &str,
    title: &str,
    cmp: &Comparison,
    reference_label: &str,
) -> Result<Vec<String>> {
    let mut csv = String::from(
        "method,seed,trials_to_5pct,trials_to_10pct,trials_to_20pct,ei_stop_at,best\n",
    );
    for m in &cmp.methods {
        for (t, counts) in m.traces.iter().zip(&m.trials_to) {
            let c = counts.map(|c| c.map_or(String::new(), |n| n.to_string()));
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{}",
                method_name(m.method),
                t.seed,
                c[0],
                c[1],
                c[2],
                t.ei_stop_at.map_or(String::new(), |n| n.to_string()),
                t.best().map_or(f64::NAN, |b| b.1)
            );
        }
    }
    let mut files = vec![write(dir, &format!("{stem}-seeds.csv"), &csv)?];
    let mut curves = String::from("method,trial,mean_best,std_best,min_best,max_best\n");
    for m in &cmp.methods {
        for i in 0..m.mean_best.len() {
            let _ = writeln!(
                curves,
                "{},{},{},{},{},{}",
                method_name(m.method),
                i + 1,
                m.mean_best[i],
                m.std_best[i],
                m.min_best[i],
                m.max_best[i]
            );
        }
    }
    files.push(write(dir, &format!("{stem}-curves.csv"), &curves)?);
    let xs: Vec<f64> = (1..=cmp.budget).map(|i| i as f64).collect();
    let series: Vec<(&str, Vec<f64>)> = cmp
        .methods
        .iter()
        .map(|m| (method_name(m.method), m.mean_best.clone()))
        .collect();
    let bands: Vec<(Vec<f64>, Vec<f64>)> = cmp
        .methods
        .iter()
        .map(|m| {
            let spread = |sign: f64| -> Vec<f64> {
                m.mean_best
                    .iter()
                    .zip(&m.std_best)
                    .map(|(a, s)| a + sign * s)
                    .collect()
            };
            (spread(-1.0), spread(1.0))
        })
        .collect();
    files.push(write(
        dir,
        &format!("{stem}.svg"),
        &chart::bands_plot(
            title,
            "trial",
            "best score so far (mean, 1 sd band)",
            &xs,
            &series,
            &bands,
            Some((cmp.reference, reference_label)),
        ),
    )?);
    Ok(files)
}

fn summary(cmp: &Comparison, method: Method) -> Result<&MethodSummary> {
    cmp.methods
        .iter()
        .find(|m| m.method == method)
        .with_context(|| format!("no runs of {}", method_name(method)))
}

/// Runs BO (with `engine`) and random search over `seeds` on `ev`.
fn bo_and_random(
    ev: &Evaluator,
    engine: Engine,
    budget: usize,
    seeds: &[u64],
    reference: Option<f64>,
    threads: usize,
) -> Result<Comparison> {
    let template = SearchSettings {
        method: Method::Bo,
        budget,
        n_init: None,
        stop_on_small_ei: false,
        engine: Some(engine.settings()),
        workers: 1,
    };
    Ok(compare(
        ev,
        &[Method::Bo, Method::Random],
        seeds,
        &template,
        reference,
        threads,
    )?)
}

/// Figures 4.18-4.27 and Table 4.1 on every object in 2D.
fn two_d(dir: &Path, args: &BoArgs, plan: &Plan, report: &mut String) -> Result<()> {
    let seeds = &plan.seeds;
    let grid_size = plan.steps[0] * plan.steps[1];
    let mut table = format!(
        "\n## Table 4.1: grid size versus BO trials (approach x vertical, medians over {} seeds)\n\n\
         BO total: trials until the engine's stopping rule (EI vanished) fired, the seeds where it fired within the \
         budget of {} in brackets (the others count as the budget). 5/10/20%: trials to within that much of the grid \
         maximum, the seeds that got there in brackets; a seed that never did counts as budget + 1, and \"-\" means \
         no more than half got there. The runs go on to the budget after the stop, so a count can exceed the total. \
         Thesis: its Table 4.1 (one run each, its own simulator).\n\n\
         | object | grid | grid max | BO total | BO 5% | BO 10% | BO 20% | random 5% | random 10% | random 20% | BO best (median) | thesis total / 5% / 10% / 20% |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
        seeds.len(),
        args.budget
    );
    let mut maps = String::from(
        "\n## Figures 4.18-4.24: 2D samples of the first seed over the grid scan\n\n\
         The thesis draws BO's samples as a surface; here they are dots (coloured by score, the best ringed) over \
         the grid scan, so one sees where BO looked against what was there.\n\n\
         | object | samples (until the stop or the budget) | best sample | file |\n|---|---|---|---|\n",
    );
    let mut curves = String::from(
        "\n## Figures 4.25-4.27: best so far versus trial, BO versus random (mean and 1 sd over seeds; every object)\n\n\
         | object | files |\n|---|---|\n",
    );
    let kinds = [ParamKind::Approach, ParamKind::Vertical];
    for object in &plan.objects {
        let name = display(object);
        let ev = object_evaluator(&args.hand, object, &kinds, args.contacts)?;
        let (axes, grid) = scan(&ev, &plan.steps, args.threads)?;
        let reference = argmax(&grid).score.score;
        let cmp = bo_and_random(
            &ev,
            plan.engine,
            args.budget,
            seeds,
            Some(reference),
            args.threads,
        )?;
        let bo = summary(&cmp, Method::Bo)?;
        let random = summary(&cmp, Method::Random)?;
        let totals: Vec<f64> = bo
            .traces
            .iter()
            .map(|t| t.ei_stop_at.unwrap_or(args.budget) as f64)
            .collect();
        let stopped = bo.traces.iter().filter(|t| t.ei_stop_at.is_some()).count();
        let finals: Vec<f64> = bo
            .traces
            .iter()
            .map(|t| t.best().map_or(f64::NAN, |b| b.1))
            .collect();
        let cells = |m: &MethodSummary| -> Vec<String> {
            (0..TARGET_FRACTIONS.len())
                .map(|k| fmt_median(m.median_trials_to[k], m.reached[k], seeds.len()))
                .collect()
        };
        let (b, r) = (cells(bo), cells(random));
        let thesis = THESIS_TABLE_4_1
            .iter()
            .find(|(o, _)| o == object)
            .map_or("-".to_string(), |(_, v)| {
                format!("{} / {} / {} / {}", v[0], v[1], v[2], v[3])
            });
        let _ = writeln!(
            table,
            "| {name} | {grid_size} | {reference:.4} | {} ({stopped}/{}) | {} | {} | {} | {} | {} | {} | {:.4} | {thesis} |",
            median(&totals).unwrap_or(f64::NAN),
            seeds.len(),
            b[0],
            b[1],
            b[2],
            r[0],
            r[1],
            r[2],
            median(&finals).unwrap_or(f64::NAN)
        );
        let first = bo.traces.first().context("no BO run")?;
        let shown = first.ei_stop_at.unwrap_or(first.scores.len());
        let samples: Vec<(f64, f64, f64)> = first.params[..shown]
            .iter()
            .zip(&first.scores)
            .map(|(p, y)| (p[0], p[1], *y))
            .collect();
        let map = write(
            dir,
            &format!("fig4.18-4.24-{object}-samples.svg"),
            &chart::samples_map(
                &format!(
                    "BO samples on the {name} (seed {}, {shown} trials)",
                    first.seed
                ),
                "approach offset (m)",
                "vertical offset (m)",
                (&axes[0], &axes[1], &touched_grid(&axes, &grid)),
                &samples,
            ),
        )?;
        let top = samples
            .iter()
            .map(|s| s.2)
            .fold(f64::NEG_INFINITY, f64::max);
        let _ = writeln!(maps, "| {name} | {shown} | {top:.4} | {map} |");
        let files = comparison_files(
            dir,
            &format!("fig4.25-4.27-{object}-bo-vs-random"),
            &format!(
                "Best so far on the {name}: BO ({}) vs random",
                plan.engine.name()
            ),
            &cmp,
            "grid maximum",
        )?;
        let _ = writeln!(curves, "| {name} | {} |", files.join(", "));
        eprintln!("2d {object}: done");
    }
    report.push_str(&table);
    report.push_str(&maps);
    report.push_str(&curves);
    Ok(())
}

/// BO versus random in the 6D pose space (three offsets, three rotations) on every object.
fn six_d(dir: &Path, args: &BoArgs, plan: &Plan, report: &mut String) -> Result<()> {
    let seeds = &plan.seeds;
    let checkpoints: Vec<usize> = [25, 50, args.budget_6d]
        .into_iter()
        .filter(|&n| n <= args.budget_6d)
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    let listed: Vec<String> = checkpoints.iter().map(usize::to_string).collect();
    let columns = listed.join(" / ");
    let _ = writeln!(
        report,
        "\n## 6D pose space: BO versus random (offsets and rotation vector, budget {}, {} seeds)\n\n\
         No grid in 6D: the median over seeds of the best score after {} trials, and the trials to within 20% \
         of the best score any run of either method found (the seeds that got there in brackets).\n\n\
         | object | best of all runs | BO median best after {columns} | random median best after {columns} | BO 20% | random 20% | files |\n\
         |---|---|---|---|---|---|---|",
        args.budget_6d,
        seeds.len(),
        listed.join(", ")
    );
    let kinds = [
        ParamKind::Approach,
        ParamKind::Lateral,
        ParamKind::Vertical,
        ParamKind::RotX,
        ParamKind::RotY,
        ParamKind::RotZ,
    ];
    for object in &plan.objects {
        let name = display(object);
        let ev = object_evaluator(&args.hand, object, &kinds, args.contacts)?;
        let cmp = bo_and_random(&ev, plan.engine, args.budget_6d, seeds, None, args.threads)?;
        let medians_at = |m: &MethodSummary| -> String {
            let curves: Vec<Vec<f64>> = m.traces.iter().map(|t| t.best_so_far()).collect();
            checkpoints
                .iter()
                .map(|&n| {
                    let v: Vec<f64> = curves
                        .iter()
                        .filter_map(|c| c.get(n - 1).copied())
                        .collect();
                    format!("{:.4}", median(&v).unwrap_or(f64::NAN))
                })
                .collect::<Vec<_>>()
                .join(" / ")
        };
        let bo = summary(&cmp, Method::Bo)?;
        let random = summary(&cmp, Method::Random)?;
        let twenty =
            |m: &MethodSummary| fmt_median(m.median_trials_to[2], m.reached[2], seeds.len());
        let files = comparison_files(
            dir,
            &format!("6d-{object}-bo-vs-random"),
            &format!(
                "6D, best so far on the {name}: BO ({}) vs random",
                plan.engine.name()
            ),
            &cmp,
            "best of all runs",
        )?;
        let _ = writeln!(
            report,
            "| {name} | {:.4} | {} | {} | {} | {} | {} |",
            cmp.reference,
            medians_at(bo),
            medians_at(random),
            twenty(bo),
            twenty(random),
            files.join(", ")
        );
        eprintln!("6d {object}: done");
    }
    Ok(())
}
