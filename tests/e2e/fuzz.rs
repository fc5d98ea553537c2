//! Malformed traffic during a run (issue 7): more than 10,000 random and mutated messages on
//! every input topic of every agent, one stream per row of the key table (`keys::TABLE`, so a
//! new topic cannot be left out: a row without a stream here fails the test): object
//! estimates (to the coordinator, the hands and the metric agent), commands (to the hand),
//! contact clouds and fingertip readings (to the metric agent), results (to the coordinator)
//! and queries (to the planner). No agent crashes, every message is counted as bad by the
//! agents that receive it, and the run gives exactly the trials of the same run without the
//! noise.
//!
//! A mutant that still decodes into a plausible message of this very run is not sent: that
//! is a well-formed message from a stranger, which access control keeps out (see
//! `tests/e2e/security.rs`), not malformed traffic.

use std::collections::BTreeMap;
use std::time::Duration;

use crate::support::{Cluster, check_journal, report, wait_until};
use graspopt_bus::{Bus, CongestionControl, zenoh_encoding};
use graspopt_journal::TrialRow;
use graspopt_protocol::keys::{
    CLOUDS, COMMAND, Entry, OBJECT, RESULT, Runs, SUGGEST, TABLE, WRENCHES,
};
use graspopt_protocol::{
    CloudPoint, ContactClouds, Encoding, FingerCloud, FingertipSurface, FingertipWrench,
    FingertipWrenches, Message, MetricValue, MetricValues, ObjectEstimate, PlannerMethod, Pose,
    RunId, SuggestRequest, TrialCommand, TrialResult, decode, encode,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::json;

const RUN: &str = "fz";
const TRIALS: usize = 16;
const SEED: &str = "9";
/// Messages per stream (seven streams).
const PER_STREAM: usize = 1_800;

/// A seeded generator (ChaCha8), so a failure replays.
struct Rng(ChaCha8Rng);
impl Rng {
    fn seeded(seed: u64) -> Rng {
        Rng(ChaCha8Rng::seed_from_u64(seed))
    }
    fn next(&mut self) -> u64 {
        self.0.random()
    }
    fn below(&mut self, n: usize) -> usize {
        self.0.random_range(0..n.max(1))
    }
}

/// A mutant of `valid`: random bytes, bit flips, a truncation, an insertion or garbage
/// appended.
fn mutate(rng: &mut Rng, valid: &[u8]) -> Vec<u8> {
    let mut b = valid.to_vec();
    match rng.below(6) {
        0 => (0..rng.below(300)).map(|_| rng.next() as u8).collect(),
        1 | 2 => {
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(b.len());
                b[i] ^= 1 << rng.below(8);
            }
            b
        }
        3 => {
            b.truncate(rng.below(b.len()));
            b
        }
        4 => {
            let i = rng.below(b.len() + 1);
            b.insert(i, rng.next() as u8);
            b
        }
        _ => {
            b.extend((0..1 + rng.below(16)).map(|_| rng.next() as u8));
            b
        }
    }
}

/// Payloads with the encoding each declares.
type Payloads = Vec<(Vec<u8>, Encoding)>;

/// Mutants of `template` (in both encodings) that the agents must refuse: ones that no
/// longer decode, or that decode into a message of another run. Returns (bytes, encoding).
fn mutants<T: Message>(rng: &mut Rng, template: &T, n: usize) -> Payloads {
    let run = RunId::new(RUN).unwrap();
    let encodings = [Encoding::Bincode, Encoding::Json];
    let valid: Vec<Vec<u8>> = encodings
        .iter()
        .map(|e| encode(template, *e).unwrap())
        .collect();
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let k = rng.below(2);
        let bytes = mutate(rng, &valid[k]);
        match decode::<T>(&bytes, encodings[k]) {
            Ok(m) if *m.run_id() == run => continue,
            _ => out.push((bytes, encodings[k])),
        }
    }
    out
}

fn elsewhere() -> RunId {
    RunId::new("elsewhere").unwrap()
}

/// A message of each type the agents receive, of another run or of trials never issued.
struct Templates {
    result: TrialResult,
    object: ObjectEstimate,
    clouds: ContactClouds,
    wrenches: FingertipWrenches,
    command: TrialCommand,
    suggest: SuggestRequest,
}

fn templates() -> Templates {
    let result = TrialResult {
        // This run, but a trial and worker it never issued: if a mutant still decodes, the
        // coordinator counts it as an unknown trial or a result it never issued.
        run_id: RunId::new(RUN).unwrap(),
        trial_id: 1_000_000,
        attempt: 1,
        worker: "fuzzer".into(),
        scorer: "fuzzer".into(),
        score: 0.5,
        metrics: Some(
            MetricValues::default()
                .with("rank", Some(MetricValue::Count(6)))
                .with("force_closure", Some(MetricValue::Flag(true)))
                .with("epsilon", Some(MetricValue::Real(0.1)))
                .with("volume", None)
                .with("distance", Some(MetricValue::Real(0.0)))
                .with("bw", Some(MetricValue::Real(0.1))),
        ),
        contacts: 3,
        fingers_in_contact: 3,
        cloud_points: 3,
        cloud_transport: "zenoh".into(),
        error: None,
        forces: None,
    };
    let object = ObjectEstimate {
        run_id: elsewhere(),
        object: "sphere".into(),
        mesh: None,
        pose: Pose::IDENTITY,
        seq: 7,
        stamp_ms: 0,
        source: "fuzzer".into(),
    };
    let clouds = ContactClouds {
        run_id: elsewhere(),
        trial_id: 1,
        attempt: 1,
        worker: "hand-1".into(),
        hand: "barrett".into(),
        palm_pose: Pose::IDENTITY,
        fingers: (0..3)
            .map(|k| FingerCloud {
                finger: Some(k),
                links: vec![format!("f{k}")],
                points: vec![CloudPoint {
                    p: [0.03, 0.0, 0.01 * k as f64],
                    n: [1.0, 0.0, 0.0],
                    w: 1.0,
                }],
            })
            .collect(),
        min_gap: None,
        error: None,
        executed_ms: 0,
    };
    let wrenches = FingertipWrenches {
        run_id: elsewhere(),
        trial_id: 1,
        attempt: 1,
        worker: "hand-1".into(),
        hand: "barrett_ft".into(),
        palm_pose: Pose::IDENTITY,
        fingertips: (0..3)
            .map(|k| FingertipWrench {
                finger: k,
                link: format!("f{k}_tip"),
                sensor_pose: Pose::IDENTITY,
                surface: FingertipSurface::Sphere {
                    center: [0.0, 0.0, 0.015],
                    radius: 0.012,
                    base_z: None,
                },
                force: [0.0, 0.0, -1.5],
                torque: [0.0, 0.0, 0.0],
                stamp_ms: 0,
            })
            .collect(),
        min_gap: None,
        error: None,
        executed_ms: 0,
    };
    let command = TrialCommand {
        run_id: elsewhere(),
        trial_id: 1,
        attempt: 1,
        worker: "hand-1".into(),
        hand: "barrett".into(),
        params: vec![0.0, 0.0],
        palm_pose: Pose::IDENTITY,
        lease_ms: 30_000,
        issued_ms: 0,
    };
    let suggest = SuggestRequest {
        run_id: elsewhere(),
        request_id: 1,
        method: PlannerMethod::Bo,
        bounds: vec![[-0.1, 0.1], [-0.05, 0.05]],
        seed: 1,
        initial: None,
        observations: Vec::new(),
        pending: Vec::new(),
        count: 1,
        engine_state: None,
    };
    Templates {
        result,
        object,
        clouds,
        wrenches,
        command,
        suggest,
    }
}

/// The largest `(N bad messages)` count an agent logged.
fn bad_count(log: &str) -> u64 {
    log.match_indices(" bad messages)")
        .filter_map(|(i, _)| {
            let head = &log[..i];
            let start = head.rfind('(')? + 1;
            head[start..].parse::<u64>().ok()
        })
        .max()
        .unwrap_or(0)
}

/// An agent of the run that counts the bad messages it receives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Agent {
    Coordinator,
    Hand,
    Metric,
    Planner,
}

/// The rows of the key table that no agent of a run receives, and why: no noise on them.
const NOT_RECEIVED: &[(&str, &str)] = &[
    (
        "status",
        "the coordinator publishes it for monitors; no agent of a run reads it",
    ),
    (
        "state",
        "a query without payload that the coordinator answers: nothing to decode",
    ),
];

/// One stream of noise: a row of the key table, the key it is sent on, its payloads, and
/// the agents that receive (and count) each of them.
struct Stream {
    topic: &'static str,
    key: String,
    query: bool,
    payloads: Payloads,
    counted_by: &'static [Agent],
}

/// The streams of noise: one per row of the key table an agent of the run receives, and one
/// of well-formed results the run never issued.
fn streams(rng: &mut Rng) -> Vec<Stream> {
    let run = RunId::new(RUN).unwrap();
    let runs = Runs::One(&run);
    let t = templates();
    let mut out = Vec::new();
    for entry in TABLE {
        let Entry { name, .. } = entry;
        let (key, payloads, counted_by): (String, Payloads, &'static [Agent]) = match name {
            "object" => (
                OBJECT.key(runs).to_string(),
                mutants(rng, &t.object, PER_STREAM),
                &[Agent::Coordinator, Agent::Hand, Agent::Metric],
            ),
            "command" => (
                COMMAND.worker_key(runs, "hand-1").to_string(),
                mutants(rng, &t.command, PER_STREAM),
                &[Agent::Hand],
            ),
            "clouds" => (
                CLOUDS.key(runs).to_string(),
                mutants(rng, &t.clouds, PER_STREAM),
                &[Agent::Metric],
            ),
            "wrenches" => (
                WRENCHES.key(runs).to_string(),
                mutants(rng, &t.wrenches, PER_STREAM),
                &[Agent::Metric],
            ),
            "result" => (
                RESULT.key(runs).to_string(),
                mutants(rng, &t.result, PER_STREAM),
                &[Agent::Coordinator],
            ),
            // Each answered with an error.
            "suggest" => (
                SUGGEST.key(&run).to_string(),
                mutants(rng, &t.suggest, PER_STREAM),
                &[Agent::Planner],
            ),
            _ => {
                assert!(
                    NOT_RECEIVED.iter().any(|(n, _)| *n == name),
                    "the key table's row `{name}` has no stream of noise: add one, or say in \
                     NOT_RECEIVED why no agent receives it"
                );
                continue;
            }
        };
        let query = entry.is_query();
        out.push(Stream {
            topic: name,
            key,
            query,
            payloads,
            counted_by,
        });
    }
    // Well-formed results this run never issued (a trial id out of range, a stranger).
    let strangers = (0..PER_STREAM as u64)
        .map(|i| {
            let mut r = t.result.clone();
            r.trial_id = if i % 2 == 0 {
                1 + i % TRIALS as u64
            } else {
                5_000 + i
            };
            r.worker = format!("stranger-{}", i % 7);
            let e = if i % 3 == 0 {
                Encoding::Json
            } else {
                Encoding::Bincode
            };
            (encode(&r, e).unwrap(), e)
        })
        .collect();
    out.push(Stream {
        topic: "result",
        key: RESULT.key(runs).to_string(),
        query: false,
        payloads: strangers,
        counted_by: &[Agent::Coordinator],
    });
    out
}

/// Messages sent: per stream, its topic, the agents that count it and how many.
#[derive(Debug, Default)]
struct Sent(Vec<(&'static str, &'static [Agent], u64)>);

impl Sent {
    fn total(&self) -> u64 {
        self.0.iter().map(|(_, _, n)| n).sum()
    }

    /// The messages that reached `agent`.
    fn to(&self, agent: Agent) -> u64 {
        self.0
            .iter()
            .filter(|(_, by, _)| by.contains(&agent))
            .map(|(_, _, n)| n)
            .sum()
    }

    /// The messages sent on each topic.
    fn per_topic(&self) -> BTreeMap<&'static str, u64> {
        let mut out = BTreeMap::new();
        for (topic, _, n) in &self.0 {
            *out.entry(*topic).or_default() += n;
        }
        out
    }
}

/// One run of `TRIALS` trials with one hand (nothing depends on timing); with `fuzz`, the
/// noise is sent while it runs. Returns the trials and the coordinator's final status.
fn run(name: &str, fuzz: bool) -> (Vec<TrialRow>, serde_json::Value, Option<(Cluster, Sent)>) {
    let c = Cluster::start(name, RUN);
    let mut agents = c.support("sphere");
    // Slow enough trials that the run outlasts the noise.
    agents.extend(c.hands(1, &["--set", "trial_cost_ms=900"]));
    let coordinator = c.coordinator("sphere", &TRIALS.to_string(), SEED, &[]);
    let sent = fuzz.then(|| send_noise(&c));
    if sent.is_some() {
        let mut coordinator = coordinator;
        assert!(
            coordinator.child.try_wait().unwrap().is_none(),
            "the run ended before the noise did: make the trials slower"
        );
        let status = c.final_status(coordinator, Duration::from_secs(180));
        for p in &mut agents {
            assert!(p.child.try_wait().unwrap().is_none(), "{} crashed", p.name);
        }
        // The other agents may still be working through their queues: wait until each has
        // logged as many rejections as it was sent (more would fail the test's equality).
        if let Some(s) = &sent {
            wait_until("every bad message logged", Duration::from_secs(60), || {
                bad_count(&c.log("hand-1")) >= s.to(Agent::Hand)
                    && bad_count(&c.log("metric")) >= s.to(Agent::Metric)
                    && bad_count(&c.log("planner")) >= s.to(Agent::Planner)
            });
        }
        let trials = check_journal(&c.journal(), RUN, TRIALS);
        drop(agents);
        return (trials, status, sent.map(|s| (c, s)));
    }
    let status = c.final_status(coordinator, Duration::from_secs(180));
    let trials = check_journal(&c.journal(), RUN, TRIALS);
    drop(agents);
    (trials, status, sent.map(|s| (c, s)))
}

fn send_noise(c: &Cluster) -> Sent {
    let run = RunId::new(RUN).unwrap();
    let mut rng = Rng::seeded(0x9E37_79B9_7F4A_7C15);
    let streams = streams(&mut rng);
    let runtime = tokio::runtime::Runtime::new().unwrap();
    runtime.block_on(async {
        let bus = Bus::open(&c.client_args(None)).await.unwrap();
        // Start once the run is under way (the first trial has been issued).
        let results = bus
            .subscribe::<TrialResult>(&RESULT.key(Runs::One(&run)).to_string())
            .await
            .unwrap();
        tokio::time::timeout(Duration::from_secs(60), results.recv())
            .await
            .expect("a first result");
        // Not read any more: a full subscription queue would block this session's own puts.
        drop(results);
        let mut sent: Vec<u64> = vec![0; streams.len()];
        // The topics, interleaved message by message.
        for i in 0..PER_STREAM {
            for (k, s) in streams.iter().enumerate().filter(|(_, s)| !s.query) {
                let (bytes, encoding) = &s.payloads[i];
                bus.put_bytes(&s.key, bytes.clone(), *encoding, CongestionControl::Block)
                    .await
                    .unwrap();
                sent[k] += 1;
            }
        }
        // The queries, one after the other.
        for (k, s) in streams.iter().enumerate().filter(|(_, s)| s.query) {
            for (bytes, encoding) in &s.payloads {
                let replies = bus
                    .session()
                    .get(&s.key)
                    .payload(bytes.clone())
                    .encoding(zenoh_encoding(*encoding))
                    .timeout(Duration::from_secs(10))
                    .await
                    .unwrap();
                while replies.recv_async().await.is_ok() {}
                sent[k] += 1;
            }
        }
        let _ = bus.close().await;
        Sent(
            streams
                .iter()
                .zip(sent)
                .map(|(s, n)| (s.topic, s.counted_by, n))
                .collect(),
        )
    })
}

/// Each row of the key table gets its noise, or a reason in `NOT_RECEIVED`; the noise on a
/// topic is of its message type and goes to the agents that subscribe to it.
#[test]
fn every_row_of_the_key_table_has_its_noise() {
    let streams = streams(&mut Rng::seeded(1));
    for entry in TABLE {
        let noise = streams.iter().filter(|s| s.topic == entry.name).count();
        let reason = NOT_RECEIVED.iter().any(|(n, _)| *n == entry.name);
        assert!(
            (noise > 0) != reason,
            "{}: {noise} streams, a reason: {reason}",
            entry.name
        );
    }
    let wrenches = streams.iter().find(|s| s.topic == "wrenches").unwrap();
    assert_eq!(wrenches.key, format!("graspopt/{RUN}/wrenches"));
    assert_eq!(wrenches.counted_by, &[Agent::Metric]);
    assert_eq!(wrenches.payloads.len(), PER_STREAM);
    // Mutants of fingertip readings: none decodes into readings of this run.
    let run = RunId::new(RUN).unwrap();
    for (bytes, encoding) in &wrenches.payloads {
        if let Ok(w) = decode::<FingertipWrenches>(bytes, *encoding) {
            assert_ne!(w.run_id, run);
        }
    }
}

#[test]
#[ignore = "slow suite: .ci/run runs it (tests/e2e/main.rs)"]
fn ten_thousand_bad_messages_change_nothing_and_are_all_counted() {
    let (clean, _, _) = run("fuzzclean", false);
    let (noisy, status, fuzzed) = run("fuzznoisy", true);
    let (c, sent) = fuzzed.unwrap();
    assert!(sent.total() >= 10_000, "{sent:?}");
    // Every topic an agent receives had its noise, fingertip readings included.
    let per_topic = sent.per_topic();
    for topic in [
        "object", "command", "clouds", "wrenches", "result", "suggest",
    ] {
        assert!(
            per_topic.get(topic) >= Some(&(PER_STREAM as u64)),
            "{sent:?}"
        );
    }
    // Same trials, bit for bit.
    let differing: Vec<u64> = clean
        .iter()
        .zip(&noisy)
        .filter(|(a, b)| (&a.params, a.score, &a.metrics) != (&b.params, b.score, &b.metrics))
        .map(|(a, _)| a.trial_id)
        .collect();
    assert!(
        differing.is_empty(),
        "trials that differ from the clean run: {differing:?}"
    );
    // Every message counted by every agent it reached.
    let e = &status["errors"];
    let coordinator = ["bad_messages", "unknown_trial", "not_issued"]
        .iter()
        .map(|k| e[k].as_u64().unwrap())
        .sum::<u64>();
    assert_eq!(
        coordinator,
        sent.to(Agent::Coordinator),
        "{status} {sent:?}"
    );
    assert_eq!(e["duplicates"], 0);
    let hand = bad_count(&c.log("hand-1"));
    let metric = bad_count(&c.log("metric"));
    let planner = bad_count(&c.log("planner"));
    assert_eq!(hand, sent.to(Agent::Hand), "hand {sent:?}");
    assert_eq!(metric, sent.to(Agent::Metric), "metric {sent:?}");
    assert_eq!(planner, sent.to(Agent::Planner), "planner {sent:?}");
    report(json!({
        "test": "fuzz: random and mutated messages on every input topic during a run",
        "sent": sent.total(),
        "sent_per_topic": per_topic,
        "counted": {"coordinator": coordinator, "hand": hand, "metric": metric, "planner": planner},
        "trials": TRIALS,
        "trials_differing_from_clean_run": differing.len(),
    }));
}
