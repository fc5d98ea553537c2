//! Scoring simulated trials: the no-contact score, BW against epsilon, frames, scans.

use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{Object, TrialSpace};
use graspopt_trial::scan::{linspace, scan_grid};
use graspopt_trial::score::{ReferenceFrame, wrench_norm_bound};
use graspopt_trial::{Evaluator, Metric};

fn sphere_evaluator() -> Evaluator {
    let object = Object::by_name("sphere").unwrap();
    let space = TrialSpace::approach_1d(&object);
    Evaluator::new(object, hand_by_name("barrett").unwrap(), space)
}

#[test]
fn no_contact_scores_below_every_touching_grasp_and_improves_nearer() {
    let ev = sphere_evaluator();
    let (lo, hi) = ev.space.bounds()[0];
    let points = scan_grid(&ev, &[linspace(lo, hi, 31)], 0, &|_| {}).unwrap();
    let untouched: Vec<_> = points.iter().filter(|p| p.score.contacts == 0).collect();
    let touched: Vec<_> = points.iter().filter(|p| p.score.contacts > 0).collect();
    assert!(!untouched.is_empty() && !touched.is_empty());
    let worst_touching = touched
        .iter()
        .map(|p| p.score.score)
        .fold(f64::INFINITY, f64::min);
    let best_untouched = untouched
        .iter()
        .map(|p| p.score.score)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(
        best_untouched < worst_touching,
        "{best_untouched} vs {worst_touching}"
    );
    for p in &touched {
        let m = p.score.metrics.unwrap();
        // Every touching score is above -B, the bound on wrench norms.
        let model = graspopt_trial::score::grasp_model(
            &ev.evaluate(&p.params).unwrap().outcome,
            &ev.object,
            &ev.score,
        )
        .unwrap();
        assert!(m.bw() >= -wrench_norm_bound(&ev.object, &model));
        assert!(p.score.score.is_finite());
    }
    // Farther away scores no better than nearer (monotone in the gap, capped at 1 rho).
    let first = untouched.first().unwrap().score.score;
    let last = untouched.last().unwrap().score.score;
    assert!(first <= last);
}

#[test]
fn bw_equals_epsilon_in_force_closure_and_scores_follow_the_metric() {
    let mut ev = sphere_evaluator();
    // Inside the sphere's force-closure window (+0.005 to +0.02 with the corrected BH8: the
    // fingers wrap the sphere with the palm near it; farther, the bent fingertips meet it).
    let x = [0.01];
    let bw = ev.evaluate(&x).unwrap().score;
    let m = bw.metrics.unwrap();
    assert!(m.force_closure(), "{m:?}");
    assert_eq!(bw.score, m.epsilon());
    assert_eq!(bw.fingers_in_contact, 3);
    ev.score.metric = Metric::Epsilon;
    assert_eq!(ev.score(&x).unwrap(), m.epsilon());
    ev.score.metric = Metric::Volume;
    assert!(ev.score(&x).unwrap() > 0.0);
    assert!(Metric::parse("gwv").is_ok() && Metric::parse("area").is_err());
}

#[test]
fn world_and_palm_frames_change_values_not_closure() {
    let mut ev = sphere_evaluator();
    ev.score.torque_scale = Some(0.05);
    let x = [-0.1];
    let object = ev.evaluate(&x).unwrap().score.metrics.unwrap();
    for frame in [
        ReferenceFrame::World,
        ReferenceFrame::Palm,
        ReferenceFrame::Point([0.3, 0.0, 0.1]),
    ] {
        ev.score.frame = frame;
        let m = ev.evaluate(&x).unwrap().score.metrics.unwrap();
        assert_eq!(m.force_closure(), object.force_closure(), "{frame:?}");
        assert_eq!(m.rank(), object.rank());
    }
}

#[test]
fn scans_are_in_grid_order_and_match_single_evaluations() {
    let object = Object::by_name("cylinder").unwrap();
    let space = TrialSpace::approach_vertical_2d(&object);
    let b = space.bounds();
    let ev = Evaluator::new(object, hand_by_name("barrett").unwrap(), space);
    let axes = vec![linspace(b[0].0, b[0].1, 4), linspace(b[1].0, b[1].1, 3)];
    let calls = std::sync::atomic::AtomicUsize::new(0);
    let points = scan_grid(&ev, &axes, 2, &|_| {
        calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    })
    .unwrap();
    assert_eq!(points.len(), 12);
    assert_eq!(calls.into_inner(), 12);
    assert_eq!(points[1].params, vec![axes[0][0], axes[1][1]]);
    assert_eq!(points[3].params, vec![axes[0][1], axes[1][0]]);
    for p in [&points[0], &points[7], &points[11]] {
        assert_eq!(ev.score(&p.params).unwrap(), p.score.score);
    }
    assert!(scan_grid(&ev, &axes[..1], 1, &|_| {}).is_err());
    assert!(scan_grid(&ev, &[vec![], vec![0.0]], 1, &|_| {}).is_err());
    let err = scan_grid(&ev, &[vec![f64::NAN], vec![0.0]], 1, &|_| {}).unwrap_err();
    assert!(
        err.to_string().contains("NaN") || err.to_string().contains("finite"),
        "{err}"
    );
}

/// A trial scored from its raw clouds alone (what a metric agent receives) equals the same
/// trial scored whole, for touching and non-touching trials.
#[test]
fn measured_clouds_score_like_the_whole_trial() {
    use graspopt_trial::measured::{MeasuredTrial, score_measured};
    let object = graspopt_sim::Object::by_name("mug").unwrap();
    let hand = graspopt_sim::hand_by_name("barrett").unwrap();
    let space = graspopt_sim::TrialSpace::approach_vertical_2d(&object);
    let evaluator = graspopt_trial::Evaluator::new(object.clone(), hand, space);
    let mut touched = 0;
    for params in [[0.0, 0.0], [-0.03, 0.02], [-0.16, 0.0], [0.015, -0.04]] {
        let e = evaluator.evaluate(&params).unwrap();
        let measured = MeasuredTrial::from_outcome(&e.outcome);
        let (score, _) =
            score_measured(&measured, &object, &evaluator.contacts, &evaluator.score).unwrap();
        assert_eq!(score, e.score, "params {params:?}");
        touched += usize::from(e.outcome.touched);
    }
    assert!((2..4).contains(&touched), "{touched} of 4 trials touched");
}

/// A full-rank grasp whose dense wrench set defeated the hull's small joggles (the star
/// prism's edges under barrett_ft's fingertips, surface and patch models): its volume is
/// available, and holds the ball of radius epsilon when it is force-closure.
#[test]
fn a_full_rank_grasp_whose_hull_needs_a_joggle_has_a_volume() {
    use graspopt_sim::ContactModel;
    use graspopt_trial::TrialSettings;

    for contacts in [ContactModel::Surface, ContactModel::CircularPatch] {
        let settings = TrialSettings {
            object: "star_prism".into(),
            hand: "barrett_ft".into(),
            contacts,
            metric: Metric::Volume,
            ..TrialSettings::default()
        };
        let ev = Evaluator::from_settings(&settings, &[]).unwrap();
        let e = ev
            .evaluate(&[])
            .unwrap_or_else(|err| panic!("{contacts}: {err}"));
        let m = e.score.metrics.unwrap();
        assert_eq!(m.rank(), 6, "{contacts}");
        let volume = m.volume().expect("a volume");
        assert!(volume.is_finite() && volume > 0.0, "{contacts}: {volume}");
        assert_eq!(e.score.score, volume);
        if m.force_closure() {
            // The 6-ball of radius epsilon lies inside the hull: pi^3 / 6 r^6.
            let ball = std::f64::consts::PI.powi(3) / 6.0 * m.epsilon().powi(6);
            assert!(volume > ball, "{contacts}: {volume} <= {ball}");
        }
    }
}
