//! Planner overhead per proposal (hyperparameter fit + acquisition maximisation) with 100
//! observations in 6D (Hartmann6), recommended settings, one benchmark per kind of round:
//! a plain round (warm-started fit, one DIRECT + polish), a diversification round (every
//! second round) and a full-refit round (random restarts, every tenth round). Run with
//! `taskset -c 0 cargo bench -p graspopt-bayesopt --bench overhead`; the per-run median over
//! consecutive rounds is printed by `cargo run --release --example overhead_suggest`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use graspopt_bayesopt::benchmark::recommended_settings;
use graspopt_bayesopt::rng::Rng;
use graspopt_bayesopt::{Optimizer, TestFunction};

/// Optimizer with 100 random observations after `warm_rounds` proposal rounds (whose points
/// are discarded), so the next round is of the wanted kind.
fn optimizer_with_100_observations(warm_rounds: usize) -> Optimizer {
    let f = TestFunction::Hartmann6;
    let mut s = recommended_settings();
    s.minimize = true;
    // 100 random observations look like a stagnating search: without this the restart rule
    // would start a new epoch and the rounds would model 6 points instead of 100.
    s.restart = None;
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
    for _ in 0..warm_rounds {
        if let Err(e) = opt.suggest(1) {
            panic!("{e}");
        }
        opt.clear_pending();
    }
    opt
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("overhead_n100_d6");
    g.sample_size(20);
    for (name, warm) in [
        ("plain_round", 2usize),
        ("diversify_round", 1),
        ("full_refit_round", 10),
    ] {
        let opt = optimizer_with_100_observations(warm);
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut o = opt.clone();
                black_box(o.suggest(1).map(|p| p.len()).unwrap_or(0))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
