use super::*;

/// Smallest squared distance between two points of `pts`.
fn smallest_gap(pts: &[Vec<f64>]) -> f64 {
    let mut gap = f64::INFINITY;
    for (a, p) in pts.iter().enumerate() {
        for q in &pts[a + 1..] {
            gap = gap.min(p.iter().zip(q).map(|(x, y)| (x - y) * (x - y)).sum());
        }
    }
    gap
}

#[test]
fn latin_hypercube_has_one_point_per_slice_and_maximin_spreads_them() {
    let (n, d) = (10, 6);
    let mut rng = Rng::new(5);
    let one = maximin_latin_hypercube(&mut rng, n, d, 1);
    let best = maximin_latin_hypercube(&mut Rng::new(5), n, d, 200);
    for pts in [&one, &best] {
        assert_eq!(pts.len(), n);
        for j in 0..d {
            let mut slices: Vec<usize> = pts.iter().map(|p| (p[j] * n as f64) as usize).collect();
            slices.sort_unstable();
            assert_eq!(slices, (0..n).collect::<Vec<_>>(), "axis {j}: {pts:?}");
        }
    }
    // the first candidate of the maximin search is the single hypercube drawn from the
    // same stream, so the best of 200 is at least as spread, and here strictly more
    assert!(smallest_gap(&best) > smallest_gap(&one));
}

#[test]
fn the_initial_design_is_handed_out_in_order_across_batches_and_pending_points() {
    let settings = Settings {
        n_init: Some(5),
        initial_design: InitialDesign::MaximinLatinHypercube { candidates: 20 },
        ..Settings::default()
    };
    let mut opt = Optimizer::new(&[(0.0, 10.0), (-1.0, 1.0)], settings, 3).unwrap();
    let mut pts = opt.suggest(2).unwrap();
    pts.extend(opt.suggest(1).unwrap());
    opt.observe(&pts[0], 1.0).unwrap();
    pts.extend(opt.suggest(2).unwrap());
    assert_eq!(opt.last_round().random_points, 2);
    let units: Vec<Vec<f64>> = pts.iter().map(|p| opt.to_unit(p)).collect();
    assert_eq!(units.len(), 5);
    for (u, v) in units.iter().zip(&opt.design) {
        for (a, b) in u.iter().zip(v) {
            assert!((a - b).abs() < 1e-12, "{units:?} against {:?}", opt.design);
        }
    }
    for j in 0..2 {
        let mut slices: Vec<usize> = units.iter().map(|u| (u[j] * 5.0) as usize).collect();
        slices.sort_unstable();
        assert_eq!(slices, vec![0, 1, 2, 3, 4]);
    }
    // The trial of a design point failed (dropped from observations and pending): the
    // next point is the design's next one, never a point still pending.
    let settings = Settings {
        n_init: Some(4),
        ..Settings::default()
    };
    let mut warm = Optimizer::new(&[(0.0, 1.0), (0.0, 1.0)], settings.clone(), 8).unwrap();
    let first = warm.suggest(2).unwrap();
    warm.set_pending(vec![first[1].clone()]).unwrap();
    let third = warm.suggest(1).unwrap();
    assert_eq!(third[0], warm.unit_to_box(&warm.design[2]));
    // rebuilt with the same history: the failed point again, not the pending one
    let mut rebuilt = Optimizer::new(&[(0.0, 1.0), (0.0, 1.0)], settings, 8).unwrap();
    rebuilt.set_pending(vec![first[1].clone()]).unwrap();
    assert_eq!(
        rebuilt.suggest(2).unwrap(),
        vec![first[0].clone(), third[0].clone()]
    );
    let bad = Settings {
        initial_design: InitialDesign::MaximinLatinHypercube { candidates: 0 },
        ..Settings::default()
    };
    assert!(matches!(
        Optimizer::new(&[(0.0, 1.0)], bad, 0),
        Err(BoError::InvalidSetting(_))
    ));
}

#[test]
fn warps_are_monotone_and_invertible() {
    let z = vec![-300.0, -120.0, -50.0, -20.0, -5.0, -1.0, -0.5, -0.4];
    let t = TailWarp::fit(&z).unwrap();
    let r = RankWarp::fit(&z).unwrap();
    for w in [Warp::Tail(t), Warp::Rank(r)] {
        let mut prev = f64::NEG_INFINITY;
        for &v in &z {
            let f = w.forward(v);
            assert!(f > prev);
            prev = f;
            assert!(
                (w.inverse(f) - v).abs() < 1e-9 * v.abs().max(1.0),
                "{w:?} {v}"
            );
            assert!(w.slope_at_image(f) > 0.0);
        }
    }
    // the tail warp leaves the good half unchanged and compresses the bad tail
    assert_eq!(t.forward(-0.4), -0.4);
    assert!(t.forward(-5.0) - t.forward(-300.0) < 295.0 / 5.0);
    assert!(TailWarp::fit(&[1.0, 1.0, 1.0]).is_none());
    assert!(RankWarp::fit(&[1.0, 1.0, 1.0]).is_none());
}
