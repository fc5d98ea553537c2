//! Readings that admit no contact: each gives its named refusal, never a point.

use graspopt_sensing::{
    ContactKind, FingertipSurface, FingertipWrench, MIN_FORCE, NoContact, SensingError,
    SensingSettings, locate,
};
use nalgebra::{Point3, Vector3};

use crate::support::angle;

fn reading(force: [f64; 3], torque: [f64; 3]) -> FingertipWrench {
    FingertipWrench {
        force: Vector3::from(force),
        torque: Vector3::from(torque),
    }
}

/// A reading of a pure force `force` whose line of action passes through `through`.
fn force_through(force: [f64; 3], through: [f64; 3]) -> FingertipWrench {
    let f = Vector3::from(force);
    FingertipWrench {
        force: f,
        torque: Vector3::from(through).cross(&f),
    }
}

fn soft() -> SensingSettings {
    SensingSettings {
        kind: ContactKind::SoftFinger,
        ..SensingSettings::default()
    }
}

fn sphere() -> FingertipSurface {
    FingertipSurface::Sphere {
        center: [0.0, 0.0, 0.01],
        radius: 0.008,
        base_z: None,
    }
}

/// A 12 mm sphere mounted on the sensor below its equator.
fn mounted() -> FingertipSurface {
    FingertipSurface::Sphere {
        center: [0.0, 0.0, 0.012],
        radius: 0.006,
        base_z: Some(0.012),
    }
}

#[test]
fn a_small_force_is_below_the_threshold() {
    let r = reading([0.0, 0.0, -0.01], [0.0, 0.0, 0.0]);
    for settings in [SensingSettings::default(), soft()] {
        let e = locate(&sphere(), &r, &settings).expect_err("below threshold");
        assert_eq!(
            e,
            NoContact::BelowThreshold {
                force: 0.01,
                threshold: 0.05
            }
        );
        assert_eq!(
            e.to_string(),
            "the force is 0.0100 N, below the contact threshold of 0.0500 N"
        );
    }
    // A zero force is no contact even with a zero threshold: MIN_FORCE is the floor.
    let zero = SensingSettings {
        force_threshold: 0.0,
        ..SensingSettings::default()
    };
    let r = reading([0.0; 3], [0.0, 1e-3, 0.0]);
    assert_eq!(
        locate(&sphere(), &r, &zero),
        Err(NoContact::BelowThreshold {
            force: 0.0,
            threshold: MIN_FORCE
        })
    );
    // Just above the floor, a contact.
    let r = reading([0.0, 0.0, -2e-9], [0.0; 3]);
    let c = locate(&sphere(), &r, &zero).expect("contact");
    assert!((c.point - Point3::new(0.0, 0.0, 0.018)).norm() < 1e-15);
}

#[test]
fn point_contact_torsion_within_the_pitch_tolerance_is_noise_beyond_it_a_refusal() {
    // Pressed straight down on the top (force along the normal): any torque along the
    // force is a torsion, and it does not move the line of action.
    let top = Vector3::new(0.0, 0.0, 0.018);
    let f = Vector3::new(0.0, 0.0, -2.0);
    // 0.1 mN m at 2 N: pitch 0.05 mm < 0.2 mm, taken as noise.
    let r = FingertipWrench {
        force: f,
        torque: top.cross(&f) + Vector3::z() * 1e-4,
    };
    let c = locate(&sphere(), &r, &SensingSettings::default()).expect("contact");
    assert!((c.point.coords - top).norm() < 1e-15, "{:?}", c.point);
    assert_eq!(c.torsion, 0.0);
    // 1 mN m at 2 N: pitch 0.5 mm, refused.
    let r = FingertipWrench {
        force: f,
        torque: top.cross(&f) + Vector3::z() * 1e-3,
    };
    let e = locate(&sphere(), &r, &SensingSettings::default()).expect_err("torsion");
    let NoContact::Torsion {
        torsion,
        pitch,
        tolerance,
    } = e
    else {
        panic!("expected Torsion, got {e:?}");
    };
    assert!((torsion + 1e-3).abs() < 1e-15, "torsion {torsion}");
    assert!((pitch + 5e-4).abs() < 1e-15, "pitch {pitch}");
    assert_eq!(tolerance, 2e-4);
    assert!(e.to_string().contains("pitch -0.5000 mm"), "{e}");
    // The soft-finger model explains it: torque = p x F - t n with n = +z, so the
    // fingertip applies t = -1 mN m about its normal.
    let c = locate(&sphere(), &r, &soft()).expect("soft-finger contact");
    assert!((c.point.coords - top).norm() < 1e-15, "{:?}", c.point);
    assert!((c.torsion + 1e-3).abs() < 1e-15, "torsion {}", c.torsion);
}

#[test]
fn a_soft_finger_torsion_beyond_the_limit_is_refused() {
    // Pressed down on the top with 1.5 N: a torsion of 10 mN m is within 1 cm times the
    // normal force, 20 mN m is not.
    let top = Vector3::new(0.0, 0.0, 0.018);
    let f = Vector3::new(0.0, 0.0, -1.5);
    let with_torsion = |t: f64| FingertipWrench {
        force: f,
        torque: top.cross(&f) - Vector3::z() * t,
    };
    let c = locate(&sphere(), &with_torsion(0.01), &soft()).expect("contact");
    assert!((c.torsion - 0.01).abs() < 1e-15, "torsion {}", c.torsion);
    let e = locate(&sphere(), &with_torsion(-0.02), &soft()).expect_err("beyond the limit");
    let NoContact::TorsionBeyondLimit {
        torsion,
        normal_force,
        limit,
    } = e
    else {
        panic!("expected TorsionBeyondLimit, got {e:?}");
    };
    assert!((torsion + 0.02).abs() < 1e-15, "torsion {torsion}");
    assert!(
        (normal_force - 1.5).abs() < 1e-15,
        "normal force {normal_force}"
    );
    assert_eq!(limit, 0.01);
    assert!(
        e.to_string()
            .contains("-2.000e-2 N m with a normal force of 1.5000 N"),
        "{e}"
    );
}

#[test]
fn a_line_of_action_missing_the_surface_is_refused_a_grazing_one_taken() {
    // Sphere of radius 8 mm about (0, 0, 10 mm); vertical lines beside it.
    let r = force_through([0.0, 0.0, -1.0], [0.008 + 2e-4, 0.0, 0.01]);
    match locate(&sphere(), &r, &SensingSettings::default()) {
        Err(NoContact::MissesSurface { distance }) => {
            assert!((distance - 2e-4).abs() < 1e-12, "distance {distance}")
        }
        other => panic!("expected MissesSurface, got {other:?}"),
    }
    let r = force_through([0.0, 0.0, -1.0], [0.008 + 5e-5, 0.0, 0.01]);
    let c = locate(&sphere(), &r, &SensingSettings::default()).expect("grazing contact");
    assert!(
        (c.point - Point3::new(0.008, 0.0, 0.01)).norm() < 1e-12,
        "{:?}",
        c.point
    );
    assert!(angle(&c.normal, &Vector3::x_axis()) < 1e-9);

    // Ellipsoid: the vertical line beside the end of the x semi-axis.
    let e = FingertipSurface::Ellipsoid {
        center: [0.0, 0.0, 0.02],
        semi_axes: [0.01, 0.006, 0.015],
        base_z: None,
    };
    let r = force_through([0.0, 0.0, -1.0], [0.01 + 3e-4, 0.0, 0.0]);
    match locate(&e, &r, &SensingSettings::default()) {
        Err(NoContact::MissesSurface { distance }) => {
            assert!((distance - 3e-4).abs() < 1e-10, "distance {distance}")
        }
        other => panic!("expected MissesSurface, got {other:?}"),
    }
    let r = force_through([0.0, 0.0, -1.0], [0.01 + 5e-5, 0.0, 0.0]);
    let c = locate(&e, &r, &SensingSettings::default()).expect("grazing contact");
    assert!(
        (c.point - Point3::new(0.01, 0.0, 0.02)).norm() < 1e-8,
        "{:?}",
        c.point
    );
    assert!(angle(&c.normal, &Vector3::x_axis()) < 1e-6);

    // Capsule: a horizontal line beside the cylinder, and one beyond the top cap.
    let k = FingertipSurface::Capsule {
        center: [0.0, 0.0, 0.02],
        half_length: 0.01,
        radius: 0.006,
        base_z: None,
    };
    let r = force_through([-1.0, 0.0, 0.0], [0.0, 0.006 + 5e-5, 0.023]);
    let c = locate(&k, &r, &SensingSettings::default()).expect("grazing contact");
    assert!(
        (c.point - Point3::new(0.0, 0.006, 0.023)).norm() < 1e-12,
        "{:?}",
        c.point
    );
    assert!(angle(&c.normal, &Vector3::y_axis()) < 1e-9);
    let r = force_through([-1.0, 0.0, 0.0], [0.0, 0.0, 0.036 + 1e-3]);
    match locate(&k, &r, &SensingSettings::default()) {
        Err(NoContact::MissesSurface { distance }) => {
            assert!((distance - 1e-3).abs() < 1e-12, "distance {distance}")
        }
        other => panic!("expected MissesSurface, got {other:?}"),
    }
}

#[test]
fn a_pushing_point_on_the_mount_with_a_usable_pulling_point_is_pulling() {
    // The object pushes the bottom of the ball (below the base) up along x = 3 mm: the
    // only usable point on that line is on top, at 30 degrees from the pole, where the
    // same force would pull.
    let r = force_through([0.0, 0.0, 1.0], [0.003, 0.0, 0.0]);
    for settings in [SensingSettings::default(), soft()] {
        match locate(&mounted(), &r, &settings) {
            Err(e @ NoContact::Pulling { normal_force }) => {
                assert!(
                    (normal_force + 3f64.sqrt() / 2.0).abs() < 1e-12,
                    "normal force {normal_force}"
                );
                assert!(
                    e.to_string()
                        .contains("pull the object (normal force -0.8660 N)"),
                    "{e}"
                );
            }
            other => panic!("expected Pulling, got {other:?}"),
        }
    }
}

#[test]
fn a_contact_only_on_the_mount_is_on_mount() {
    // A horizontal force line 4 mm below the base: both surface points are on the mount.
    let r = force_through([-1.0, 0.0, 0.0], [0.0, 0.0, 0.008]);
    for settings in [SensingSettings::default(), soft()] {
        match locate(&mounted(), &r, &settings) {
            Err(NoContact::OnMount { z, base_z }) => {
                assert!((z - 0.008).abs() < 1e-15, "z {z}");
                assert_eq!(base_z, 0.012);
            }
            other => panic!("expected OnMount, got {other:?}"),
        }
    }
    // 0.05 mm below the base is within the surface tolerance: a contact.
    let r = force_through([-1.0, 0.0, 0.0], [0.0, 0.0, 0.012 - 5e-5]);
    let c = locate(&mounted(), &r, &SensingSettings::default()).expect("contact");
    assert!((c.point.z - (0.012 - 5e-5)).abs() < 1e-15);
    assert!(c.point.x > 0.0);
}

#[test]
fn invalid_input_is_refused_with_the_field_named() {
    let good = reading([0.0, 0.0, -1.0], [0.0; 3]);
    let nan = reading([0.0, f64::NAN, -1.0], [0.0; 3]);
    match locate(&sphere(), &nan, &SensingSettings::default()) {
        Err(NoContact::Invalid(SensingError::NotFinite { field, .. })) => {
            assert_eq!(field, "force[1]")
        }
        other => panic!("expected Invalid, got {other:?}"),
    }
    let inf = reading([0.0, 0.0, -1.0], [0.0, 0.0, f64::INFINITY]);
    let e = locate(&sphere(), &inf, &SensingSettings::default()).expect_err("invalid");
    assert_eq!(
        e.to_string(),
        "invalid input: torque[2] is not finite (inf)"
    );
    let flat = FingertipSurface::Sphere {
        center: [0.0; 3],
        radius: 0.0,
        base_z: None,
    };
    let e = locate(&flat, &good, &SensingSettings::default()).expect_err("invalid");
    assert_eq!(
        e.to_string(),
        "invalid input: radius is 0: it must be between 1e-6 and 1000 m"
    );
    let huge = reading([0.0, 0.0, -2e6], [0.0; 3]);
    let e = locate(&sphere(), &huge, &SensingSettings::default()).expect_err("invalid");
    assert_eq!(
        e.to_string(),
        "invalid input: force[2] is -2000000: it must be at most 1e6 in absolute value"
    );
    let negative = SensingSettings {
        surface_tolerance: -1.0,
        ..SensingSettings::default()
    };
    let e = locate(&sphere(), &good, &negative).expect_err("invalid");
    assert!(matches!(
        e,
        NoContact::Invalid(SensingError::OutOfRange {
            field: "surface_tolerance",
            ..
        })
    ));
}
