//! Contact regions seen through the scores: the result converges in the contact
//! computation's one setting, and the star prism's approach scan has no period tied to it.

use graspopt_sim::contact::DEFAULT_RESOLUTION;
use graspopt_sim::{BarrettOracle, Object, TrialSpace};
use graspopt_trial::Evaluator;
use graspopt_trial::scan::{ScanPoint, grid_axes, scan_grid};

fn scan(object: &str, two_d: bool, steps: &[usize], resolution: f64) -> Vec<ScanPoint> {
    let object = Object::by_name(object).unwrap();
    let space = if two_d {
        TrialSpace::approach_vertical_2d(&object)
    } else {
        TrialSpace::approach_1d(&object)
    };
    let mut ev = Evaluator::new(object, Box::new(BarrettOracle::default()), space);
    ev.contacts.cloud.resolution = resolution;
    let axes = grid_axes(&ev.space.bounds(), steps);
    scan_grid(&ev, &axes, 0, &|_| {}).unwrap()
}

fn closure(p: &ScanPoint) -> bool {
    p.score.metrics.is_some_and(|m| m.force_closure())
}

#[test]
fn halving_the_resolution_keeps_the_star_prisms_scores() {
    let a = scan("star_prism", true, &[13, 5], DEFAULT_RESOLUTION);
    let b = scan("star_prism", true, &[13, 5], DEFAULT_RESOLUTION / 2.0);
    let mut touching = 0;
    let mut rel = Vec::new();
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(closure(x), closure(y), "at {:?}", x.params);
        let (sx, sy) = (x.score.score, y.score.score);
        rel.push((sx - sy).abs() / sy.abs().max(1e-3));
        touching += usize::from(x.score.contacts > 0);
    }
    rel.sort_by(f64::total_cmp);
    let p95 = rel[(rel.len() as f64 * 0.95).ceil() as usize - 1];
    // The criterion is the 95th percentile. Not every point has converged at the
    // default resolution: with the corrected BH8, one of the 65 changes by 0.19 (listed in
    // docs/benchmarks.md).
    assert!(p95 <= 1e-3, "95th percentile {p95:e}; all: {rel:?}");
    assert!(touching > 20, "{touching}");
}

#[test]
fn the_star_prisms_approach_scan_flips_force_closure_rarely() {
    // 181 points, 1 mm apart: the 2.5 mm sample grid on the links of the old clouds flipped
    // force closure 67 times here (5 with the regions).
    let points = scan("star_prism", false, &[181], DEFAULT_RESOLUTION);
    let flips = points
        .windows(2)
        .filter(|w| closure(&w[0]) != closure(&w[1]))
        .count();
    let with = points.iter().filter(|p| closure(p)).count();
    assert!(flips <= 10, "{flips} flips");
    assert!(with > 10, "force closure at {with} points");
}
