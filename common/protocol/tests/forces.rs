//! A trial's force analysis on the wire (issue 29): least forces that are unavailable travel
//! with their reason beside a score that stands, results and statuses written before that
//! field still decode, and the text for people names the norm and the largest force apart.

use graspopt_protocol::*;

fn run() -> RunId {
    RunId::new("forces").unwrap()
}

const WHY: &str = "the conic solver stopped without an answer in each of the 4 ways it was tried (as posed: InsufficientProgress)";

fn held() -> ForceAnalysis {
    ForceAnalysis {
        external: [0.0, 0.0, -4.905, 0.0, 0.0, 0.0],
        resisting_norm: Some(6.25),
        resisting_max: Some(3.5),
        net_wrench: None,
        slip_margins: Vec::new(),
        unavailable: None,
    }
}

fn unknown() -> ForceAnalysis {
    ForceAnalysis {
        resisting_norm: None,
        resisting_max: None,
        net_wrench: Some([0.0, 0.0, 4.8, 0.0, 0.0, 0.0]),
        slip_margins: vec![0.5],
        unavailable: Some(WHY.into()),
        ..held()
    }
}

fn result(forces: Option<ForceAnalysis>) -> TrialResult {
    TrialResult {
        run_id: run(),
        trial_id: 4,
        attempt: 1,
        worker: "hand-1".into(),
        scorer: "metric".into(),
        score: 0.25,
        metrics: None,
        contacts: 46,
        fingers_in_contact: 3,
        cloud_points: 120,
        cloud_transport: "shm".into(),
        error: None,
        forces,
    }
}

fn status(best_forces: Option<ForceAnalysis>) -> RunStatus {
    RunStatus {
        run_id: run(),
        phase: RunPhase::Running,
        object: "sphere".into(),
        param_names: vec!["approach".into(), "vertical".into()],
        budget: 60,
        completed: 4,
        running: 1,
        failed: 0,
        best: None,
        best_history: vec![0.25],
        workers: Vec::new(),
        errors: ErrorCounts::default(),
        stamp_ms: 1_700_000_000_000,
        waiting: Vec::new(),
        best_forces,
    }
}

#[test]
fn unavailable_least_forces_travel_with_their_reason() {
    let r = result(Some(unknown()));
    for enc in [Encoding::Bincode, Encoding::Json] {
        assert_eq!(
            decode::<TrialResult>(&encode(&r, enc).unwrap(), enc).unwrap(),
            r
        );
    }
    let json: serde_json::Value =
        serde_json::from_slice(&encode(&r, Encoding::Json).unwrap()).unwrap();
    assert_eq!(json["forces"]["unavailable"], WHY);
    assert_eq!(json["score"], 0.25);
    let f = unknown();
    // Neither "can" nor "cannot": unknown.
    assert_eq!(f.can_resist(), None);
    assert_eq!(held().can_resist(), Some(true));
    assert_eq!(
        f.describe(),
        format!(
            "least contact forces unavailable (load 4.905 N): {WHY}; measured: net force 4.800 N, smallest slip margin 0.500 N"
        )
    );
    // Unknown forces with a norm contradict each other: refused, naming the field.
    let bad = result(Some(ForceAnalysis {
        resisting_norm: Some(1.0),
        ..unknown()
    }));
    let e = decode::<TrialResult>(&encode(&bad, Encoding::Bincode).unwrap(), Encoding::Bincode)
        .unwrap_err();
    assert!(e.to_string().contains("forces.unavailable"), "{e}");
}

#[test]
fn the_text_names_the_norm_of_all_forces_and_the_largest_single_one_apart() {
    assert_eq!(
        held().describe(),
        "holds the load (4.905 N): least contact forces 6.250 N in all (2-norm over the contacts), 3.500 N at the most loaded contact"
    );
    let cannot = ForceAnalysis {
        resisting_norm: None,
        resisting_max: None,
        ..held()
    };
    assert_eq!(cannot.can_resist(), Some(false));
    assert_eq!(cannot.describe(), "cannot hold the load (4.905 N)");
}

/// `ForceAnalysis.unavailable` was appended within wire version 3: a result or a status
/// written before it (by an older agent) still decodes, its forces known or "cannot resist".
#[test]
fn results_and_statuses_from_before_unavailable_still_decode() {
    // The old bincode layout ends where `unavailable` begins: `None` is one 0 byte, the
    // last of the message (forces and best_forces are the last fields).
    let r = result(Some(held()));
    let mut old = encode(&r, Encoding::Bincode).unwrap();
    assert_eq!(old.pop(), Some(0));
    assert_eq!(decode::<TrialResult>(&old, Encoding::Bincode).unwrap(), r);
    let s = status(Some(held()));
    let mut old = encode(&s, Encoding::Bincode).unwrap();
    assert_eq!(old.pop(), Some(0));
    assert_eq!(decode::<RunStatus>(&old, Encoding::Bincode).unwrap(), s);
    // Still refused: a payload cut anywhere else.
    old.pop();
    assert!(decode::<RunStatus>(&old, Encoding::Bincode).is_err());
    // JSON without the field.
    let mut json: serde_json::Value =
        serde_json::from_slice(&encode(&r, Encoding::Json).unwrap()).unwrap();
    json["forces"]
        .as_object_mut()
        .unwrap()
        .remove("unavailable");
    let json = serde_json::to_vec(&json).unwrap();
    assert_eq!(decode::<TrialResult>(&json, Encoding::Json).unwrap(), r);
}
