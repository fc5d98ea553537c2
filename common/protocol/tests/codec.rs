//! Round trips of every message in both encodings, and refusal of bad payloads.

use graspopt_protocol::codec::BINCODE_MIME;
use graspopt_protocol::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

mod common;
use common::{clouds, run};

fn result() -> TrialResult {
    TrialResult {
        run_id: run(),
        trial_id: 7,
        attempt: 1,
        worker: "hand-1".into(),
        scorer: "metric-1".into(),
        score: 0.123_456_789_012_345_67,
        metrics: Some(
            MetricValues::default()
                .with("rank", Some(MetricValue::Count(6)))
                .with("force_closure", Some(MetricValue::Flag(true)))
                .with("epsilon", Some(MetricValue::Real(0.123_456_789_012_345_67)))
                .with("volume", None)
                .with("distance", Some(MetricValue::Real(0.0)))
                .with("bw", Some(MetricValue::Real(0.123_456_789_012_345_67))),
        ),
        contacts: 63,
        fingers_in_contact: 3,
        cloud_points: 120,
        cloud_transport: "zenoh".into(),
        error: None,
        forces: None,
    }
}

#[test]
fn every_message_round_trips_exactly_in_both_encodings() {
    let c = clouds();
    let r = result();
    let cmd = TrialCommand {
        run_id: run(),
        trial_id: 3,
        attempt: 1,
        worker: "hand-2".into(),
        hand: "barrett".into(),
        params: vec![-0.031_415_926_535_897_93, 0.02],
        palm_pose: Pose::IDENTITY,
        lease_ms: 30_000,
        issued_ms: 5,
    };
    let req = SuggestRequest {
        run_id: run(),
        request_id: 9,
        method: PlannerMethod::Bo,
        bounds: vec![[-0.16, 0.02], [-0.05, 0.05]],
        seed: 42,
        initial: Some(5),
        observations: vec![Observation {
            x: vec![0.0, 0.01],
            y: -1.5,
        }],
        pending: vec![vec![0.01, 0.0]],
        count: 3,
        engine_state: Some(vec![0, 7, 255]),
    };
    for enc in [Encoding::Bincode, Encoding::Json] {
        assert_eq!(
            decode::<ContactClouds>(&encode(&c, enc).unwrap(), enc).unwrap(),
            c
        );
        assert_eq!(
            decode::<TrialResult>(&encode(&r, enc).unwrap(), enc).unwrap(),
            r
        );
        assert_eq!(
            decode::<TrialCommand>(&encode(&cmd, enc).unwrap(), enc).unwrap(),
            cmd
        );
        assert_eq!(
            decode::<SuggestRequest>(&encode(&req, enc).unwrap(), enc).unwrap(),
            req
        );
    }
}

/// A planner question names the first value that is not finite, in the history or the
/// pending trials.
#[test]
fn a_planner_question_names_its_first_value_not_finite() {
    let question = || SuggestRequest {
        run_id: run(),
        request_id: 1,
        method: PlannerMethod::Bo,
        bounds: vec![[0.0, 1.0], [0.0, 1.0]],
        seed: 0,
        initial: None,
        observations: (0..4)
            .map(|i| Observation {
                x: vec![0.1 * f64::from(i), 0.5],
                y: f64::from(i),
            })
            .collect(),
        pending: vec![vec![0.2, 0.3], vec![0.4, 0.6]],
        count: 2,
        engine_state: None,
    };
    assert_eq!(question().validate(), Ok(()));
    type Spoil = fn(&mut SuggestRequest);
    let cases: [(&str, Spoil); 4] = [
        ("observations[2].x[1] is not finite (NaN)", |q| {
            q.observations[2].x[1] = f64::NAN;
            q.observations[3].y = f64::NAN;
        }),
        ("observations[1].y[0] is not finite (inf)", |q| {
            q.observations[1].y = f64::INFINITY
        }),
        ("pending[1][0] is not finite (-inf)", |q| {
            q.pending[1][0] = f64::NEG_INFINITY
        }),
        ("observations[3].x has 1 values, not 2", |q| {
            q.observations[3].x.pop();
        }),
    ];
    for (expected, spoil) in cases {
        let mut q = question();
        spoil(&mut q);
        let e = q.validate().unwrap_err();
        assert_eq!(e.to_string(), expected);
        assert_eq!(e.message_type, "SuggestRequest");
        assert!(expected.starts_with(&format!("{} ", e.field)), "{e:?}");
    }
}

/// A validation error names the message, the field and the problem apart, and reads as
/// the field then the problem.
#[test]
fn a_validation_error_names_the_message_the_field_and_the_problem() {
    let mut c = clouds();
    c.fingers[0].points[0].n = [0.0, 0.0, 2.0];
    let e = c.validate().unwrap_err();
    assert_eq!(e.message_type, "ContactClouds");
    assert_eq!(e.field, "fingers[0].points[0].n");
    assert_eq!(e.problem, error::Problem::NotUnitNormal(2.0));
    assert_eq!(
        e.to_string(),
        "fingers[0].points[0].n is not a unit normal (norm 2)"
    );
    let mut r = result();
    r.worker = "hand/1".into();
    let e = r.validate().unwrap_err();
    assert_eq!(
        (e.message_type, e.field.as_str()),
        ("TrialResult", "worker")
    );
    assert!(matches!(e.problem, error::Problem::InvalidId(_)), "{e:?}");
    assert!(
        e.to_string()
            .starts_with("worker: invalid agent id \"hand/1\""),
        "{e}"
    );
    // A part checked on its own is named by its own type.
    let mut pose = Pose::IDENTITY;
    pose.translation[1] = f64::NAN;
    let e = pose.validate("grip").unwrap_err();
    assert_eq!(
        (e.message_type, e.field.as_str()),
        ("Pose", "grip.translation[1]")
    );
    assert_eq!(e.to_string(), "grip.translation[1] is not finite (NaN)");
}

#[test]
fn bincode_payload_starts_with_the_wire_version() {
    let bytes = encode(&result(), Encoding::Bincode).unwrap();
    assert_eq!(u16::from_le_bytes([bytes[0], bytes[1]]), WIRE_VERSION);
    let json: serde_json::Value =
        serde_json::from_slice(&encode(&result(), Encoding::Json).unwrap()).unwrap();
    assert_eq!(json["wire"], serde_json::json!(WIRE_VERSION));
    assert_eq!(Encoding::from_mime(BINCODE_MIME), Encoding::Bincode);
    assert_eq!(
        Encoding::from_mime("application/json;charset=utf-8"),
        Encoding::Json
    );
}

#[test]
fn a_hand_written_json_result_decodes() {
    // What an agent in another language writes, from docs/protocol.md.
    let text = r#"{"wire": 4, "run_id": "run-1", "trial_id": 4, "attempt": 1,
        "worker": "py-hand", "scorer": "py", "score": -2.5, "metrics": null,
        "contacts": 0, "fingers_in_contact": 0, "cloud_points": 0, "cloud_transport": "",
        "error": null}"#;
    let r: TrialResult = decode(text.as_bytes(), Encoding::Json).unwrap();
    assert_eq!(r.trial_id, 4);
    assert_eq!(r.score, -2.5);
}

#[test]
fn wrong_version_is_refused_by_name() {
    let mut bytes = encode(&result(), Encoding::Bincode).unwrap();
    bytes[0] = 9;
    let e = decode::<TrialResult>(&bytes, Encoding::Bincode).unwrap_err();
    assert!(
        matches!(e, DecodeError::WrongVersion { found: 9, .. }),
        "{e}"
    );
    assert!(e.to_string().contains("TrialResult"));
    let text = r#"{"wire": 1, "run_id": "r"}"#;
    let e = decode::<TrialResult>(text.as_bytes(), Encoding::Json).unwrap_err();
    assert!(
        matches!(e, DecodeError::WrongVersion { found: 1, .. }),
        "{e}"
    );
}

#[test]
fn garbage_truncation_and_trailing_bytes_are_refused() {
    let bytes = encode(&clouds(), Encoding::Bincode).unwrap();
    for cut in 0..bytes.len() {
        assert!(decode::<ContactClouds>(&bytes[..cut], Encoding::Bincode).is_err());
    }
    let mut long = bytes.clone();
    long.push(0);
    let e = decode::<ContactClouds>(&long, Encoding::Bincode).unwrap_err();
    assert!(e.to_string().contains("trailing"), "{e}");
    // A huge length prefix must not allocate: the 64 MiB limit refuses it.
    let mut huge = WIRE_VERSION.to_le_bytes().to_vec();
    huge.extend_from_slice(&[5, b'r', b'u', b'n', b'-', b'1', 7, 2, 0xfd]);
    huge.extend_from_slice(&u64::MAX.to_le_bytes());
    assert!(decode::<ContactClouds>(&huge, Encoding::Bincode).is_err());
    // Pseudo-random bytes.
    let mut rng = ChaCha8Rng::seed_from_u64(0x9e37_79b9_7f4a_7c15);
    for len in 0..2000 {
        let junk: Vec<u8> = (0..len % 300).map(|_| rng.random::<u8>()).collect();
        let _ = decode::<ContactClouds>(&junk, Encoding::Bincode);
        let _ = decode::<TrialResult>(&junk, Encoding::Json);
    }
}

#[test]
fn invalid_content_is_refused_naming_the_field() {
    let mut c = clouds();
    c.fingers[0].points[0].p[1] = f64::NAN;
    // JSON cannot carry NaN: bincode can, and validation catches it.
    let bytes = encode(&c, Encoding::Bincode).unwrap();
    let e = decode::<ContactClouds>(&bytes, Encoding::Bincode).unwrap_err();
    assert!(matches!(e, DecodeError::Invalid { .. }));
    assert!(e.to_string().contains("fingers[0].points[0].p[1]"), "{e}");

    let mut c = clouds();
    c.fingers[0].points[0].n = [0.0, 0.0, 0.0];
    let e = decode::<ContactClouds>(&encode(&c, Encoding::Bincode).unwrap(), Encoding::Bincode)
        .unwrap_err();
    assert!(e.to_string().contains("unit normal"), "{e}");

    let mut r = result();
    r.score = f64::INFINITY;
    let e = decode::<TrialResult>(&encode(&r, Encoding::Bincode).unwrap(), Encoding::Bincode)
        .unwrap_err();
    assert!(e.to_string().contains("score"), "{e}");

    let text = r#"{"wire": 4, "run_id": "a/b", "trial_id": 4}"#;
    let e = decode::<TrialResult>(text.as_bytes(), Encoding::Json).unwrap_err();
    assert!(matches!(e, DecodeError::Malformed { .. }), "{e}");
}

#[test]
fn a_topic_decodes_to_its_message_fields() {
    let msg = result();
    for enc in [Encoding::Bincode, Encoding::Json] {
        let bytes = encode(&msg, enc).unwrap();
        let v = decode_topic(Topic::Result, &bytes, enc).unwrap();
        assert_eq!(v["trial_id"], msg.trial_id);
        assert_eq!(v["score"], msg.score);
        assert_eq!(v["worker"], msg.worker.as_str());
        assert!(v.get("wire").is_none());
        // Another topic's type does not decode from these bytes.
        assert!(decode_topic(Topic::Object, &bytes, enc).is_err());
    }
    // Each topic decodes its own row's message type.
    for topic in Topic::ALL {
        let e = decode_topic(topic, &[], Encoding::Bincode).unwrap_err();
        let message_type = topic.message_type();
        assert_eq!(e, DecodeError::Empty { message_type }, "{topic:?}");
    }
}

/// `msg` encoded with bincode (which carries any number) is refused on decoding, naming
/// `field`.
fn refused_naming<T: Message + std::fmt::Debug>(msg: &T, field: &str) {
    let e = decode::<T>(&encode(msg, Encoding::Bincode).unwrap(), Encoding::Bincode).unwrap_err();
    assert!(e.to_string().contains(field), "{e}");
}

fn status(waiting: Vec<Waiting>) -> RunStatus {
    RunStatus {
        run_id: run(),
        phase: RunPhase::Waiting,
        object: "mug".into(),
        param_names: vec!["approach".into()],
        budget: 10,
        completed: 0,
        running: 0,
        failed: 0,
        best: None,
        best_history: vec![],
        workers: vec![],
        errors: ErrorCounts::default(),
        stamp_ms: 1_700_000_005_000,
        waiting,
        best_forces: None,
    }
}

/// `RunStatus.waiting` was appended within wire version 3: a status written before it (an
/// older coordinator's) still decodes, in both encodings, with nothing waited for.
#[test]
fn a_status_from_before_waiting_still_decodes() {
    let waits = vec![
        Waiting {
            reason: WaitReason::ObjectEstimate,
            since_ms: 1_700_000_000_000,
        },
        Waiting {
            reason: WaitReason::Planner,
            since_ms: 1_700_000_004_000,
        },
    ];
    let s = status(waits);
    for enc in [Encoding::Bincode, Encoding::Json] {
        assert_eq!(
            decode::<RunStatus>(&encode(&s, enc).unwrap(), enc).unwrap(),
            s
        );
    }
    let json: serde_json::Value =
        serde_json::from_slice(&encode(&s, Encoding::Json).unwrap()).unwrap();
    assert_eq!(json["waiting"][1]["reason"], "planner");
    // The old bincode layout ends where `waiting` begins: an empty list is one 0 byte (after
    // it, `best_forces`, appended later, is one more when `None`).
    let empty = status(vec![]);
    let mut old = encode(&empty, Encoding::Bincode).unwrap();
    assert_eq!(old.pop(), Some(0));
    assert_eq!(old.pop(), Some(0));
    assert_eq!(decode::<RunStatus>(&old, Encoding::Bincode).unwrap(), empty);
    let mut old_json: serde_json::Value =
        serde_json::from_slice(&encode(&empty, Encoding::Json).unwrap()).unwrap();
    old_json.as_object_mut().unwrap().remove("waiting");
    let old_json = serde_json::to_vec(&old_json).unwrap();
    assert_eq!(
        decode::<RunStatus>(&old_json, Encoding::Json).unwrap(),
        empty
    );
    // Still refused: a payload cut anywhere else, and bytes after the message.
    old.pop();
    assert!(decode::<RunStatus>(&old, Encoding::Bincode).is_err());
    let mut long = encode(&empty, Encoding::Bincode).unwrap();
    long.push(0);
    assert!(decode::<RunStatus>(&long, Encoding::Bincode).is_err());
}

/// `TrialResult.forces` was appended within wire version 3: a result written before it (an
/// older metric agent's) still decodes, in both encodings, without a force analysis.
#[test]
fn a_result_from_before_forces_still_decodes() {
    let with = TrialResult {
        forces: Some(ForceAnalysis {
            external: [0.0, 0.0, -4.905, 0.0, 0.0, 0.0],
            resisting_norm: Some(5.5),
            resisting_max: Some(3.0),
            net_wrench: None,
            slip_margins: vec![0.25, 1.5],
            unavailable: None,
        }),
        ..result()
    };
    for enc in [Encoding::Bincode, Encoding::Json] {
        assert_eq!(
            decode::<TrialResult>(&encode(&with, enc).unwrap(), enc).unwrap(),
            with
        );
    }
    // The old bincode layout ends where `forces` begins: `None` is one 0 byte.
    let without = result();
    let mut old = encode(&without, Encoding::Bincode).unwrap();
    assert_eq!(old.pop(), Some(0));
    assert_eq!(
        decode::<TrialResult>(&old, Encoding::Bincode).unwrap(),
        without
    );
    let mut old_json: serde_json::Value =
        serde_json::from_slice(&encode(&without, Encoding::Json).unwrap()).unwrap();
    old_json.as_object_mut().unwrap().remove("forces");
    let old_json = serde_json::to_vec(&old_json).unwrap();
    assert_eq!(
        decode::<TrialResult>(&old_json, Encoding::Json).unwrap(),
        without
    );
    // A force analysis with a NaN is refused, naming the field.
    let mut bad = with.clone();
    if let Some(f) = bad.forces.as_mut() {
        f.slip_margins[1] = f64::NAN;
    }
    refused_naming(&bad, "forces.slip_margins[1]");
}

/// `RunStatus.best_forces` was appended after `waiting`: a status written before it still
/// decodes (bincode), as does one from before `waiting`.
#[test]
fn a_status_from_before_best_forces_still_decodes() {
    let mut s = status(vec![Waiting {
        reason: WaitReason::Hand,
        since_ms: 1_700_000_004_000,
    }]);
    s.best_forces = Some(ForceAnalysis {
        external: [0.0, 0.0, -4.905, 0.0, 0.0, 0.0],
        resisting_norm: None,
        resisting_max: None,
        net_wrench: Some([0.1, 0.0, 4.8, 0.0, 0.01, 0.0]),
        slip_margins: vec![-0.5],
        unavailable: None,
    });
    for enc in [Encoding::Bincode, Encoding::Json] {
        assert_eq!(
            decode::<RunStatus>(&encode(&s, enc).unwrap(), enc).unwrap(),
            s
        );
    }
    // Forces that are not numbers are refused as a result's are (JSON cannot carry them:
    // fuzzing found a status that decoded from bincode and not from its own JSON).
    let mut bad = s.clone();
    if let Some(f) = bad.best_forces.as_mut() {
        f.external[1] = f64::NAN;
    }
    refused_naming(&bad, "best_forces.external");
    // Before best_forces: the layout ends after `waiting` (`None` is one 0 byte).
    s.best_forces = None;
    let mut old = encode(&s, Encoding::Bincode).unwrap();
    assert_eq!(old.pop(), Some(0));
    assert_eq!(decode::<RunStatus>(&old, Encoding::Bincode).unwrap(), s);
}

fn wrenches() -> FingertipWrenches {
    FingertipWrenches {
        run_id: run(),
        trial_id: 7,
        attempt: 1,
        worker: "ft-hand".into(),
        hand: "barrett_ft".into(),
        palm_pose: Pose::IDENTITY,
        fingertips: vec![FingertipWrench {
            finger: 1,
            link: "f2_tip".into(),
            sensor_pose: Pose::IDENTITY,
            surface: FingertipSurface::Capsule {
                center: [0.0, 0.0, 0.02],
                half_length: 0.01,
                radius: 0.008,
                base_z: Some(0.0),
            },
            force: [0.25, 0.0, -2.0],
            torque: [0.0, 0.03, 0.0],
            stamp_ms: 1_700_000_000_000,
        }],
        min_gap: None,
        error: None,
        executed_ms: 1_700_000_000_001,
    }
}

#[test]
fn fingertip_wrenches_round_trip_and_bad_readings_are_refused_by_field() {
    let w = wrenches();
    for enc in [Encoding::Bincode, Encoding::Json] {
        assert_eq!(
            decode::<FingertipWrenches>(&encode(&w, enc).unwrap(), enc).unwrap(),
            w
        );
    }
    // The surface as a Python hand writes it.
    let json: serde_json::Value =
        serde_json::from_slice(&encode(&w, Encoding::Json).unwrap()).unwrap();
    assert_eq!(json["fingertips"][0]["surface"]["shape"], "capsule");
    assert_eq!(json["fingertips"][0]["surface"]["half_length"], 0.01);
    let refused = |w: &FingertipWrenches| {
        let e =
            decode::<FingertipWrenches>(&encode(w, Encoding::Bincode).unwrap(), Encoding::Bincode)
                .unwrap_err();
        assert!(
            matches!(e, DecodeError::Invalid { about: Some(_), .. }),
            "{e}"
        );
        e.to_string()
    };
    let mut nan = w.clone();
    nan.fingertips[0].torque[2] = f64::NAN;
    assert!(refused(&nan).contains("fingertips[0].torque[2]"));
    let mut flat = w.clone();
    flat.fingertips[0].surface = FingertipSurface::Sphere {
        center: [0.0; 3],
        radius: 0.0,
        base_z: None,
    };
    let e = refused(&flat);
    assert!(
        e.contains("fingertips[0].surface") && e.contains("radius"),
        "{e}"
    );
    let mut turned = w.clone();
    turned.fingertips[0].sensor_pose.rotation = [1.0, 1.0, 0.0, 0.0];
    assert!(refused(&turned).contains("fingertips[0].sensor_pose.rotation"));
}

/// Fingertip readings with each fingertip shape, with and without a base height: the
/// surface, an internally tagged enum in JSON, must round-trip in bincode too.
#[test]
fn fingertip_readings_round_trip_in_both_encodings() {
    let tip = |surface| FingertipWrench {
        finger: 1,
        link: "tip".into(),
        sensor_pose: Pose::IDENTITY,
        surface,
        force: [0.1, -0.2, -2.0],
        torque: [1e-4, 0.0, -3e-5],
        stamp_ms: 12,
    };
    let w = FingertipWrenches {
        run_id: run(),
        trial_id: 4,
        attempt: 2,
        worker: "hand-1".into(),
        hand: "barrett_ft".into(),
        palm_pose: Pose::IDENTITY,
        fingertips: vec![
            tip(FingertipSurface::Sphere {
                center: [0.0, 0.0, 0.015],
                radius: 0.012,
                base_z: None,
            }),
            tip(FingertipSurface::Ellipsoid {
                center: [0.0, 0.0, 0.01],
                semi_axes: [0.01, 0.012, 0.015],
                base_z: Some(0.0),
            }),
            tip(FingertipSurface::Capsule {
                center: [0.0, 0.0, 0.02],
                half_length: 0.01,
                radius: 0.008,
                base_z: Some(0.005),
            }),
        ],
        min_gap: None,
        error: None,
        executed_ms: 13,
    };
    for enc in [Encoding::Bincode, Encoding::Json] {
        let back = decode::<FingertipWrenches>(&encode(&w, enc).unwrap(), enc);
        assert_eq!(back.as_ref().ok(), Some(&w), "{enc:?}: {back:?}");
    }
    // JSON keeps the documented surface form (keys in sorted order), without an absent
    // base_z.
    let json = String::from_utf8(encode(&w, Encoding::Json).unwrap()).unwrap();
    assert!(
        json.contains(r#""surface":{"center":[0.0,0.0,0.015],"radius":0.012,"shape":"sphere"}"#),
        "{json}"
    );
}
