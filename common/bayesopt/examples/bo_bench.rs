//! Measurement runner: `cargo run --release -p graspopt-bayesopt --features tools --example
//! bo_bench -- FUNCTION SEEDS BUDGET INIT Q [XI|thesis] [THREADS]`. Prints evaluations (and
//! rounds) to regret 5%, 1%, 0.1% per seed and a summary. XI is a fixed xi on standardised
//! outputs (default 0) or `thesis` (sigma_f^2 / 100).

use std::time::Instant;

use graspopt_bayesopt::benchmark::{
    SeedSummary, aggregate, recommended_settings, run_seed_with, summarize,
};
use graspopt_bayesopt::{TestFunction, XiRule};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let get = |i: usize, d: &str| args.get(i).cloned().unwrap_or_else(|| d.to_string());
    let f = match TestFunction::from_name(&get(1, "branin")) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("{e}");
            return;
        }
    };
    let seeds: u64 = get(2, "10").parse().unwrap_or(10);
    let budget: usize = get(3, "50").parse().unwrap_or(50);
    let init: usize = get(4, "5").parse().unwrap_or(5);
    let q: usize = get(5, "1").parse().unwrap_or(1);
    let xi_arg = get(6, "0");
    let threads: u64 = get(7, "2").parse().unwrap_or(2);
    let mut settings = recommended_settings();
    settings.n_init = Some(init);
    settings.xi = if xi_arg == "thesis" {
        XiRule::ThesisSignalVariance
    } else {
        XiRule::Fixed(xi_arg.parse().unwrap_or(0.0))
    };
    // Tuning overrides (environment): BO_KERNEL=m32|m52|se, BO_LS (prior median length scale),
    // BO_LSSD, BO_DIRECT (evals per dim), BO_POLISH (starts), BO_RESTARTS,
    // BO_BATCH=kb|clmin|clmean|clmax|qei[:SAMPLES].
    let env = |k: &str| std::env::var(k).ok();
    if let Some(k) = env("BO_KERNEL") {
        settings.kernel = match k.as_str() {
            "m52" => graspopt_bayesopt::KernelKind::Matern52,
            "se" => graspopt_bayesopt::KernelKind::SquaredExponential,
            _ => graspopt_bayesopt::KernelKind::Matern32,
        };
    }
    if let Some(v) = env("BO_LS").and_then(|v| v.parse::<f64>().ok()) {
        settings.fit.length_scale_log_mean = v.ln();
    }
    if let Some(v) = env("BO_LSSD").and_then(|v| v.parse::<f64>().ok()) {
        settings.fit.length_scale_log_sd = v;
    }
    if let Some(v) = env("BO_DIRECT").and_then(|v| v.parse::<usize>().ok()) {
        settings.direct_evals_per_dim = v;
    }
    if let Some(v) = env("BO_POLISH").and_then(|v| v.parse::<usize>().ok()) {
        settings.polish_starts = v;
    }
    if let Some(v) = env("BO_RESTARTS").and_then(|v| v.parse::<usize>().ok()) {
        settings.fit.restarts = v;
    }
    if let Some(v) = env("BO_NOISE").and_then(|v| v.parse::<f64>().ok()) {
        settings.fit.noise_log_mean = v.ln();
    }
    if let Some(v) = env("BO_NOISEFLOOR").and_then(|v| v.parse::<f64>().ok()) {
        settings.fit.noise_bounds.0 = v;
    }
    if let Some(v) = env("BO_LSMAX").and_then(|v| v.parse::<f64>().ok()) {
        settings.fit.length_scale_bounds.1 = v;
    }
    if let Some(v) = env("BO_EXPLORE").and_then(|v| v.parse::<f64>().ok()) {
        settings.explore_below_ei = Some(v);
    }
    if let Some(v) = env("BO_PMQ").and_then(|v| v.parse::<f64>().ok()) {
        settings.prior_mean_quantile = Some(v);
    }
    if let Some(v) = env("BO_DIV").and_then(|v| v.parse::<usize>().ok()) {
        settings.diversify_every = v;
    }
    if let Some(v) = env("BO_DEPTH").and_then(|v| v.parse::<usize>().ok()) {
        settings.diversify_depth = v;
    }
    if let Some(v) = env("BO_WARP") {
        settings.output_transform = match v.as_str() {
            "1" => graspopt_bayesopt::OutputTransform::TailLog,
            "rank" => graspopt_bayesopt::OutputTransform::Rank,
            _ => graspopt_bayesopt::OutputTransform::None,
        };
    }
    if let Some(v) = env("BO_RESTART") {
        // window,tol,init,tabu_radius[,max_relative_ei] (anything else: off)
        let p: Vec<f64> = v.split(',').filter_map(|t| t.parse().ok()).collect();
        settings.restart = (p.len() == 4 || p.len() == 5).then(|| graspopt_bayesopt::RestartRule {
            window: p[0] as usize,
            tol: p[1],
            init: p[2] as usize,
            tabu_radius: p[3],
            max_relative_ei: p.get(4).copied(),
        });
    }
    if let Some(v) = env("BO_LHS").and_then(|v| v.parse::<usize>().ok()) {
        settings.initial_design =
            graspopt_bayesopt::InitialDesign::MaximinLatinHypercube { candidates: v };
    }
    if let Some(b) = env("BO_BATCH") {
        settings.batch = match b.as_str() {
            "clmin" => graspopt_bayesopt::BatchStrategy::ConstantLiarMin,
            "clmean" => graspopt_bayesopt::BatchStrategy::ConstantLiarMean,
            "clmax" => graspopt_bayesopt::BatchStrategy::ConstantLiarMax,
            "kb" => graspopt_bayesopt::BatchStrategy::KrigingBeliever,
            "qei" => graspopt_bayesopt::BatchStrategy::Qei { samples: 128 },
            s if s.starts_with("qei:") => match s["qei:".len()..].parse() {
                Ok(samples) => graspopt_bayesopt::BatchStrategy::Qei { samples },
                Err(_) => {
                    eprintln!("BO_BATCH={s}: the sample count is not a whole number");
                    return;
                }
            },
            other => {
                eprintln!("BO_BATCH={other}: known are kb, clmin, clmean, clmax, qei, qei:N");
                return;
            }
        };
    }
    let t0 = Instant::now();
    let mut results: Vec<SeedSummary> = Vec::new();
    let handles: Vec<_> = (0..threads)
        .map(|t| {
            let s = settings.clone();
            std::thread::spawn(move || {
                let mut out = Vec::new();
                let seed0: u64 = std::env::var("BO_SEED0")
                    .ok()
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(0);
                let mut seed = seed0 + t;
                while seed < seed0 + seeds {
                    let ts = Instant::now();
                    match run_seed_with(f, seed, budget, q, s.clone()) {
                        Ok(trace) => {
                            let sm = summarize(f, seed, &trace, q);
                            if std::env::var("BO_QUIET").is_err() { println!(
                                "seed {seed}: evals to 5%/1%/0.1% {:?} rounds {:?} final regret {:.2e} ({:.1}s)",
                                sm.evals_to,
                                sm.rounds_to,
                                sm.final_regret,
                                ts.elapsed().as_secs_f64()
                            ); }
                            out.push(sm);
                        }
                        Err(e) => eprintln!("seed {seed}: {e}"),
                    }
                    seed += threads;
                }
                out
            })
        })
        .collect();
    for h in handles {
        if let Ok(v) = h.join() {
            results.extend(v);
        }
    }
    results.sort_by_key(|s| s.seed);
    for l in aggregate(&results, budget, q) {
        println!(
            "regret {:>6}: {}/{} seeds, median evals {:?}, median rounds {:?}, worst {:?}",
            l.level, l.reached, l.seeds, l.median_evals, l.median_rounds, l.max_evals
        );
    }
    println!("total {:.1}s", t0.elapsed().as_secs_f64());
}
