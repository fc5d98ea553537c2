//! How much the contact computation's one setting (`CloudSettings::resolution`) moves the
//! scores, and how often force closure flips along the star prism's approach axis.
//!
//! `cargo run --release -p graspopt-trial --features tools --example contact_convergence -- convergence [R]`:
//! for each of the seven objects, the 67 x 33 approach-vertical grid (Barrett hand, default
//! scoring) at resolution `R` (default: the default resolution) and at `R / 2`, then the 95th
//! percentile and the maximum of `|BW(R) - BW(R/2)| / |BW(R/2)|` over the grid.
//!
//! `cargo run --release -p graspopt-trial --features tools --example contact_convergence -- flips [N] [R]`: the
//! star prism's approach scan of `N` points (default 721) at resolution `R`: how many times
//! force closure changes from one point to the next.

use graspopt_sim::contact::DEFAULT_RESOLUTION;
use graspopt_sim::{BarrettOracle, Object, TrialSpace};
use graspopt_trial::Evaluator;
use graspopt_trial::scan::{ScanPoint, grid_axes, scan_grid};

fn scan(object: &str, space_2d: bool, steps: &[usize], resolution: f64) -> Vec<ScanPoint> {
    let object = Object::by_name(object).expect("a built-in object");
    let space = if space_2d {
        TrialSpace::approach_vertical_2d(&object)
    } else {
        TrialSpace::approach_1d(&object)
    };
    let mut ev = Evaluator::new(object, Box::new(BarrettOracle::default()), space);
    ev.contacts.cloud.resolution = resolution;
    let axes = grid_axes(&ev.space.bounds(), steps);
    scan_grid(&ev, &axes, 0, &|_| {}).expect("the scan runs")
}

fn bw(p: &ScanPoint) -> f64 {
    p.score.metrics.map_or(p.score.score, |m| m.bw())
}

fn closure(p: &ScanPoint) -> bool {
    p.score.metrics.is_some_and(|m| m.force_closure())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mode = args.first().map_or("convergence", String::as_str);
    let number = |i: usize, default: f64| -> f64 {
        args.get(i)
            .map_or(default, |s| s.parse().expect("a number"))
    };
    match mode {
        "flips" => {
            let n = number(1, 721.0) as usize;
            let r = number(2, DEFAULT_RESOLUTION);
            let points = scan("star_prism", false, &[n], r);
            let flips = points
                .windows(2)
                .filter(|w| closure(&w[0]) != closure(&w[1]))
                .count();
            let fc = points.iter().filter(|p| closure(p)).count();
            println!(
                "star_prism approach scan, {n} points, resolution {r:e} m: {flips} flips of force closure, {fc} points with force closure"
            );
        }
        "flips2d" => {
            let (nx, ny) = (number(1, 721.0) as usize, number(2, 121.0) as usize);
            let r = number(3, DEFAULT_RESOLUTION);
            let points = scan("star_prism", true, &[nx, ny], r);
            // Points come with the last axis (vertical) fastest: row j of approach values.
            let mut flips = 0;
            let mut gaps = std::collections::BTreeMap::new();
            for j in 0..ny {
                let row: Vec<bool> = (0..nx).map(|i| closure(&points[i * ny + j])).collect();
                let at: Vec<usize> = (1..nx).filter(|&i| row[i] != row[i - 1]).collect();
                flips += at.len();
                for w in at.windows(3) {
                    *gaps.entry(w[2] - w[0]).or_insert(0usize) += 1;
                }
            }
            let mut common: Vec<(usize, usize)> = gaps.into_iter().map(|(g, n)| (n, g)).collect();
            common.sort_unstable_by(|a, b| b.cmp(a));
            println!(
                "star_prism {nx} x {ny}, resolution {r:e} m: {flips} flips of force closure along the approach axis; most common spacings between every other flip, i.e. periods (grid steps: count): {:?}",
                &common[..common.len().min(5)]
                    .iter()
                    .map(|(n, g)| (*g, *n))
                    .collect::<Vec<_>>()
            );
        }
        _ => {
            let r = number(1, DEFAULT_RESOLUTION);
            println!("| object | p95 relative BW change | max | force closure differs |");
            println!("|---|---|---|---|");
            for name in Object::names() {
                let a = scan(name, true, &[67, 33], r);
                let b = scan(name, true, &[67, 33], r / 2.0);
                let mut rel: Vec<f64> = a
                    .iter()
                    .zip(&b)
                    .map(|(x, y)| (bw(x) - bw(y)).abs() / bw(y).abs().max(1e-12))
                    .collect();
                rel.sort_by(f64::total_cmp);
                let p95 = rel[((rel.len() as f64) * 0.95).ceil() as usize - 1];
                let max = rel[rel.len() - 1];
                let fc = a
                    .iter()
                    .zip(&b)
                    .filter(|(x, y)| closure(x) != closure(y))
                    .count();
                println!("| {name} | {p95:.1e} | {max:.1e} | {fc} of {} |", a.len());
            }
        }
    }
}
