//! `graspopt launch deploy/local.toml`: the example launch file starts a router and every agent
//! as processes, the run completes, and nothing is left running.

use std::process::Command;
use std::time::Duration;

use graspopt_e2e::{check_journal, free_port, graspopt_bin, journal_best, tempdir};

#[test]
fn the_local_launch_file_runs_a_whole_run_and_stops_everything() {
    let dir = tempdir("launch");
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../deploy/local.toml");
    let port = free_port();
    let out = Command::new(graspopt_bin())
        .current_dir(&dir)
        .env("RUST_LOG", "warn")
        .args([
            "launch",
            file.to_str().unwrap(),
            "--endpoint",
            &format!("tcp/127.0.0.1:{port}"),
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The coordinator's final status came through on stdout and agrees with the journal.
    let status: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    let journal = dir.join("results/mug-local/journal.sqlite");
    let trials = check_journal(&journal, "mug-local", 60);
    assert_eq!(status["completed"], 60);
    let (best_id, _) = journal_best(&journal, "mug-local");
    assert_eq!(status["best"]["trial_id"], best_id);
    // Three hands took part; each process had its log.
    let mut workers: Vec<&str> = trials.iter().map(|t| t.worker.as_str()).collect();
    workers.sort();
    workers.dedup();
    assert_eq!(workers, ["hand-1", "hand-2", "hand-3"]);
    for name in [
        "router",
        "perception",
        "planner",
        "metric",
        "hand-1",
        "coordinator",
    ] {
        assert!(
            dir.join(format!("logs/mug-local/{name}.log")).exists(),
            "{name}"
        );
    }
    // The router was stopped with the rest: its port is free again.
    std::thread::sleep(Duration::from_millis(200));
    assert!(std::net::TcpStream::connect(("127.0.0.1", port)).is_err());
}
