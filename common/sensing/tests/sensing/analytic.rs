//! Contacts with known answers, readings written out by hand.

use graspopt_sensing::{
    ContactKind, FingertipSurface, FingertipWrench, NoContact, SensedContact, SensingSettings,
    locate, wrench_of,
};
use nalgebra::{Point3, Unit, Vector3};

use crate::support::angle;

const H: f64 = std::f64::consts::FRAC_1_SQRT_2;

fn sphere() -> FingertipSurface {
    FingertipSurface::Sphere {
        center: [0.0, 0.0, 0.01],
        radius: 0.008,
        base_z: None,
    }
}

fn reading(force: [f64; 3], torque: [f64; 3]) -> FingertipWrench {
    FingertipWrench {
        force: Vector3::from(force),
        torque: Vector3::from(torque),
    }
}

fn point_contact(surface: &FingertipSurface, r: &FingertipWrench) -> SensedContact {
    match locate(surface, r, &SensingSettings::default()) {
        Ok(c) => c,
        Err(e) => panic!("no contact for {r:?}: {e}"),
    }
}

/// Asserts the contact is at `point` with outward normal `normal` and applies -force.
fn assert_contact(c: &SensedContact, r: &FingertipWrench, point: [f64; 3], normal: [f64; 3]) {
    let expected = Point3::from(point);
    assert!(
        (c.point - expected).norm() < 1e-12,
        "point {:?}, expected {expected:?}",
        c.point
    );
    let n = Unit::new_normalize(Vector3::from(normal));
    assert!(
        angle(&c.normal, &n) < 1e-12,
        "normal {:?}, expected {n:?}",
        c.normal
    );
    assert_eq!(c.force, -r.force);
}

#[test]
fn sphere_pressed_along_known_directions() {
    let s = sphere();
    // Pressed straight down on the top.
    let r = reading([0.0, 0.0, -2.0], [0.0, 0.0, 0.0]);
    assert_contact(
        &point_contact(&s, &r),
        &r,
        [0.0, 0.0, 0.018],
        [0.0, 0.0, 1.0],
    );
    // Pressed along -x on the side: torque p x F = (0, -0.03, 0).
    let r = reading([-3.0, 0.0, 0.0], [0.0, -0.03, 0.0]);
    assert_contact(
        &point_contact(&s, &r),
        &r,
        [0.008, 0.0, 0.01],
        [1.0, 0.0, 0.0],
    );
    // Oblique force (with friction) on the top: torque (0, -0.018, 0).
    let r = reading([-1.0, 0.0, -2.0], [0.0, -0.018, 0.0]);
    assert_contact(
        &point_contact(&s, &r),
        &r,
        [0.0, 0.0, 0.018],
        [0.0, 0.0, 1.0],
    );
    // Pressed along the normal at 45 degrees in the y-z plane: torque (0.01 sqrt 2, 0, 0).
    let sq2 = std::f64::consts::SQRT_2;
    let r = reading([0.0, -sq2, -sq2], [0.01 * sq2, 0.0, 0.0]);
    let p = [0.0, 0.008 * H, 0.01 + 0.008 * H];
    assert_contact(&point_contact(&s, &r), &r, p, [0.0, 1.0, 1.0]);
    // The same readings with the soft-finger model: the same contacts, no torsion.
    let soft = SensingSettings {
        kind: ContactKind::SoftFinger,
        ..SensingSettings::default()
    };
    let c = locate(&s, &r, &soft).expect("soft-finger contact");
    assert_contact(&c, &r, p, [0.0, 1.0, 1.0]);
    assert!(c.torsion.abs() < 1e-15, "torsion {}", c.torsion);
}

#[test]
fn ellipsoid_contacts() {
    let e = FingertipSurface::Ellipsoid {
        center: [0.0, 0.0, 0.02],
        semi_axes: [0.01, 0.006, 0.015],
        base_z: None,
    };
    // The end of the x semi-axis, pushed along -x with a tangential part.
    let r = reading([-1.0, 0.2, 0.0], [-0.004, -0.02, 0.002]);
    assert_contact(
        &point_contact(&e, &r),
        &r,
        [0.01, 0.0, 0.02],
        [1.0, 0.0, 0.0],
    );
    // The top.
    let r = reading([0.0, 0.0, -1.5], [0.0, 0.0, 0.0]);
    assert_contact(
        &point_contact(&e, &r),
        &r,
        [0.0, 0.0, 0.035],
        [0.0, 0.0, 1.0],
    );
    // At 60 degrees round the equator, pressed along its normal, the gradient
    // (x / a^2, y / b^2, 0).
    let (x, y) = (0.01 * 0.5, 0.006 * 3f64.sqrt() / 2.0);
    let n = Vector3::new(x / 1e-4, y / 3.6e-5, 0.0).normalize();
    let p = Vector3::new(x, y, 0.02);
    let f = -n * 2.5;
    let r = FingertipWrench {
        force: f,
        torque: p.cross(&f),
    };
    assert_contact(&point_contact(&e, &r), &r, p.into(), n.into());
}

#[test]
fn capsule_contacts_on_the_cylinder_and_each_cap() {
    let k = FingertipSurface::Capsule {
        center: [0.0, 0.0, 0.02],
        half_length: 0.01,
        radius: 0.006,
        base_z: None,
    };
    // On the cylinder, pushed inwards and down: torque (0, -0.047, 0).
    let r = reading([-2.0, 0.0, -0.5], [0.0, -0.047, 0.0]);
    assert_contact(
        &point_contact(&k, &r),
        &r,
        [0.006, 0.0, 0.025],
        [1.0, 0.0, 0.0],
    );
    // The top of the top cap, with a tangential part: torque (0, 0.0108, 0).
    let r = reading([0.3, 0.0, -2.0], [0.0, 0.0108, 0.0]);
    assert_contact(
        &point_contact(&k, &r),
        &r,
        [0.0, 0.0, 0.036],
        [0.0, 0.0, 1.0],
    );
    // The bottom of the bottom cap: torque (-0.0008, 0, 0).
    let r = reading([0.0, 0.2, 2.0], [-0.0008, 0.0, 0.0]);
    assert_contact(
        &point_contact(&k, &r),
        &r,
        [0.0, 0.0, 0.004],
        [0.0, 0.0, -1.0],
    );
    // 45 degrees round each cap, pressed along the normal.
    for (p, n) in [
        ([0.0, 0.006 * H, 0.03 + 0.006 * H], [0.0, H, H]),
        ([0.006 * H, 0.0, 0.01 - 0.006 * H], [H, 0.0, -H]),
    ] {
        let f = -Vector3::from(n) * 2.0;
        let r = FingertipWrench {
            force: f,
            torque: Vector3::from(p).cross(&f),
        };
        assert_contact(&point_contact(&k, &r), &r, p, n);
    }
    // Half a capsule radius in from the seam on the cylinder, the force pointing across
    // the top cap's region.
    let p = Vector3::new(0.0, -0.006, 0.029);
    let f = Vector3::new(0.5, 2.0, -1.0);
    let r = FingertipWrench {
        force: f,
        torque: p.cross(&f),
    };
    assert_contact(&point_contact(&k, &r), &r, p.into(), [0.0, -1.0, 0.0]);
}

#[test]
fn soft_finger_recovers_a_known_torsion() {
    let s = sphere();
    // At 45 degrees in the y-z plane: normal force 2 N, tangential 0.5 N along x (inside a
    // cone of mu 0.5), torsion 1.5 mN m about the normal, then the opposite one.
    let p = Vector3::new(0.0, 0.008 * H, 0.01 + 0.008 * H);
    let n = Vector3::new(0.0, H, H);
    let f = n * 2.0 + Vector3::new(0.5, 0.0, 0.0);
    for t in [1.5e-3, -1.5e-3] {
        // The sensor measures the opposite of the wrench on the object.
        let force = -f;
        let r = FingertipWrench {
            force,
            torque: p.cross(&force) - n * t,
        };
        let model = wrench_of(&s, &p.into(), &f, t);
        assert_eq!(model.force, r.force);
        assert!(
            (model.torque - r.torque).norm() < 1e-17,
            "{model:?} vs {r:?}"
        );
        let soft = SensingSettings {
            kind: ContactKind::SoftFinger,
            ..SensingSettings::default()
        };
        let c = locate(&s, &r, &soft).expect("soft-finger contact");
        assert_contact(&c, &r, p.into(), n.into());
        assert!(
            (c.torsion - t).abs() < 1e-15,
            "torsion {}, expected {t}",
            c.torsion
        );
        // The point model refuses it: the torque's component along the force is
        // -t n . F / |F| = 2 t / |f| (pitch 2 t / |f|^2, far above 0.2 mm).
        match locate(&s, &r, &SensingSettings::default()) {
            Err(NoContact::Torsion {
                torsion,
                pitch,
                tolerance,
            }) => {
                let expected = 2.0 * t / f.norm();
                assert!((torsion - expected).abs() < 1e-15, "torsion {torsion}");
                assert!((pitch - expected / f.norm()).abs() < 1e-15, "pitch {pitch}");
                assert_eq!(tolerance, 2e-4);
            }
            other => panic!("expected a Torsion refusal, got {other:?}"),
        }
    }
}

#[test]
fn soft_finger_torsion_on_an_ellipsoid_and_a_capsule() {
    let e = FingertipSurface::Ellipsoid {
        center: [0.0, 0.0, 0.02],
        semi_axes: [0.01, 0.006, 0.015],
        base_z: None,
    };
    let k = FingertipSurface::Capsule {
        center: [0.0, 0.0, 0.02],
        half_length: 0.01,
        radius: 0.006,
        base_z: None,
    };
    let soft = SensingSettings {
        kind: ContactKind::SoftFinger,
        ..SensingSettings::default()
    };
    // The end of the ellipsoid's x semi-axis; the capsule's cylinder and its top cap.
    let cases = [
        (e, [0.01, 0.0, 0.02], [1.0, 0.0, 0.0]),
        (k, [0.006, 0.0, 0.025], [1.0, 0.0, 0.0]),
        (k, [0.0, 0.0, 0.036], [0.0, 0.0, 1.0]),
    ];
    for (surface, p, n) in cases {
        let pv = Vector3::from(p);
        let nv = Vector3::from(n);
        // Normal 2 N, tangential 0.6 N along y; torsion 2 mN m.
        let f = nv * 2.0 + Vector3::new(0.0, 0.6, 0.0);
        let t = 2e-3;
        let r = FingertipWrench {
            force: -f,
            torque: pv.cross(&-f) - nv * t,
        };
        let c = locate(&surface, &r, &soft).expect("soft-finger contact");
        assert_contact(&c, &r, p, n);
        assert!(
            (c.torsion - t).abs() < 1e-15,
            "torsion {}, expected {t}",
            c.torsion
        );
    }
}
