//! Tries engine settings on the 2D grasp landscapes of the seven objects: per variant, the
//! median trials to within 5% of the grid maximum over seeds, next to random search.
//! `cargo run --release -p graspopt-experiment --example tune -- SEEDS BUDGET VARIANT...`

use graspopt_bayesopt::{
    Method, OutputTransform, Settings, XiRule, benchmark::recommended_settings,
};
use graspopt_experiment::{SearchSettings, compare};
use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{Object, ParamKind, TrialSpace};
use graspopt_trial::Evaluator;
use graspopt_trial::scan::{linspace, scan_grid};

fn variant(name: &str) -> Option<Settings> {
    let t = Settings::default();
    let b = recommended_settings();
    Some(match name {
        "thesis" => t,
        "bo" => b,
        "thesis-tail" => Settings {
            output_transform: OutputTransform::TailLog,
            ..t
        },
        "thesis-rank" => Settings {
            output_transform: OutputTransform::Rank,
            ..t
        },
        "thesis-xi0" => Settings {
            xi: XiRule::Fixed(0.0),
            ..t
        },
        "thesis-init8" => Settings {
            n_init: Some(8),
            ..t
        },
        "thesis-init3" => Settings {
            n_init: Some(3),
            ..t
        },
        "thesis-div2" => Settings {
            diversify_every: 2,
            ..t
        },
        "thesis-tail-div2" => Settings {
            diversify_every: 2,
            output_transform: OutputTransform::TailLog,
            ..t
        },
        "bo-norestart" => Settings { restart: None, ..b },
        "bo-nodiv" => Settings {
            diversify_every: 0,
            ..b
        },
        "bo-nopm" => Settings {
            prior_mean_quantile: None,
            ..b
        },
        "bo-thesisxi" => Settings {
            xi: XiRule::ThesisSignalVariance,
            ..b
        },
        "bo-none" => Settings {
            output_transform: OutputTransform::None,
            ..b
        },
        "tail-noise" => Settings {
            output_transform: OutputTransform::TailLog,
            fit: graspopt_bayesopt::FitSettings {
                noise_log_mean: 1e-2f64.ln(),
                ..t.fit.clone()
            },
            ..t.clone()
        },
        "tail-ls01" => Settings {
            output_transform: OutputTransform::TailLog,
            fit: graspopt_bayesopt::FitSettings {
                length_scale_log_mean: 0.1f64.ln(),
                ..t.fit.clone()
            },
            ..t.clone()
        },
        "tail-ucb" => Settings {
            output_transform: OutputTransform::TailLog,
            acquisition: graspopt_bayesopt::AcquisitionKind::Ucb { beta: 4.0 },
            ..t.clone()
        },
        "tail-xi0" => Settings {
            output_transform: OutputTransform::TailLog,
            xi: XiRule::Fixed(0.0),
            ..t.clone()
        },
        "tail-init8" => Settings {
            output_transform: OutputTransform::TailLog,
            n_init: Some(8),
            ..t.clone()
        },
        "tail-init3" => Settings {
            output_transform: OutputTransform::TailLog,
            n_init: Some(3),
            ..t.clone()
        },
        "tail-m52" => Settings {
            output_transform: OutputTransform::TailLog,
            kernel: graspopt_bayesopt::KernelKind::Matern52,
            ..t.clone()
        },
        "tail-pm" => Settings {
            output_transform: OutputTransform::TailLog,
            prior_mean_quantile: Some(0.0),
            ..t.clone()
        },
        "tail-restart" => Settings {
            output_transform: OutputTransform::TailLog,
            restart: b.restart,
            ..t.clone()
        },
        "tail-explore" => Settings {
            output_transform: OutputTransform::TailLog,
            explore_below_ei: Some(1e-3),
            ..t.clone()
        },
        "tail-m52-pm" => Settings {
            output_transform: OutputTransform::TailLog,
            kernel: graspopt_bayesopt::KernelKind::Matern52,
            prior_mean_quantile: Some(0.0),
            ..t.clone()
        },
        "random" => t,
        _ => return None,
    })
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seeds: u64 = args[0].parse().expect("seeds");
    let budget: usize = args[1].parse().expect("budget");
    let all = [
        "sphere",
        "wine_glass",
        "cylinder",
        "mug",
        "cuboid",
        "rotated_cuboid",
        "star_prism",
    ];
    let only = std::env::var("OBJECTS").unwrap_or_default();
    let objects: Vec<&str> = all
        .into_iter()
        .filter(|o| only.is_empty() || only.split(',').any(|x| x == *o))
        .collect();
    let mut evs = Vec::new();
    for o in objects {
        let object = Object::by_name(o).expect("object");
        let full = TrialSpace::full_6d(&object);
        let params = [ParamKind::Approach, ParamKind::Vertical]
            .iter()
            .map(|k| *full.params.iter().find(|p| p.kind == *k).expect("param"))
            .collect();
        let space = TrialSpace::new(full.reference, params).expect("space");
        let ev = Evaluator::new(object, hand_by_name("barrett").expect("hand"), space);
        let axes: Vec<Vec<f64>> = ev
            .space
            .bounds()
            .iter()
            .zip([67, 33])
            .map(|(&(l, h), n)| linspace(l, h, n))
            .collect();
        let grid = scan_grid(&ev, &axes, 0, &|_| {}).expect("scan");
        let max = grid
            .iter()
            .map(|p| p.score.score)
            .fold(f64::NEG_INFINITY, f64::max);
        evs.push((o, ev, max));
    }
    let seed0: u64 = std::env::var("SEED0")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let seeds: Vec<u64> = (seed0..seed0 + seeds).collect();
    for name in &args[2..] {
        let Some(settings) = variant(name) else {
            eprintln!("unknown variant {name}");
            continue;
        };
        let method = if name == "random" {
            Method::Random
        } else {
            Method::Bo
        };
        let template = SearchSettings {
            method,
            budget,
            n_init: None,
            stop_on_small_ei: false,
            engine: Some(settings),
        };
        let t0 = std::time::Instant::now();
        let mut line = format!("{name:>18}:");
        let mut worst: f64 = 0.0;
        for (o, ev, max) in &evs {
            let c = compare(ev, &[method], &seeds, &template, Some(*max), 0).expect("compare");
            let m = &c.methods[0];
            let v = m.median_trials_to[0].unwrap_or(f64::INFINITY);
            worst = worst.max(v);
            line += &format!(
                " {}={}({}/{})",
                o.get(..4).unwrap_or(o),
                v,
                m.reached[0],
                seeds.len()
            );
        }
        println!("{line}  worst={worst} [{:.0}s]", t0.elapsed().as_secs_f64());
    }
}
