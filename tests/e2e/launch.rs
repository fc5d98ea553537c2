//! `graspopt launch deploy/local.toml`: the example launch file starts a router and every agent
//! as processes, the run completes, and nothing is left running.

use std::os::unix::process::CommandExt;
use std::process::{Command, Stdio};
use std::time::Duration;

use crate::support::{
    check_journal, completed_now, free_port, graspopt_bin, journal_best, repo_root, tempdir,
    wait_until,
};
use graspopt_journal::{Journal, StoredRunPhase, StoredTrialPhase};

#[test]
fn the_local_launch_file_runs_a_whole_run_and_stops_everything() {
    let dir = tempdir("launch");
    let file = repo_root().join("deploy/local.toml");
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

/// A launch stopped by Ctrl-C is continued by `graspopt launch --resume FILE`: the trials
/// completed before the stop are kept and the run finishes its budget. The same launch
/// without `--resume` is refused by the coordinator, which says how to resume. Ctrl-C is
/// sent as a terminal sends it, to launch's whole process group: the coordinator stops
/// first, without seeing its workers leave.
#[test]
fn a_stopped_launch_is_continued_by_launch_resume() {
    let dir = tempdir("launch-resume");
    let port = free_port();
    let file = dir.join("run.toml");
    std::fs::write(
        &file,
        format!(
            r#"run = "lr"
endpoint = "tcp/127.0.0.1:{port}"
[router]
[[agent]]
kind = "perception"
args = ["--set", "object=cylinder"]
[[agent]]
kind = "planner"
[[agent]]
kind = "metric"
[[agent]]
kind = "hand"
args = ["--set", "trial_cost_ms=100"]
[[agent]]
kind = "coordinator"
args = ["--object", "cylinder", "--trials", "12", "--method", "random", "--set", "journal=results/lr/journal.sqlite"]
"#
        ),
    )
    .unwrap();
    let launch = |extra: &[&str]| {
        let mut c = Command::new(graspopt_bin());
        c.current_dir(&dir)
            .env("RUST_LOG", "warn")
            .arg("launch")
            .arg(&file)
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        c
    };
    let journal = dir.join("results/lr/journal.sqlite");
    // In a process group of its own, as a shell runs a foreground job.
    let first = launch(&[]).process_group(0).spawn().unwrap();
    wait_until("three trials", Duration::from_secs(60), || {
        completed_now(&journal, "lr") >= 3
    });
    let ok = Command::new("kill")
        .args(["-INT", "--", &format!("-{}", first.id())])
        .status()
        .unwrap()
        .success();
    assert!(ok);
    let out = first.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    // The final status the coordinator printed says what the journal records: stopped.
    let stdout = String::from_utf8_lossy(&out.stdout);
    let status: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(status["phase"], "stopped", "{stdout}");
    assert!(
        stderr.contains(&format!(
            "continue the run with graspopt launch --resume {}",
            file.display()
        )),
        "{stderr}"
    );
    let before: Vec<_> = Journal::open(&journal)
        .unwrap()
        .trials("lr")
        .unwrap()
        .into_iter()
        .filter(|t| t.state == StoredTrialPhase::Completed)
        .collect();
    assert!(
        (3..12).contains(&before.len()),
        "{} completed",
        before.len()
    );
    let log = std::fs::read_to_string(dir.join("logs/lr/coordinator.log")).unwrap();
    assert!(!log.contains("lost with trial"), "{log}");
    let j = Journal::open(&journal).unwrap();
    assert_eq!(
        j.run("lr").unwrap().unwrap().status,
        StoredRunPhase::Stopped
    );
    drop(j);

    // Launched again as it was: the coordinator refuses, naming the way to resume.
    let out = launch(&[]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains("run \"lr\" already exists") && stderr.contains("graspopt launch --resume"),
        "{stderr}"
    );

    let out = launch(&["--resume"]).output().unwrap();
    assert!(
        out.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let after = check_journal(&journal, "lr", 12);
    for t in &before {
        let a = &after[t.trial_id as usize - 1];
        assert_eq!(
            (&a.params, a.score),
            (&t.params, t.score),
            "trial {}",
            t.trial_id
        );
    }
    let j = Journal::open(&journal).unwrap();
    assert_eq!(
        j.run("lr").unwrap().unwrap().status,
        StoredRunPhase::Finished
    );
}
