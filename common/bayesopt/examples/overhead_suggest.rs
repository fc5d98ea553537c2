//! Planner overhead per proposal at about 100 observations in 6D (Hartmann6, recommended
//! settings): 100 random observations, then 20 consecutive rounds of `suggest(1)` + `observe`
//! (all kinds of rounds: plain, diversification, full refit). Prints each round's time and the
//! median. `OV_PRESET=grasp` times the planner's preset ([`Settings::for_grasps`]) instead.
//! Run on one core: `taskset -c 0 cargo run --release -p graspopt-bayesopt --features
//! tools --example overhead_suggest`.

use std::time::Instant;

use graspopt_bayesopt::benchmark::recommended_settings;
use graspopt_bayesopt::rng::Rng;
use graspopt_bayesopt::{Optimizer, Settings, TestFunction};

fn main() {
    let f = TestFunction::Hartmann6;
    let mut s = if std::env::var("OV_PRESET").as_deref() == Ok("grasp") {
        Settings::for_grasps()
    } else {
        recommended_settings()
    };
    s.minimize = true;
    // keep the 100-observation model (the restart rule would start a new, small epoch)
    s.restart = None;
    if let Some(v) = std::env::var("OV_FIT").ok().and_then(|v| v.parse().ok()) {
        s.fit.max_iter = v;
        s.fit.warm_max_iter = v;
    }
    if let Some(v) = std::env::var("OV_POLISH").ok().and_then(|v| v.parse().ok()) {
        s.polish_iters = v;
    }
    let Ok(mut opt) = Optimizer::new(&[(0.0, 1.0); 6], s, 1) else {
        return;
    };
    let mut rng = Rng::new(5);
    for _ in 0..100 {
        let x = rng.unit_point(6);
        let _ = opt.observe(&x, f.eval(&x));
    }
    let mut ts = Vec::new();
    for round in 0..20 {
        let t = Instant::now();
        let Ok(p) = opt.suggest(1) else { return };
        let ms = t.elapsed().as_secs_f64() * 1e3;
        ts.push(ms);
        println!("round {round:2} ({} obs): {ms:.2} ms", opt.len());
        for x in p {
            let _ = opt.observe(&x, f.eval(&x));
        }
    }
    ts.sort_by(|a, b| a.total_cmp(b));
    println!(
        "median {:.2} ms, min {:.2} ms, max {:.2} ms over {} rounds",
        0.5 * (ts[9] + ts[10]),
        ts[0],
        ts[19],
        ts.len()
    );
}
