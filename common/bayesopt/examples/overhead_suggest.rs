//! Time `suggest(1)` at 100 observations in 6D under setting variations (median of 15).
use std::time::Instant;

use graspopt_bayesopt::benchmark::recommended_settings;
use graspopt_bayesopt::rng::Rng;
use graspopt_bayesopt::{Optimizer, Settings, TestFunction};

fn time(label: &str, s: Settings) {
    let f = TestFunction::Hartmann6;
    let Ok(mut opt) = Optimizer::new(&[(0.0, 1.0); 6], s, 1) else {
        return;
    };
    let mut rng = Rng::new(5);
    for _ in 0..100 {
        let x = rng.unit_point(6);
        let _ = opt.observe(&x, f.eval(&x));
    }
    let _ = opt.suggest(1);
    opt.clear_pending();
    let mut ts = Vec::new();
    for _ in 0..15 {
        let mut o = opt.clone();
        let t = Instant::now();
        let _ = o.suggest(1);
        ts.push(t.elapsed().as_secs_f64() * 1e3);
    }
    ts.sort_by(|a, b| a.total_cmp(b));
    println!("{label}: median {:.2} ms (min {:.2})", ts[7], ts[0]);
}

fn main() {
    let mut base = recommended_settings();
    base.minimize = true;
    time("recommended", base.clone());
    let mut s = base.clone();
    s.direct_evals_per_dim = 150;
    time("direct 150/dim", s);
    let mut s = base.clone();
    s.direct_evals_per_dim = 150;
    s.fit.max_iter = 10;
    time("direct 150/dim, fit 10 iters", s);
    let mut s = base.clone();
    s.direct_evals_per_dim = 10;
    time("direct 60", s);
    let mut s = base.clone();
    s.fit.max_iter = 0;
    time("no fit iters", s);
}
