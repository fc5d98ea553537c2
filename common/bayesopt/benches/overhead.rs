//! Planner overhead per proposal (hyperparameter fit + acquisition maximisation) with 100
//! observations in 6D (Hartmann6), recommended settings. Run with
//! `cargo bench -p graspopt-bayesopt --bench overhead`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use graspopt_bayesopt::benchmark::recommended_settings;
use graspopt_bayesopt::rng::Rng;
use graspopt_bayesopt::{Optimizer, TestFunction};

fn optimizer_with_100_observations() -> Optimizer {
    let f = TestFunction::Hartmann6;
    let mut s = recommended_settings();
    s.minimize = true;
    let bounds = vec![(0.0, 1.0); 6];
    let mut opt = match Optimizer::new(&bounds, s, 1) {
        Ok(o) => o,
        Err(e) => panic!("{e}"),
    };
    let mut rng = Rng::new(5);
    for _ in 0..100 {
        let x = rng.unit_point(6);
        if let Err(e) = opt.observe(&x, f.eval(&x)) {
            panic!("{e}");
        }
    }
    // one proposal so the hyperparameters are warm, as in a running planner
    if let Err(e) = opt.suggest(1) {
        panic!("{e}");
    }
    opt.clear_pending();
    opt
}

fn bench(c: &mut Criterion) {
    let opt = optimizer_with_100_observations();
    let mut g = c.benchmark_group("overhead");
    g.sample_size(20);
    g.bench_function("suggest_q1_n100_d6", |b| {
        b.iter(|| {
            let mut o = opt.clone();
            black_box(o.suggest(1).map(|p| p.len()).unwrap_or(0))
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
