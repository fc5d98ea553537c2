//! Round trips of every message in both encodings, and refusal of bad payloads.

use graspopt_protocol::codec::BINCODE_MIME;
use graspopt_protocol::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn run() -> RunId {
    RunId::new("run-1").unwrap()
}

fn clouds() -> ContactClouds {
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
        assert_eq!(q.validate(), Err(expected.to_string()));
    }
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

// The shared-memory layout of contact clouds (`layout`).

/// `c` written through the layout into a buffer of junk (every byte must be written).
fn layout_bytes(c: &ContactClouds) -> Vec<u8> {
    let mut out = vec![0xa5; layout::clouds_len(c).unwrap()];
    layout::write_clouds(c, &mut out).unwrap();
    out
}

/// Clouds with every optional field set, a palm cloud and more than one link and point.
fn full_clouds() -> ContactClouds {
    let mut c = clouds();
    c.min_gap = Some(0.0125);
    c.fingers[1].points = vec![
        CloudPoint {
            p: [-0.5, 0.25, 1e10],
            n: [1.0, 0.0, 0.0],
            w: 3.5e-6,
        };
        3
    ];
    c.fingers.push(FingerCloud {
        finger: Some(u32::MAX),
        links: vec!["é-link".into(), String::new(), "f3_proximal".into()],
        points: vec![],
    });
    c
}

#[test]
fn clouds_round_trip_through_the_shm_layout() {
    let mut failed = clouds();
    failed.fingers.clear();
    failed.error = Some("unreachable: joint 2 at its limit".into());
    failed.executed_ms = -5;
    for c in [clouds(), full_clouds(), failed] {
        let bytes = layout_bytes(&c);
        assert_eq!(&bytes[..4], b"GPCL");
        assert_eq!(
            bytes.len() % 8,
            0,
            "points start 8-aligned and take 56 bytes each"
        );
        assert_eq!(layout::read_clouds(&bytes).unwrap(), c);
    }
    // The header of `clouds()`: 112 fixed bytes, two finger entries, the texts
    // "run-1" "hand-1" "barrett", the links "f1_distal" and "palm" with their lengths,
    // padding from 183 to 184, then one point.
    let bytes = layout_bytes(&clouds());
    assert_eq!(bytes.len(), 184 + 56);
    assert_eq!(u64::from_le_bytes(bytes[8..16].try_into().unwrap()), 7);
    assert_eq!(
        f64::from_le_bytes(bytes[184 + 32..184 + 40].try_into().unwrap()),
        0.6
    );
    // Points are copied as one block when the payload is aligned for f64 (an iceoryx2 0.10
    // sample is) and through an aligned buffer when not: both read the same clouds.
    let full = full_clouds();
    let bytes = layout_bytes(&full);
    let mut words = vec![0u64; bytes.len() / 8 + 1];
    let aligned = zerocopy::IntoBytes::as_mut_bytes(words.as_mut_slice());
    aligned[..bytes.len()].copy_from_slice(&bytes);
    assert_eq!(layout::read_clouds(&aligned[..bytes.len()]).unwrap(), full);
    aligned[1..=bytes.len()].copy_from_slice(&bytes);
    assert_eq!(
        layout::read_clouds(&aligned[1..=bytes.len()]).unwrap(),
        full
    );
    // A buffer of the wrong size is refused, not overrun.
    let c = clouds();
    let mut short = vec![0; layout::clouds_len(&c).unwrap() - 1];
    assert!(layout::write_clouds(&c, &mut short).is_err());
}

/// The layout refuses bad points with the message `decode` gives for the same clouds in
/// bincode.
#[test]
fn the_shm_layout_refuses_bad_points_as_validate_does() {
    type Spoil = fn(&mut CloudPoint);
    let cases: [(&str, Spoil); 4] = [
        ("fingers[1].points[2].p[1] is not finite (NaN)", |p| {
            p.p[1] = f64::NAN
        }),
        ("fingers[1].points[2].n[2] is not finite (-inf)", |p| {
            p.n[2] = f64::NEG_INFINITY
        }),
        (
            "fingers[1].points[2].n is not a unit normal (norm 0.5)",
            |p| p.n = [0.5, 0.0, 0.0],
        ),
        (
            "fingers[1].points[2].w must be finite and > 0, got 0",
            |p| p.w = 0.0,
        ),
    ];
    for (expected, spoil) in cases {
        let mut c = full_clouds();
        spoil(&mut c.fingers[1].points[2]);
        let e = layout::read_clouds(&layout_bytes(&c)).unwrap_err();
        let DecodeError::Invalid { detail, about, .. } = &e else {
            panic!("{expected}: {e:?}");
        };
        assert_eq!(detail, expected);
        assert_eq!(about.as_ref().unwrap().trial_id, 7);
        let bincode =
            decode::<ContactClouds>(&encode(&c, Encoding::Bincode).unwrap(), Encoding::Bincode)
                .unwrap_err();
        assert_eq!(e, bincode);
    }
    let mut c = full_clouds();
    c.min_gap = Some(-1.0);
    let e = layout::read_clouds(&layout_bytes(&c)).unwrap_err();
    assert!(e.to_string().contains("min_gap must be finite"), "{e}");
    let mut c = full_clouds();
    c.worker = "hand/1".into();
    let e = layout::read_clouds(&layout_bytes(&c)).unwrap_err();
    assert!(e.to_string().contains("worker"), "{e}");
}

/// The branch-free check (which `validate` and the bulk readers run first) accepts exactly
/// the points the rule accepts, written here plainly: p and n finite, |n| within 1e-3 of 1,
/// w finite and > 0; edge values included (infinities times zero, norms just inside and
/// outside 1e-3, a norm whose square overflows). `validate` gives an error exactly then.
#[test]
fn the_fast_point_check_agrees_with_validate() {
    let values = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.5,
        0.9991,
        0.9989,
        1.0009,
        1.0011,
        1e-300,
        1e200,
        f64::MAX,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    let mut checked = 0;
    let mut accepted = 0;
    for &a in &values {
        for &b in &values {
            for &c in &values {
                for &w in &values {
                    for pt in [
                        CloudPoint {
                            p: [a, b, c],
                            n: [0.0, 0.0, 1.0],
                            w,
                        },
                        CloudPoint {
                            p: [w, 0.0, 0.0],
                            n: [a, b, c],
                            w: 1.0,
                        },
                        CloudPoint {
                            p: [0.0; 3],
                            n: [a, b, c],
                            w,
                        },
                    ] {
                        let norm = pt.n.iter().map(|v| v * v).sum::<f64>().sqrt();
                        let rule = pt.p.iter().chain(&pt.n).all(|v| v.is_finite())
                            && (norm - 1.0).abs() <= 1e-3
                            && pt.w.is_finite()
                            && pt.w > 0.0;
                        assert_eq!(pt.is_valid(), rule, "{pt:?}");
                        assert_eq!(pt.validate(0, 0).is_ok(), rule, "{pt:?}");
                        checked += 1;
                        accepted += usize::from(pt.is_valid());
                    }
                }
            }
        }
    }
    assert_eq!(checked, 3 * values.len().pow(4));
    // Both outcomes occur: the comparison is not vacuous.
    assert!(
        accepted > 0 && accepted < checked,
        "{accepted} of {checked}"
    );
}

/// Of several bad points, the layout names the first, as `validate` does.
#[test]
fn the_shm_layout_names_the_first_bad_point() {
    let mut c = full_clouds();
    c.fingers[1].points[2].w = f64::INFINITY;
    c.fingers[1].points[1].p[0] = f64::NEG_INFINITY;
    let last = c.fingers.len() - 1;
    c.fingers[last].points.push(CloudPoint {
        p: [0.0; 3],
        n: [0.0; 3],
        w: 1.0,
    });
    let e = layout::read_clouds(&layout_bytes(&c)).unwrap_err();
    assert!(
        e.to_string()
            .contains("fingers[1].points[1].p[0] is not finite (-inf)"),
        "{e}"
    );
}

#[test]
fn a_truncated_or_inconsistent_shm_layout_is_refused_naming_the_field() {
    let bytes = layout_bytes(&full_clouds());
    let refused = |b: &[u8]| layout::read_clouds(b).unwrap_err().to_string();
    for cut in 0..bytes.len() {
        refused(&bytes[..cut]);
    }
    let e = refused(&bytes[..50]);
    assert!(
        e.contains("truncated: palm_pose[1] needs 8 bytes at offset 48"),
        "{e}"
    );
    let e = refused(&bytes[..130]);
    assert!(e.contains("the finger table (3 fingers)"), "{e}");
    // Cut inside the third finger's first link name ("é-link", after the texts).
    let link = bytes
        .windows(7)
        .position(|w| w == "é-link".as_bytes())
        .unwrap();
    let e = refused(&bytes[..link + 3]);
    assert!(
        e.contains("truncated: fingers[2].links[0] needs 7 bytes"),
        "{e}"
    );
    // Cut inside the points, or one byte too many.
    let e = refused(&bytes[..bytes.len() - 8]);
    assert!(
        e.contains("declares 4 points (224 bytes), the payload has 216"),
        "{e}"
    );
    let mut long = bytes.clone();
    long.extend_from_slice(&[0; 8]);
    assert!(refused(&long).contains("the payload has 232"));
    // A finger table declaring more points or links than the payload holds, a bad tag,
    // a wrong magic or version, unknown flags.
    let mut more = bytes.clone();
    more[112 + 12..112 + 16].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(refused(&more).contains("declares 4294967298 points"));
    let mut links = bytes.clone();
    links[112 + 8..112 + 12].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = refused(&links);
    assert!(e.contains("truncated: fingers[0].links["), "{e}");
    let mut tag = bytes.clone();
    tag[112 + 16] = 2;
    assert!(refused(&tag).contains("fingers[1].finger has tag 2"));
    let mut magic = bytes.clone();
    magic[0] = b'X';
    assert!(refused(&magic).contains("magic"));
    let mut version = bytes.clone();
    version[4] = version[4].wrapping_add(1);
    assert!(matches!(
        layout::read_clouds(&version),
        Err(DecodeError::WrongVersion { .. })
    ));
    let mut flags = bytes.clone();
    flags[6] = 4;
    assert!(refused(&flags).contains("unknown bits"));
    // Bincode is not this layout, and pseudo-random bytes after a valid magic never panic.
    let bincode = encode(&full_clouds(), Encoding::Bincode).unwrap();
    assert!(refused(&bincode).contains("magic"));
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed);
    for len in 0..3000 {
        let mut junk = bytes[..8].to_vec();
        junk.extend((0..len % 400).map(|_| rng.random::<u8>()));
        let _ = layout::read_clouds(&junk);
    }
}
