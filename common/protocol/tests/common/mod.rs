//! What the protocol's test targets share: a run id and contact clouds with one point.

use graspopt_protocol::*;

pub fn run() -> RunId {
    RunId::new("run-1").unwrap()
}

pub fn clouds() -> ContactClouds {
    ContactClouds {
        run_id: run(),
        trial_id: 7,
        attempt: 2,
        worker: "hand-1".into(),
        hand: "barrett".into(),
        palm_pose: Pose {
            translation: [0.1, -0.2, 0.3],
            rotation: [0.5, 0.5, 0.5, 0.5],
        },
        fingers: vec![
            FingerCloud {
                finger: Some(0),
                links: vec!["f1_distal".into()],
                points: vec![CloudPoint {
                    p: [0.01, 0.1 + 0.2, 1e-300],
                    n: [0.0, 0.6, 0.8],
                    w: 1.0,
                }],
            },
            FingerCloud {
                finger: None,
                links: vec!["palm".into()],
                points: vec![],
            },
        ],
        min_gap: None,
        error: None,
        executed_ms: 1_700_000_000_000,
    }
}
