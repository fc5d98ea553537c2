//! The 100 reference cases of `shared/reference/metric-cases.json` (a copy lives in
//! `tests/data/`): every metric within 1e-7 absolute or 1e-6 relative, rank and force
//! closure exactly; the wrenches generated from the contacts equal the file's; Clarabel
//! agrees with the min-norm solver; the expanding polytope agrees with the full hull.

use graspopt_quality::cases::{Case, CaseFile};
use graspopt_quality::hull::{epa, quickhull};
use graspopt_quality::metrics::{
    DistanceSolver, MetricsOptions, Value as MetricValue, distance_to_hull, evaluate,
};
use graspopt_quality::{GraspMap, Wrench};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde_json::Value;

fn cases() -> Vec<Case> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/metric-cases.json"
    );
    let text = std::fs::read_to_string(path).expect("reference file");
    serde_json::from_str::<CaseFile>(&text)
        .expect("the case file's types")
        .cases
}

fn grasp(case: &Case) -> GraspMap {
    case.grasp_map().unwrap()
}

fn reference_wrenches(case: &Case) -> Vec<Wrench> {
    let wrenches = case.wrenches.as_ref().expect("the reference wrenches");
    wrenches.iter().map(|w| Wrench::from_row_slice(w)).collect()
}

fn close(actual: f64, expected: f64) -> bool {
    (actual - expected).abs() <= 1e-7 || (actual - expected).abs() <= 1e-6 * expected.abs()
}

#[test]
fn all_reference_cases_match() {
    let cases = cases();
    assert_eq!(cases.len(), 100);
    let mut failures = Vec::new();
    for (i, case) in cases.iter().enumerate() {
        let g = grasp(case);
        let m = evaluate(&g, &MetricsOptions::default()).unwrap();
        let e = case.expected.expect("the expected values");
        assert!(
            e.iter().filter(|(_, v)| v.is_some()).count() >= 6,
            "case {i}: the reference has the six hull metrics"
        );
        let mut bad = Vec::new();
        // Every metric the reference has: counts and flags exactly, reals within tolerance.
        for ((def, value), (_, expected)) in m.iter().zip(e.iter()) {
            let (Some(value), Some(expected)) = (value, expected) else {
                continue;
            };
            let same = match (value, expected) {
                (MetricValue::Real(a), MetricValue::Real(b)) => close(a, b),
                (a, b) => a == b,
            };
            if !same {
                bad.push(format!("{} {value:?} vs {expected:?}", def.key));
            }
        }
        if !bad.is_empty() {
            failures.push(format!("case {i}: {}", bad.join(", ")));
        }
    }
    assert!(
        failures.is_empty(),
        "{} cases differ:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn generated_wrenches_equal_the_reference_wrenches() {
    for (i, case) in cases().iter().enumerate() {
        let ours = grasp(case);
        let theirs = reference_wrenches(case);
        assert_eq!(ours.wrenches().len(), theirs.len(), "case {i}");
        for (k, (a, b)) in ours.wrenches().iter().zip(&theirs).enumerate() {
            assert!((a - b).norm() < 1e-12, "case {i} wrench {k}: {a} vs {b}");
        }
        // The wrenches alone give the same metrics as the contacts.
        let from_wrenches = GraspMap::from_wrenches(theirs).unwrap();
        let a = evaluate(&ours, &MetricsOptions::without_volume()).unwrap();
        let b = evaluate(&from_wrenches, &MetricsOptions::without_volume()).unwrap();
        assert!(close(a.bw(), b.bw()), "case {i}");
    }
}

#[test]
fn clarabel_agrees_with_the_min_norm_solver() {
    for (i, case) in cases().iter().enumerate() {
        let g = grasp(case);
        let fast = distance_to_hull(g.wrenches(), DistanceSolver::MinNorm).unwrap();
        let qp = distance_to_hull(g.wrenches(), DistanceSolver::Clarabel).unwrap();
        assert!(
            (fast - qp).abs() < 1e-7,
            "case {i}: min-norm {fast:e}, clarabel {qp:e}"
        );
    }
}

#[test]
fn expanding_polytope_agrees_with_the_full_hull() {
    let mut checked = 0;
    for (i, case) in cases().iter().enumerate() {
        let g = grasp(case);
        let Ok(hull) = quickhull::Hull::new(g.wrenches()) else {
            continue;
        };
        let full = hull.min_offset();
        if full <= 0.0 {
            continue; // origin outside: the expanding polytope only certifies that
        }
        let inner = epa::inner_distance(g.wrenches()).unwrap();
        assert!(
            (inner.offset - full).abs() < 1e-9,
            "case {i}: epa {} vs hull {full}",
            inner.offset
        );
        checked += 1;
    }
    assert!(checked >= 40, "only {checked} force-closure cases");
}

/// A surface-model wrench set on which the expanding polytope once asked for a point it
/// had already added (the polytope went non-convex in rounding) and grew without bound.
/// It must now finish, with a radius whose ball fits inside the exact hull: along every
/// direction the support function reaches at least that radius (up to the joggle the
/// recovery may use, at most 1e-6 of the coordinate scale).
#[test]
fn expanding_polytope_terminates_on_a_near_degenerate_surface_model() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/epa-regression.json"
    );
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let w: Vec<Wrench> = doc["wrenches"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| Wrench::from_iterator(w.as_array().unwrap().iter().map(|x| x.as_f64().unwrap())))
        .collect();
    assert_eq!(w.len(), 960);
    let m = evaluate(
        &GraspMap::from_wrenches(w.clone()).unwrap(),
        &MetricsOptions::without_volume(),
    )
    .unwrap();
    assert!(m.force_closure() && m.epsilon() > 0.01, "{m:?}");
    let scale = w
        .iter()
        .flat_map(|x| x.iter())
        .fold(0.0f64, |a, b| a.max(b.abs()));
    let mut rng = ChaCha8Rng::seed_from_u64(0x1234_5678_9abc_def1);
    let mut normal = move || rng.sample::<f64, _>(StandardNormal);
    let mut tightest = f64::INFINITY;
    for _ in 0..20_000 {
        let u = Wrench::from_fn(|_, _| normal()).normalize();
        let support = w
            .iter()
            .map(|x| x.dot(&u))
            .fold(f64::NEG_INFINITY, f64::max);
        tightest = tightest.min(support);
        assert!(
            support >= m.epsilon() - 1e-6 * scale * 6.0,
            "ball pokes out along {u}"
        );
    }
    // Sampled directions only bound epsilon from above: it must not exceed them.
    assert!(m.epsilon() <= tightest + 1e-6 * scale * 6.0);
    // The volume is requested: the hull of these points needs a joggle beyond 1e-6 (it
    // failed before the larger ones); were it not built, that is an error naming the
    // problem, never a silent 0.
    match evaluate(
        &GraspMap::from_wrenches(w).unwrap(),
        &MetricsOptions::default(),
    ) {
        Ok(m) => assert!(m.volume().unwrap() > 0.0),
        Err(e) => assert!(e.to_string().contains("could not be built"), "{e}"),
    }
}
