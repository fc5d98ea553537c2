//! The least resisting forces of grasps on which Clarabel stopped without an answer when the
//! program was solved once (`tests/data/forces-numerical-failures.json`, issue 29): solved
//! again in another way, they resist their load, and their norm is the one of the same
//! grasp under another load, scaled.

use graspopt_quality::{
    Contact, FrictionModel, Resisting, Wrench, net_wrench, resisting_forces, slip_margins,
};
use nalgebra::Vector3;
use serde::Deserialize;

#[derive(Deserialize)]
struct CaseFile {
    cases: Vec<Case>,
}

#[derive(Deserialize)]
struct Case {
    trial: String,
    status: String,
    model: FrictionModel,
    reference_point: Vector3<f64>,
    external: [f64; 6],
    contacts: Vec<Contact>,
}

fn cases() -> Vec<Case> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/forces-numerical-failures.json"
    );
    let text = std::fs::read_to_string(path).expect("the case file");
    serde_json::from_str::<CaseFile>(&text)
        .expect("the case file's types")
        .cases
}

/// The norm of the least forces resisting `external`, checked to cancel it inside the cones.
fn least_norm(case: &Case, external: &Wrench) -> f64 {
    let result = resisting_forces(&case.contacts, &case.model, external, &case.reference_point);
    let Ok(Resisting::Forces { forces, norm }) = result else {
        panic!(
            "{} (once {}): expected forces, got {result:?}",
            case.trial, case.status
        );
    };
    let net = net_wrench(&case.contacts, &forces, &case.reference_point).unwrap();
    assert!(
        (net + external).amax() <= 1e-6 * external.amax(),
        "{}: net {net:?} does not cancel {external:?}",
        case.trial
    );
    for (i, m) in slip_margins(&case.contacts, &case.model, &forces)
        .unwrap()
        .iter()
        .enumerate()
    {
        assert!(
            m.holds(1e-9 * external.amax()),
            "{}: contact {i}: {m:?}",
            case.trial
        );
    }
    norm
}

#[test]
fn grasps_the_solver_once_gave_up_on_resist_their_load() {
    let cases = cases();
    assert_eq!(cases.len(), 4);
    for case in &cases {
        let external = Wrench::from_row_slice(&case.external);
        let norm = least_norm(case, &external);
        // The least forces are linear in the load: 0.6 times the load (a scale that rounds
        // every number differently) needs 0.6 times the forces.
        let lighter = least_norm(case, &(external * 0.6));
        assert!(
            (lighter / 0.6 - norm).abs() <= 1e-6 * norm,
            "{}: {norm} N, but {lighter} N for 0.6 times the load",
            case.trial
        );
        assert!(norm > 0.0, "{}", case.trial);
    }
}
