//! The grid of `--axes` and `--steps`: the counts per axis and the size limits.

use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{Object, ParamKind, TrialSpace};
use graspopt_trial::Evaluator;
use graspopt_trial::scan::{Grid, MAX_GRID_POINTS, grid_points, grid_steps};

#[test]
fn one_count_applies_to_every_axis_and_several_are_taken_in_order() {
    assert_eq!(grid_steps("5", 3).unwrap(), [5, 5, 5]);
    assert_eq!(grid_steps(" 3, 4 ", 2).unwrap(), [3, 4]);
}

#[test]
fn bad_counts_are_refused_with_the_flag_named() {
    let msg = |text: &str, axes: usize| grid_steps(text, axes).unwrap_err().to_string();
    assert_eq!(
        msg("0", 1),
        "--steps: expected whole numbers >= 1, got \"0\""
    );
    assert_eq!(
        msg("3,x", 2),
        "--steps: expected whole numbers >= 1, got \"x\""
    );
    assert_eq!(msg("3,4,5", 2), "--steps has 3 values for 2 axes");
    assert_eq!(
        msg("4000,4000", 2),
        "--steps 4000,4000: a grid of 16000000 points is more than the 10000000 allowed; \
         use fewer steps or axes"
    );
    // The largest grid allowed passes.
    assert_eq!(
        grid_steps(&MAX_GRID_POINTS.to_string(), 1).unwrap(),
        [MAX_GRID_POINTS]
    );
}

#[test]
fn a_grid_too_large_to_count_is_an_error_not_an_overflow() {
    assert_eq!(grid_points(&[3, 4, 5]).unwrap(), 60);
    let e = grid_points(&[usize::MAX, 2]).unwrap_err().to_string();
    assert!(e.contains("more points than can be counted"), "{e}");
}

#[test]
fn a_grid_spans_the_whole_trial_space() {
    let object = Object::by_name("sphere").unwrap();
    let kinds = vec![ParamKind::Approach, ParamKind::Vertical];
    let space = TrialSpace::with_params(&object, &kinds).unwrap();
    let bounds = space.bounds();
    let ev = Evaluator::new(object, hand_by_name("barrett").unwrap(), space);
    let grid = Grid::new(ev, kinds, vec![3, 2]);
    assert_eq!(grid.points(), 6);
    assert_eq!(grid.axes.len(), 2);
    let close = |a: f64, b: f64| (a - b).abs() < 1e-15;
    let (lo, hi) = bounds[0];
    assert_eq!(grid.axes[0].len(), 3);
    for (v, want) in grid.axes[0].iter().zip([lo, (lo + hi) / 2.0, hi]) {
        assert!(close(*v, want), "{:?} vs {:?}", grid.axes[0], bounds[0]);
    }
    assert_eq!(grid.axes[1].len(), 2);
    assert!(close(grid.axes[1][0], bounds[1].0) && close(grid.axes[1][1], bounds[1].1));
}
