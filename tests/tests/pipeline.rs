//! The distributed pipeline end to end, as users run it: the embedded run (every agent in
//! one process) and every agent as its own process around a router.

use std::path::Path;
use std::time::Duration;

use graspopt_e2e::{Proc, free_port, graspopt, read_csv, tempdir};
use graspopt_journal::{Journal, TrialState};

/// Column index by name.
fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

/// The best trial reported on stdout: `best: trial N score S at ...`.
fn reported_best(stdout: &str) -> (u64, f64) {
    let line = stdout
        .lines()
        .find(|l| l.starts_with("best: trial "))
        .unwrap_or_else(|| panic!("no best line in {stdout}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    (words[2].parse().unwrap(), words[4].parse().unwrap())
}

/// Checks the journal of a finished run: exactly `n` completed trials with finite scores and
/// metrics, ids 1..=n, and returns (best id, best score) from the journal.
fn check_journal(path: &Path, run: &str, n: usize) -> (u64, f64) {
    let journal = Journal::open(path).unwrap();
    assert!(journal.integrity_check().unwrap());
    let trials = journal.trials(run).unwrap();
    assert_eq!(trials.len(), n, "trials in the journal");
    for (i, t) in trials.iter().enumerate() {
        assert_eq!(t.trial_id, i as u64 + 1);
        assert_eq!(t.state, TrialState::Completed, "trial {}", t.trial_id);
        assert!(t.score.unwrap().is_finite());
        if let Some(m) = &t.metrics {
            assert!(m.bw.is_finite() && m.epsilon >= 0.0 && m.distance >= 0.0);
            assert_eq!(m.bw > 0.0, m.force_closure, "trial {}", t.trial_id);
        }
    }
    let best = journal.best(run).unwrap().unwrap();
    (best.trial_id, best.score.unwrap())
}

#[test]
fn embedded_run_completes_every_trial_and_reports_the_journal_best() {
    let dir = tempdir("embedded");
    let out = dir.join("results");
    let o = graspopt(&[
        "run",
        "--object",
        "cuboid",
        "--workers",
        "3",
        "--trials",
        "15",
        "--seed",
        "4",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--shm-prefix",
        &format!("graspopt_e2e_emb_{}_", std::process::id()),
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let (best_id, best_score) = check_journal(&out.join("journal.sqlite"), "run", 15);
    assert_eq!(reported_best(&stdout), (best_id, best_score));
    // The CSV holds the same trials and the same best.
    let (header, rows) = read_csv(&out.join("trials.csv"));
    assert_eq!(rows.len(), 15);
    let score = col(&header, "score");
    let max = rows
        .iter()
        .map(|r| r[score].parse::<f64>().unwrap())
        .fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(max, best_score);
    assert!(out.join("best.svg").exists());
    // Bad input to `run`: a clear error, not a panic.
    let o = graspopt(&[
        "run",
        "--object",
        "teapot",
        "--quiet",
        "--out",
        dir.join("x").to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("teapot"), "{err}");
    // Re-running into the same journal without --resume is refused, and loses nothing.
    let o = graspopt(&[
        "run",
        "--object",
        "cuboid",
        "--trials",
        "3",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--resume"));
    check_journal(&out.join("journal.sqlite"), "run", 15);
}

/// Every agent a process: router, perception, planner, metric, three hands, coordinator.
#[test]
fn multi_process_run_over_a_router_completes_40_trials() {
    let dir = tempdir("multiprocess");
    let port = free_port();
    let router = format!("tcp/127.0.0.1:{port}");
    let journal = dir.join("journal.sqlite");
    let shm = format!("graspopt_e2e_mp_{}_", std::process::id());
    let common = |extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = extra.iter().map(|s| s.to_string()).collect();
        v.extend(
            [
                "--run",
                "mp",
                "--connect",
                &router,
                "--no-multicast-scouting",
                "--shm-prefix",
                &shm,
            ]
            .iter()
            .map(|s| s.to_string()),
        );
        v
    };
    let start = |name: &str, args: Vec<String>| {
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        Proc::start(name, &refs, &dir)
    };
    let _router = Proc::start(
        "router",
        &["router", "--listen", &router, "--no-multicast-scouting"],
        &dir,
    );
    std::thread::sleep(Duration::from_millis(300));
    let _perception = start(
        "perception",
        common(&["agent", "perception", "--object", "cylinder"]),
    );
    let _planner = start("planner", common(&["agent", "planner"]));
    let _metric = start("metric", common(&["agent", "metric"]));
    let _hands: Vec<Proc> = (1..=3)
        .map(|i| {
            let id = format!("hand-{i}");
            start(&id, common(&["agent", "hand", "--id", &id]))
        })
        .collect();
    let coordinator = start(
        "coordinator",
        common(&[
            "agent",
            "coordinator",
            "--object",
            "cylinder",
            "--trials",
            "40",
            "--seed",
            "2",
            "--journal",
            journal.to_str().unwrap(),
        ]),
    );
    let (status, stdout) = coordinator.wait_output(Duration::from_secs(240));
    assert!(
        status.success(),
        "coordinator failed: {stdout}\n{}",
        graspopt_e2e::log(&dir, "coordinator")
    );
    let final_status: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(final_status["completed"], 40);
    assert_eq!(final_status["phase"], "finished");
    let (best_id, best_score) = check_journal(&journal, "mp", 40);
    assert_eq!(final_status["best"]["trial_id"], best_id);
    assert_eq!(final_status["best"]["score"].as_f64().unwrap(), best_score);
    // Three workers took part.
    let j = Journal::open(&journal).unwrap();
    let mut workers: Vec<String> = j
        .trials("mp")
        .unwrap()
        .into_iter()
        .map(|t| t.worker)
        .collect();
    workers.sort();
    workers.dedup();
    assert_eq!(workers, ["hand-1", "hand-2", "hand-3"]);
}
