//! Simulated fingertip sensors: readings made from the simulator's fingertip contacts give
//! those contacts back (intrinsic contact sensing), exactly without noise.

use graspopt_sensing::{SensingSettings, SensorNoise};
use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{Object, TrialSpace};
use graspopt_trial::fingertips::{
    FingertipSettings, SimulatedFingertip, fingertips, sense, simulate_wrenches,
};
use graspopt_trial::forces::ForceSettings;
use graspopt_trial::{Evaluation, Evaluator, ScoreSettings};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The fingertip readings of trial `e` of `ev`, with the default score and load.
fn readings(
    ev: &Evaluator,
    e: &Evaluation,
    settings: &FingertipSettings,
    rng: &mut ChaCha8Rng,
) -> Vec<SimulatedFingertip> {
    simulate_wrenches(
        &e.outcome,
        ev.hand.as_ref(),
        &ev.object,
        &ScoreSettings::default(),
        &ForceSettings::default(),
        settings,
        rng,
    )
    .unwrap()
}

#[test]
fn barrett_ft_has_one_spherical_fingertip_per_finger_and_barrett_has_none() {
    let ft = hand_by_name("barrett_ft").unwrap();
    let tips = fingertips(ft.as_ref()).unwrap();
    let fingers: Vec<usize> = tips.iter().map(|t| t.finger).collect();
    assert_eq!(fingers, [0, 1, 2]);
    assert!(tips.iter().all(|t| (t.radius - 0.012).abs() < 1e-15));
    let err = fingertips(hand_by_name("barrett").unwrap().as_ref()).unwrap_err();
    assert!(err.to_string().contains("no spherical fingertips"), "{err}");
}

#[test]
fn noise_free_readings_give_back_the_fingertip_contacts_on_every_object() {
    let exact = FingertipSettings {
        noise: SensorNoise::NONE,
        ..FingertipSettings::default()
    };
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut checked = 0;
    for name in Object::names() {
        let object = Object::by_name(name).unwrap();
        let space = TrialSpace::full_6d(&object);
        let ev = Evaluator::new(object, hand_by_name("barrett_ft").unwrap(), space);
        for _ in 0..20 {
            let u: Vec<f64> = (0..ev.space.dim()).map(|_| rng.random::<f64>()).collect();
            let params = ev.space.from_unit(&u).unwrap();
            let e = ev.evaluate(&params).unwrap();
            let tips = readings(&ev, &e, &exact, &mut rng);
            for tip in &tips {
                let got = sense(&tip.sensor, &SensingSettings::default()).unwrap_or_else(|e| {
                    panic!("{name} {params:?} finger {}: {e}", tip.sensor.finger)
                });
                let dp = (got.point - tip.truth.point).norm();
                // atan2 of the cross and dot products: acos loses half the digits near 0.
                let (a, b) = (got.normal, tip.truth.normal);
                let angle = a.cross(&b).norm().atan2(a.dot(&b));
                assert!(
                    dp <= 1e-9,
                    "{name} finger {}: point off by {dp}",
                    tip.sensor.finger
                );
                assert!(
                    angle <= 1e-9,
                    "{name} finger {}: normal off by {angle}",
                    tip.sensor.finger
                );
                assert!(
                    (got.force - tip.truth.force).norm() <= 1e-9 * (1.0 + tip.truth.force.norm())
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 30, "only {checked} fingertip contacts");
}

#[test]
fn averaging_sixteen_samples_quarters_the_error_of_a_reading() {
    let object = Object::by_name("cuboid").unwrap();
    let space = TrialSpace::full_6d(&object);
    let ev = Evaluator::new(object, hand_by_name("barrett_ft").unwrap(), space);
    let median_error = |samples: u32| {
        let settings = FingertipSettings {
            samples,
            ..FingertipSettings::default()
        };
        let mut trials = ChaCha8Rng::seed_from_u64(3);
        let mut noise = ChaCha8Rng::seed_from_u64(4);
        let mut errors = Vec::new();
        for _ in 0..120 {
            let u: Vec<f64> = (0..ev.space.dim())
                .map(|_| trials.random::<f64>())
                .collect();
            let e = ev.evaluate(&ev.space.from_unit(&u).unwrap()).unwrap();
            let tips = readings(&ev, &e, &settings, &mut noise);
            for tip in &tips {
                let sensing = graspopt_trial::fingertips::soft_finger_sensing();
                let got = sense(&tip.sensor, &sensing).unwrap();
                errors.push((got.point - tip.truth.point).norm());
            }
        }
        assert!(errors.len() >= 20, "{} fingertip contacts", errors.len());
        errors.sort_by(f64::total_cmp);
        errors[errors.len() / 2]
    };
    let (one, sixteen) = (median_error(1), median_error(16));
    assert!(one > 0.0 && sixteen > 0.0);
    let ratio = one / sixteen;
    assert!(
        (2.5..=6.0).contains(&ratio),
        "median error {one} with 1 sample, {sixteen} with 16"
    );
}
