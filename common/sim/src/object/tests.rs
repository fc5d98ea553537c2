use super::*;

#[test]
fn all_builtins_build_and_unknown_name_lists_valid_ones() {
    for name in Object::names() {
        let o = Object::by_name(name).unwrap();
        assert_eq!(o.name(), name);
        let (lo, hi) = o.aabb();
        let size = hi - lo;
        assert!(size.max() <= 0.16 && size.min() >= 0.02, "{name}: {size:?}");
        let com = o.centre_of_mass();
        assert!(com.z > 0.0 && com.z < hi.z, "{name}: com {com:?}");
    }
    let e = Object::by_name("teapot").unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, SimError::UnknownObject { .. }));
    assert!(
        msg.contains("teapot") && msg.contains("mug") && msg.contains("star_prism"),
        "{msg}"
    );
    assert!(Object::by_name("Rotated-Cuboid").is_ok());
}

#[test]
fn sphere_queries_are_exact() {
    let s = Object::by_name("sphere").unwrap();
    let c = Point3::new(0.0, 0.0, 0.035);
    let hit = s
        .cast_ray(&Point3::new(-1.0, 0.0, 0.035), &Vector3::x(), 10.0)
        .unwrap()
        .unwrap();
    assert!((hit.point - Point3::new(-0.035, 0.0, 0.035)).norm() < 1e-12);
    assert!((hit.outward_normal + Vector3::x()).norm() < 1e-12);
    assert!((hit.distance - 0.965).abs() < 1e-12);
    let q = Point3::new(0.01, 0.02, 0.05);
    let sp = s.closest_point(&q).unwrap();
    let expect = (q - c).norm() - 0.035;
    assert!((sp.signed_distance - expect).abs() < 1e-12);
    assert!(((sp.point - c).norm() - 0.035).abs() < 1e-12);
    assert!(
        s.cast_ray(&Point3::new(-1.0, 1.0, 0.0), &Vector3::x(), 10.0)
            .unwrap()
            .is_none()
    );
    assert!(s.closest_point(&Point3::new(f64::NAN, 0.0, 0.0)).is_err());
}

#[test]
fn rotated_cuboid_normals_follow_the_frame() {
    let o = Object::by_name("rotated_cuboid").unwrap();
    let hit = o
        .cast_ray(&Point3::new(0.0, -1.0, 0.06), &Vector3::y(), 2.0)
        .unwrap()
        .unwrap();
    // The first hit from -y is the edge region; normals are one of the two rotated faces.
    let n = hit.outward_normal;
    assert!((n.z).abs() < 1e-12 && (n.norm() - 1.0).abs() < 1e-12);
    let c = std::f64::consts::FRAC_1_SQRT_2;
    assert!(
        (n.x.abs() - c).abs() < 1e-9 && (n.y.abs() - c).abs() < 1e-9,
        "{n:?}"
    );
}

#[test]
fn mug_is_hollow_and_has_a_handle() {
    let o = Object::by_name("mug").unwrap();
    // Straight down into the cup: hits the inner bottom at z = 0.006.
    let hit = o
        .cast_ray(&Point3::new(0.0, 0.0, 0.5), &-Vector3::z(), 1.0)
        .unwrap()
        .unwrap();
    assert!((hit.point.z - 0.006).abs() < 1e-9, "{hit:?}");
    // The handle on +x at mid height reaches out to x = 0.033 + 0.025 + 0.005 = 0.063.
    let hit = o
        .cast_ray(&Point3::new(0.5, 0.0, 0.0475), &-Vector3::x(), 1.0)
        .unwrap()
        .unwrap();
    assert!((hit.point.x - 0.063).abs() < 1e-3, "{hit:?}");
    // In the wall (radius 0.031..0.035): inside; in the cup's hollow: outside.
    assert!(o.signed_distance(&Point3::new(0.0, 0.033, 0.05)).unwrap() < 0.0);
    assert!(o.signed_distance(&Point3::new(0.0, 0.0, 0.05)).unwrap() > 0.0);
}

#[test]
fn convex_pieces_match_the_query_surface() {
    // The distance from a tiny ball to the collision pieces must equal the distance to the
    // (mesh) surface used by point queries, for points around each decomposed object.
    let probe = Ball::new(1e-5);
    for name in [
        "wine_glass",
        "mug",
        "star_prism",
        "cylinder",
        "rotated_cuboid",
    ] {
        let o = Object::by_name(name).unwrap();
        let (lo, hi) = o.aabb();
        let mut checked = 0;
        for i in 0..9 {
            for j in 0..9 {
                for k in 0..9 {
                    let f = |a: f64, b: f64, t: usize| a - 0.01 + (b - a + 0.02) * t as f64 / 8.0;
                    let p = Point3::new(f(lo.x, hi.x, i), f(lo.y, hi.y, j), f(lo.z, hi.z, k));
                    let sd = o.signed_distance(&p).unwrap();
                    if sd <= 2e-3 {
                        continue;
                    }
                    let pose = iso2pose(&Isometry3::translation(p.x, p.y, p.z));
                    let d = o.distance_to_shape(&pose, &probe).unwrap() + 1e-5;
                    assert!(
                        (d - sd).abs() < 1e-6,
                        "{name} at {p:?}: pieces {d}, surface {sd}"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 100, "{name}: {checked}");
    }
}
