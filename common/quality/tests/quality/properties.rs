//! Properties of the metrics: invariance under a common rotation, BW's sign, and BW's
//! continuity across the force-closure boundary.

use graspopt_quality::metrics::{MetricsOptions, evaluate_contacts, evaluate_wrenches};
use graspopt_quality::{Contact, FrictionModel, GraspMap, GraspModel, Wrench};
use nalgebra::{Rotation3, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Frictionless contacts on the faces of the box [-1,1]^3, two per face and off-centre,
/// so their normals make torques: a force-closure grasp with no tangent-basis
/// convention involved (its wrenches rotate exactly with the contacts).
fn box_grasp() -> Vec<Contact> {
    let mut contacts = Vec::new();
    for axis in 0..3 {
        for side in [-1.0, 1.0] {
            let mut n = Vector3::zeros();
            n[axis] = -side;
            for (du, dv) in [(0.5, 0.2), (-0.3, -0.6)] {
                let mut p = Vector3::zeros();
                p[axis] = side;
                p[(axis + 1) % 3] = du * side;
                p[(axis + 2) % 3] = dv;
                contacts.push(Contact::new(p, n));
            }
        }
    }
    contacts
}

#[test]
fn epsilon_and_volume_do_not_change_under_a_common_rotation() {
    let contacts = box_grasp();
    let c = Vector3::new(0.1, -0.2, 0.05);
    let model = GraspModel::new(FrictionModel::Frictionless)
        .with_reference_point(c)
        .with_torque_scale(1.3);
    let base = evaluate_contacts(&contacts, &model, &MetricsOptions::default()).unwrap();
    assert!(base.force_closure(), "{base:?}");
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..5 {
        let r = Rotation3::from_euler_angles(
            rng.random_range(-3.0..3.0),
            rng.random_range(-1.5..1.5),
            rng.random_range(-3.0..3.0),
        );
        let rotated: Vec<Contact> = contacts
            .iter()
            .map(|k| Contact::new(r * k.position, r * k.normal))
            .collect();
        let m = evaluate_contacts(
            &rotated,
            &model.with_reference_point(r * c),
            &MetricsOptions::default(),
        )
        .unwrap();
        assert!((m.epsilon() - base.epsilon()).abs() < 1e-10);
        let (v, v0) = (m.volume().unwrap(), base.volume().unwrap());
        assert!((v - v0).abs() < 1e-9 * v0, "{v} vs {v0}");
    }
    // Soft-finger wrench sets rotated in wrench space (R acting on force and torque).
    let soft = GraspModel::new(FrictionModel::SoftFinger {
        mu: 0.4,
        edges: 6,
        gamma: 0.1,
    });
    let w = GraspMap::from_contacts(&contacts[..4], &soft).unwrap();
    let base = evaluate_wrenches(w.wrenches(), &MetricsOptions::default()).unwrap();
    let r = Rotation3::from_euler_angles(0.4, -1.1, 2.0);
    let rotated: Vec<Wrench> = w
        .wrenches()
        .iter()
        .map(|x| {
            let f = r * Vector3::new(x[0], x[1], x[2]);
            let t = r * Vector3::new(x[3], x[4], x[5]);
            Wrench::new(f.x, f.y, f.z, t.x, t.y, t.z)
        })
        .collect();
    let m = evaluate_wrenches(&rotated, &MetricsOptions::default()).unwrap();
    assert!((m.bw() - base.bw()).abs() < 1e-10);
    assert!((m.volume().unwrap() - base.volume().unwrap()).abs() < 1e-9 * base.volume().unwrap());
}

#[test]
fn bw_sign_agrees_with_force_closure() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let model = GraspModel::new(FrictionModel::SoftFinger {
        mu: 0.5,
        edges: 6,
        gamma: 0.05,
    });
    let (mut closed, mut open) = (0, 0);
    for _ in 0..200 {
        let n = rng.random_range(1..5);
        let contacts: Vec<Contact> = (0..n)
            .map(|_| {
                let p = Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                )
                .normalize();
                Contact::new(p, -p)
            })
            .collect();
        let m = evaluate_contacts(&contacts, &model, &MetricsOptions::without_volume()).unwrap();
        if m.force_closure() {
            closed += 1;
            assert!(m.bw() > 0.0 && m.bw() == m.epsilon());
        } else {
            open += 1;
            assert!(m.bw() <= 0.0 && m.epsilon() == 0.0);
            assert_eq!(m.bw(), -m.distance());
        }
    }
    assert!(closed > 20 && open > 20, "closed {closed}, open {open}");
}

/// BW along a path of grasps must change sign without jumping: the third contact of an
/// equator grasp slides towards the second, and force closure is lost on the way.
#[test]
fn bw_is_continuous_across_the_force_closure_boundary() {
    let model = GraspModel::new(FrictionModel::PointFriction { mu: 0.3, edges: 8 });
    let at = |deg: f64| {
        let (s, c) = deg.to_radians().sin_cos();
        let p = Vector3::new(c, s, 0.0);
        Contact::new(p, -p)
    };
    let steps = 400;
    let mut values = Vec::new();
    for i in 0..=steps {
        let phi = 240.0 - 110.0 * i as f64 / steps as f64;
        let grasp = [at(0.0), at(120.0), at(phi)];
        let m = evaluate_contacts(&grasp, &model, &MetricsOptions::without_volume()).unwrap();
        values.push(m.bw());
    }
    assert!(values[0] > 0.1, "starts in force closure: {}", values[0]);
    assert!(
        *values.last().unwrap() < -0.01,
        "ends outside: {:?}",
        values.last()
    );
    let max_jump = values
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    // The path moves 110 degrees in 400 steps (0.0048 rad per step): BW is Lipschitz in
    // the contact position, so no step may move it by more than a few times that.
    assert!(max_jump < 0.01, "largest jump {max_jump}");
    let crossing = values
        .windows(2)
        .position(|w| w[0] > 0.0 && w[1] <= 0.0)
        .unwrap();
    assert!(values[crossing].abs() < 0.01 && values[crossing + 1].abs() < 0.01);

    // The same in wrench space: sliding a hull across the origin.
    let grasp = GraspMap::from_contacts(&[at(0.0), at(120.0), at(240.0)], &model).unwrap();
    let dir = Wrench::new(0.3, -0.2, 0.5, 0.1, 0.7, -0.2).normalize();
    let mut last = None;
    for i in 0..=200 {
        let t = 1.5 * i as f64 / 200.0;
        let moved: Vec<Wrench> = grasp.wrenches().iter().map(|w| w + dir * t).collect();
        let bw = evaluate_wrenches(&moved, &MetricsOptions::without_volume())
            .unwrap()
            .bw();
        if let Some(prev) = last {
            // Moving the hull by dt changes both epsilon and the distance by at most dt.
            assert!((bw - prev) <= 1.5 / 200.0 + 1e-9 && (prev - bw) <= 1.5 / 200.0 + 1e-9);
        }
        last = Some(bw);
    }
    assert!(last.unwrap() < 0.0);
}
