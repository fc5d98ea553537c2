//! Hands that answer from recorded contact data: `graspopt agent hand --set replay=FILE` and the
//! Python hand agent (`examples/python/hand_agent.py`, JSON on the wire). A recording of a
//! grid of grasps is made with `graspopt record`; an optimization then runs with the replaying
//! hand as its only worker, and every trial's score must be the recorded score of the grasp
//! nearest to the trial's parameters (the metric agent scores the recorded clouds again).

use std::path::{Path, PathBuf};
use std::time::Duration;

use graspopt_journal::TrialRow;

use crate::support::{Cluster, Proc, check_journal, graspopt, repo_root};

const TRIALS: usize = 10;

/// Records a 7 x 7 grid of cuboid grasps; returns (params, score) of each.
pub(crate) fn record(dir: &Path) -> (PathBuf, Vec<(Vec<f64>, f64)>) {
    let path = dir.join("cuboid.jsonl");
    let o = graspopt(&[
        "record",
        "--object",
        "cuboid",
        "--steps",
        "7",
        "--out",
        path.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let grasps: Vec<(Vec<f64>, f64)> = std::fs::read_to_string(&path)
        .unwrap()
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            let params = v["params"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            (params, v["score"].as_f64().unwrap())
        })
        .collect();
    assert_eq!(grasps.len(), 49);
    (path, grasps)
}

/// Runs `TRIALS` trials on the cuboid with `hand` as the only worker; checks every score is
/// the nearest recorded grasp's and that `worker` did them.
fn optimize_with(c: &Cluster, hand: Proc, worker: &str, grasps: &[(Vec<f64>, f64)]) {
    let trials = run_with_only(c, hand, worker, "cuboid", TRIALS, "3", &[]);
    check_replayed(&trials, grasps);
}

/// Every trial's score is the recorded score of the grasp nearest to its parameters.
pub(crate) fn check_replayed(trials: &[TrialRow], grasps: &[(Vec<f64>, f64)]) {
    for t in trials {
        let nearest = grasps
            .iter()
            .min_by(|a, b| dist(&a.0, &t.params).total_cmp(&dist(&b.0, &t.params)))
            .unwrap();
        let score = t.score.unwrap();
        assert!(
            (score - nearest.1).abs() <= 1e-9 * (1.0 + nearest.1.abs()),
            "trial {} at {:?}: score {score}, recorded grasp at {:?} scored {}",
            t.trial_id,
            t.params,
            nearest.0,
            nearest.1
        );
    }
}

/// Runs `trials` trials on `object` (coordinator seed `seed`, more coordinator flags `extra`)
/// with `hand` as the only worker, id `worker`; returns the journal's trials, checked: each
/// recorded once, all by `worker`.
pub(crate) fn run_with_only(
    c: &Cluster,
    hand: Proc,
    worker: &str,
    object: &str,
    trials: usize,
    seed: &str,
    extra: &[&str],
) -> Vec<TrialRow> {
    let journal = c.journal();
    let _support = c.support(object);
    let coordinator = c.coordinator(object, &trials.to_string(), seed, extra);
    let (status, stdout) = coordinator.wait_output(Duration::from_secs(120));
    assert!(
        status.success(),
        "coordinator failed: {stdout}\n{}\nhand log:\n{}\nmetric log:\n{}",
        c.log("coordinator"),
        c.log(&hand.name),
        c.log("metric")
    );
    drop(hand);
    let rows = check_journal(&journal, &c.run, trials);
    for t in &rows {
        assert_eq!(t.worker, worker);
    }
    rows
}

/// Squared distance between two parameter vectors.
pub(crate) fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

#[test]
fn replay_hand_answers_trials_from_a_recording() {
    let c = Cluster::start("replay", "replay");
    let (rec, grasps) = record(&c.dir);
    let hand = c.agent(
        "replay-hand",
        &[
            "hand",
            "--id",
            "replay-hand",
            "--set",
            &format!("replay={}", rec.display()),
        ],
    );
    optimize_with(&c, hand, "replay-hand", &grasps);
    // A recording that is not one is refused by name.
    let bad = c.dir.join("bad.jsonl");
    std::fs::write(&bad, "{\"params\": [0.1, 0.2]}\n").unwrap();
    let o = graspopt(&[
        "agent",
        "hand",
        "--set",
        &format!("replay={}", bad.display()),
        "--connect",
        &c.endpoint,
        "--no-multicast-scouting",
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("bad.jsonl, line 1"), "{err}");
}

/// The example Python hand agent (`examples/python/hand_agent.py`) as worker `id` of the
/// cluster's run, answering from the recording `rec`; its stderr goes to `<dir>/<name>.log`.
/// Needs `GRASPOPT_PYTHON`, a Python with eclipse-zenoh (`.ci/run` makes one).
fn python_hand(c: &Cluster, rec: &Path, name: &str, id: &str) -> Proc {
    python_agent(c, "hand_agent.py", rec, name, id)
}

/// The Python hand `script` of `examples/python/` as worker `id`, answering from the
/// recording `rec`; its stderr goes to `<dir>/<name>.log`.
pub(crate) fn python_agent(c: &Cluster, script: &str, rec: &Path, name: &str, id: &str) -> Proc {
    python_agent_at(&c.dir, &c.endpoint, &c.run, script, rec, name, id, &[])
}

/// The Python hand `script` of `examples/python/` as worker `id` of `run`, connecting to
/// `endpoint` with `extra` flags, answering from the recording `rec`; its stderr goes to
/// `<dir>/<name>.log`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn python_agent_at(
    dir: &Path,
    endpoint: &str,
    run: &str,
    script: &str,
    rec: &Path,
    name: &str,
    id: &str,
    extra: &[&str],
) -> Proc {
    let python = std::env::var("GRASPOPT_PYTHON")
        .expect("set GRASPOPT_PYTHON to a Python with eclipse-zenoh (see .ci/run)");
    let script = repo_root().join("examples/python").join(script);
    let log = std::fs::File::create(dir.join(format!("{name}.log"))).unwrap();
    let child = std::process::Command::new(python)
        .arg(&script)
        .args([
            "--connect",
            endpoint,
            "--run",
            run,
            "--id",
            id,
            "--recording",
            rec.to_str().unwrap(),
        ])
        .args(extra)
        .stderr(log)
        .spawn()
        .unwrap_or_else(|e| panic!("start the Python hand {}: {e}", script.display()));
    Proc {
        name: name.into(),
        child,
    }
}

/// The Python hand takes its place and gives way by graspopt's rules and in its words
/// (common/bus/src/alive.rs): refused while a hand with its id is alive or only its settled
/// claim is seen; before it settles, it gives way to a settled claim whatever the numbers;
/// once settled (its `settled` token out), it stays for a smaller number held and gives
/// way to a smaller number settled. `tests/e2e/python_claims.py` declares the other claims
/// by hand on one isolated session.
#[test]
#[ignore = "needs Python with eclipse-zenoh (GRASPOPT_PYTHON); .ci/run runs it"]
fn python_hand_takes_its_place_by_the_same_rules() {
    let python = std::env::var("GRASPOPT_PYTHON")
        .expect("set GRASPOPT_PYTHON to a Python with eclipse-zenoh (see .ci/run)");
    let child = std::process::Command::new(python)
        .arg(repo_root().join("tests/e2e/python_claims.py"))
        .env("PYTHONPATH", repo_root().join("examples/python"))
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let script = Proc {
        name: "python_claims.py".into(),
        child,
    };
    let (status, out) = script.wait_output(Duration::from_secs(60));
    assert!(status.success(), "{out}");
    let gives_way = |id: &str| {
        format!(
            "run \"pyclaims\": another agent, a hand with the id {id}, took its place at the same \
             moment and keeps it: this one gives way (give it another --id)"
        )
    };
    let want = [
        "alive holder: run \"pyclaims\" already has a hand with the id h1, alive on host hostx: \
         stop it first, or give this one another --id"
            .to_string(),
        "settled claim: run \"pyclaims\" already has a hand with the id h2: stop it first, or \
         give this one another --id"
            .to_string(),
        format!("fresh vs settled larger: {}", gives_way("h3")),
        "settled phases: ['held', 'settled']".to_string(),
        "settled vs smaller held: None".to_string(),
        format!("settled vs smaller settled: {}", gives_way("h4")),
    ];
    assert_eq!(out.lines().collect::<Vec<_>>(), want);
}

/// Needs Python with eclipse-zenoh: `.ci/run` makes a venv and runs this with
/// `GRASPOPT_PYTHON` set (`cargo test -p graspopt --test e2e -- --ignored replay::`).
#[test]
#[ignore = "needs Python with eclipse-zenoh (GRASPOPT_PYTHON); .ci/run runs it"]
fn python_hand_agent_is_the_only_worker_of_an_optimization() {
    let c = Cluster::start("pyhand", "pyhand");
    let (rec, grasps) = record(&c.dir);
    let hand = python_hand(&c, &rec, "py-hand", "py-hand-1");
    optimize_with(&c, hand, "py-hand-1", &grasps);
}

/// Two Python hands and a graspopt hand started at the same moment with one id: they take
/// the place the same way, so exactly one of them keeps it and the others give way. (Two
/// Python hands start alike, so they meet in the claim itself; the graspopt hand may meet
/// them there or find the place held.) Run by `.ci/run` with the test above.
#[test]
#[ignore = "needs Python with eclipse-zenoh (GRASPOPT_PYTHON); .ci/run runs it"]
fn hands_started_together_with_one_id_leave_one_running() {
    let c = Cluster::start("pytwin", "pytwin");
    let (rec, _) = record(&c.dir);
    let mut hands = vec![
        python_hand(&c, &rec, "py-twin-a", "twin"),
        python_hand(&c, &rec, "py-twin-b", "twin"),
        c.agent("rust-twin", &["hand", "--id", "twin"]),
    ];
    // Each takes about 2 s to take its place; one that gives way waits up to 5 s for the
    // place to come free first.
    std::thread::sleep(Duration::from_secs(10));
    let mut running = Vec::new();
    let mut gave_way = Vec::new();
    for hand in &mut hands {
        match hand.child.try_wait().unwrap() {
            None => running.push(hand.name.clone()),
            Some(status) => gave_way.push((hand.name.clone(), status.success())),
        }
    }
    let logs: String = hands
        .iter()
        .map(|h| format!("{}: {}\n", h.name, c.log(&h.name)))
        .collect();
    assert_eq!(
        running.len(),
        1,
        "running {running:?}, exited {gave_way:?}\n{logs}"
    );
    for (name, success) in gave_way {
        assert!(!success, "{name} exited successfully\n{logs}");
        let said = c.log(&name);
        assert!(
            said.contains("gives way") || said.contains("already has"),
            "{name}: {said}"
        );
    }
}

/// A run whose every trial fails (here a replay hand whose recording has two parameters per
/// grasp, for a run of three) ends by saying why, with how many trials each reason ended: in
/// the final status the coordinator prints (`failures`) and on its stderr; and the
/// coordinator exits with status 3, not 0.
#[test]
fn a_coordinator_whose_every_trial_failed_says_why_and_exits_3() {
    let c = Cluster::start("all-failed", "allfail");
    let (rec, _) = record(&c.dir);
    let _hand = c.agent(
        "replay-hand",
        &[
            "hand",
            "--id",
            "hand-1",
            "--set",
            &format!("replay={}", rec.display()),
        ],
    );
    let _support = c.support("cuboid");
    let coordinator = c.coordinator("cuboid", "6", "0", &["--params", "x,y,rz"]);
    let (status, stdout) = coordinator.wait_output(Duration::from_secs(120));
    let log = c.log("coordinator");
    assert_eq!(status.code(), Some(3), "{stdout}\n{log}");
    let reason = format!(
        "the recording {} has 2 parameters per grasp, the trial has 3",
        rec.display()
    );
    let json: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(
        (&json["completed"], &json["failed"]),
        (&0.into(), &6.into())
    );
    assert_eq!(
        json["failures"],
        serde_json::json!([{"reason": reason, "trials": 6}]),
        "{stdout}"
    );
    assert!(
        log.contains("run \"allfail\": 0 of 6 trials completed, 6 failed")
            && log.contains(&format!("failed: 6 × {reason}")),
        "{log}"
    );
}
