//! Force analysis: net wrench, slip margins, and the least-norm contact forces that
//! resist an external wrench, against hand-computed values.

use graspopt_quality::{
    Contact, ContactForces, FrictionModel, QualityError, Resisting, Wrench, gravity_wrench,
    net_wrench, resisting_forces, slip_margins,
};
use nalgebra::Vector3;

const G: Vector3<f64> = Vector3::new(0.0, 0.0, -9.81);

fn point(mu: f64) -> FrictionModel {
    FrictionModel::PointFriction { mu, edges: 8 }
}

fn soft(mu: f64, gamma: f64) -> FrictionModel {
    FrictionModel::SoftFinger {
        mu,
        edges: 8,
        gamma,
    }
}

/// Two contacts at x = +-r, normals pointing in.
fn opposing(r: f64) -> Vec<Contact> {
    vec![
        Contact::new(Vector3::new(r, 0.0, 0.0), -Vector3::x()),
        Contact::new(Vector3::new(-r, 0.0, 0.0), Vector3::x()),
    ]
}

/// The forces of a grasp that resists, or a failure naming the outcome.
fn solve(
    contacts: &[Contact],
    model: &FrictionModel,
    external: &Wrench,
    reference: &Vector3<f64>,
) -> (ContactForces, f64) {
    match resisting_forces(contacts, model, external, reference) {
        Ok(Resisting::Forces { forces, norm }) => {
            // Whatever the grasp, the forces cancel the external wrench and sit in
            // their cones.
            let net = net_wrench(contacts, &forces, reference).unwrap();
            let scale = external.amax();
            assert!(
                (net + external).amax() <= 1e-8 * scale,
                "net {net:?} does not cancel {external:?}"
            );
            for (i, m) in slip_margins(contacts, model, &forces)
                .unwrap()
                .iter()
                .enumerate()
            {
                assert!(m.holds(1e-9 * scale), "contact {i}: {m:?}");
            }
            (forces, norm)
        }
        other => panic!("expected forces, got {other:?}"),
    }
}

fn assert_close(a: &Vector3<f64>, b: &Vector3<f64>, rel: f64, what: &str) {
    assert!(
        (a - b).norm() <= rel * b.norm().max(f64::MIN_POSITIVE),
        "{what}: {a:?} != {b:?}"
    );
}

fn assert_cannot_resist(result: Result<Resisting, QualityError>) {
    assert!(
        matches!(result, Ok(Resisting::CannotResist { .. })),
        "expected cannot resist, got {result:?}"
    );
}

#[test]
fn two_opposing_frictional_contacts_hold_a_weight() {
    // Least norm: f_n = W / (2 mu) and f_t = W / 2 up on each contact, so each
    // |f| = (W / 2) sqrt(1 + 1 / mu^2).
    let r = 0.04;
    let mass = 0.3;
    let w = mass * 9.81;
    let origin = Vector3::zeros();
    let external = gravity_wrench(mass, &G, &origin, &origin).unwrap();
    for mu in [0.2, 0.5, 1.0, 3.0] {
        for model in [point(mu), soft(mu, 0.01)] {
            let (forces, norm) = solve(&opposing(r), &model, &external, &origin);
            let expected = [
                Vector3::new(-w / (2.0 * mu), 0.0, w / 2.0),
                Vector3::new(w / (2.0 * mu), 0.0, w / 2.0),
            ];
            for (f, e) in forces.forces.iter().zip(&expected) {
                assert_close(f, e, 1e-6, &format!("mu {mu}"));
                let magnitude = w / 2.0 * (1.0 + 1.0 / (mu * mu)).sqrt();
                assert!((f.norm() - magnitude).abs() <= 1e-6 * magnitude);
            }
            for t in &forces.torsions {
                assert!(t.abs() <= 1e-8 * w * 0.01, "torsion {t}");
            }
            let expected_norm = w / 2f64.sqrt() * (1.0 + 1.0 / (mu * mu)).sqrt();
            assert!(
                (norm - expected_norm).abs() <= 1e-6 * expected_norm,
                "{norm}"
            );
        }
    }
}

#[test]
fn the_forces_do_not_depend_on_the_units() {
    // The same grasp in lengths scaled by `l` and forces by `f`: forces scale by `f`.
    let mu = 0.5;
    let base = {
        let origin = Vector3::zeros();
        let external = gravity_wrench(0.3, &G, &Vector3::new(0.0, 0.01, 0.0), &origin).unwrap();
        solve(&opposing(0.04), &soft(mu, 0.01), &external, &origin).0
    };
    for (l, f) in [(1e-6, 1e3), (1e3, 1e-6), (1e6, 1e6), (3.7, 0.013)] {
        let origin = Vector3::new(0.2, -0.1, 0.3) * l;
        let contacts: Vec<Contact> = opposing(0.04 * l)
            .iter()
            .map(|c| Contact::new(c.position + origin, c.normal))
            .collect();
        let external = gravity_wrench(
            0.3 * f,
            &G,
            &(origin + Vector3::new(0.0, 0.01 * l, 0.0)),
            &origin,
        )
        .unwrap();
        let (forces, _) = solve(&contacts, &soft(mu, 0.01 * l), &external, &origin);
        for (a, b) in forces.forces.iter().zip(&base.forces) {
            assert_close(&(a / f), b, 1e-6, &format!("lengths x{l}, forces x{f}"));
        }
        for (a, b) in forces.torsions.iter().zip(&base.torsions) {
            assert!(
                (a / (f * l) - b).abs() <= 1e-6 * b.abs().max(1e-3),
                "{a} {b}"
            );
        }
    }
}

#[test]
fn frictionless_opposing_contacts_squeeze_but_cannot_hold_a_weight() {
    let origin = Vector3::zeros();
    let weight = gravity_wrench(0.3, &G, &origin, &origin).unwrap();
    assert_cannot_resist(resisting_forces(
        &opposing(0.04),
        &FrictionModel::Frictionless,
        &weight,
        &origin,
    ));
    // Friction with mu = 0 is frictionless too.
    assert_cannot_resist(resisting_forces(
        &opposing(0.04),
        &point(0.0),
        &weight,
        &origin,
    ));
    // A push along their axis: only the contact facing it pushes back.
    let push = Wrench::new(-2.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let (forces, norm) = solve(
        &opposing(0.04),
        &FrictionModel::Frictionless,
        &push,
        &origin,
    );
    assert!(forces.forces[0].norm() <= 1e-8);
    assert_close(
        &forces.forces[1],
        &Vector3::new(2.0, 0.0, 0.0),
        1e-8,
        "near",
    );
    assert!((norm - 2.0).abs() <= 1e-8, "{norm}");
}

#[test]
fn a_single_contact_cannot_resist_a_torque_beyond_its_torsion() {
    // A contact on the bottom of the object, normal up; the world twists the object
    // about z by -1 N m.
    let contact = [Contact::new(Vector3::new(0.0, 0.0, -0.05), Vector3::z())];
    let twist = Wrench::new(0.0, 0.0, 0.0, 0.0, 0.0, -1.0);
    let origin = Vector3::zeros();
    assert_cannot_resist(resisting_forces(&contact, &point(0.8), &twist, &origin));
    assert_cannot_resist(resisting_forces(
        &contact,
        &FrictionModel::Frictionless,
        &twist,
        &origin,
    ));
    let gamma = 0.02;
    assert_cannot_resist(resisting_forces(
        &contact,
        &soft(0.8, gamma),
        &twist,
        &origin,
    ));
    // Pressed down with 10 N, a soft finger carries up to gamma 10 N = 0.2 N m by
    // torsion about its normal: torsion 0.1 N m about +z.
    let pressed = Wrench::new(0.0, 0.0, -10.0, 0.0, 0.0, -0.1);
    let (forces, norm) = solve(&contact, &soft(0.8, gamma), &pressed, &origin);
    assert_close(&forces.forces[0], &Vector3::new(0.0, 0.0, 10.0), 1e-8, "f");
    assert!(
        (forces.torsions[0] - 0.1).abs() <= 1e-9,
        "{:?}",
        forces.torsions
    );
    let expected = (100.0 + (0.1f64 / gamma).powi(2)).sqrt();
    assert!((norm - expected).abs() <= 1e-8 * expected, "{norm}");
    let too_much = Wrench::new(0.0, 0.0, -10.0, 0.0, 0.0, -0.3);
    assert_cannot_resist(resisting_forces(
        &contact,
        &soft(0.8, gamma),
        &too_much,
        &origin,
    ));
}

#[test]
fn three_soft_fingers_resist_a_torsion_about_their_common_axis() {
    // One finger on top (normal -z), two below (normal +z), all on the z axis: only
    // their torsions resist a twist T about z. Least norm: every contact at the limit
    // of its torsional cone, the top one with twice the force of each lower one:
    // f_n = T / (2 gamma) on top and T / (4 gamma) below; torsion -T / 2 on top (about
    // -z) and T / 4 below.
    let h = 0.03;
    let gamma = 0.01;
    let t = 0.2;
    let origin = Vector3::zeros();
    let twist = Wrench::new(0.0, 0.0, 0.0, 0.0, 0.0, -t);
    let grasps = [
        // Friction that cannot help: the lower contacts on the axis.
        (0.0, 0.5),
        // Lower contacts off the axis, frictionless.
        (0.02, 0.0),
    ];
    for (offset, mu) in grasps {
        let contacts = [
            Contact::new(Vector3::new(0.0, 0.0, h), -Vector3::z()),
            Contact::new(Vector3::new(offset, 0.0, -h), Vector3::z()),
            Contact::new(Vector3::new(-offset, 0.0, -h), Vector3::z()),
        ];
        let (forces, _) = solve(&contacts, &soft(mu, gamma), &twist, &origin);
        let what = format!("offset {offset}, mu {mu}");
        let top = t / (2.0 * gamma);
        assert_close(
            &forces.forces[0],
            &Vector3::new(0.0, 0.0, -top),
            1e-6,
            &what,
        );
        for f in &forces.forces[1..] {
            assert_close(f, &Vector3::new(0.0, 0.0, top / 2.0), 1e-6, &what);
        }
        let expected = [-t / 2.0, t / 4.0, t / 4.0];
        for (a, e) in forces.torsions.iter().zip(expected) {
            assert!((a - e).abs() <= 1e-6 * t, "{what}: {:?}", forces.torsions);
        }
        // Point contacts on the same grasp cannot: no torque about z from forces
        // along z.
        assert_cannot_resist(resisting_forces(&contacts, &point(0.0), &twist, &origin));
    }
    // With friction and a lever arm the lower contacts also push sideways, so the
    // answer changes but still resists.
    let contacts = [
        Contact::new(Vector3::new(0.0, 0.0, h), -Vector3::z()),
        Contact::new(Vector3::new(0.02, 0.0, -h), Vector3::z()),
        Contact::new(Vector3::new(-0.02, 0.0, -h), Vector3::z()),
    ];
    solve(&contacts, &soft(0.5, gamma), &twist, &origin);
}

#[test]
fn three_fingers_hold_an_off_centre_weight() {
    // Three soft fingers on the equator of a 4 cm sphere; the weight of 0.5 kg hangs
    // 1 cm off centre. The checks inside `solve` (equilibrium, cones) are the test.
    let radius = 0.04;
    let contacts: Vec<Contact> = [0.0f64, 120.0, 240.0]
        .iter()
        .map(|a| {
            let (s, c) = a.to_radians().sin_cos();
            let p = Vector3::new(c, s, 0.0) * radius;
            Contact::new(p, -p / radius)
        })
        .collect();
    let origin = Vector3::zeros();
    let com = Vector3::new(0.01, 0.0, 0.0);
    let external = gravity_wrench(0.5, &G, &com, &origin).unwrap();
    let (forces, norm) = solve(&contacts, &soft(0.5, 0.005), &external, &origin);
    // About another reference point the external wrench changes but the forces do not.
    let elsewhere = Vector3::new(0.1, -0.2, 0.05);
    let moved = gravity_wrench(0.5, &G, &com, &elsewhere).unwrap();
    let (again, norm_again) = solve(&contacts, &soft(0.5, 0.005), &moved, &elsewhere);
    for (a, b) in again.forces.iter().zip(&forces.forces) {
        assert_close(a, b, 1e-6, "moved reference point");
    }
    assert!((norm - norm_again).abs() <= 1e-6 * norm);
    // The weight is carried: the vertical forces sum to m g.
    let lift: f64 = forces.forces.iter().map(|f| f.z).sum();
    assert!((lift - 0.5 * 9.81).abs() <= 1e-8, "{lift}");
}

#[test]
fn no_external_wrench_needs_no_force() {
    let origin = Vector3::zeros();
    let (forces, norm) =
        match resisting_forces(&opposing(0.04), &point(0.5), &Wrench::zeros(), &origin) {
            Ok(Resisting::Forces { forces, norm }) => (forces, norm),
            other => panic!("{other:?}"),
        };
    assert_eq!(norm, 0.0);
    assert_eq!(forces.forces, vec![Vector3::zeros(); 2]);
    assert_eq!(forces.torsions, vec![0.0; 2]);
}

#[test]
fn net_wrench_and_slip_margins_by_hand() {
    let contacts = [
        Contact::new(Vector3::new(1.0, 0.0, 0.0), Vector3::z()),
        Contact::new(Vector3::new(0.0, 2.0, 0.0), -Vector3::x()),
    ];
    let forces = ContactForces::new(
        vec![Vector3::new(0.3, 0.4, 1.0), Vector3::new(-2.0, 0.0, 1.5)],
        vec![0.015, -0.05],
    );
    // Torques: (1,0,0) x (0.3,0.4,1) = (0,-1,0.4), plus 0.015 z;
    // (0,2,0) x (-2,0,1.5) = (3,0,4), plus -0.05 (-x).
    let net = net_wrench(&contacts, &forces, &Vector3::zeros()).unwrap();
    let expected = Wrench::new(-1.7, 0.4, 2.5, 3.05, -1.0, 4.415);
    assert!((net - expected).amax() <= 1e-12, "{net:?}");
    // About (1, 0, 0) the first contact's force has no moment.
    let net = net_wrench(&contacts, &forces, &Vector3::new(1.0, 0.0, 0.0)).unwrap();
    let expected = Wrench::new(-1.7, 0.4, 2.5, 3.05, 1.5, 4.015);
    assert!((net - expected).amax() <= 1e-12, "{net:?}");

    // Contact 0: f_n = 1, |f_t| = 0.5; contact 1: f_n = 2, |f_t| = 1.5.
    let m = slip_margins(&contacts, &soft(0.8, 0.02), &forces).unwrap();
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12;
    assert!(
        close(m[0].normal, 1.0) && close(m[0].friction, 0.3),
        "{m:?}"
    );
    assert!(close(m[0].torsion.unwrap(), 0.005), "{m:?}");
    assert!(
        close(m[1].normal, 2.0) && close(m[1].friction, 0.1),
        "{m:?}"
    );
    // gamma f_n - |torsion| = 0.04 - 0.05: the second contact would twist.
    assert!(close(m[1].torsion.unwrap(), -0.01), "{m:?}");
    assert!(m[0].holds(0.0) && !m[1].holds(0.0) && m[1].holds(0.02));
    // With less friction the second contact slips.
    let m = slip_margins(&contacts, &soft(0.5, 0.03), &forces).unwrap();
    assert!(close(m[1].friction, -0.5) && close(m[1].torsion.unwrap(), 0.01));
    // A pulling frictionless contact: negative normal margin.
    let pull = ContactForces::without_torsion(vec![Vector3::new(0.0, 0.0, -1.0); 1]);
    let m = slip_margins(&contacts[..1], &FrictionModel::Frictionless, &pull).unwrap();
    assert_eq!(
        (m[0].normal, m[0].friction, m[0].torsion),
        (-1.0, 0.0, None)
    );
    assert!(!m[0].holds(0.5));
    // A torsion on a point contact is not in its model.
    assert!(matches!(
        slip_margins(&contacts, &point(0.5), &forces),
        Err(QualityError::TorsionWithoutSoftFinger { index: 0, .. })
    ));
}

#[test]
fn gravity_wrench_by_hand() {
    let w = gravity_wrench(
        2.0,
        &G,
        &Vector3::new(0.1, 0.0, 0.3),
        &Vector3::new(0.0, 0.0, 0.3),
    )
    .unwrap();
    let expected = Wrench::new(0.0, 0.0, -19.62, 0.0, 1.962, 0.0);
    assert!((w - expected).amax() <= 1e-12, "{w:?}");
}

#[test]
fn bad_input_is_named() {
    let origin = Vector3::zeros();
    let weight = gravity_wrench(0.3, &G, &origin, &origin).unwrap();
    let contacts = opposing(0.04);
    let forces = ContactForces::without_torsion(vec![Vector3::zeros(); 2]);

    assert_eq!(
        resisting_forces(&[], &point(0.5), &weight, &origin),
        Err(QualityError::Empty("contacts"))
    );
    assert_eq!(
        net_wrench(&[], &ContactForces::without_torsion(vec![]), &origin),
        Err(QualityError::Empty("contacts"))
    );
    let mut bad = contacts.clone();
    bad[1].position.y = f64::NAN;
    assert!(matches!(
        resisting_forces(&bad, &point(0.5), &weight, &origin),
        Err(QualityError::NotFinite {
            index: 1,
            field: "position",
            ..
        })
    ));
    let mut bad = contacts.clone();
    bad[0].normal *= 2.0;
    assert!(matches!(
        slip_margins(&bad, &point(0.5), &forces),
        Err(QualityError::NonUnitNormal { index: 0, .. })
    ));
    for (model, name) in [
        (point(-0.1), "mu"),
        (point(f64::NAN), "mu"),
        (soft(0.5, -1.0), "gamma"),
        (soft(0.5, f64::INFINITY), "gamma"),
    ] {
        for result in [
            resisting_forces(&contacts, &model, &weight, &origin).map(|_| ()),
            slip_margins(&contacts, &model, &forces).map(|_| ()),
        ] {
            assert!(
                matches!(result, Err(QualityError::Parameter { name: n, .. }) if n == name),
                "{model:?}: {result:?}"
            );
        }
    }
    let mut external = weight;
    external[4] = f64::NAN;
    let err = resisting_forces(&contacts, &point(0.5), &external, &origin).unwrap_err();
    assert!(matches!(err, QualityError::ExternalWrench { .. }), "{err}");
    assert!(err.to_string().contains("external wrench"), "{err}");
    external[4] = 1e13;
    assert!(matches!(
        resisting_forces(&contacts, &point(0.5), &external, &origin),
        Err(QualityError::ExternalWrench { .. })
    ));
    let far = Vector3::new(f64::INFINITY, 0.0, 0.0);
    assert!(matches!(
        resisting_forces(&contacts, &point(0.5), &weight, &far),
        Err(QualityError::NotFinite {
            field: "reference_point",
            ..
        })
    ));

    // Forces that do not match the contacts.
    let one = ContactForces::without_torsion(vec![Vector3::zeros()]);
    let err = net_wrench(&contacts, &one, &origin).unwrap_err();
    assert_eq!(
        err,
        QualityError::ForceCount {
            contacts: 2,
            forces: 1,
            torsions: 1
        }
    );
    assert!(
        err.to_string()
            .contains("1 forces and 1 torsions given for 2 contacts")
    );
    let mut nan = forces.clone();
    nan.forces[1].z = f64::NAN;
    assert!(matches!(
        slip_margins(&contacts, &point(0.5), &nan),
        Err(QualityError::NotFinite {
            index: 1,
            field: "force",
            ..
        })
    ));
    let mut nan = forces.clone();
    nan.torsions[0] = f64::NAN;
    assert!(matches!(
        net_wrench(&contacts, &nan, &origin),
        Err(QualityError::TorsionOutOfRange { index: 0, .. })
    ));

    // Gravity.
    for mass in [-1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            gravity_wrench(mass, &G, &origin, &origin),
            Err(QualityError::Parameter { name: "mass", .. })
        ));
    }
    assert!(matches!(
        gravity_wrench(1.0, &Vector3::new(0.0, f64::NAN, 0.0), &origin, &origin),
        Err(QualityError::NotFinite { field: "g", .. })
    ));
    assert!(matches!(
        gravity_wrench(1e12, &G, &Vector3::new(1e12, 0.0, 0.0), &origin),
        Err(QualityError::ExternalWrench { .. })
    ));
}

#[test]
fn force_closure_grasps_resist_any_wrench() {
    // The metrics' sampled cones are inscribed in the exact ones, so a grasp in force
    // closure by the metrics resists every wrench here. Grasps not in force closure
    // resist some wrenches and not others; the forces, when found, are checked inside
    // `solve`.
    use graspopt_quality::GraspModel;
    use graspopt_quality::metrics::{MetricsOptions, evaluate_contacts};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    let mut rng = ChaCha8Rng::seed_from_u64(20);
    let model = soft(0.5, 0.005);
    let origin = Vector3::zeros();
    let (mut closed, mut resisted, mut refused) = (0, 0, 0);
    for _ in 0..60 {
        let contacts: Vec<Contact> = (0..3)
            .map(|_| {
                let z: f64 = rng.random_range(-1.0..1.0);
                let lon: f64 = rng.random_range(0.0..std::f64::consts::TAU);
                let r = (1.0 - z * z).sqrt();
                let n = Vector3::new(r * lon.cos(), r * lon.sin(), z);
                Contact::new(n * 0.04, -n)
            })
            .collect();
        let external = Wrench::from_fn(|_, _| rng.random_range(-1.0..1.0))
            .component_mul(&Wrench::new(5.0, 5.0, 5.0, 0.1, 0.1, 0.1));
        let metrics = evaluate_contacts(
            &contacts,
            &GraspModel::new(model),
            &MetricsOptions::without_volume(),
        )
        .unwrap();
        match resisting_forces(&contacts, &model, &external, &origin).unwrap() {
            Resisting::Forces { .. } => {
                solve(&contacts, &model, &external, &origin);
                resisted += 1;
            }
            Resisting::CannotResist { .. } => {
                assert!(!metrics.force_closure(), "{contacts:?} {external:?}");
                refused += 1;
            }
            Resisting::Unavailable { reason } => panic!("{contacts:?} {external:?}: {reason}"),
        }
        closed += usize::from(metrics.force_closure());
    }
    // The sample holds both outcomes and grasps in force closure.
    assert!(
        closed >= 5 && resisted > closed && refused >= 5,
        "{closed} {resisted} {refused}"
    );
}

#[test]
fn extreme_valid_input_gives_forces_or_a_named_error() {
    // Parameters far from ordinary grasps: the forces cancel the external wrench
    // (relative to its size, torques to its size times the grasp's length: its largest
    // coordinate or gamma). At mu = 1e6, the largest accepted, the solver may stop
    // short (a named error), never a panic.
    let origin = Vector3::zeros();
    let weight = |m: f64| gravity_wrench(m, &G, &origin, &origin).unwrap();
    let cases = [
        (opposing(0.04), point(1e5), weight(0.3)),
        (opposing(0.04), soft(1e5, 0.01), weight(0.3)),
        (opposing(0.04), point(1e-6), weight(0.3)),
        (opposing(1e11), soft(0.5, 1e12), weight(0.3)),
        (opposing(1e-9), soft(0.5, 1e-12), weight(0.3)),
        (opposing(0.04), point(0.5), weight(1e-300)),
        (opposing(0.04), point(0.5), weight(1e11)),
        (opposing(0.04), point(1e6), weight(0.3)),
    ];
    for (contacts, model, external) in cases {
        let gamma = match model {
            FrictionModel::SoftFinger { gamma, .. } => gamma,
            _ => 0.0,
        };
        let length = gamma.max(contacts[0].position.amax());
        match resisting_forces(&contacts, &model, &external, &origin) {
            Ok(Resisting::Forces { forces, norm }) => {
                let residual = net_wrench(&contacts, &forces, &origin).unwrap() + external;
                let scale = external.amax();
                assert!(
                    residual.fixed_rows::<3>(0).amax() <= 1e-6 * scale
                        && residual.fixed_rows::<3>(3).amax() <= 1e-6 * scale * length,
                    "{model:?} {external:?}: {residual:?}"
                );
                assert!(norm.is_finite());
            }
            Ok(Resisting::Unavailable { reason }) if model == point(1e6) => {
                println!("{reason}");
            }
            other => panic!("{model:?} {external:?}: {other:?}"),
        }
    }
}
