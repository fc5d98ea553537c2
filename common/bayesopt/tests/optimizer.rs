//! Integration tests of the ask/tell optimizer: determinism, serde round trip, batches,
//! stopping and input validation.

use graspopt_bayesopt::{
    AskTell, BoError, Optimizer, Settings, StopReason, StopRule, TestFunction, XiRule,
};

fn branin_bounds() -> Vec<(f64, f64)> {
    vec![(-5.0, 10.0), (0.0, 15.0)]
}

fn fast_settings() -> Settings {
    Settings {
        minimize: true,
        n_init: Some(5),
        direct_evals_per_dim: 150,
        xi: XiRule::Fixed(0.0),
        ..Settings::default()
    }
}

fn step(opt: &mut Optimizer, q: usize) -> Vec<Vec<f64>> {
    let pts = opt.suggest(q).unwrap();
    for p in &pts {
        opt.observe(p, TestFunction::Branin.eval(p)).unwrap();
    }
    pts
}

#[test]
fn same_seed_same_proposals() {
    let mut a = Optimizer::new(&branin_bounds(), fast_settings(), 42).unwrap();
    let mut b = Optimizer::new(&branin_bounds(), fast_settings(), 42).unwrap();
    for _ in 0..9 {
        assert_eq!(step(&mut a, 1), step(&mut b, 1));
    }
    let mut c = Optimizer::new(&branin_bounds(), fast_settings(), 43).unwrap();
    assert_ne!(step(&mut c, 1), {
        let mut d = Optimizer::new(&branin_bounds(), fast_settings(), 42).unwrap();
        step(&mut d, 1)
    });
}

#[test]
fn serde_round_trip_continues_identically() {
    // recommended-style settings so every piece of state is exercised
    let s = Settings {
        diversify_every: 2,
        full_refit_every: 3,
        output_transform: graspopt_bayesopt::OutputTransform::TailLog,
        prior_mean_quantile: Some(0.0),
        ..fast_settings()
    };
    let mut a = Optimizer::new(&branin_bounds(), s, 7).unwrap();
    for _ in 0..8 {
        step(&mut a, 1);
    }
    // one pending point at the time of the snapshot
    let pending = a.suggest(1).unwrap();
    let json = serde_json::to_string(&a).unwrap();
    let mut b: Optimizer = serde_json::from_str(&json).unwrap();
    assert_eq!(a, b);
    for p in &pending {
        let y = TestFunction::Branin.eval(p);
        a.observe(p, y).unwrap();
        b.observe(p, y).unwrap();
    }
    for _ in 0..4 {
        assert_eq!(step(&mut a, 1), step(&mut b, 1));
    }
    assert_eq!(step(&mut a, 3), step(&mut b, 3));
    assert_eq!(a, b);
}

#[test]
fn a_latin_hypercube_design_round_trips_halfway() {
    let s = Settings {
        initial_design: graspopt_bayesopt::InitialDesign::MaximinLatinHypercube { candidates: 30 },
        ..fast_settings()
    };
    let mut a = Optimizer::new(&branin_bounds(), s, 9).unwrap();
    step(&mut a, 2);
    let json = serde_json::to_string(&a).unwrap();
    let mut b: Optimizer = serde_json::from_str(&json).unwrap();
    assert_eq!(a, b);
    // the rest of the design (3 points), then model-based proposals
    for _ in 0..5 {
        assert_eq!(step(&mut a, 1), step(&mut b, 1));
    }
    assert_eq!(a, b);
}

#[test]
fn restarts_round_trip_and_continue_identically() {
    let s = Settings {
        restart: Some(graspopt_bayesopt::RestartRule {
            window: 2,
            tol: 1.0,
            init: 2,
            tabu_radius: 0.1,
            max_relative_ei: None,
        }),
        ..fast_settings()
    };
    let mut a = Optimizer::new(&branin_bounds(), s, 11).unwrap();
    for _ in 0..14 {
        step(&mut a, 1);
    }
    assert!(a.restarts() >= 1, "tol = 1 must restart");
    assert!(a.epoch_start() > 0 && a.epoch_start() <= a.len());
    let json = serde_json::to_string(&a).unwrap();
    let mut b: Optimizer = serde_json::from_str(&json).unwrap();
    assert_eq!(a, b);
    for _ in 0..5 {
        assert_eq!(step(&mut a, 1), step(&mut b, 1));
    }
    assert_eq!(step(&mut a, 2), step(&mut b, 2));
    assert_eq!(a, b);
    // the best value covers every epoch
    let min = a
        .observations()
        .map(|(_, y)| y)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(a.best().unwrap().1, min);
}

#[test]
fn batch_points_are_distinct_and_pending_is_tracked() {
    let mut opt = Optimizer::new(&branin_bounds(), fast_settings(), 3).unwrap();
    for _ in 0..2 {
        step(&mut opt, 4);
    }
    let first = opt.suggest(4).unwrap();
    assert_eq!(opt.pending().len(), 4);
    let second = opt.suggest(2).unwrap();
    assert_eq!(opt.pending().len(), 6);
    let all: Vec<&Vec<f64>> = first
        .iter()
        .chain(second.iter())
        .chain(std::iter::empty())
        .collect();
    for i in 0..all.len() {
        for j in 0..i {
            let d: f64 = all[i]
                .iter()
                .zip(all[j].iter())
                .map(|(a, b)| (a - b).powi(2))
                .sum();
            assert!(d > 1e-10, "duplicate proposals {i} {j}");
        }
        for (x, _) in opt.observations() {
            assert_ne!(x, all[i].as_slice());
        }
    }
    opt.observe(&first[0], 1.0).unwrap();
    assert_eq!(opt.pending().len(), 5);
    opt.clear_pending();
    assert!(opt.pending().is_empty());
}

#[test]
fn qei_batches_are_distinct_and_round_trip_with_points_pending() {
    let s = Settings {
        batch: graspopt_bayesopt::BatchStrategy::Qei { samples: 32 },
        diversify_every: 2,
        ..fast_settings()
    };
    let mut a = Optimizer::new(&branin_bounds(), s, 5).unwrap();
    for _ in 0..3 {
        step(&mut a, 3);
    }
    // two rounds in flight: the second one's points are chosen jointly with the first's
    let first = a.suggest(3).unwrap();
    let second = a.suggest(2).unwrap();
    let all: Vec<&Vec<f64>> = first.iter().chain(&second).collect();
    for i in 0..all.len() {
        for j in 0..i {
            let d2: f64 = all[i]
                .iter()
                .zip(all[j])
                .map(|(a, b)| (a - b).powi(2))
                .sum();
            assert!(d2 > 1e-6, "points {i} and {j} coincide: {:?}", all[i]);
        }
    }
    let json = serde_json::to_string(&a).unwrap();
    let mut b: Optimizer = serde_json::from_str(&json).unwrap();
    assert_eq!(a, b);
    // a qEI point proposed while five are pending, after the restore
    let third = a.suggest(1).unwrap();
    assert_eq!(third, b.suggest(1).unwrap());
    for p in first.iter().chain(&second).chain(&third) {
        let y = TestFunction::Branin.eval(p);
        a.observe(p, y).unwrap();
        b.observe(p, y).unwrap();
    }
    for q in [4, 1, 3] {
        assert_eq!(step(&mut a, q), step(&mut b, q));
    }
    assert_eq!(a, b);
}

#[test]
fn qei_batches_find_the_branin_basin() {
    // Five rounds of four after five random points reach 1% regret (seeds 0 to 2).
    for seed in 0..3 {
        let s = Settings {
            batch: graspopt_bayesopt::BatchStrategy::Qei { samples: 64 },
            ..fast_settings()
        };
        let mut opt = Optimizer::new(&branin_bounds(), s, seed).unwrap();
        step(&mut opt, 5);
        for _ in 0..5 {
            step(&mut opt, 4);
        }
        let best = opt.best().unwrap().1;
        assert!(
            TestFunction::Branin.regret(best) < 0.01,
            "seed {seed}: {best}"
        );
    }
}

#[test]
fn maximisation_convention_and_best() {
    let s = Settings {
        n_init: Some(3),
        direct_evals_per_dim: 100,
        ..Settings::default()
    };
    let mut opt = Optimizer::new(&[(0.0, 1.0)], s, 1).unwrap();
    let f = |x: f64| -(x - 0.7).powi(2);
    for _ in 0..10 {
        let p = opt.suggest(1).unwrap();
        opt.observe(&p[0], f(p[0][0])).unwrap();
    }
    let (x, y) = opt.best().unwrap();
    assert!((x[0] - 0.7).abs() < 0.02, "{x:?} {y}");
    let (m, sd) = opt.predict(&[0.7]).unwrap();
    assert!(m.abs() < 0.05 && sd >= 0.0);
}

#[test]
fn stops_at_budget_and_on_small_ei() {
    let s = Settings {
        stop: StopRule {
            budget: Some(12),
            ..StopRule::default()
        },
        ..fast_settings()
    };
    let mut opt = Optimizer::new(&branin_bounds(), s, 1).unwrap();
    while opt.stop_reason().is_none() {
        step(&mut opt, 1);
    }
    assert_eq!(opt.len(), 12);
    assert_eq!(opt.stop_reason(), Some(StopReason::Budget));

    // A constant function: EI collapses, stop after min_evals and patience.
    let s = Settings {
        n_init: Some(3),
        direct_evals_per_dim: 100,
        stop: StopRule {
            budget: Some(60),
            min_evals: Some(8),
            relative_ei_threshold: 1e-3,
            patience: 2,
        },
        ..Settings::default()
    };
    let mut opt = Optimizer::new(&[(0.0, 1.0)], s, 2).unwrap();
    while opt.stop_reason().is_none() {
        let p = opt.suggest(1).unwrap();
        let y = -(p[0][0] - 0.3).powi(2);
        opt.observe(&p[0], y).unwrap();
    }
    assert_eq!(
        opt.stop_reason(),
        Some(StopReason::SmallExpectedImprovement)
    );
    assert!(opt.len() >= 8 && opt.len() < 60, "{}", opt.len());
}

#[test]
fn bad_input_gives_errors() {
    let s = Settings::default;
    assert_eq!(
        Optimizer::new(&[], s(), 0).unwrap_err(),
        BoError::EmptyBounds
    );
    assert!(matches!(
        Optimizer::new(&[(1.0, 1.0)], s(), 0),
        Err(BoError::InvalidBound { .. })
    ));
    assert!(Optimizer::new(&[(2.0, 1.0)], s(), 0).is_err());
    assert!(Optimizer::new(&[(f64::NAN, 1.0)], s(), 0).is_err());
    let bad = Settings {
        xi: XiRule::Fixed(-1.0),
        ..Settings::default()
    };
    assert!(Optimizer::new(&[(0.0, 1.0)], bad, 0).is_err());
    for samples in [0, graspopt_bayesopt::MAX_QEI_SAMPLES + 1, usize::MAX] {
        let bad_samples = Settings {
            batch: graspopt_bayesopt::BatchStrategy::Qei { samples },
            ..Settings::default()
        };
        assert!(matches!(
            Optimizer::new(&[(0.0, 1.0)], bad_samples, 0),
            Err(BoError::InvalidSetting(m)) if m.contains("samples")
        ));
    }
    let mut opt = Optimizer::new(&[(0.0, 1.0), (0.0, 1.0)], s(), 0).unwrap();
    assert!(matches!(
        opt.observe(&[0.5], 1.0),
        Err(BoError::DimensionMismatch { .. })
    ));
    assert!(matches!(
        opt.observe(&[0.5, 0.5], f64::NAN),
        Err(BoError::NonFinite { .. })
    ));
    assert!(matches!(
        opt.observe(&[0.5, 1.5], 1.0),
        Err(BoError::OutOfBounds { .. })
    ));
    assert!(opt.observe(&[0.5, f64::INFINITY], 1.0).is_err());
    assert!(opt.suggest(0).is_err());
    assert!(opt.predict(&[0.5, 0.5]).is_err());
    assert!(opt.is_empty());
    // duplicates and constant observations do not break the engine
    for _ in 0..6 {
        opt.observe(&[0.5, 0.5], 2.0).unwrap();
    }
    let p = opt.suggest(2).unwrap();
    assert_eq!(p.len(), 2);
    assert!(AskTell::best(&opt).is_some());
    let qei = Settings {
        batch: graspopt_bayesopt::BatchStrategy::Qei { samples: 16 },
        ..Settings::default()
    };
    let mut opt = Optimizer::new(&[(0.0, 1.0), (0.0, 1.0)], qei, 0).unwrap();
    for _ in 0..6 {
        opt.observe(&[0.5, 0.5], 2.0).unwrap();
    }
    let p = opt.suggest(3).unwrap();
    assert_eq!(p.len(), 3);
    assert!(p.iter().flatten().all(|v| (0.0..=1.0).contains(v)));
}

#[test]
fn transforms_prior_mean_exploration_and_ucb_run_and_stay_in_bounds() {
    use graspopt_bayesopt::{AcquisitionKind, BatchStrategy, OutputTransform};
    let variants = vec![
        Settings {
            output_transform: OutputTransform::TailLog,
            prior_mean_quantile: Some(0.0),
            ..fast_settings()
        },
        Settings {
            output_transform: OutputTransform::Rank,
            batch: BatchStrategy::ConstantLiarMin,
            ..fast_settings()
        },
        Settings {
            explore_below_ei: Some(1e9),
            batch: BatchStrategy::ConstantLiarMean,
            ..fast_settings()
        },
        Settings {
            acquisition: AcquisitionKind::Ucb { beta: 4.0 },
            batch: BatchStrategy::ConstantLiarMax,
            xi: XiRule::ThesisSignalVariance,
            ..fast_settings()
        },
    ];
    for s in variants {
        let mut opt = Optimizer::new(&branin_bounds(), s.clone(), 11).unwrap();
        for _ in 0..4 {
            for p in step(&mut opt, 2) {
                assert!((-5.0..=10.0).contains(&p[0]) && (0.0..=15.0).contains(&p[1]));
            }
        }
        if s.explore_below_ei.is_some() {
            assert_eq!(opt.last_round().exploration_points, 2);
        }
        // predictions come back on the raw scale and interpolate the data roughly
        let (x, y) = opt.best().unwrap();
        let (m, sd) = opt.predict(&x).unwrap();
        assert!(sd.is_finite() && sd >= 0.0);
        assert!((m - y).abs() < 0.2 * y.abs().max(1.0), "{s:?}: {m} vs {y}");
    }
}

#[test]
fn branin_quick_run_finds_the_basin() {
    // Short smoke run of the recommended engine: 25 evaluations reach 1% regret.
    let trace = graspopt_bayesopt::benchmark::run_seed(
        TestFunction::Branin,
        0,
        25,
        5,
        1,
        graspopt_bayesopt::Method::Bo(graspopt_bayesopt::Preset::Benchmark),
    )
    .unwrap();
    let best = trace.last().copied().unwrap();
    assert!(TestFunction::Branin.regret(best) < 0.01, "{best}");
}

#[test]
fn expected_improvement_vanishes_at_observations_and_not_between_them() {
    let mut opt = Optimizer::new(&[(0.0, 1.0)], Settings::for_grasps(), 5).unwrap();
    assert!(opt.expected_improvement(&[0.5]).is_err(), "no data yet");
    // A smooth 1D bump observed at five points, then one model-based round to fit.
    let f = |x: f64| -(x - 0.62) * (x - 0.62);
    for x in [0.0, 0.25, 0.5, 0.75, 1.0] {
        opt.observe(&[x], f(x)).unwrap();
    }
    let next = opt.suggest(1).unwrap();
    opt.clear_pending();
    let at_data = opt.expected_improvement(&[0.5]).unwrap();
    let at_next = opt.expected_improvement(&next[0]).unwrap();
    assert!(
        (0.0..1e-3).contains(&at_data),
        "EI {at_data} at an observation"
    );
    assert!(
        at_next > 10.0 * at_data.max(1e-6),
        "EI {at_next} at the proposal"
    );
    // Near the optimum (between 0.5 and 0.75) EI beats the far, bad end.
    assert!(
        opt.expected_improvement(&[0.62]).unwrap() > opt.expected_improvement(&[0.02]).unwrap()
    );
    assert!(
        opt.expected_improvement(&[0.5, 0.5]).is_err(),
        "wrong dimension"
    );
    assert!(
        opt.expected_improvement(&[f64::NAN]).is_err(),
        "not a number"
    );
}
