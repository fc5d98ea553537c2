//! What a run says at its end, and how counts are refused: the failure reasons with their
//! counts and the exit status of a run without a completed trial, the rounding of what a
//! person reads, and the accepted range of every count flag.

use graspopt_journal::{Journal, RunLifecycle, TrialIssue};

use crate::support::{graspopt, graspopt_ok, tempdir};

/// The number `text` writes, and its significant digits.
fn significant_digits(text: &str) -> usize {
    text.trim_start_matches(['-', '0', '.'])
        .chars()
        .filter(char::is_ascii_digit)
        .count()
}

/// A run whose every trial failed ends with why, with how many trials each reason ended,
/// and exits with status 3 (not 0, and not Ctrl-C's 130). The journal is made here: the
/// settings of a real one-trial run, and three failed trials (two reasons).
#[test]
fn a_run_without_a_completed_trial_says_why_and_exits_3() {
    let dir = tempdir("all-failed");
    let first = dir.join("first");
    let flags = ["--object", "sphere", "--workers", "1", "--method", "random"];
    let mut args = vec!["run", "--run", "af", "--trials", "1", "--quiet", "--out"];
    args.push(first.to_str().unwrap());
    args.extend_from_slice(&flags);
    graspopt_ok(&args);
    let record = Journal::open(&first.join("journal.sqlite"))
        .unwrap()
        .run("af")
        .unwrap()
        .unwrap();
    let failed = dir.join("failed");
    std::fs::create_dir(&failed).unwrap();
    let mut j = Journal::open(&failed.join("journal.sqlite")).unwrap();
    j.create_run(&graspopt_journal::RunRecord {
        status: RunLifecycle::Stopped,
        ..record
    })
    .unwrap();
    for (id, why) in [
        (1, "the hand broke"),
        (2, "no cloud"),
        (3, "the hand broke"),
    ] {
        j.record_issue(&TrialIssue {
            run_id: "af".into(),
            trial_id: id,
            attempt: 1,
            params: vec![0.0, 0.0],
            worker: "hand-1".into(),
            at_ms: 1,
            lease_until_ms: 2,
            reason: None,
        })
        .unwrap();
        j.record_failure("af", id, 1, why, 3).unwrap();
    }
    drop(j);
    let out = graspopt(&[
        "run",
        "--resume",
        "--trials",
        "3",
        "--quiet",
        "--out",
        failed.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stdout}\n{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(
        lines[..4],
        [
            "run \"af\": 0 of 3 trials completed, 3 failed",
            "failed:",
            "  2 × the hand broke",
            "  1 × no cloud",
        ],
        "{stdout}"
    );
}

/// The summary of a run rounds the best score to five significant digits (the journal
/// keeps every digit), and its first line reads well with the default run id.
#[test]
fn a_run_s_summary_rounds_its_best_score() {
    let dir = tempdir("rounded");
    let out = graspopt_ok(&[
        "run",
        "--object",
        "cylinder",
        "--trials",
        "3",
        "--workers",
        "1",
        "--method",
        "random",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let best = Journal::open(&dir.join("journal.sqlite"))
        .unwrap()
        .best("run")
        .unwrap()
        .unwrap();
    let exact = best.score.unwrap();
    let line = stdout
        .lines()
        .find(|l| l.starts_with("best: "))
        .unwrap_or_else(|| panic!("no best line: {stdout}"));
    let shown = line
        .split(" score ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .unwrap();
    assert!(significant_digits(shown) <= 5, "{line}");
    let value: f64 = shown.parse().unwrap();
    assert!(
        (value - exact).abs() <= 0.5e-4 * exact.abs(),
        "{line}: the journal has {exact}"
    );
    assert!(
        stdout.starts_with("run \"run\": 3 of 3 trials completed, 0 failed\n"),
        "{stdout}"
    );
}
