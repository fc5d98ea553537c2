//! The metric agent's scoring of fingertip force/torque readings (no bus): readings made
//! from simulated fingertip contacts score as those contacts do, their measured forces are
//! analysed, and readings that admit no contact are left out with their reason. Clouds whose
//! least forces the solver once gave up on get their force analysis.

use graspopt_convert::{TrialTag, clouds_from_outcome, pose};
use graspopt_metric::{MetricConfig, score_clouds, score_wrenches};
use graspopt_protocol::{FingertipWrench, FingertipWrenches, RunId};
use graspopt_sensing::SensorNoise;
use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{ContactModelSettings, Object, ParamKind, TrialSpace};
use graspopt_trial::fingertips::{
    FingertipSettings, SimulatedFingertip, fingertip_score, simulate_wrenches,
};
use graspopt_trial::forces::ForceSettings;
use graspopt_trial::measured::{MeasuredTrial, score_measured};
use graspopt_trial::{Evaluation, Evaluator, ScoreSettings};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// A star-prism trial of barrett_ft where all three fingertips touch and the fingertip
/// contacts are in force closure, its exact readings, and the evaluator.
fn three_tip_trial() -> (Evaluator, Evaluation, Vec<SimulatedFingertip>) {
    let object = Object::by_name("star_prism").unwrap();
    let space =
        TrialSpace::with_params(&object, &[ParamKind::Approach, ParamKind::Vertical]).unwrap();
    let ev = Evaluator::new(object, hand_by_name("barrett_ft").unwrap(), space);
    let exact = FingertipSettings {
        noise: SensorNoise::NONE,
        ..FingertipSettings::default()
    };
    let (lo, hi) = (ev.space.bounds()[0], ev.space.bounds()[1]);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    for i in 0..40 {
        for j in 0..10 {
            let x = lo.0 + (lo.1 - lo.0) * f64::from(i) / 39.0;
            let y = hi.0 + (hi.1 - hi.0) * f64::from(j) / 9.0;
            let e = ev.evaluate(&[x, y]).unwrap();
            let tips = simulate_wrenches(
                &e.outcome,
                ev.hand.as_ref(),
                &ev.object,
                &ScoreSettings::default(),
                &ForceSettings::default(),
                &exact,
                &mut rng,
            )
            .unwrap();
            if tips.len() == 3 && truth_score(&ev, &e, &tips).metrics.unwrap().force_closure() {
                return (ev, e, tips);
            }
        }
    }
    panic!("no three-fingertip force-closure trial on the star prism");
}

fn truth_score(
    ev: &Evaluator,
    e: &Evaluation,
    tips: &[SimulatedFingertip],
) -> graspopt_trial::TrialScore {
    let truth: Vec<_> = tips
        .iter()
        .map(|t| (t.sensor.finger, t.sensor.link.clone(), t.truth))
        .collect();
    let m = MeasuredTrial::from_fingertips(ev.hand.name(), e.outcome.grasp.palm_pose, &truth, None);
    let score = fingertip_score(&ScoreSettings::default());
    score_measured(&m, &ev.object, &ContactModelSettings::default(), &score)
        .unwrap()
        .0
}

fn message(e: &Evaluation, tips: &[SimulatedFingertip]) -> FingertipWrenches {
    FingertipWrenches {
        run_id: RunId::new("ft").unwrap(),
        trial_id: 3,
        attempt: 1,
        worker: "ft-hand".into(),
        hand: "barrett_ft".into(),
        palm_pose: pose(&e.outcome.grasp.palm_pose),
        fingertips: tips
            .iter()
            .map(|t| FingertipWrench {
                finger: t.sensor.finger as u32,
                link: t.sensor.link.clone(),
                sensor_pose: pose(&t.sensor.sensor_pose),
                surface: t.sensor.surface,
                force: t.sensor.reading.force.into(),
                torque: t.sensor.reading.torque.into(),
                stamp_ms: 0,
            })
            .collect(),
        min_gap: None,
        error: None,
        executed_ms: 0,
    }
}

#[test]
fn exact_readings_score_as_their_contacts_and_their_forces_hold_the_weight() {
    let (ev, e, tips) = three_tip_trial();
    let config = MetricConfig::default();
    let (result, refused) = score_wrenches(&message(&e, &tips), &ev.object, &config);
    assert!(refused.is_empty(), "{refused:?}");
    assert_eq!(result.error, None);
    let truth = truth_score(&ev, &e, &tips);
    assert!(
        (result.score - truth.score).abs() <= 1e-9 * truth.score.abs(),
        "{} vs {}",
        result.score,
        truth.score
    );
    assert_eq!((result.cloud_points, result.fingers_in_contact), (3, 3));
    // The simulated hand applies the least forces that hold the weight: measured, they
    // cancel it, each inside its friction cone.
    let f = result.forces.expect("a force analysis");
    let net = f.net_wrench.expect("measured forces");
    for (n, w) in net.iter().zip(f.external) {
        assert!(
            (n + w).abs() <= 1e-6,
            "net {net:?} vs load {:?}",
            f.external
        );
    }
    assert_eq!(f.slip_margins.len(), 3);
    assert!(
        f.slip_margins.iter().all(|m| *m >= -1e-9),
        "{:?}",
        f.slip_margins
    );
    assert_eq!(f.can_resist(), Some(true));
    let weight = ForceSettings::default().object_mass * 9.81;
    assert!((f.external[2] + weight).abs() <= 1e-12, "{:?}", f.external);
}

#[test]
fn a_reading_without_contact_is_left_out_with_its_reason() {
    let (ev, e, tips) = three_tip_trial();
    let mut msg = message(&e, &tips);
    // Finger 2's tip feels almost nothing: below the contact threshold.
    msg.fingertips[1].force = [0.001, 0.0, 0.0];
    msg.fingertips[1].torque = [0.0; 3];
    let (result, refused) = score_wrenches(&msg, &ev.object, &MetricConfig::default());
    assert_eq!(refused.len(), 1, "{refused:?}");
    assert!(
        refused[0].starts_with(&format!("finger 1 ({})", tips[1].sensor.link))
            && refused[0].contains("below the contact threshold"),
        "{}",
        refused[0]
    );
    assert_eq!(result.error, None);
    assert_eq!(result.fingers_in_contact, 2);
    assert_eq!(result.forces.unwrap().slip_margins.len(), 2);
}

#[test]
fn a_hand_error_fails_the_trial_with_it() {
    let (ev, e, tips) = three_tip_trial();
    let mut msg = message(&e, &tips);
    msg.fingertips.clear();
    msg.error = Some("sensor 2 saturated".into());
    let (result, _) = score_wrenches(&msg, &ev.object, &MetricConfig::default());
    assert_eq!(result.error.as_deref(), Some("sensor 2 saturated"));
    assert_eq!(result.forces, None);
}

/// A sphere trial whose least forces Clarabel gave up on when it solved the program once
/// (issue 29: the agent logged "WARN ... the conic solver failed" in the middle of a run and
/// the result had no force analysis). Its clouds now get one: solved again, the forces hold
/// the weight, and they are linear in it (0.6 times the mass, 0.6 times the forces).
#[test]
fn clouds_the_solver_once_gave_up_on_get_their_force_analysis() {
    let object = Object::by_name("sphere").unwrap();
    let space =
        TrialSpace::with_params(&object, &[ParamKind::Approach, ParamKind::Vertical]).unwrap();
    let ev = Evaluator::new(object, hand_by_name("barrett").unwrap(), space);
    let e = ev
        .evaluate(&[0.012411758742978396, 0.0361960938036442])
        .unwrap();
    let tag = TrialTag {
        run_id: RunId::new("forces").unwrap(),
        trial_id: 9,
        attempt: 1,
        worker: "hand-1".into(),
    };
    let clouds = clouds_from_outcome(&tag, &e.outcome, 0);
    let analysed = |mass: f64| {
        let mut config = MetricConfig::default();
        config.forces.object_mass = mass;
        let result = score_clouds(&clouds, &ev.object, &config);
        assert_eq!(result.error, None);
        assert_eq!(result.score, e.score.score);
        result.forces.expect("a force analysis")
    };
    let f = analysed(0.5);
    assert_eq!(
        (f.can_resist(), f.unavailable.as_deref()),
        (Some(true), None)
    );
    let norm = f.resisting_norm.unwrap();
    let lighter = analysed(0.3).resisting_norm.unwrap();
    assert!(
        (lighter / 0.6 - norm).abs() <= 1e-6 * norm,
        "{norm} vs {lighter}"
    );
}
