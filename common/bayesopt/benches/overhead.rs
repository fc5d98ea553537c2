//! Planner overhead per proposal (hyperparameter fit + acquisition maximisation) with 100
//! observations in 6D (Hartmann6), recommended settings, one benchmark per kind of round:
//! a plain round (warm-started fit, one DIRECT + polish), a diversification round (every
//! second round) and a full-refit round (random restarts, every tenth round), plus realistic
//! sequences of 20 consecutive rounds with each proposal observed (90 to 109 and 100 to 119
//! observations; all kinds of rounds in the proportions they occur: 10 diversification rounds,
//! 2 full refits) whose per-round medians are printed, and a batch round of four points with
//! qEI and with the kriging believer. Run with
//! `taskset -c 0 cargo bench -p graspopt-bayesopt --bench overhead`; the same sequence, once,
//! is printed by `cargo run --release -p graspopt-bayesopt --features tools --example
//! overhead_suggest`.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use graspopt_bayesopt::benchmark::{median, recommended_settings};
use graspopt_bayesopt::rng::Rng;
use graspopt_bayesopt::{BatchStrategy, Optimizer, TestFunction};

/// Optimizer with `n_obs` random observations after `warm_rounds` proposal rounds (whose
/// points are discarded), so the next round is of the wanted kind.
fn optimizer_with_observations(n_obs: usize, warm_rounds: usize) -> Optimizer {
    optimizer_with_batch(n_obs, warm_rounds, recommended_settings().batch)
}

/// [`optimizer_with_observations`] with another batch strategy.
fn optimizer_with_batch(n_obs: usize, warm_rounds: usize, batch: BatchStrategy) -> Optimizer {
    let f = TestFunction::Hartmann6;
    let mut s = recommended_settings();
    s.batch = batch;
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
    for _ in 0..n_obs {
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
        let opt = optimizer_with_observations(100, warm);
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut o = opt.clone();
                black_box(o.suggest(1).map(|p| p.len()).unwrap_or(0))
            })
        });
    }
    g.finish();
}

/// Rounds of the realistic sequence.
const SEQUENCE_ROUNDS: usize = 20;

/// Run the rounds of the sequence from `start`, each proposal being evaluated and observed as
/// in a real run (so the model grows by one observation per round and the warm-started fit has
/// new data to adapt to), calling `each` with the round index and its time (suggest only).
fn run_sequence(start: &Optimizer, mut each: impl FnMut(usize, Duration)) {
    let f = TestFunction::Hartmann6;
    let mut opt = start.clone();
    for r in 0..SEQUENCE_ROUNDS {
        let t = Instant::now();
        let p = opt.suggest(1);
        each(r, t.elapsed());
        for x in black_box(p).unwrap_or_default() {
            if let Err(e) = opt.observe(&x, f.eval(&x)) {
                panic!("{e}");
            }
        }
    }
}

/// 20 consecutive rounds from round 0: 10 diversification rounds, 2 full refits (rounds 0 and
/// 10) and 8 plain rounds, from 90 observations (90 to 109 observations, centred on the 100 of
/// the requirement) and from 100 (100 to 119). Criterion reports the mean time per round (full
/// refits included); the per-round medians (over repetitions of the sequence) and their
/// median, the figure of the requirement, are printed.
fn bench_sequence(c: &mut Criterion) {
    let mut g = c.benchmark_group("overhead_d6_sequence");
    g.sample_size(10);
    for n_obs in [90usize, 100] {
        let start = optimizer_with_observations(n_obs, 0);
        g.bench_function(format!("mean_per_round_of_20_from_{n_obs}_obs"), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    run_sequence(&start, |_, t| total += t);
                }
                total / SEQUENCE_ROUNDS as u32
            })
        });
        let reps = 15;
        let mut times: Vec<Vec<f64>> = vec![Vec::new(); SEQUENCE_ROUNDS];
        for _ in 0..reps {
            run_sequence(&start, |r, t| times[r].push(t.as_secs_f64() * 1e3));
        }
        let per_round: Vec<f64> = times
            .iter()
            .map(|t| median(t).unwrap_or(f64::NAN))
            .collect();
        let line: Vec<String> = per_round.iter().map(|t| format!("{t:.2}")).collect();
        println!(
            "from {n_obs} obs, per-round median (ms, rounds 0..20): {}",
            line.join(" ")
        );
        println!(
            "from {n_obs} obs, median over the 20 rounds of the per-round medians: {:.2} ms",
            median(&per_round).unwrap_or(f64::NAN)
        );
    }
    g.finish();
}

/// One batch round of four points at 100 observations in 6D (a plain round: warm-started fit,
/// no diversification), with the recommended sequential-greedy qEI and with the kriging
/// believer, to price the batch strategy per point.
fn bench_batch(c: &mut Criterion) {
    let mut g = c.benchmark_group("overhead_n100_d6_batch_q4");
    g.sample_size(10);
    let qei = optimizer_with_observations(100, 2);
    let believer = optimizer_with_batch(100, 2, BatchStrategy::KrigingBeliever);
    for (name, opt) in [("qei_128", &qei), ("kriging_believer", &believer)] {
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut o = opt.clone();
                black_box(o.suggest(4).map(|p| p.len()).unwrap_or(0))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench, bench_sequence, bench_batch);
criterion_main!(benches);
