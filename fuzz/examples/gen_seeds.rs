//! Writes valid inputs for every fuzz target into `<corpus>/<target>/seed-*` (run.sh runs it
//! when a corpus has no seeds): the fuzzer then starts from real messages instead of
//! discovering the wire format from nothing.
//!
//! `cargo +nightly run --manifest-path fuzz/Cargo.toml --example gen_seeds -- fuzz/corpus`

use std::path::{Path, PathBuf};

use graspopt_protocol::keys::AgentKind;
use graspopt_protocol::keys::{CLOUDS, COMMAND, OBJECT, RESULT, Runs, STATUS, alive_token};
use graspopt_protocol::{
    BestTrial, CloudPoint, ContactClouds, Encoding, ErrorCounts, FingerCloud, FingertipSurface,
    FingertipWrench, FingertipWrenches, MeshData, Message,
    MetricValue, MetricValues, ObjectEstimate, Observation, PlannerMethod, Pose, RunId, RunPhase, RunStatus,
    SuggestReply, SuggestRequest, Topic, TrialCommand, TrialResult, WaitReason, Waiting,
    WorkerStatus, decode, encode, layout,
};

struct Out(PathBuf);

impl Out {
    fn write(&self, target: &str, name: &str, bytes: &[u8]) {
        let dir = self.0.join(target);
        std::fs::create_dir_all(&dir).expect("create the corpus directory");
        std::fs::write(dir.join(format!("seed-{name}")), bytes).expect("write a seed");
    }

    /// `msg` in both encodings, behind the selector byte of the message targets; also for
    /// `decode_topic` when the message is a topic's. Every seed is checked to decode.
    fn message<T: Message>(&self, target: &str, name: &str, msg: &T, topic: Option<Topic>) {
        for (encoding, bit) in [(Encoding::Bincode, 0u8), (Encoding::Json, 1)] {
            let payload = encode(msg, encoding).expect("a seed encodes");
            if let Err(e) = decode::<T>(&payload, encoding) {
                panic!("the {target} seed {name} ({encoding:?}) does not decode: {e}");
            }
            let tag = if bit == 0 { "bincode" } else { "json" };
            self.write(
                target,
                &format!("{name}-{tag}"),
                &[&[bit][..], &payload].concat(),
            );
            if let Some(topic) = topic {
                let index = Topic::ALL
                    .iter()
                    .position(|t| *t == topic)
                    .expect("a topic") as u8;
                let selector = (index << 1) | bit;
                self.write(
                    "decode_topic",
                    &format!("{target}-{name}-{tag}"),
                    &[&[selector][..], &payload].concat(),
                );
            }
        }
    }
}

impl Out {
    /// Clouds in the shared-memory layout, for `decode_clouds_layout` (no selector byte).
    fn layout(&self, name: &str, clouds: &ContactClouds) {
        let mut bytes = vec![0; layout::clouds_len(clouds).expect("a seed has a length")];
        layout::write_clouds(clouds, &mut bytes).expect("a seed writes");
        if let Err(e) = layout::read_clouds(&bytes) {
            panic!("the decode_clouds_layout seed {name} does not read back: {e}");
        }
        self.write("decode_clouds_layout", name, &bytes);
    }
}

fn main() {
    let root = std::env::args_os()
        .nth(1)
        .unwrap_or_else(|| "corpus".into());
    let out = Out(Path::new(&root).to_path_buf());
    let run = RunId::new("run-1").expect("a run id");
    let pose = Pose {
        translation: [0.1, -0.2, 0.3],
        rotation: [0.5, 0.5, 0.5, 0.5],
    };

    let mut object = ObjectEstimate {
        run_id: run.clone(),
        object: "mug".into(),
        mesh: None,
        pose,
        seq: 3,
        stamp_ms: 1_700_000_000_000,
        source: "perception-1".into(),
    };
    out.message("decode_object", "builtin", &object, Some(Topic::Object));
    object.object = "wedge".into();
    object.mesh = Some(MeshData {
        vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        triangles: vec![[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]],
    });
    out.message("decode_object", "mesh", &object, Some(Topic::Object));

    let command = TrialCommand {
        run_id: run.clone(),
        trial_id: 42,
        attempt: 2,
        worker: "hand-1".into(),
        hand: "barrett".into(),
        params: vec![0.25, -1.5, 3.0],
        palm_pose: pose,
        lease_ms: 30_000,
        issued_ms: 1_700_000_000_123,
    };
    out.message("decode_command", "command", &command, Some(Topic::Command));

    let point = |x: f64| CloudPoint {
        p: [x, 0.02, -0.01],
        n: [0.0, 0.6, 0.8],
        w: 1.0,
    };
    let mut clouds = ContactClouds {
        run_id: run.clone(),
        trial_id: 42,
        attempt: 2,
        worker: "hand-1".into(),
        hand: "barrett".into(),
        palm_pose: pose,
        fingers: vec![
            FingerCloud {
                finger: Some(0),
                links: vec!["finger_0_tip".into()],
                points: vec![point(0.01), point(0.02)],
            },
            FingerCloud {
                finger: None,
                links: vec!["palm".into()],
                points: vec![point(0.0)],
            },
        ],
        min_gap: Some(0.0),
        error: None,
        executed_ms: 1_700_000_000_456,
    };
    out.message("decode_clouds", "clouds", &clouds, Some(Topic::Clouds));
    out.layout("clouds", &clouds);
    clouds.fingers.clear();
    clouds.min_gap = None;
    clouds.error = Some("unreachable pose".into());
    out.message("decode_clouds", "error", &clouds, Some(Topic::Clouds));
    out.layout("error", &clouds);

    let mut wrenches = FingertipWrenches {
        run_id: run.clone(),
        trial_id: 42,
        attempt: 2,
        worker: "hand-1".into(),
        hand: "barrett_ft".into(),
        palm_pose: pose,
        fingertips: vec![FingertipWrench {
            finger: 0,
            link: "f1_tip".into(),
            sensor_pose: pose,
            surface: FingertipSurface::Sphere {
                center: [0.0, 0.0, 0.015],
                radius: 0.012,
                base_z: None,
            },
            force: [0.1, -0.2, -1.5],
            torque: [0.004, 0.001, 0.0],
            stamp_ms: 1_700_000_000_450,
        }],
        min_gap: None,
        error: None,
        executed_ms: 1_700_000_000_456,
    };
    out.message("decode_wrenches", "wrenches", &wrenches, Some(Topic::Wrenches));
    wrenches.fingertips.clear();
    wrenches.error = Some("sensor offline".into());
    out.message("decode_wrenches", "error", &wrenches, Some(Topic::Wrenches));

    let mut result = TrialResult {
        run_id: run.clone(),
        trial_id: 42,
        attempt: 2,
        worker: "hand-1".into(),
        scorer: "metric-1".into(),
        score: 0.125,
        metrics: Some(MetricValues::default()
.with("rank", Some(MetricValue::Count(6)))
.with("force_closure", Some(MetricValue::Flag(true)))
.with("epsilon", Some(MetricValue::Real(0.125)))
.with("volume", Some(MetricValue::Real(0.002)))
.with("distance", Some(MetricValue::Real(0.01)))
.with("bw", Some(MetricValue::Real(0.5)))),
        contacts: 3,
        fingers_in_contact: 2,
        cloud_points: 3,
        cloud_transport: "shm".into(),
        error: None,
        forces: None,
    };
    out.message("decode_result", "scored", &result, Some(Topic::Result));
    result.metrics = None;
    result.score = 0.0;
    result.error = Some("unreachable pose".into());
    out.message("decode_result", "failed", &result, Some(Topic::Result));

    let status = RunStatus {
        run_id: run.clone(),
        phase: RunPhase::Running,
        object: "mug".into(),
        param_names: vec!["roll".into(), "pitch".into(), "spread".into()],
        budget: 100,
        completed: 2,
        running: 1,
        failed: 1,
        best: Some(BestTrial {
            trial_id: 7,
            score: 0.3,
            params: vec![0.1, 0.2, 0.3],
            force_closure: Some(true),
        }),
        best_history: vec![0.1, 0.3],
        workers: vec![WorkerStatus {
            id: "hand-1".into(),
            host: "host-a".into(),
            trial: Some(42),
        }],
        errors: ErrorCounts {
            bad_messages: 1,
            ..ErrorCounts::default()
        },
        stamp_ms: 1_700_000_000_789,
        waiting: vec![Waiting {
            reason: WaitReason::MetricAgent,
            since_ms: 1_700_000_000_000,
        }],
        best_forces: None,
    };
    out.message("decode_status", "status", &status, Some(Topic::Status));

    let request = SuggestRequest {
        run_id: run.clone(),
        request_id: 9,
        method: PlannerMethod::Bo,
        bounds: vec![[-1.0, 1.0], [0.0, 2.0]],
        seed: 5,
        initial: Some(4),
        observations: vec![Observation {
            x: vec![0.5, 1.5],
            y: 0.25,
        }],
        pending: vec![vec![-0.5, 0.5]],
        count: 2,
        engine_state: Some(vec![1, 2, 3, 4]),
    };
    out.message("decode_suggest_request", "request", &request, None);

    let mut reply = SuggestReply {
        run_id: run.clone(),
        request_id: 9,
        points: vec![vec![0.1, 1.9], vec![-0.9, 0.3]],
        error: None,
        engine_state: Some(vec![9, 8, 7]),
    };
    out.message("decode_suggest_reply", "reply", &reply, None);
    reply.points.clear();
    reply.error = Some("no planner".into());
    out.message("decode_suggest_reply", "error", &reply, None);

    let alive = alive_token(&run, AgentKind::Hand, "host-a", "hand-1", None);
    let keys = [
        ("alive", alive.clone()),
        ("alive-json", format!("{alive}/json")),
        ("alive-json-wrenches", format!("{alive}/json/wrenches")),
        (
            "alive-coordinator",
            alive_token(&run, AgentKind::Coordinator, "h", "c-1", None),
        ),
        ("object", OBJECT.key(Runs::One(&run)).to_string()),
        (
            "command",
            COMMAND.worker_key(Runs::One(&run), "hand-1").to_string(),
        ),
        ("clouds", CLOUDS.key(Runs::One(&run)).to_string()),
        ("result", RESULT.key(Runs::One(&run)).to_string()),
        ("status", STATUS.key(Runs::One(&run)).to_string()),
    ];
    for (name, key) in keys {
        out.write("parse_alive_key", name, key.as_bytes());
    }
    println!("seeds written under {}", out.0.display());
}
