//! The known values of `docs/metric-conventions.md`.

use graspopt_quality::metrics::{Metrics, MetricsOptions, evaluate_contacts, evaluate_wrenches};
use graspopt_quality::{Contact, FrictionModel, GraspModel, Wrench};

use crate::support::equator;

fn friction(mu: f64) -> GraspModel {
    GraspModel::new(FrictionModel::PointFriction { mu, edges: 8 })
}

fn metrics(contacts: &[Contact], model: GraspModel) -> Metrics {
    evaluate_contacts(contacts, &model, &MetricsOptions::default()).unwrap()
}

#[test]
fn three_equator_contacts_epsilon_and_volume() {
    let grasp = equator(&[0.0, 120.0, 240.0]);
    for (mu, eps) in [(0.3, 0.162210364), (0.5, 0.275925156), (1.0, 0.554694462)] {
        let m = metrics(&grasp, friction(mu));
        assert!(m.force_closure(), "mu {mu}");
        assert_eq!(m.rank(), 6);
        assert!((m.epsilon() - eps).abs() < 1e-9, "mu {mu}: {}", m.epsilon());
        assert_eq!(m.bw(), m.epsilon());
        assert!(m.distance() < 1e-12);
    }
    let m = metrics(&grasp, friction(0.5));
    assert!(
        (m.volume().unwrap() - 0.0788798).abs() < 1e-7,
        "{:?}",
        m.volume()
    );
}

#[test]
fn two_antipodal_contacts() {
    let grasp = equator(&[0.0, 180.0]);
    let m = metrics(&grasp, friction(0.5));
    assert_eq!(m.rank(), 5);
    assert!(!m.force_closure());
    assert_eq!(m.epsilon(), 0.0);
    assert_eq!(m.volume(), Some(0.0));
    assert!(m.bw().abs() < 1e-12 && m.bw() <= 0.0);
    let soft = GraspModel::new(FrictionModel::SoftFinger {
        mu: 0.5,
        edges: 8,
        gamma: 0.2,
    });
    let m = metrics(&grasp, soft);
    assert!(m.force_closure());
    assert_eq!(m.rank(), 6);
    assert!((m.epsilon() - 0.2).abs() < 1e-9, "{}", m.epsilon());
}

#[test]
fn one_contact() {
    let m = metrics(&equator(&[30.0]), friction(0.5));
    assert!((m.distance() - 1.0).abs() < 1e-12);
    assert!((m.bw() + 1.0).abs() < 1e-12);
    assert!(!m.force_closure());
    assert_eq!(m.rank(), 2);
}

#[test]
fn cross_polytope_and_cube() {
    let mut cross = Vec::new();
    for i in 0..6 {
        for s in [-1.0, 1.0] {
            let mut w = Wrench::zeros();
            w[i] = s;
            cross.push(w);
        }
    }
    let m = evaluate_wrenches(&cross, &MetricsOptions::default()).unwrap();
    assert!((m.epsilon() - 1.0 / 6.0f64.sqrt()).abs() < 1e-12);
    assert!((m.volume().unwrap() - 64.0 / 720.0).abs() < 1e-12);
    let cube: Vec<Wrench> = (0..64)
        .map(|bits| Wrench::from_fn(|i, _| if bits & (1 << i) != 0 { 1.0 } else { -1.0 }))
        .collect();
    let m = evaluate_wrenches(&cube, &MetricsOptions::default()).unwrap();
    assert!((m.epsilon() - 1.0).abs() < 1e-12);
    assert!((m.volume().unwrap() - 64.0).abs() < 1e-9);
    assert!(m.force_closure() && m.rank() == 6);
}

/// The grasp isotropy index (`isotropy`), sigma_min / sigma_max of the matrix whose columns
/// are the wrenches, against singular values known in closed form.
#[test]
fn isotropy_of_grasps_with_known_singular_values() {
    use graspopt_quality::metrics::Metric;
    let isotropy = |m: &Metrics| m.real(Metric::Isotropy).unwrap();
    // +-e_i: G G^T = 2 I, every singular value sqrt(2).
    let axis = |i: usize, s: f64| Wrench::from_fn(|k, _| if k == i { s } else { 0.0 });
    let cross: Vec<Wrench> = (0..12).map(|k| axis(k / 2, [-1.0, 1.0][k % 2])).collect();
    let m = evaluate_wrenches(&cross, &MetricsOptions::default()).unwrap();
    assert!((isotropy(&m) - 1.0).abs() < 1e-12, "{}", isotropy(&m));
    // +-2 e_1 and +-e_2..e_6: singular values 2 sqrt(2) and sqrt(2).
    let stretched: Vec<Wrench> = cross
        .iter()
        .enumerate()
        .map(|(k, w)| if k < 2 { w * 2.0 } else { *w })
        .collect();
    let m = evaluate_wrenches(&stretched, &MetricsOptions::default()).unwrap();
    assert!((isotropy(&m) - 0.5).abs() < 1e-12, "{}", isotropy(&m));

    // Two antipodal soft fingers on the unit sphere (x = +-1), 8 edges: G G^T is diagonal,
    // 32 for each force along the normals and 32 gamma^2 for the torque about them (every
    // wrench +-1 and +-gamma), 16 mu^2 for the four tangential directions (sum of cos^2 over
    // 8 edges = 4, times 2 contacts and 2 torsion signs). Isotropy: the smallest of 1,
    // mu / sqrt(2) and gamma over the largest.
    let grasp = equator(&[0.0, 180.0]);
    for (gamma, expected) in [(0.2, 0.2), (0.5, 0.5 / 2f64.sqrt())] {
        let soft = GraspModel::new(FrictionModel::SoftFinger {
            mu: 0.5,
            edges: 8,
            gamma,
        });
        let got = isotropy(&metrics(&grasp, soft));
        assert!((got - expected).abs() < 1e-12, "gamma {gamma}: {got}");
    }
    // As point contacts nothing resists the torque about the normals: rank 5, isotropy 0.
    assert_eq!(isotropy(&metrics(&grasp, friction(0.5))), 0.0);
}
