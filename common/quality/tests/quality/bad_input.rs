//! Bad input gets a clear error naming the problem, or a defined result; never a panic.

use graspopt_quality::limits::{MAX_COORDINATE, MAX_EDGES, MAX_MU, MAX_WRENCHES};
use graspopt_quality::metrics::{
    DistanceSolver, MetricsOptions, distance_to_hull, evaluate_contacts, evaluate_wrenches,
};
use graspopt_quality::{Contact, FrictionModel, GraspMap, GraspModel, QualityError, Wrench};
use nalgebra::Vector3;

use crate::support;

fn sphere_grasp() -> Vec<Contact> {
    support::equator(&[0.0, 120.0, 240.0])
}

fn model() -> GraspModel {
    GraspModel::new(FrictionModel::PointFriction { mu: 0.5, edges: 8 })
}

fn eval(contacts: &[Contact], model: &GraspModel) -> Result<f64, QualityError> {
    evaluate_contacts(contacts, model, &MetricsOptions::default()).map(|m| m.bw())
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
            GraspModel::new(FrictionModel::PointFriction { mu: -0.1, edges: 8 }),
            "mu",
        ),
        (
            GraspModel::new(FrictionModel::PointFriction { mu: 0.5, edges: 2 }),
            "edges",
        ),
        (
            GraspModel::new(FrictionModel::SoftFinger {
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
    assert!((m.epsilon() - base.epsilon()).abs() < 1e-12);
    assert!((m.volume().unwrap() - base.volume().unwrap()).abs() < 1e-12);
    // All contacts at one point with one normal: a defined, non-closing result.
    let same = vec![g[0]; 5];
    let m = evaluate_contacts(&same, &model(), &MetricsOptions::default()).unwrap();
    assert_eq!(m.rank(), 2);
    assert!(!m.force_closure() && m.bw() < 0.0);
    // Zero friction: every cone edge is the normal; still defined.
    let frictionless_cone = GraspModel::new(FrictionModel::PointFriction { mu: 0.0, edges: 8 });
    let m = evaluate_contacts(&g, &frictionless_cone, &MetricsOptions::default()).unwrap();
    assert!(!m.force_closure() && m.rank() < 6);
}

#[test]
fn edge_counts_are_bounded_before_anything_is_allocated() {
    // 3 contacts x 2^40 edges: the old code asked for 158 TB and aborted.
    for edges in [1usize << 40, MAX_EDGES + 1, usize::MAX] {
        for contact in [
            FrictionModel::PointFriction { mu: 0.5, edges },
            FrictionModel::SoftFinger {
                mu: 0.5,
                edges,
                gamma: 0.1,
            },
        ] {
            let err = eval(&sphere_grasp(), &GraspModel::new(contact)).unwrap_err();
            assert!(
                matches!(err, QualityError::Parameter { name: "edges", .. }),
                "{err:?}"
            );
            let text = err.to_string();
            assert!(text.starts_with("edges = "), "{text}");
            assert!(text.contains("at most 4096 edges"), "{text}");
        }
    }
    assert_eq!(MAX_EDGES, 4096);
    // The limit itself is accepted: one contact on the unit sphere is at distance 1.
    let fine = GraspModel::new(FrictionModel::PointFriction {
        mu: 0.5,
        edges: MAX_EDGES,
    });
    let g = GraspMap::from_contacts(&sphere_grasp()[..1], &fine).unwrap();
    assert_eq!(g.wrenches().len(), 4096);
    let m = evaluate_contacts(&sphere_grasp()[..1], &fine, &MetricsOptions::default()).unwrap();
    assert_eq!(m.rank(), 2);
    assert!((m.distance() - 1.0).abs() < 1e-12 && (m.bw() + 1.0).abs() < 1e-12);
}

#[test]
fn wrench_counts_are_bounded() {
    // 250 contacts x 2 x 4096 soft-finger wrenches = 2,048,000 > 2,000,000.
    let model = GraspModel::new(FrictionModel::SoftFinger {
        mu: 0.5,
        edges: MAX_EDGES,
        gamma: 0.1,
    });
    let contacts = vec![sphere_grasp()[0]; 250];
    let err = GraspMap::from_contacts(&contacts, &model).unwrap_err();
    assert_eq!(
        err,
        QualityError::TooManyContactWrenches {
            contacts: 250,
            per_contact: 8192,
            count: 2_048_000,
            limit: MAX_WRENCHES,
        }
    );
    assert!(
        err.to_string()
            .starts_with("250 contacts x 8192 wrenches per contact = 2048000 wrenches, more than the limit of 2000000"),
        "{err}"
    );
    // Given wrenches: the same limit.
    let many = vec![Wrench::zeros(); MAX_WRENCHES + 1];
    let err = evaluate_wrenches(&many, &MetricsOptions::default()).unwrap_err();
    assert_eq!(
        err,
        QualityError::TooManyWrenches {
            count: 2_000_001,
            limit: 2_000_000,
        }
    );
}

#[test]
fn huge_magnitudes_are_named_errors_not_null_metrics() {
    // mu = 1e308 used to give NaN distance and bw (printed as null) with min-norm.
    let huge_mu = GraspModel::new(FrictionModel::PointFriction {
        mu: 1e308,
        edges: 8,
    });
    for solver in [DistanceSolver::MinNorm, DistanceSolver::Clarabel] {
        let options = MetricsOptions {
            volume: false,
            distance_solver: solver,
        };
        let err = evaluate_contacts(&sphere_grasp(), &huge_mu, &options).unwrap_err();
        assert!(
            matches!(err, QualityError::Parameter { name: "mu", value, .. } if value == 1e308),
            "{err:?}"
        );
        assert!(
            err.to_string().starts_with("mu = 1e308 is invalid"),
            "{err}"
        );
    }
    let soft = |gamma| {
        GraspModel::new(FrictionModel::SoftFinger {
            mu: 0.5,
            edges: 8,
            gamma,
        })
    };
    let named = |m: &GraspModel| match eval(&sphere_grasp(), m) {
        Err(QualityError::Parameter { name, .. }) => name,
        other => panic!("{other:?}"),
    };
    assert_eq!(named(&soft(1e300)), "gamma");
    let over_mu = GraspModel::new(FrictionModel::PointFriction {
        mu: MAX_MU * 2.0,
        edges: 8,
    });
    assert_eq!(named(&over_mu), "mu");
    // Positions and the reference point beyond 1e12.
    let mut far = sphere_grasp();
    far[2].position.x = 2e12;
    let err = eval(&far, &model()).unwrap_err();
    assert!(
        matches!(
            err,
            QualityError::OutOfRange {
                what: "contact",
                index: 2,
                field: "position",
                ..
            }
        ),
        "{err:?}"
    );
    assert!(
        err.to_string().contains("at most 1e12 in absolute value"),
        "{err}"
    );
    let err = eval(
        &sphere_grasp(),
        &model().with_reference_point(Vector3::new(0.0, -1e13, 0.0)),
    )
    .unwrap_err();
    assert!(err.to_string().contains("reference_point"), "{err}");
    // A tiny torque scale makes torques of 5e299: named by contact.
    let err = eval(&sphere_grasp(), &model().with_torque_scale(1e-300)).unwrap_err();
    assert!(
        matches!(err, QualityError::ContactWrenchOutOfRange { index: 0, .. }),
        "{err:?}"
    );
    assert!(err.to_string().contains("torque_scale"), "{err}");
    // Given wrenches +-1e308 e_x, +-e_y: rank 0 and distance 1 before; now an error.
    let mut big = [Wrench::zeros(); 4];
    big[0][0] = 1e308;
    big[1][0] = -1e308;
    big[2][1] = 1.0;
    big[3][1] = -1.0;
    let err = evaluate_wrenches(&big, &MetricsOptions::default()).unwrap_err();
    assert_eq!(
        err,
        QualityError::WrenchOutOfRange {
            index: 0,
            component: 0,
            value: 1e308,
            limit: MAX_COORDINATE,
        }
    );
    assert!(
        err.to_string()
            .starts_with("wrench 0: component 0 = 1e308 is out of range"),
        "{err}"
    );
}

#[test]
fn both_solvers_agree_up_to_the_magnitude_limit() {
    let both = |w: &[Wrench]| {
        [DistanceSolver::MinNorm, DistanceSolver::Clarabel]
            .map(|s| distance_to_hull(w, s).unwrap_or_else(|e| panic!("{s:?}: {e}")))
    };
    // +-1e12 e_x, +-e_y: the origin is inside the hull. Min-norm used to stop at e_y
    // and report distance 1 (with Clarabel at 0).
    let mut mixed = [Wrench::zeros(); 4];
    mixed[0][0] = MAX_COORDINATE;
    mixed[1][0] = -MAX_COORDINATE;
    mixed[2][1] = 1.0;
    mixed[3][1] = -1.0;
    for d in both(&mixed) {
        assert!(d < 1e-3, "{d}");
    }
    let m = evaluate_wrenches(&mixed, &MetricsOptions::default()).unwrap();
    assert!(
        m.distance() < 1e-3 && m.bw() == 0.0 && !m.force_closure(),
        "{m:?}"
    );
    // One contact (distance 1) and two contacts (distance 0.0669872981) in units from
    // 1e-9 to 1e12: Clarabel failed (PrimalInfeasible) at 1e12 and drifted at 1e-9.
    let g = sphere_grasp();
    for (contacts, expected) in [(&g[..1], 1.0), (&g[..2], 0.066_987_298_107_780_8)] {
        let base = GraspMap::from_contacts(contacts, &model()).unwrap();
        for s in [1e-9, 1.0, 1e12] {
            let w: Vec<Wrench> = base.wrenches().iter().map(|x| x * s).collect();
            for d in both(&w) {
                assert!(
                    (d / s - expected).abs() < 1e-7,
                    "scale {s}: {} vs {expected}",
                    d / s
                );
            }
        }
    }
}

#[test]
fn bw_is_a_positive_zero_on_the_boundary() {
    // Two antipodal frictionless contacts: the origin lies on the (segment) hull, so
    // distance 0 and bw = -0 before; now +0 with either solver.
    let g = [
        Contact::new(Vector3::x(), -Vector3::x()),
        Contact::new(-Vector3::x(), Vector3::x()),
    ];
    let m = GraspModel::new(FrictionModel::Frictionless);
    for solver in [DistanceSolver::MinNorm, DistanceSolver::Clarabel] {
        let options = MetricsOptions {
            volume: true,
            distance_solver: solver,
        };
        let r = evaluate_contacts(&g, &m, &options).unwrap();
        assert_eq!((r.rank(), r.force_closure()), (1, false));
        assert_eq!(r.bw(), 0.0);
        assert!(r.bw().is_sign_positive(), "{solver:?}: bw = {:?}", r.bw());
        assert!(r.distance().is_sign_positive() && r.volume() == Some(0.0));
    }
}

#[test]
fn hulls_too_large_for_memory_are_refused() {
    // 3 contacts x 256 cone edges: the full hull (volume) needs more than 5 million
    // facets; the old code built it in 2 GB (at 1,024 edges it used 24 GB and was
    // killed). The inscribed radius alone (expanding polytope) stays cheap.
    let dense = GraspModel::new(FrictionModel::PointFriction {
        mu: 0.5,
        edges: 256,
    });
    let err = evaluate_contacts(&sphere_grasp(), &dense, &MetricsOptions::default()).unwrap_err();
    assert_eq!(
        err,
        QualityError::HullTooLarge {
            metric: "volume",
            points: 768,
            limit: 5_000_000,
        }
    );
    assert!(
        err.to_string().contains("more than 5000000 facets"),
        "{err}"
    );
    let m = evaluate_contacts(&sphere_grasp(), &dense, &MetricsOptions::without_volume()).unwrap();
    assert!(m.force_closure());
    // Between the 8-edge value and the friction cone's limit.
    assert!(
        (m.epsilon() - 0.287_685_384).abs() < 1e-8,
        "{}",
        m.epsilon()
    );
}
