//! Noise-free round trips: a contact through the forward model and back.

use graspopt_sensing::{ContactKind, FingertipSurface, SensingSettings, locate, wrench_of};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::support::{angle, capsule, cone_force, ellipsoid, sphere, surface_point};

/// Round trips of `count` random contacts on `surface`: forces with a normal part of 1
/// to 5 N inside a friction cone of mu 0.5, torsions up to 2 mN m for the soft finger.
/// Returns the worst position (m), normal (rad) and torsion (N m) errors.
fn round_trips(surface: &FingertipSurface, kind: ContactKind, count: usize, seed: u64) -> [f64; 3] {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let settings = SensingSettings {
        kind,
        ..SensingSettings::default()
    };
    let mut worst = [0.0_f64; 3];
    for i in 0..count {
        let p = surface_point(surface, &mut rng);
        let n = surface.outward_normal(&p);
        let f = cone_force(&n, 0.5, 1.0, 5.0, &mut rng);
        let t = match kind {
            ContactKind::Point => 0.0,
            ContactKind::SoftFinger => 2e-3 * (2.0 * rng.random::<f64>() - 1.0),
        };
        let r = wrench_of(surface, &p, &f, t);
        let c = match locate(surface, &r, &settings) {
            Ok(c) => c,
            Err(e) => panic!("case {i}: point {p:?}, force {f:?}, torsion {t}: {e}"),
        };
        worst[0] = worst[0].max((c.point - p).norm());
        worst[1] = worst[1].max(angle(&c.normal, &n));
        worst[2] = worst[2].max((c.torsion - t).abs());
        assert_eq!(c.force, f, "case {i}");
    }
    worst
}

fn check(surface: &FingertipSurface, seed: u64) {
    for kind in [ContactKind::Point, ContactKind::SoftFinger] {
        let [dp, dn, dt] = round_trips(surface, kind, 5000, seed);
        println!(
            "{surface:?} {kind:?}: worst position {dp:.2e} m, normal {dn:.2e} rad, torsion {dt:.2e} N m"
        );
        assert!(dp < 1e-9, "{kind:?}: position error {dp} m");
        assert!(dn < 1e-9, "{kind:?}: normal error {dn} rad");
        assert!(dt < 1e-12, "{kind:?}: torsion error {dt} N m");
    }
}

#[test]
fn sphere_round_trips() {
    check(&sphere(), 1);
    // Mounted below its centre: only the upper half can be touched.
    let mounted = FingertipSurface::Sphere {
        center: [0.0, 0.0, 0.012],
        radius: 0.006,
        base_z: Some(0.012),
    };
    check(&mounted, 2);
}

#[test]
fn ellipsoid_round_trips() {
    check(&ellipsoid(), 3);
    let flat = FingertipSurface::Ellipsoid {
        center: [0.002, 0.0, 0.015],
        semi_axes: [0.012, 0.004, 0.007],
        base_z: Some(0.01),
    };
    check(&flat, 4);
}

#[test]
fn capsule_round_trips() {
    check(&capsule(), 5);
    let whole = FingertipSurface::Capsule {
        center: [0.001, 0.002, 0.025],
        half_length: 0.015,
        radius: 0.007,
        base_z: None,
    };
    check(&whole, 6);
    // A capsule of length 0 is a sphere.
    let ball = FingertipSurface::Capsule {
        center: [0.0, 0.0, 0.01],
        half_length: 0.0,
        radius: 0.008,
        base_z: None,
    };
    check(&ball, 7);
}
