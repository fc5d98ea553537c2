//! Bad input gets a clear error naming the problem, or a defined result; never a panic.

use graspopt_quality::metrics::{MetricsOptions, evaluate_contacts, evaluate_wrenches};
use graspopt_quality::{Contact, ContactModel, GraspModel, QualityError, Wrench};
use nalgebra::Vector3;

mod support;

fn sphere_grasp() -> Vec<Contact> {
    support::equator(&[0.0, 120.0, 240.0])
}

fn model() -> GraspModel {
    GraspModel::new(ContactModel::PointFriction { mu: 0.5, edges: 8 })
}

fn eval(contacts: &[Contact], model: &GraspModel) -> Result<f64, QualityError> {
    evaluate_contacts(contacts, model, &MetricsOptions::default()).map(|m| m.bw)
}

#[test]
fn non_finite_coordinates_are_named() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut g = sphere_grasp();
        g[1].position.y = bad;
        let err = eval(&g, &model()).unwrap_err();
        assert!(matches!(
            err,
            QualityError::NotFinite {
                index: 1,
                field: "position",
                ..
            }
        ));
        assert!(
            err.to_string()
                .contains("contact 1: position is not finite"),
            "{err}"
        );
        let mut g = sphere_grasp();
        g[2].normal.x = bad;
        assert!(matches!(
            eval(&g, &model()),
            Err(QualityError::NotFinite {
                index: 2,
                field: "normal",
                ..
            })
        ));
    }
    let mut w = Wrench::zeros();
    w[4] = f64::INFINITY;
    let err = evaluate_wrenches(&[Wrench::zeros(), w], &MetricsOptions::default()).unwrap_err();
    assert!(matches!(
        err,
        QualityError::WrenchNotFinite { index: 1, .. }
    ));
    assert!(
        err.to_string().starts_with("wrench 1 is not finite"),
        "{err}"
    );
}

#[test]
fn bad_normals_are_named() {
    let mut g = sphere_grasp();
    g[0].normal = Vector3::zeros();
    let err = eval(&g, &model()).unwrap_err();
    assert_eq!(err, QualityError::ZeroNormal { index: 0 });
    assert!(err.to_string().contains("normal is zero"));
    let mut g = sphere_grasp();
    g[2].normal *= 2.0;
    let err = eval(&g, &model()).unwrap_err();
    assert!(matches!(err, QualityError::NonUnitNormal { index: 2, .. }));
    assert!(err.to_string().contains("length 2"), "{err}");
}

#[test]
fn bad_parameters_are_named() {
    let cases = [
        (
            GraspModel::new(ContactModel::PointFriction { mu: -0.1, edges: 8 }),
            "mu",
        ),
        (
            GraspModel::new(ContactModel::PointFriction { mu: 0.5, edges: 2 }),
            "edges",
        ),
        (
            GraspModel::new(ContactModel::SoftFinger {
                mu: 0.5,
                edges: 8,
                gamma: -1.0,
            }),
            "gamma",
        ),
        (model().with_torque_scale(0.0), "torque_scale"),
        (model().with_torque_scale(-2.0), "torque_scale"),
        (model().with_torque_scale(f64::NAN), "torque_scale"),
    ];
    for (m, expected) in cases {
        match eval(&sphere_grasp(), &m) {
            Err(QualityError::Parameter { name, .. }) => assert_eq!(name, expected),
            other => panic!("{expected}: {other:?}"),
        }
    }
    let err = eval(
        &sphere_grasp(),
        &model().with_reference_point(Vector3::new(0.0, f64::NAN, 0.0)),
    )
    .unwrap_err();
    assert!(err.to_string().contains("reference_point"), "{err}");
}

#[test]
fn empty_input_is_an_error() {
    assert_eq!(eval(&[], &model()), Err(QualityError::Empty("contacts")));
    assert_eq!(
        evaluate_wrenches(&[], &MetricsOptions::default()),
        Err(QualityError::Empty("wrenches"))
    );
}

#[test]
fn duplicated_points_give_the_same_result() {
    let g = sphere_grasp();
    let base = evaluate_contacts(&g, &model(), &MetricsOptions::default()).unwrap();
    let doubled: Vec<Contact> = g.iter().chain(g.iter()).copied().collect();
    let m = evaluate_contacts(&doubled, &model(), &MetricsOptions::default()).unwrap();
    assert!((m.epsilon - base.epsilon).abs() < 1e-12);
    assert!((m.volume.unwrap() - base.volume.unwrap()).abs() < 1e-12);
    // All contacts at one point with one normal: a defined, non-closing result.
    let same = vec![g[0]; 5];
    let m = evaluate_contacts(&same, &model(), &MetricsOptions::default()).unwrap();
    assert_eq!(m.rank, 2);
    assert!(!m.force_closure && m.bw < 0.0);
    // Zero friction: every cone edge is the normal; still defined.
    let frictionless_cone = GraspModel::new(ContactModel::PointFriction { mu: 0.0, edges: 8 });
    let m = evaluate_contacts(&g, &frictionless_cone, &MetricsOptions::default()).unwrap();
    assert!(!m.force_closure && m.rank < 6);
}
