//! `graspopt scan --object sphere --axes x,y --steps 41,41`: a grid scan of a metric over
//! one or two trial parameters (any number for the CSV), in parallel over cores, with a
//! progress bar. Writes `<out>/<object>-<metric>-<axes>.csv`, and images for one axis (an
//! SVG line plot) or two (an SVG and a PNG heatmap); three or more axes write the CSV only,
//! with a note. Grids hold at most [`MAX_GRID_POINTS`] points.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Args;
use graspopt_trial::scan::{ScanPoint, grid_axes, scan_grid, worker_count};
use indicatif::{ProgressBar, ProgressStyle};

use super::setup::{SimArgs, param_kind};
use crate::out::outln;
use graspopt_pictures::chart;

/// The most points a grid (`--steps` multiplied over the axes) may hold.
pub const MAX_GRID_POINTS: usize = 10_000_000;

#[derive(Args, Debug)]
#[command(
    after_help = "Writes <out>/<object>-<metric>-<axes>.csv for any number of axes, and images for \
                  1 axis (an SVG line plot) or 2 axes (an SVG and a PNG heatmap); 3 or more axes \
                  write the CSV only. A grid holds at most 10,000,000 points."
)]
pub struct ScanArgs {
    #[command(flatten)]
    pub sim: SimArgs,
    /// Parameters to scan, comma separated: x (approach), y (vertical), lateral, rx, ry, rz
    /// (images for 1 or 2 axes only; more axes write the CSV alone).
    #[arg(long, visible_alias = "params", default_value = "x")]
    pub axes: String,
    /// Grid points per axis, comma separated (one value applies to every axis); at most
    /// 10,000,000 points in all.
    #[arg(long, default_value = "41")]
    pub steps: String,
    /// Output folder.
    #[arg(long, default_value = "results/scan")]
    pub out: PathBuf,
    /// Worker threads (0: all cores).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
}

/// A grid of trials: the evaluator, the parameters, points per axis and the axes' values.
pub struct Grid {
    pub ev: graspopt_trial::Evaluator,
    pub kinds: Vec<graspopt_sim::ParamKind>,
    pub steps: Vec<usize>,
    pub axes: Vec<Vec<f64>>,
}

/// The grid of `--axes` and `--steps` (shared with `graspopt record`).
pub fn grid(sim: &SimArgs, axes: &str, steps: &str) -> Result<Grid> {
    let steps_text = steps;
    let kinds = axes
        .split(',')
        .map(param_kind)
        .collect::<Result<Vec<_>>>()?;
    let steps: Vec<usize> = steps
        .split(',')
        .map(|s| {
            s.trim()
                .parse::<usize>()
                .ok()
                .filter(|&n| n >= 1)
                .with_context(|| format!("--steps: expected whole numbers >= 1, got {s:?}"))
        })
        .collect::<Result<_>>()?;
    let steps = match steps.len() {
        1 => vec![steps[0]; kinds.len()],
        n if n == kinds.len() => steps,
        n => bail!("--steps has {n} values for {} axes", kinds.len()),
    };
    let total = grid_points(&steps)?;
    if total > MAX_GRID_POINTS {
        bail!(
            "--steps {}: a grid of {total} points is more than the {MAX_GRID_POINTS} allowed; \
             use fewer steps or axes",
            steps_text.trim()
        );
    }
    let ev = sim.evaluator(&kinds)?;
    let axes = grid_axes(&ev.space.bounds(), &steps);
    Ok(Grid {
        ev,
        kinds,
        steps,
        axes,
    })
}

/// Points of a grid with `steps[k]` points on axis `k`; errors (naming `--steps`) when the
/// product does not fit in a `usize`.
pub fn grid_points(steps: &[usize]) -> Result<usize> {
    steps
        .iter()
        .try_fold(1usize, |acc, &n| acc.checked_mul(n))
        .with_context(|| {
            let list: Vec<String> = steps.iter().map(usize::to_string).collect();
            format!(
                "--steps {}: the grid has more points than can be counted (at most {MAX_GRID_POINTS} allowed)",
                list.join(",")
            )
        })
}

pub fn run(args: &ScanArgs) -> Result<std::process::ExitCode> {
    let Grid {
        ev,
        kinds,
        steps,
        axes,
    } = grid(&args.sim, &args.axes, &args.steps)?;
    let total: usize = steps.iter().product();
    let bar = ProgressBar::new(total as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} trials  {per_sec}  eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let started = Instant::now();
    let points = scan_grid(&ev, &axes, args.threads, &|_| bar.inc(1))?;
    bar.finish_and_clear();
    let elapsed = started.elapsed();

    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let names: Vec<&str> = kinds.iter().map(|k| k.name()).collect();
    let stem = format!(
        "{}-{}-{}",
        ev.object.name(),
        args.sim.metric,
        names.join("-")
    );
    let csv_path = args.out.join(format!("{stem}.csv"));
    std::fs::write(&csv_path, csv(&names, &points))
        .with_context(|| format!("cannot write {}", csv_path.display()))?;
    let title = format!(
        "{} on the {} ({} contacts)",
        args.sim.metric.name().to_uppercase(),
        ev.object.name(),
        ev.score.contacts
    );
    let mut extra = Vec::new();
    let chart = match axes.len() {
        1 => Some(chart::line_plot(
            &title,
            &format!("{} offset (m)", names[0]),
            args.sim.metric.name(),
            &axes[0],
            &points.iter().map(|p| p.score.score).collect::<Vec<_>>(),
        )),
        2 => {
            let z: Vec<Vec<f64>> = (0..axes[0].len())
                .map(|i| {
                    (0..axes[1].len())
                        .map(|j| touched_score(&points[i * axes[1].len() + j]))
                        .collect()
                })
                .collect();
            let png_path = args.out.join(format!("{stem}.png"));
            graspopt_pictures::preview::heatmap_figure(&z, 8, &title, chart::MISSING_LABEL)
                .save_png(&png_path)?;
            extra.push(png_path.display().to_string());
            Some(chart::heatmap(
                &title,
                &format!("{} offset (m)", names[0]),
                &format!("{} offset (m)", names[1]),
                &axes[0],
                &axes[1],
                &z,
            ))
        }
        n => {
            eprintln!(
                "note: no image for a {n}-axis scan (images are drawn for 1 or 2 axes); the CSV holds every point"
            );
            None
        }
    };
    let mut written = vec![csv_path.display().to_string()];
    if let Some(chart) = chart {
        let svg_path = args.out.join(format!("{stem}.svg"));
        std::fs::write(&svg_path, chart)
            .with_context(|| format!("cannot write {}", svg_path.display()))?;
        written.push(svg_path.display().to_string());
    }
    written.extend(extra);
    let best = points
        .iter()
        .max_by(|a, b| a.score.score.total_cmp(&b.score.score))
        .context("empty scan")?;
    let closed = points
        .iter()
        .filter(|p| p.score.metrics.is_some_and(|m| m.force_closure))
        .count();
    eprintln!(
        "{total} trials in {:.2} s ({:.2} ms per trial per thread); force closure in {closed}; best {} {:.6} at {:?}",
        elapsed.as_secs_f64(),
        elapsed.as_secs_f64() * 1e3 * worker_count(args.threads, total) as f64 / total as f64,
        args.sim.metric,
        best.score.score,
        best.params
    );
    for w in written {
        outln!("{w}")?;
    }
    Ok(std::process::ExitCode::SUCCESS)
}

/// The score for a map: NaN where the hand touched nothing, so the colour scale spans
/// the touching grasps (the CSV keeps the defined no-contact score).
pub fn touched_score(p: &ScanPoint) -> f64 {
    if p.score.contacts == 0 {
        f64::NAN
    } else {
        p.score.score
    }
}

fn csv(names: &[&str], points: &[ScanPoint]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{},score,force_closure,epsilon,distance,contacts,fingers_in_contact",
        names.join(",")
    );
    for p in points {
        for v in &p.params {
            let _ = write!(out, "{v},");
        }
        // A grasp that touched nothing has no metrics: empty fields, as in trials.csv.
        let metrics = p.score.metrics.map_or_else(
            || ",,".to_string(),
            |m| format!("{},{},{}", m.force_closure, m.epsilon, m.distance),
        );
        let _ = writeln!(
            out,
            "{},{metrics},{},{}",
            p.score.score, p.score.contacts, p.score.fingers_in_contact
        );
    }
    out
}
