//! Where the force analysis gives no answer (issue 29): analyses the forces of many trials of
//! a built-in object (Barrett hand, default scoring, the default run's parameters `x,y`:
//! approach and vertical) for several object masses, and prints each trial whose least
//! resisting forces are unavailable, with its parameters in full precision.
//!
//! `cargo run -p graspopt-trial --features tools --example force_failures -- OBJECT NX NY
//! [RANDOM] [MASSES...]`: an `NX x NY` grid, then `RANDOM` uniform random points (seed 29,
//! default 0), each for each mass (default 0.5 kg).
//!
//! `... --example force_failures -- --cases < FILE`: the trials listed in FILE, one a line,
//! `OBJECT X Y MASS` (as the grid mode prints them, e.g. to measure how many of them a change
//! to the solver rescues).

use graspopt_quality::forces::Resisting;
use graspopt_sim::ParamKind;
use graspopt_trial::forces::{ForceSettings, analyse_outcome};
use graspopt_trial::scan::grid_axes;
use graspopt_trial::{Evaluator, TrialSettings};
use rand::{RngExt, SeedableRng};

fn evaluator(object: &str) -> Evaluator {
    let settings = TrialSettings {
        object: object.to_string(),
        ..TrialSettings::default()
    };
    Evaluator::from_settings(&settings, &[ParamKind::Approach, ParamKind::Vertical])
        .expect("an evaluator")
}

/// Analyses the trial at `p` for each mass; prints and counts the unavailable analyses.
/// Returns (analysed, unavailable).
fn analyse(ev: &Evaluator, object: &str, p: &[f64], masses: &[f64]) -> (usize, usize) {
    let Ok(e) = ev.evaluate(p) else {
        return (0, 0);
    };
    let mut unavailable = 0;
    for &mass in masses {
        let f = ForceSettings {
            object_mass: mass,
            ..ForceSettings::default()
        };
        let why = match analyse_outcome(&e.outcome, &ev.object, &ev.score, &f) {
            Ok(g) => match g.resisting {
                Resisting::Unavailable { reason } => reason,
                _ => continue,
            },
            Err(e) => e.to_string(),
        };
        unavailable += 1;
        println!(
            "{object} x={:?},y={:?} mass {mass}: contacts {} score {}: {why}",
            p[0], p[1], e.score.contacts, e.score.score
        );
    }
    (masses.len(), unavailable)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--cases") {
        let (mut analysed, mut unavailable) = (0, 0);
        for line in std::io::stdin().lines() {
            let line = line.expect("a line of the cases");
            let w: Vec<&str> = line.split_whitespace().collect();
            let [object, x, y, mass] = w[..] else {
                continue;
            };
            let num = |s: &str| s.parse::<f64>().expect("a number");
            let (a, u) = analyse(&evaluator(object), object, &[num(x), num(y)], &[num(mass)]);
            analysed += a;
            unavailable += u;
        }
        println!("cases: {unavailable} of {analysed} analyses unavailable");
        return;
    }
    let object = args.first().cloned().unwrap_or_else(|| "mug".into());
    let nx: usize = args.get(1).map_or(67, |s| s.parse().expect("NX"));
    let ny: usize = args.get(2).map_or(33, |s| s.parse().expect("NY"));
    let random: usize = args.get(3).map_or(0, |s| s.parse().expect("RANDOM"));
    let masses: Vec<f64> = if args.len() > 4 {
        args[4..]
            .iter()
            .map(|s| s.parse().expect("a mass"))
            .collect()
    } else {
        vec![0.5]
    };
    let ev = evaluator(&object);
    let axes = grid_axes(&ev.space.bounds(), &[nx, ny]);
    let mut points: Vec<Vec<f64>> = axes[0]
        .iter()
        .flat_map(|&x| axes[1].iter().map(move |&y| vec![x, y]))
        .collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(29);
    let bounds = ev.space.bounds();
    for _ in 0..random {
        points.push(
            bounds
                .iter()
                .map(|&(l, u)| rng.random_range(l..=u))
                .collect(),
        );
    }
    let (mut analysed, mut unavailable) = (0, 0);
    for p in &points {
        let (a, u) = analyse(&ev, &object, p, &masses);
        analysed += a;
        unavailable += u;
    }
    println!("{object}: {unavailable} of {analysed} analyses unavailable");
}
