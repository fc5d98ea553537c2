//! Validation errors (each names its field), normals, and the serde forms.

use graspopt_sensing::{
    ContactKind, FingertipSurface, FingertipWrench, SensedContact, SensingError, SensingSettings,
    SensorNoise,
};
use nalgebra::{Point3, Vector3};

use crate::support::angle;

fn field_of(e: SensingError) -> &'static str {
    match e {
        SensingError::NotFinite { field, .. } | SensingError::OutOfRange { field, .. } => field,
    }
}

fn invalid_field(s: FingertipSurface) -> &'static str {
    field_of(s.validate().expect_err(&format!("{s:?} should be invalid")))
}

#[test]
fn validate_names_the_bad_field() {
    let sphere = |center: [f64; 3], radius: f64, base_z: Option<f64>| FingertipSurface::Sphere {
        center,
        radius,
        base_z,
    };
    assert_eq!(sphere([0.0, 0.0, 0.01], 0.008, None).validate(), Ok(()));
    assert_eq!(
        sphere([0.0, 0.0, 0.01], 0.008, Some(0.017)).validate(),
        Ok(())
    );
    assert_eq!(invalid_field(sphere([0.0, 0.0, 0.01], 0.0, None)), "radius");
    assert_eq!(
        invalid_field(sphere([0.0, 0.0, 0.01], -1e-3, None)),
        "radius"
    );
    assert_eq!(invalid_field(sphere([0.0, 0.0, 0.01], 2e3, None)), "radius");
    assert_eq!(
        invalid_field(sphere([0.0, 0.0, f64::NAN], 0.008, None)),
        "center[2]"
    );
    assert_eq!(
        invalid_field(sphere([-1e4, 0.0, 0.0], 0.008, None)),
        "center[0]"
    );
    // The base at or above the top leaves nothing to touch.
    assert_eq!(
        invalid_field(sphere([0.0, 0.0, 0.01], 0.008, Some(0.02))),
        "base_z"
    );
    assert_eq!(
        invalid_field(sphere([0.0, 0.0, 0.01], 0.008, Some(f64::INFINITY))),
        "base_z"
    );

    let ellipsoid = |semi_axes: [f64; 3]| FingertipSurface::Ellipsoid {
        center: [0.0; 3],
        semi_axes,
        base_z: None,
    };
    assert_eq!(ellipsoid([0.01, 0.006, 0.015]).validate(), Ok(()));
    assert_eq!(
        invalid_field(ellipsoid([0.01, -0.006, 0.015])),
        "semi_axes[1]"
    );
    assert_eq!(
        invalid_field(ellipsoid([0.01, 0.006, f64::NAN])),
        "semi_axes[2]"
    );

    let capsule = |half_length: f64, radius: f64, base_z: Option<f64>| FingertipSurface::Capsule {
        center: [0.0, 0.0, 0.02],
        half_length,
        radius,
        base_z,
    };
    assert_eq!(capsule(0.0, 0.006, None).validate(), Ok(()));
    assert_eq!(capsule(0.01, 0.006, Some(0.035)).validate(), Ok(()));
    assert_eq!(invalid_field(capsule(-1e-3, 0.006, None)), "half_length");
    assert_eq!(invalid_field(capsule(0.01, 0.0, None)), "radius");
    assert_eq!(invalid_field(capsule(0.01, 0.006, Some(0.04))), "base_z");

    let e = capsule(-1e-3, 0.006, None).validate().expect_err("invalid");
    assert_eq!(
        e.to_string(),
        "half_length is -0.001: it must be >= 0 and at most 1000 m"
    );

    let settings = SensingSettings {
        force_threshold: f64::NAN,
        ..SensingSettings::default()
    };
    assert_eq!(
        field_of(settings.validate().expect_err("invalid")),
        "force_threshold"
    );
    let settings = SensingSettings {
        torsion_ratio_limit: -1.0,
        ..SensingSettings::default()
    };
    assert_eq!(
        field_of(settings.validate().expect_err("invalid")),
        "torsion_ratio_limit"
    );
    let noise = SensorNoise {
        torque_resolution: -1e-5,
        ..SensorNoise::default()
    };
    assert_eq!(
        field_of(noise.validate().expect_err("invalid")),
        "torque_resolution"
    );
    assert_eq!(SensorNoise::default().validate(), Ok(()));
}

#[test]
fn outward_normals() {
    let capsule = FingertipSurface::Capsule {
        center: [0.0, 0.0, 0.02],
        half_length: 0.01,
        radius: 0.006,
        base_z: None,
    };
    let h = std::f64::consts::FRAC_1_SQRT_2;
    for (p, n) in [
        ([0.006, 0.0, 0.025], [1.0, 0.0, 0.0]),
        ([0.0, -0.006, 0.015], [0.0, -1.0, 0.0]),
        ([0.0, 0.0, 0.036], [0.0, 0.0, 1.0]),
        ([0.006 * h, 0.0, 0.03 + 0.006 * h], [h, 0.0, h]),
        ([0.0, 0.0, 0.004], [0.0, 0.0, -1.0]),
    ] {
        let got = capsule.outward_normal(&Point3::from(p));
        let want = nalgebra::Unit::new_normalize(Vector3::from(n));
        assert!(angle(&got, &want) < 1e-15, "at {p:?}: {got:?}");
    }
    // The ellipsoid's normal is its gradient (x / a^2, y / b^2, z / c^2).
    let e = FingertipSurface::Ellipsoid {
        center: [0.0, 0.0, 0.02],
        semi_axes: [0.01, 0.006, 0.015],
        base_z: None,
    };
    let p = Point3::new(0.005, 0.003, 0.02 + 0.015 * 0.5f64.sqrt());
    let want = nalgebra::Unit::new_normalize(Vector3::new(
        0.005 / 1e-4,
        0.003 / 3.6e-5,
        0.015 * 0.5f64.sqrt() / 2.25e-4,
    ));
    assert!(angle(&e.outward_normal(&p), &want) < 1e-15);
    // Projections onto the surface.
    let k = capsule;
    let on = k.project(&Point3::new(0.0, 0.007, 0.022));
    assert!(
        (on - Point3::new(0.0, 0.006, 0.022)).norm() < 1e-15,
        "{on:?}"
    );
    let on = k.project(&Point3::new(0.0, 0.0, 0.04));
    assert!((on - Point3::new(0.0, 0.0, 0.036)).norm() < 1e-15, "{on:?}");
    let on = e.project(&Point3::new(0.0, 0.0, 0.0));
    assert!((on - Point3::new(0.0, 0.0, 0.005)).norm() < 1e-15, "{on:?}");
    let near = Point3::new(0.0101, 0.0, 0.02);
    assert!((e.project(&near) - Point3::new(0.01, 0.0, 0.02)).norm() < 1e-15);
    // At the centre the normal is undefined: +z, not NaN.
    assert_eq!(
        e.outward_normal(&Point3::new(0.0, 0.0, 0.02)),
        Vector3::z_axis()
    );
}

#[test]
fn json_forms() {
    let s: FingertipSurface =
        serde_json::from_str(r#"{"shape":"sphere","center":[0,0,0.01],"radius":0.008}"#)
            .expect("sphere");
    assert_eq!(
        s,
        FingertipSurface::Sphere {
            center: [0.0, 0.0, 0.01],
            radius: 0.008,
            base_z: None
        }
    );
    assert_eq!(
        serde_json::to_string(&s).expect("json"),
        r#"{"shape":"sphere","center":[0.0,0.0,0.01],"radius":0.008}"#
    );
    let k: FingertipSurface = serde_json::from_str(
        r#"{"shape":"capsule","center":[0,0,0.02],"half_length":0.01,"radius":0.006,"base_z":0.012}"#,
    )
    .expect("capsule");
    assert_eq!(k.base_z(), Some(0.012));
    let e: FingertipSurface = serde_json::from_str(
        r#"{"shape":"ellipsoid","center":[0,0,0.02],"semi_axes":[0.01,0.006,0.015]}"#,
    )
    .expect("ellipsoid");
    assert!(matches!(e, FingertipSurface::Ellipsoid { .. }));
    // A misspelt field is an error, not silently ignored.
    let err = serde_json::from_str::<FingertipSurface>(
        r#"{"shape":"sphere","center":[0,0,0.01],"radius":0.008,"base":0.01}"#,
    )
    .expect_err("unknown field");
    assert!(err.to_string().contains("unknown field `base`"), "{err}");
    assert!(
        serde_json::from_str::<FingertipSurface>(r#"{"shape":"cube","center":[0,0,0]}"#).is_err()
    );

    let settings: SensingSettings =
        serde_json::from_str(r#"{"kind":"soft_finger"}"#).expect("settings");
    assert_eq!(settings.kind, ContactKind::SoftFinger);
    assert_eq!(settings.force_threshold, 0.05);
    assert_eq!(settings.surface_tolerance, 1e-4);
    let r: FingertipWrench =
        serde_json::from_str(r#"{"force":[0,0,-2],"torque":[0.001,0,0]}"#).expect("reading");
    assert_eq!(r.force, Vector3::new(0.0, 0.0, -2.0));
    assert_eq!(r.torque, Vector3::new(0.001, 0.0, 0.0));
    let c = SensedContact {
        point: Point3::new(0.0, 0.0, 0.018),
        normal: Vector3::z_axis(),
        force: Vector3::new(0.0, 0.0, 2.0),
        torsion: 0.0,
    };
    let json = serde_json::to_string(&c).expect("json");
    assert_eq!(
        json,
        r#"{"point":[0.0,0.0,0.018],"normal":[0.0,0.0,1.0],"force":[0.0,0.0,2.0],"torsion":0.0}"#
    );
    assert_eq!(
        serde_json::from_str::<SensedContact>(&json).expect("contact"),
        c
    );
    let noise: SensorNoise = serde_json::from_str("{}").expect("noise");
    assert_eq!(noise, SensorNoise::default());
    assert_eq!(noise.force_resolution, 1.0 / 320.0);
    assert_eq!(noise.torque_resolution, 1.5625e-5);
}
