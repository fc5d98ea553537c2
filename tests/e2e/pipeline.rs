//! The distributed pipeline end to end, as users run it: the embedded run (every agent in
//! one process) and every agent as its own process around a router.

use std::time::Duration;

use crate::support::{
    Cluster, check_journal, cloud_transport, col, graspopt, journal_best, read_csv, tempdir,
};

/// The best trial reported on stdout: `best: trial N score S at ...`.
fn reported_best(stdout: &str) -> (u64, f64) {
    let line = stdout
        .lines()
        .find(|l| l.starts_with("best: trial "))
        .unwrap_or_else(|| panic!("no best line in {stdout}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    (words[2].parse().unwrap(), words[4].parse().unwrap())
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
    let journal = out.join("journal.sqlite");
    check_journal(&journal, "run", 15);
    let (best_id, best_score) = journal_best(&journal, "run");
    // The summary rounds the score a person reads (five significant digits).
    let (reported_id, reported_score) = reported_best(&stdout);
    assert_eq!(reported_id, best_id, "{stdout}");
    assert!(
        (reported_score - best_score).abs() <= 0.5e-4 * best_score.abs(),
        "{stdout}: the journal's best scored {best_score}"
    );
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
    let c = Cluster::start("multiprocess", "mp");
    let journal = c.journal();
    let _support = c.support("cylinder");
    let _hands = c.hands(3, &[]);
    let coordinator = c.coordinator("cylinder", "40", "2", &[]);
    let final_status = c.final_status(coordinator, Duration::from_secs(240));
    assert_eq!(final_status["completed"], 40);
    assert_eq!(final_status["phase"], "finished");
    let trials = check_journal(&journal, "mp", 40);
    let (best_id, best_score) = journal_best(&journal, "mp");
    assert_eq!(final_status["best"]["trial_id"], best_id);
    assert_eq!(final_status["best"]["score"].as_f64().unwrap(), best_score);
    // Three workers took part, and on one host every cloud went through shared memory.
    let mut workers: Vec<&str> = trials.iter().map(|t| t.worker.as_str()).collect();
    workers.sort();
    workers.dedup();
    assert_eq!(workers, ["hand-1", "hand-2", "hand-3"]);
    for t in &trials {
        assert_eq!(cloud_transport(t), "shm", "trial {}", t.trial_id);
    }
}
