//! Tries engine settings on the 2D grasp landscapes of the built-in objects: per variant, the
//! median trials to within 5% of the grid maximum (67 x 33 grid) over seeds. This is how the
//! `grasp` engine was chosen (docs/benchmarks.md).
//!
//! `[OBJECTS=a,b] [SEED0=n] cargo run --release -p graspopt-experiment --features tools --example tune -- SEEDS BUDGET VARIANT...`
//! with variants `random`, `thesis`, `benchmark`, `grasp` and `grasp-` followed by one change:
//! `rank`, `xi0`, `init3`, `init8`, `m52`, `pm` (pessimistic prior mean), `m52-pm`, `noise`
//! (noise prior 100x larger), `ls01` (length-scale prior 0.1), `ucb`, `explore`, `restart`,
//! `uniform` (uniform initial design instead of the Latin hypercube), `qei` (sequential-greedy
//! qEI with 128 base samples for the pending trials instead of the kriging believer).
//!
//! `WORKERS=W` runs W asynchronous workers instead of one trial at a time
//! ([`SearchSettings::workers`]): each proposal sees the other trials in flight as pending,
//! and trials count in completion order. `WORKERS=1` is the sequential search.
//! `PER_SEED=1` also prints, per object, the trials to 5% of every seed (`-`: never).

use graspopt_bayesopt::benchmark::recommended_settings;
use std::time::Instant;

use graspopt_bayesopt::{
    AcquisitionKind, BatchStrategy, InitialDesign, KernelKind, Method, OutputTransform, Preset,
    Settings, XiRule,
};
use graspopt_experiment::{SearchSettings, compare};
use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{Object, TrialSpace};
use graspopt_trial::Evaluator;
use graspopt_trial::scan::{grid_axes, scan_grid};

fn variant(name: &str) -> Option<Settings> {
    let grasp = Settings::for_grasps();
    let mut s = match name {
        "random" | "thesis" => return Some(Settings::default()),
        "benchmark" => return Some(recommended_settings()),
        "grasp" => return Some(grasp),
        _ => grasp.clone(),
    };
    match name.strip_prefix("grasp-")? {
        "rank" => s.output_transform = OutputTransform::Rank,
        "xi0" => s.xi = XiRule::Fixed(0.0),
        "init3" => s.n_init = Some(3),
        "init8" => s.n_init = Some(8),
        "m52" => s.kernel = KernelKind::Matern52,
        "pm" => s.prior_mean_quantile = Some(0.0),
        "m52-pm" => {
            s.kernel = KernelKind::Matern52;
            s.prior_mean_quantile = Some(0.0);
        }
        "noise" => s.fit.noise_log_mean = 1e-2f64.ln(),
        "ls01" => s.fit.length_scale_log_mean = 0.1f64.ln(),
        "ucb" => s.acquisition = AcquisitionKind::Ucb { beta: 4.0 },
        "explore" => s.explore_below_ei = Some(1e-3),
        "restart" => s.restart = recommended_settings().restart,
        "uniform" => s.initial_design = InitialDesign::Random,
        "qei" => s.batch = BatchStrategy::Qei { samples: 128 },
        _ => return None,
    }
    Some(s)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(seeds), Some(budget)) = (
        args.first().and_then(|s| s.parse::<u64>().ok()),
        args.get(1).and_then(|s| s.parse::<usize>().ok()),
    ) else {
        eprintln!("usage: tune SEEDS BUDGET VARIANT...");
        std::process::exit(2);
    };
    let only = std::env::var("OBJECTS").unwrap_or_default();
    let seed0: u64 = std::env::var("SEED0")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let seeds: Vec<u64> = (seed0..seed0 + seeds).collect();
    let workers: usize = match std::env::var("WORKERS").map(|w| w.parse::<usize>()) {
        Err(_) => 1,
        Ok(Ok(w)) if w >= 1 => w,
        Ok(_) => {
            eprintln!("WORKERS must be a whole number >= 1");
            std::process::exit(2);
        }
    };
    let mut landscapes = Vec::new();
    for name in Object::names() {
        if !only.is_empty() && !only.split(',').any(|o| o == name) {
            continue;
        }
        let object = Object::by_name(name).expect("a built-in object");
        let space = TrialSpace::approach_vertical_2d(&object);
        let ev = Evaluator::new(
            object,
            hand_by_name("barrett").expect("the Barrett hand"),
            space,
        );
        let axes = grid_axes(&ev.space.bounds(), &[67, 33]);
        let grid = scan_grid(&ev, &axes, 0, &|_| {}).expect("the grid scan");
        let max = grid
            .iter()
            .map(|p| p.score.score)
            .fold(f64::NEG_INFINITY, f64::max);
        landscapes.push((name, ev, max));
    }
    for name in &args[2..] {
        let Some(settings) = variant(name) else {
            eprintln!("unknown variant {name}");
            continue;
        };
        let method = if name == "random" {
            Method::Random
        } else {
            Method::Bo(Preset::Benchmark)
        };
        let template = SearchSettings {
            method,
            budget,
            n_init: None,
            stop_on_small_ei: false,
            engine: Some(settings),
            workers,
        };
        let mut line = if workers > 1 {
            format!("{name:>14} W={workers}:")
        } else {
            format!("{name:>14}:")
        };
        let start = Instant::now();
        for (object, ev, max) in &landscapes {
            let m = compare(ev, &[method], &seeds, &template, Some(*max), 0)
                .expect("the runs")
                .methods
                .remove(0);
            let median = m.median_trials_to[0].map_or("-".to_string(), |v| v.to_string());
            line += &format!(" {object}={median}({}/{})", m.reached[0], seeds.len());
            if std::env::var_os("PER_SEED").is_some() {
                let per_seed: Vec<String> = m
                    .trials_to
                    .iter()
                    .map(|t| t[0].map_or("-".to_string(), |n| n.to_string()))
                    .collect();
                line += &format!("[{}]", per_seed.join(","));
            }
        }
        line += &format!(" ({:.0} s)", start.elapsed().as_secs_f64());
        println!("{line}");
    }
}
