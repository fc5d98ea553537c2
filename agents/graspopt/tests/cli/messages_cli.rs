//! What a run says at its end, and how counts are refused: the failure reasons with their
//! counts and the exit status of a run without a completed trial, the rounding of what a
//! person reads, and the accepted range of every count flag.

use graspopt_journal::{Journal, StoredRunPhase, TrialIssue};

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
    j.create_run(&graspopt_journal::RunRow {
        status: StoredRunPhase::Stopped,
        ..record
    })
    .unwrap();
    for (id, why) in [
        (1, "the hand broke"),
        (2, "no cloud"),
        (3, "the hand broke"),
    ] {
        j.write_issue(&TrialIssue {
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
        j.write_failure("af", id, 1, why, 3).unwrap();
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

/// A negative count (which clap would take for an unknown flag) is refused naming the range
/// the flag accepts, in every command that takes a count.
#[test]
fn a_negative_count_is_refused_naming_the_accepted_range() {
    let dir = tempdir("negative-counts");
    let out = dir.join("never");
    let o = out.to_str().unwrap();
    let journal = format!("journal={o}");
    for (args, expected) in [
        (
            vec!["run", "--trials", "-5", "--out", o],
            "--trials <TRIALS>': must be a whole number from 1 to 1,000,000,000",
        ),
        (
            vec!["run", "--workers", "-1", "--out", o],
            "--workers <WORKERS>': must be a whole number of 0 or more",
        ),
        (
            vec!["run", "--initial", "-1", "--out", o],
            "--initial <INITIAL>': must be a whole number",
        ),
        (
            vec!["agent", "coordinator", "--trials", "-5", "--set", &journal],
            "--trials <TRIALS>': must be a whole number from 1 to 1,000,000,000",
        ),
        (
            vec!["bench", "coordinator", "--trials", "-5"],
            "must be a whole number from 1 to 100,000",
        ),
        (
            vec!["bench", "pipeline", "--workers", "-2,4"],
            "must be a whole number from 1 to 256",
        ),
        (
            vec!["bench", "pipeline", "--trials-per-worker", "-1"],
            "must be a whole number",
        ),
        (
            vec!["bench", "clouds", "--messages", "-1"],
            "must be a whole number from 1 to 100,000",
        ),
        (
            vec!["bench", "planner", "--rounds", "-1"],
            "must be a whole number from 1 to 1,000",
        ),
        (
            vec!["experiment", "bo", "--seeds", "-1", "--out", o],
            "must be a whole number from 1 to 1,000",
        ),
        (
            vec!["experiment", "bo", "--budget", "-1", "--out", o],
            "must be a whole number",
        ),
        (
            vec!["experiment", "metrics", "--steps", "-1", "--out", o],
            "must be a whole number",
        ),
        (
            vec!["experiment", "sensing", "--trials", "-1"],
            "-1 is not in 1..=100000",
        ),
        (
            vec!["optimize-function", "branin", "--seeds", "-1"],
            "must be a whole number from 1 to 1,000",
        ),
        (
            vec!["optimize-function", "branin", "--budget", "-1"],
            "must be a whole number from 1 to 100,000",
        ),
        (
            vec!["scan", "--steps", "-5", "--out", o],
            "--steps: expected whole numbers >= 1, got \"-5\"",
        ),
        (
            vec!["scan", "--threads", "-1", "--out", o],
            "must be a whole number",
        ),
        (
            vec!["topic", "echo", "status", "--count", "-1"],
            "must be a whole number",
        ),
    ] {
        let run = graspopt(&args);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{args:?} ran");
        assert!(
            !stderr.contains("unexpected argument"),
            "{args:?}: {stderr}"
        );
        assert!(
            stderr.contains(expected),
            "{args:?}: {expected:?} not in {stderr}"
        );
    }
    assert!(!out.exists(), "a refused command wrote {o}");
}

/// `monitor --once` at an address where nothing answers says so and fails (as `topic list`
/// does), without a warning from the background connection as it exits.
#[test]
fn monitor_once_where_nothing_answers_says_so_without_a_warning() {
    let out = graspopt(&["monitor", "--once", "--connect", "tcp/127.0.0.1:1"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("nothing answers at tcp/127.0.0.1:1"),
        "{stderr}"
    );
    assert!(!stderr.contains("WARN"), "{stderr}");
    assert!(out.stdout.is_empty());
}
