//! Behaviour of the trial journal: recording rules, durability, exports.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdout, Command, Stdio};
use std::time::{Duration, Instant};

use graspopt_journal::export::{write_csv, write_json};
use graspopt_journal::{
    EventRow, Journal, JournalError, MetricValue, MetricValues, ResultOutcome, ResultRow, RunRow,
    SCHEMA_VERSION, StateCounts, StoredRunPhase, StoredTrialPhase, TrialIssue, TrialRow,
    event_kind,
};

// ------------------------------------------------------------------ helpers

/// A scratch folder, removed on drop.
struct TempDir(tempfile::TempDir);

impl TempDir {
    fn new(tag: &str) -> TempDir {
        let prefix = format!("graspopt-journal-{tag}-");
        TempDir(tempfile::Builder::new().prefix(&prefix).tempdir().unwrap())
    }

    fn db(&self) -> PathBuf {
        self.0.path().join("journal.sqlite")
    }
}

const RUN: &str = "run-a";

fn run_record(run_id: &str) -> RunRow {
    RunRow {
        run_id: run_id.to_string(),
        created_ms: 1_000,
        config_json: r#"{"objective":"epsilon","budget":50,"hand":{"fingers":3}}"#.to_string(),
        param_names: vec!["approach_x".into(), "roll".into(), "aperture".into()],
        status: StoredRunPhase::Running,
    }
}

/// Parameters that are hard to round-trip through text.
fn params_for(trial: u64) -> Vec<f64> {
    vec![
        0.1 + 0.2 + trial as f64,
        f64::MIN_POSITIVE / 3.0 * (trial as f64 + 1.0), // subnormal
        -(trial as f64 + 1.0) / 7.0,
    ]
}

fn issue(run_id: &str, trial: u64, attempt: u32, worker: &str, at_ms: i64) -> TrialIssue {
    TrialIssue {
        run_id: run_id.to_string(),
        trial_id: trial,
        attempt,
        params: params_for(trial),
        worker: worker.to_string(),
        at_ms,
        lease_until_ms: at_ms + 30_000,
        reason: None,
    }
}

fn metrics_for(trial: u64) -> MetricValues {
    MetricValues::default()
        .with("rank", Some(MetricValue::Count(6)))
        .with(
            "force_closure",
            Some(MetricValue::Flag(trial.is_multiple_of(2))),
        )
        .with(
            "epsilon",
            Some(MetricValue::Real(0.0123456789012345 * (trial as f64 + 1.0))),
        )
        .with("volume", Some(MetricValue::Real(1.0 / 3.0 + trial as f64)))
        .with("distance", Some(MetricValue::Real(2.0f64.sqrt())))
        .with("bw", Some(MetricValue::Real(1e-17 * (trial as f64 + 1.0))))
}

fn score_for(trial: u64) -> f64 {
    (trial as f64 + 1.0).ln() / 3.0
}

fn result(
    run_id: &str,
    trial: u64,
    attempt: u32,
    worker: &str,
    at_ms: i64,
    score: f64,
) -> ResultRow {
    ResultRow {
        run_id: run_id.to_string(),
        trial_id: trial,
        attempt,
        worker: worker.to_string(),
        at_ms,
        score,
        metrics: Some(metrics_for(trial)),
        contacts: 7,
        fingers_in_contact: 3,
        cloud_points: 4096,
        details_json: format!(r#"{{"trial":{trial},"note":"ok"}}"#),
        forces: None,
    }
}

fn journal_with_run() -> Journal {
    let mut j = Journal::open_in_memory().unwrap();
    j.create_run(&run_record(RUN)).unwrap();
    j
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn kinds(events: &[EventRow]) -> Vec<&str> {
    events.iter().map(|e| e.kind.as_str()).collect()
}

/// A minimal RFC 4180 reader: records of fields, quoted fields may hold
/// commas, doubled quotes and line breaks.
fn parse_csv(text: &str) -> Vec<Vec<String>> {
    let mut records = Vec::new();
    let mut record = Vec::new();
    let mut field = String::new();
    let mut chars = text.chars().peekable();
    let mut in_quotes = false;
    while let Some(c) = chars.next() {
        if in_quotes {
            match c {
                '"' if chars.peek() == Some(&'"') => {
                    chars.next();
                    field.push('"');
                }
                '"' => in_quotes = false,
                _ => field.push(c),
            }
        } else {
            match c {
                '"' => {
                    assert!(field.is_empty(), "quote inside an unquoted field");
                    in_quotes = true;
                }
                ',' => record.push(std::mem::take(&mut field)),
                '\n' => {
                    record.push(std::mem::take(&mut field));
                    records.push(std::mem::take(&mut record));
                }
                _ => field.push(c),
            }
        }
    }
    assert!(!in_quotes, "unterminated quoted field");
    assert!(field.is_empty() && record.is_empty(), "last line not ended");
    records
}

// -------------------------------------------------------------------- tests

/// Issue, result, re-issue, failure and reopening: the life of a trial in the journal.
mod batch;
/// The CSV and JSON exports of a run.
mod export;
mod forces;
mod lifecycle;

#[test]
fn journal_is_send() {
    fn assert_send<T: Send>() {}
    assert_send::<Journal>();
    // And usable behind a mutex from another thread.
    let j = std::sync::Mutex::new(journal_with_run());
    std::thread::scope(|s| {
        s.spawn(|| {
            let mut j = j.lock().unwrap();
            j.write_issue(&issue(RUN, 1, 1, "w1", 10)).unwrap();
        });
    });
    assert_eq!(j.lock().unwrap().counts(RUN).unwrap().running, 1);
}

#[test]
fn schema_version_checked_at_open() {
    let dir = TempDir::new("schema");
    let db = dir.db();
    Journal::open(&db).unwrap();
    {
        let raw = rusqlite::Connection::open(&db).unwrap();
        raw.execute_batch("PRAGMA user_version = 99").unwrap();
    }
    let err = Journal::open(&db).unwrap_err();
    assert!(
        matches!(
            err,
            JournalError::SchemaVersion {
                found: 99,
                expected: SCHEMA_VERSION
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("99"), "{err}");

    // Some other SQLite database is not taken for an empty journal.
    let other = dir.0.path().join("other.sqlite");
    {
        let raw = rusqlite::Connection::open(&other).unwrap();
        raw.execute_batch("CREATE TABLE notes (body TEXT)").unwrap();
    }
    let err = Journal::open(&other).unwrap_err();
    assert!(matches!(err, JournalError::Schema(_)), "{err}");

    // Right version number, wrong layout.
    let tampered = dir.0.path().join("tampered.sqlite");
    Journal::open(&tampered).unwrap();
    {
        let raw = rusqlite::Connection::open(&tampered).unwrap();
        raw.execute_batch("ALTER TABLE trials ADD COLUMN extra TEXT")
            .unwrap();
    }
    let err = Journal::open(&tampered).unwrap_err();
    assert!(
        matches!(&err, JournalError::Schema(m) if m.contains("trials")),
        "{err}"
    );
}

#[test]
fn create_run_idempotent_and_config_mismatch() {
    let mut j = Journal::open_in_memory().unwrap();
    let run = run_record(RUN);
    j.create_run(&run).unwrap();
    j.create_run(&run).unwrap();
    // Same JSON value, other spelling: still the same config.
    let mut respelled = run.clone();
    respelled.config_json =
        r#"{ "hand": {"fingers": 3}, "budget": 50, "objective": "epsilon" }"#.to_string();
    j.create_run(&respelled).unwrap();
    assert_eq!(j.runs().unwrap(), vec![run.clone()]);

    let mut changed = run.clone();
    changed.config_json = r#"{"objective":"epsilon","budget":60,"hand":{"fingers":3}}"#.into();
    let err = j.create_run(&changed).unwrap_err();
    assert!(
        matches!(&err, JournalError::ConfigMismatch { run_id } if run_id == RUN),
        "{err}"
    );
    assert!(err.to_string().contains(RUN), "{err}");

    let mut renamed = run.clone();
    renamed.param_names[1] = "pitch".into();
    let err = j.create_run(&renamed).unwrap_err();
    assert!(matches!(err, JournalError::ConfigMismatch { .. }), "{err}");
    assert_eq!(j.run(RUN).unwrap().unwrap(), run);

    // runs() is by creation time, not by id or insertion.
    let mut late = run_record("a-late");
    late.created_ms = 5_000;
    let mut early = run_record("z-early");
    early.created_ms = 10;
    j.create_run(&late).unwrap();
    j.create_run(&early).unwrap();
    let ids: Vec<String> = j.runs().unwrap().into_iter().map(|r| r.run_id).collect();
    assert_eq!(ids, ["z-early", RUN, "a-late"]);

    j.set_run_phase("a-late", StoredRunPhase::Stopped, 6_000)
        .unwrap();
    assert_eq!(
        j.run("a-late").unwrap().unwrap().status,
        StoredRunPhase::Stopped
    );
    let err = j
        .set_run_phase("ghost", StoredRunPhase::Stopped, 6_000)
        .unwrap_err();
    assert!(
        matches!(&err, JournalError::UnknownRun(r) if r == "ghost"),
        "{err}"
    );
    assert_eq!(j.run("ghost").unwrap(), None);

    j.set_run_config("a-late", r#"{"trials":90}"#).unwrap();
    let late = j.run("a-late").unwrap().unwrap();
    assert_eq!(late.config_json, r#"{"trials":90}"#);
    assert_eq!(late.status, StoredRunPhase::Stopped);
    assert!(matches!(
        j.set_run_config("ghost", "{}").unwrap_err(),
        JournalError::UnknownRun(r) if r == "ghost"
    ));
}

#[test]
fn non_finite_values_refused() {
    let mut j = journal_with_run();
    j.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
    let before = j.trial(RUN, 1).unwrap().unwrap();

    let cases: Vec<(&str, ResultRow)> = vec![
        ("score", result(RUN, 1, 1, "w1", 200, f64::NAN)),
        ("score", result(RUN, 1, 1, "w1", 200, f64::INFINITY)),
        ("metrics.epsilon", {
            let mut r = result(RUN, 1, 1, "w1", 200, 0.5);
            r.metrics
                .as_mut()
                .unwrap()
                .set("epsilon", Some(MetricValue::Real(f64::NEG_INFINITY)));
            r
        }),
        ("metrics.volume", {
            let mut r = result(RUN, 1, 1, "w1", 200, 0.5);
            r.metrics
                .as_mut()
                .unwrap()
                .set("volume", Some(MetricValue::Real(f64::NAN)));
            r
        }),
        ("metrics.distance", {
            let mut r = result(RUN, 1, 1, "w1", 200, 0.5);
            r.metrics
                .as_mut()
                .unwrap()
                .set("distance", Some(MetricValue::Real(f64::NAN)));
            r
        }),
        ("metrics.bw", {
            let mut r = result(RUN, 1, 1, "w1", 200, 0.5);
            r.metrics
                .as_mut()
                .unwrap()
                .set("bw", Some(MetricValue::Real(f64::INFINITY)));
            r
        }),
    ];
    for (field, r) in cases {
        let err = j.write_result(&r).unwrap_err();
        assert!(
            matches!(&err, JournalError::NonFinite { field: f } if f == field),
            "{field}: {err}"
        );
        assert!(err.to_string().contains(field), "{err}");
    }
    assert_eq!(j.trial(RUN, 1).unwrap().unwrap(), before);
    assert_eq!(kinds(&j.events(RUN).unwrap()), ["issued"]);

    let mut bad = issue(RUN, 2, 1, "w1", 100);
    bad.params[1] = f64::NAN;
    let err = j.write_issue(&bad).unwrap_err();
    assert!(
        matches!(&err, JournalError::NonFinite { field } if field == "params[1]"),
        "{err}"
    );
    assert_eq!(j.trial(RUN, 2).unwrap(), None);
    assert_eq!(j.events(RUN).unwrap().len(), 1);

    // The valid result still goes through afterwards.
    assert_eq!(
        j.write_result(&result(RUN, 1, 1, "w1", 200, 0.5)).unwrap(),
        ResultOutcome::Accepted
    );
}

#[test]
fn best_and_counts() {
    let mut j = journal_with_run();
    assert_eq!(j.best(RUN).unwrap(), None);
    assert_eq!(j.counts(RUN).unwrap(), StateCounts::default());
    for t in 1..=6 {
        j.write_issue(&issue(RUN, t, 1, "w", 100 + t as i64))
            .unwrap();
    }
    j.write_result(&result(RUN, 1, 1, "w", 200, 0.3)).unwrap();
    j.write_result(&result(RUN, 2, 1, "w", 200, 0.8)).unwrap();
    j.write_result(&result(RUN, 3, 1, "w", 200, -2.0)).unwrap();
    j.write_result(&result(RUN, 4, 1, "w", 200, 0.8)).unwrap(); // tie with 2
    j.write_failure(RUN, 5, 1, "hand error", 300).unwrap();

    let best = j.best(RUN).unwrap().unwrap();
    assert_eq!(best.trial_id, 2);
    assert_eq!(best.score, Some(0.8));
    assert_eq!(
        j.counts(RUN).unwrap(),
        StateCounts {
            running: 1,
            completed: 4,
            failed: 1
        }
    );

    // A better late result moves best; a duplicate that would be better does not.
    j.write_result(&result(RUN, 6, 1, "w", 400, 0.95)).unwrap();
    j.write_result(&result(RUN, 3, 1, "w", 500, 10.0)).unwrap();
    assert_eq!(j.best(RUN).unwrap().unwrap().trial_id, 6);
    assert_eq!(
        j.counts(RUN).unwrap(),
        StateCounts {
            running: 0,
            completed: 5,
            failed: 1
        }
    );

    // Other runs do not leak in.
    j.create_run(&run_record("run-b")).unwrap();
    assert_eq!(j.best("run-b").unwrap(), None);
    assert_eq!(j.counts("run-b").unwrap(), StateCounts::default());
}

#[test]
fn leases_and_max_trial_id() {
    let mut j = journal_with_run();
    assert_eq!(j.max_trial_id(RUN).unwrap(), None);
    j.write_issue(&issue(RUN, 1, 1, "w1", 0)).unwrap(); // lease to 30_000
    j.write_issue(&issue(RUN, 2, 1, "w2", 10_000)).unwrap(); // lease to 40_000
    j.write_issue(&issue(RUN, 3, 1, "w3", 0)).unwrap();
    j.write_result(&result(RUN, 3, 1, "w3", 100, 0.1)).unwrap();
    assert_eq!(j.max_trial_id(RUN).unwrap(), Some(3));
    let ids = |rows: Vec<TrialRow>| rows.into_iter().map(|t| t.trial_id).collect::<Vec<_>>();
    assert_eq!(ids(j.expired_leases(RUN, 35_000).unwrap()), [1]);
    assert_eq!(ids(j.expired_leases(RUN, 45_000).unwrap()), [1, 2]);
    assert!(j.expired_leases(RUN, 1_000).unwrap().is_empty());
}

#[test]
fn unknown_run_reads_are_errors() {
    let j = journal_with_run();
    let ghost = "ghost-run";
    let check = |err: JournalError| {
        assert!(
            matches!(&err, JournalError::UnknownRun(r) if r == ghost),
            "{err}"
        );
        assert!(err.to_string().contains(ghost), "{err}");
    };
    check(j.trials(ghost).unwrap_err());
    check(j.trial(ghost, 1).unwrap_err());
    check(j.events(ghost).unwrap_err());
    check(j.best(ghost).unwrap_err());
    check(j.counts(ghost).unwrap_err());
    check(j.export(ghost).unwrap_err());
    let mut out = Vec::new();
    check(write_csv(&j, ghost, &mut out).unwrap_err());
    check(write_json(&j, ghost, &mut out).unwrap_err());
    assert!(out.is_empty());
    assert!(j.trials(RUN).unwrap().is_empty());
}

// ------------------------------------------------------------ kill -9 test

const CHILD_ENV: &str = "JOURNAL_CHILD_DB";
const KILL_RUN: &str = "kill-run";
const READY: &str = "JOURNAL_CHILD_READY";

/// Not a test on its own: the body of the child process of
/// `kill9_leaves_consistent_prefix`, which re-runs this binary with
/// `JOURNAL_CHILD_DB` set. Without it, it returns at once.
#[test]
fn child_writer() {
    let Ok(path) = std::env::var(CHILD_ENV) else {
        return;
    };
    let mut j = Journal::open(Path::new(&path)).unwrap();
    j.create_run(&run_record(KILL_RUN)).unwrap();
    let mut next = j.max_trial_id(KILL_RUN).unwrap().unwrap_or(0);
    // A trial left running by the previous kill is finished first.
    if next > 0 && j.trial(KILL_RUN, next).unwrap().unwrap().state == StoredTrialPhase::Running {
        j.write_result(&result(KILL_RUN, next, 1, "child", 0, score_for(next)))
            .unwrap();
    }
    println!("{READY}");
    let deadline = Instant::now() + Duration::from_secs(30);
    while Instant::now() < deadline {
        next += 1;
        j.write_issue(&issue(KILL_RUN, next, 1, "child", 0))
            .unwrap();
        j.write_result(&result(KILL_RUN, next, 1, "child", 0, score_for(next)))
            .unwrap();
    }
    panic!("child writer was not killed within 30 s");
}

/// Checks that the journal holds trials 1..=n, all completed with the right
/// result except possibly the last (issued, not yet completed), with exactly
/// the matching events. Returns n.
fn check_prefix(j: &Journal) -> usize {
    let trials = j.trials(KILL_RUN).unwrap();
    let events = j.events(KILL_RUN).unwrap();
    let mut per_trial: BTreeMap<u64, Vec<&str>> = BTreeMap::new();
    for e in &events {
        per_trial
            .entry(e.trial_id)
            .or_default()
            .push(e.kind.as_str());
    }
    for (i, t) in trials.iter().enumerate() {
        let id = i as u64 + 1;
        assert_eq!(t.trial_id, id, "trial ids must be contiguous from 1");
        assert_eq!(bits(&t.params), bits(&params_for(id)), "trial {id}");
        let is_last = i + 1 == trials.len();
        match t.state {
            StoredTrialPhase::Completed => {
                assert_eq!(t.score.map(f64::to_bits), Some(score_for(id).to_bits()));
                assert_eq!(t.metrics, Some(metrics_for(id)));
                assert_eq!(t.cloud_points, 4096);
                assert_eq!(per_trial[&id], ["issued", "result"], "trial {id}");
            }
            StoredTrialPhase::Running => {
                assert!(
                    is_last,
                    "only the last trial may be unfinished (trial {id})"
                );
                assert_eq!(t.score, None);
                assert_eq!(per_trial[&id], ["issued"], "trial {id}");
            }
            StoredTrialPhase::Failed => panic!("trial {id} failed"),
        }
    }
    assert_eq!(per_trial.len(), trials.len(), "events for unknown trials");
    trials.len()
}

/// Runs this test binary's test `name` alone in a child process, with `env` set to the
/// journal `db` (the child's writer body runs only then); its stdout piped.
fn spawn_writer(name: &str, env: &str, db: &Path) -> (Child, ChildStdout) {
    let exe = std::env::current_exe().unwrap();
    let mut child = Command::new(exe)
        .args(["--exact", name, "--nocapture", "--test-threads=1"])
        .env(env, db)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let stdout = child.stdout.take().unwrap();
    (child, stdout)
}

#[test]
fn kill9_leaves_consistent_prefix() {
    let dir = TempDir::new("kill9");
    let db = dir.db();
    let mut previous = 0;
    for round in 0..3 {
        let (mut child, stdout) = spawn_writer("child_writer", CHILD_ENV, &db);
        let mut lines = BufReader::new(stdout).lines();
        loop {
            match lines.next() {
                // libtest prints "test child_writer ... " before the body runs.
                Some(Ok(line)) if line.trim_end().ends_with(READY) => break,
                Some(Ok(_)) => {}
                other => {
                    let _ = child.kill();
                    let _ = child.wait();
                    panic!("child ended before it was ready: {other:?}");
                }
            }
        }
        std::thread::sleep(Duration::from_millis(200));
        child.kill().unwrap(); // SIGKILL on Unix
        let status = child.wait().unwrap();
        assert!(!status.success(), "round {round}: child was not killed");

        let j = Journal::open(&db).unwrap();
        assert!(j.integrity_check().unwrap(), "round {round}");
        let n = check_prefix(&j);
        let last = j.trial(KILL_RUN, n as u64).unwrap().map(|t| t.state);
        println!("round {round}: {n} trials, last {last:?}");
        assert!(
            n > previous,
            "round {round}: no progress ({n} trials, {previous} before)"
        );
        previous = n;
    }
}

#[test]
fn planner_state_is_kept_per_run_replaced_and_reopened() {
    let dir = TempDir::new("planner-state");
    let db = dir.db();
    {
        let mut j = Journal::open(&db).unwrap();
        j.create_run(&run_record(RUN)).unwrap();
        j.create_run(&run_record("other")).unwrap();
        assert_eq!(j.planner_state(RUN).unwrap(), None);
        j.set_planner_state(RUN, &[1, 2, 3], 10).unwrap();
        j.set_planner_state(RUN, &[4, 5], 20).unwrap();
        j.set_planner_state("other", &[], 30).unwrap();
        assert_eq!(j.planner_state(RUN).unwrap(), Some(vec![4, 5]));
        let err = j.set_planner_state("nobody", &[1], 40).unwrap_err();
        assert!(matches!(err, JournalError::UnknownRun(_)), "{err}");
    }
    let j = Journal::open(&db).unwrap();
    assert_eq!(j.planner_state(RUN).unwrap(), Some(vec![4, 5]));
    assert_eq!(j.planner_state("other").unwrap(), Some(vec![]));
    assert_eq!(j.planner_state("nobody").unwrap(), None);
}

#[test]
fn only_a_run_without_trials_is_removed_for_a_fresh_start() {
    let mut j = Journal::open_in_memory().unwrap();
    j.create_run(&run_record(RUN)).unwrap();
    j.create_run(&run_record("started")).unwrap();
    j.set_planner_state(RUN, &[1, 2], 10).unwrap();
    j.write_issue(&issue("started", 1, 1, "w1", 100)).unwrap();
    // A run with a trial, and one never recorded, stay as they are.
    assert!(!j.remove_unstarted_run("started").unwrap());
    assert!(!j.remove_unstarted_run("nobody").unwrap());
    assert_eq!(j.trials("started").unwrap().len(), 1);
    // The run without trials goes, with its planner state; it can be created again with
    // another config and other parameter names.
    assert!(j.remove_unstarted_run(RUN).unwrap());
    assert!(j.run(RUN).unwrap().is_none());
    assert_eq!(j.planner_state(RUN).unwrap(), None);
    let other = RunRow {
        config_json: "{}".into(),
        param_names: vec!["x".into()],
        ..run_record(RUN)
    };
    j.create_run(&other).unwrap();
    assert_eq!(j.run(RUN).unwrap().unwrap().param_names, ["x"]);
    assert!(j.integrity_check().unwrap());
}

#[test]
fn a_version_1_journal_is_upgraded_in_place_with_its_trials() {
    let dir = TempDir::new("upgrade");
    let db = dir.db();
    {
        let mut j = Journal::open(&db).unwrap();
        j.create_run(&run_record(RUN)).unwrap();
        j.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
        j.write_result(&result(RUN, 1, 1, "w1", 200, 0.5)).unwrap();
    }
    // Version 1 is version 3 without the planner_state table and the forces column.
    {
        let raw = rusqlite::Connection::open(&db).unwrap();
        raw.execute_batch(
            "DROP TABLE planner_state; ALTER TABLE trials DROP COLUMN forces_json;
             PRAGMA user_version = 1",
        )
        .unwrap();
    }
    let mut j = Journal::open(&db).unwrap();
    let version: i64 = rusqlite::Connection::open(&db)
        .unwrap()
        .query_row("PRAGMA user_version", [], |r| r.get(0))
        .unwrap();
    assert_eq!(version, SCHEMA_VERSION);
    assert_eq!(j.trials(RUN).unwrap()[0].score, Some(0.5));
    assert_eq!(j.planner_state(RUN).unwrap(), None);
    j.set_planner_state(RUN, &[9], 300).unwrap();
    drop(j);
    assert_eq!(
        Journal::open(&db).unwrap().planner_state(RUN).unwrap(),
        Some(vec![9])
    );
}

#[test]
fn a_journal_without_a_metric_column_gains_it_and_reads_the_metric_as_missing() {
    // A journal written before the last metric of the table existed.
    let dir = TempDir::new("metric-column");
    let db = dir.db();
    let newest = graspopt_quality::metrics::TABLE.last().unwrap().key;
    {
        let mut j = Journal::open(&db).unwrap();
        j.create_run(&run_record(RUN)).unwrap();
        j.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
        j.write_result(&result(RUN, 1, 1, "w1", 200, 0.5)).unwrap();
    }
    {
        let raw = rusqlite::Connection::open(&db).unwrap();
        raw.execute_batch(&format!("ALTER TABLE trials DROP COLUMN {newest}"))
            .unwrap();
    }
    let j = Journal::open_existing(&db).unwrap();
    let t = j.trial(RUN, 1).unwrap().unwrap();
    let m = t.metrics.unwrap();
    assert_eq!(m.get(newest), None);
    assert_eq!(m, metrics_for(1));
    let raw = rusqlite::Connection::open(&db).unwrap();
    let has: bool = raw
        .query_row(
            "SELECT count(*) FROM pragma_table_info('trials') WHERE name = ?1",
            [newest],
            |r| r.get(0),
        )
        .unwrap();
    assert!(has, "the column is added back when the journal is opened");
}
