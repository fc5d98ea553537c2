//! The sensor noise model, and the contact errors it causes (Nano17 resolution on a
//! 12 mm fingertip).

use graspopt_sensing::{
    ContactKind, FingertipSurface, FingertipWrench, NoContact, SensingSettings, SensorNoise,
    locate, wrench_of,
};
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::support::{angle, cone_force, surface_point};

#[test]
fn no_noise_changes_nothing() {
    let r = FingertipWrench {
        force: Vector3::new(0.123456789, -1.0, 2.5),
        torque: Vector3::new(1e-7, 3e-3, -2e-5),
    };
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    assert_eq!(SensorNoise::NONE.apply(&r, &mut rng), r);
}

#[test]
fn noise_is_quantised_and_of_the_resolution_size() {
    let noise = SensorNoise::default();
    let (qf, qt) = (noise.force_resolution, noise.torque_resolution);
    let r = FingertipWrench {
        force: Vector3::new(1.23456, -0.5, 2.0),
        torque: Vector3::new(1.7e-3, -2.2e-4, 3e-5),
    };
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let count = 20_000;
    let (mut sum, mut sum_sq) = (0.0, 0.0);
    for _ in 0..count {
        let n = noise.apply(&r, &mut rng);
        for i in 0..3 {
            // Every component is a multiple of its resolution.
            let kf = n.force[i] / qf;
            let kt = n.torque[i] / qt;
            assert!((kf - kf.round()).abs() < 1e-6, "force {}", n.force[i]);
            assert!((kt - kt.round()).abs() < 1e-6, "torque {}", n.torque[i]);
        }
        let e = (n.force.x - r.force.x) / qf;
        sum += e;
        sum_sq += e * e;
    }
    // A Gaussian of standard deviation q then rounding: mean 0, variance about
    // q^2 (1 + 1/12).
    let mean = sum / count as f64;
    let std = (sum_sq / count as f64 - mean * mean).sqrt();
    assert!(mean.abs() < 0.03, "mean error {mean} resolutions");
    assert!(
        (std - (1.0 + 1.0 / 12.0_f64).sqrt()).abs() < 0.03,
        "std {std} resolutions"
    );
}

/// Median position and normal errors over `count` noisy readings of contacts on
/// `surface` with forces of 1 to 5 N (normal part) in a friction cone of mu 0.5, and the
/// share of readings refused.
fn noisy_errors(surface: &FingertipSurface, kind: ContactKind, count: usize) -> (f64, f64, f64) {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let settings = SensingSettings {
        kind,
        ..SensingSettings::default()
    };
    let noise = SensorNoise::default();
    let (mut dp, mut dn) = (Vec::new(), Vec::new());
    let mut refused = 0;
    for _ in 0..count {
        let p = surface_point(surface, &mut rng);
        let n = surface.outward_normal(&p);
        let f = cone_force(&n, 0.5, 1.0, 5.0, &mut rng);
        let r = noise.apply(&wrench_of(surface, &p, &f, 0.0), &mut rng);
        match locate(surface, &r, &settings) {
            Ok(c) => {
                dp.push((c.point - p).norm());
                dn.push(angle(&c.normal, &n));
            }
            Err(NoContact::Torsion { .. }) => refused += 1,
            Err(e) => panic!("noisy reading of {p:?}, {f:?} refused: {e}"),
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    (
        median(&mut dp),
        median(&mut dn),
        refused as f64 / count as f64,
    )
}

#[test]
fn nano17_noise_on_a_12_mm_fingertip() {
    // A 12 mm (diameter) sphere whose centre is 12 mm above the sensor, mounted at its
    // equator; and a capsule of the same radius.
    let sphere = FingertipSurface::Sphere {
        center: [0.0, 0.0, 0.012],
        radius: 0.006,
        base_z: Some(0.012),
    };
    let capsule = FingertipSurface::Capsule {
        center: [0.0, 0.0, 0.02],
        half_length: 0.01,
        radius: 0.006,
        base_z: Some(0.012),
    };
    for surface in [sphere, capsule] {
        for kind in [ContactKind::Point, ContactKind::SoftFinger] {
            let (dp, dn, refused) = noisy_errors(&surface, kind, 4000);
            println!(
                "{surface:?} {kind:?}: median position error {:.4} mm, normal error {:.3} deg, refused {:.2}%",
                dp * 1e3,
                dn.to_degrees(),
                refused * 100.0
            );
            // Issue #20 asks for at most 0.5 mm and 2 degrees; the model gives a fifth
            // of that, so a fifth is the bound.
            assert!(dp < 0.1e-3, "median position error {dp} m");
            assert!(dn < 0.4f64.to_radians(), "median normal error {dn} rad");
            assert!(refused < 0.01, "refused {refused}");
        }
    }
}
