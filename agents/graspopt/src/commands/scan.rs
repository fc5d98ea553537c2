//! `graspopt scan --object sphere --axes x,y --steps 41,41`: a grid scan of a metric over
//! one or two trial parameters (any number for the CSV), in parallel over cores, with a
//! progress bar. Writes `<out>/<object>-<metric>-<axes>.csv`, and images for one axis (an
//! SVG and a PNG line plot) or two (an SVG and a PNG heatmap); three or more axes write the
//! CSV only, with a note. Grids hold at most `graspopt_trial::scan::MAX_GRID_POINTS` points;
//! the files are written by `graspopt_report::scan`.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use graspopt_sim::ParamKind;
use graspopt_trial::scan::{Grid, grid_steps, scan_grid, worker_count};
use indicatif::{ProgressBar, ProgressStyle};

use super::setup::{SimArgs, count};
use crate::out::outln;

#[derive(Args, Debug)]
#[command(
    after_help = "Writes <out>/<object>-<metric>-<axes>.csv for any number of axes, and images for \
                  1 axis (an SVG and a PNG line plot) or 2 axes (an SVG and a PNG heatmap); 3 or \
                  more axes write the CSV only. A grid holds at most 10,000,000 points."
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
    #[arg(long, default_value_t = 0, value_parser = count::<usize>(0, u64::MAX))]
    pub threads: usize,
}

/// The grid of `--axes` and `--steps` (shared with `graspopt record`).
pub fn grid(sim: &SimArgs, axes: &str, steps: &str) -> Result<Grid> {
    let kinds = axes
        .split(',')
        .map(ParamKind::parse)
        .collect::<Result<Vec<_>, _>>()?;
    let steps = grid_steps(steps, kinds.len())?;
    let ev = sim.evaluator(&kinds)?;
    Ok(Grid::new(ev, kinds, steps))
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

    let written = graspopt_report::scan::write_scan(
        &args.out,
        &ev,
        args.sim.metric.name(),
        &kinds,
        &axes,
        &points,
    )?;
    if axes.len() > 2 {
        eprintln!(
            "note: no image for a {}-axis scan (images are drawn for 1 or 2 axes); the CSV holds every point",
            axes.len()
        );
    }
    let best = points
        .iter()
        .max_by(|a, b| a.score.score.total_cmp(&b.score.score))
        .context("empty scan")?;
    let closed = points
        .iter()
        .filter(|p| p.score.metrics.is_some_and(|m| m.force_closure()))
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
        outln!("{}", w.display())?;
    }
    Ok(std::process::ExitCode::SUCCESS)
}
