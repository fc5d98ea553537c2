//! A command whose reader goes away (`graspopt trial ... | head -1`) ends quietly with
//! status 0: no panic, no "Broken pipe" message.

use crate::support::tempdir;
use std::process::{Command, Stdio};

/// Runs `graspopt args` with its stdout a pipe whose reading end is already closed, so its
/// first write fails as if `head -1` had gone away. Returns the status and stderr.
fn with_closed_stdout(args: &[&str]) -> (std::process::ExitStatus, String) {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_graspopt"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(writer)
        .stderr(Stdio::piped())
        .output()
        .expect("run graspopt");
    (
        out.status,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn assert_quiet(args: &[&str]) {
    let (status, stderr) = with_closed_stdout(args);
    assert!(
        !stderr.contains("panicked") && !stderr.contains("Broken pipe"),
        "graspopt {}: {stderr}",
        args.join(" ")
    );
    assert!(
        status.success(),
        "graspopt {}: {status}: {stderr}",
        args.join(" ")
    );
}

#[test]
fn one_shot_commands_end_quietly_when_their_reader_goes_away() {
    let repo = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let cases = format!("{repo}/tests/data/metric-cases.json");
    let launch = format!("{repo}/deploy/local.toml");
    for args in [
        vec!["trial", "--object", "sphere", "--at", "x=-0.09"],
        vec![
            "trial", "--object", "sphere", "--at", "x=-0.09", "--format", "json",
        ],
        vec![
            "optimize-function",
            "branin",
            "--budget",
            "8",
            "--seeds",
            "1",
        ],
        vec!["launch", "--dry-run", &launch],
        vec!["quality", "--input", &cases, "--no-volume"],
        vec![
            "quality",
            "--input",
            &cases,
            "--no-volume",
            "--format",
            "table",
        ],
    ] {
        assert_quiet(&args);
    }
}

#[test]
fn run_and_export_end_quietly_when_their_reader_goes_away() {
    let dir = tempdir("pipe-run");
    let out = dir.join("r");
    let out_s = out.to_str().unwrap();
    assert_quiet(&[
        "run",
        "--object",
        "sphere",
        "--trials",
        "3",
        "--workers",
        "1",
        "--quiet",
        "--out",
        out_s,
    ]);
    // The run finished and wrote its results before it printed.
    assert!(out.join("trials.csv").exists());
    let journal = out.join("journal.sqlite");
    assert_quiet(&["export", "run", "--journal", journal.to_str().unwrap()]);
    std::fs::remove_dir_all(&dir).unwrap();
}
