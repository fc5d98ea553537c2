//! The life of a trial in the journal: issue, result (exactly once), re-issue, failure,
//! validation and durability across reopening.

use super::*;

#[test]
fn issue_result_round_trip() {
    let mut j = journal_with_run();
    let mut iss = issue(RUN, 1, 1, "worker-1", 2_000);
    iss.params = vec![0.1 + 0.2, 5e-324, -0.0];
    j.write_issue(&iss).unwrap();

    let running = j.trial(RUN, 1).unwrap().unwrap();
    assert_eq!(running.state, StoredTrialPhase::Running);
    assert_eq!(running.attempts, 1);
    assert_eq!(running.worker, "worker-1");
    assert_eq!(running.issued_ms, 2_000);
    assert_eq!(running.lease_until_ms, 32_000);
    assert_eq!(running.score, None);
    assert_eq!(running.metrics, None);
    assert_eq!(running.completed_ms, None);
    assert_eq!(bits(&running.params), bits(&[0.1 + 0.2, 5e-324, -0.0]));
    assert!(running.params[2].is_sign_negative());

    let res = result(RUN, 1, 1, "worker-1", 2_500, 0.734_251_998_123_456_7);
    assert_eq!(j.write_result(&res).unwrap(), ResultOutcome::Accepted);

    let row = j.trial(RUN, 1).unwrap().unwrap();
    let expected = TrialRow {
        run_id: RUN.to_string(),
        trial_id: 1,
        state: StoredTrialPhase::Completed,
        attempts: 1,
        params: iss.params.clone(),
        worker: "worker-1".to_string(),
        issued_ms: 2_000,
        lease_until_ms: 32_000,
        completed_ms: Some(2_500),
        result_attempt: Some(1),
        score: Some(0.734_251_998_123_456_7),
        metrics: Some(metrics_for(1)),
        contacts: 7,
        fingers_in_contact: 3,
        cloud_points: 4096,
        details_json: Some(r#"{"trial":1,"note":"ok"}"#.to_string()),
        error: None,
        forces: None,
    };
    assert_eq!(row, expected);
    assert_eq!(bits(&row.params), bits(&iss.params));
    let m = row.metrics.as_ref().unwrap();
    let want = metrics_for(1);
    assert_eq!(
        m.real("epsilon").unwrap().to_bits(),
        want.real("epsilon").unwrap().to_bits()
    );
    assert_eq!(
        m.real("bw").unwrap().to_bits(),
        want.real("bw").unwrap().to_bits()
    );
    assert_eq!(
        m.real("volume").unwrap().to_bits(),
        want.real("volume").unwrap().to_bits()
    );

    // Metrics absent, and metrics with no volume, read back as such.
    j.write_issue(&issue(RUN, 2, 1, "worker-2", 3_000)).unwrap();
    let mut r2 = result(RUN, 2, 1, "worker-2", 3_100, -1.5);
    r2.metrics = None;
    j.write_result(&r2).unwrap();
    j.write_issue(&issue(RUN, 3, 1, "worker-2", 3_200)).unwrap();
    let mut r3 = result(RUN, 3, 1, "worker-2", 3_300, f64::MAX);
    r3.metrics.as_mut().unwrap().set("volume", None);
    j.write_result(&r3).unwrap();
    assert_eq!(j.trial(RUN, 2).unwrap().unwrap().metrics, None);
    assert_eq!(j.trial(RUN, 2).unwrap().unwrap().score, Some(-1.5));
    assert_eq!(j.trial(RUN, 3).unwrap().unwrap().metrics, r3.metrics);
    assert_eq!(j.trial(RUN, 3).unwrap().unwrap().score, Some(f64::MAX));

    let events = j.events(RUN).unwrap();
    assert_eq!(
        kinds(&events),
        ["issued", "result", "issued", "result", "issued", "result"]
    );
    assert_eq!(
        events[1],
        EventRow {
            seq: events[1].seq,
            run_id: RUN.to_string(),
            trial_id: 1,
            attempt: 1,
            kind: event_kind::RESULT.to_string(),
            worker: "worker-1".to_string(),
            at_ms: 2_500,
            note: None,
        }
    );
    assert!(events.windows(2).all(|w| w[0].seq < w[1].seq));
    assert_eq!(j.trial(RUN, 4).unwrap(), None);
}

#[test]
fn exactly_once_duplicate_result() {
    let mut j = journal_with_run();
    j.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
    let first = result(RUN, 1, 1, "w1", 200, 0.5);
    let mut second = result(RUN, 1, 1, "w1", 300, 0.9);
    second.contacts = 1;
    assert_eq!(j.write_result(&first).unwrap(), ResultOutcome::Accepted);
    let after_first = j.trial(RUN, 1).unwrap().unwrap();
    assert_eq!(j.write_result(&second).unwrap(), ResultOutcome::Duplicate);
    let after_second = j.trial(RUN, 1).unwrap().unwrap();
    assert_eq!(after_second, after_first);
    assert_eq!(after_second.score, Some(0.5));
    assert_eq!(after_second.completed_ms, Some(200));
    assert_eq!(after_second.contacts, 7);

    let events = j.events(RUN).unwrap();
    assert_eq!(kinds(&events), ["issued", "result", "duplicate"]);
    assert_eq!(events[2].at_ms, 300);
    assert_eq!(events[2].attempt, 1);
    assert!(
        events[2].note.as_deref().unwrap().contains("attempt 1"),
        "{:?}",
        events[2].note
    );
    assert_eq!(
        j.counts(RUN).unwrap(),
        StateCounts {
            running: 0,
            completed: 1,
            failed: 0
        }
    );
}

#[test]
fn unknown_trial_writes_nothing() {
    let mut j = journal_with_run();
    j.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
    let before_trials = j.trials(RUN).unwrap();
    let before_events = j.events(RUN).unwrap();

    assert_eq!(
        j.write_result(&result(RUN, 99, 1, "w1", 200, 0.5)).unwrap(),
        ResultOutcome::UnknownTrial
    );
    assert_eq!(
        j.write_result(&result("no-such-run", 1, 1, "w1", 200, 0.5))
            .unwrap(),
        ResultOutcome::UnknownTrial
    );
    assert_eq!(
        j.write_result(&result(RUN, u64::MAX, 1, "w1", 200, 0.5))
            .unwrap(),
        ResultOutcome::UnknownTrial
    );
    assert!(!j.write_failure(RUN, 99, 1, "boom", 300).unwrap());
    assert!(!j.write_failure("no-such-run", 1, 1, "boom", 300).unwrap());

    assert_eq!(j.trials(RUN).unwrap(), before_trials);
    assert_eq!(j.events(RUN).unwrap(), before_events);
    assert_eq!(j.trials(RUN).unwrap().len(), 1);
    assert_eq!(j.events(RUN).unwrap().len(), 1);
    assert_eq!(j.runs().unwrap().len(), 1);
}

#[test]
fn reissue_then_late_result_accepted_once() {
    let mut j = journal_with_run();
    j.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
    let mut re = issue(RUN, 1, 2, "w2", 40_000);
    re.reason = Some("lease expired (w1 silent)".to_string());
    j.write_issue(&re).unwrap();

    let row = j.trial(RUN, 1).unwrap().unwrap();
    assert_eq!(row.state, StoredTrialPhase::Running);
    assert_eq!(row.attempts, 2);
    assert_eq!(row.worker, "w2");
    assert_eq!(row.issued_ms, 100, "issued_ms is the first issue");
    assert_eq!(row.lease_until_ms, 70_000);

    let events = j.events(RUN).unwrap();
    assert_eq!(kinds(&events), ["issued", "reissued"]);
    assert_eq!(events[1].attempt, 2);
    assert_eq!(events[1].worker, "w2");
    assert_eq!(events[1].at_ms, 40_000);
    assert_eq!(events[1].note.as_deref(), Some("lease expired (w1 silent)"));

    // The late result of attempt 1 arrives: the work was done, accept it.
    let late = result(RUN, 1, 1, "w1", 41_000, 0.25);
    assert_eq!(j.write_result(&late).unwrap(), ResultOutcome::Accepted);
    let done = j.trial(RUN, 1).unwrap().unwrap();
    assert_eq!(done.state, StoredTrialPhase::Completed);
    assert_eq!(done.attempts, 2);
    assert_eq!(done.result_attempt, Some(1));
    assert_eq!(done.worker, "w1");
    assert_eq!(done.score, Some(0.25));

    // Attempt 2's result, and a repeat of attempt 1's, are duplicates.
    let current = result(RUN, 1, 2, "w2", 42_000, 0.75);
    assert_eq!(j.write_result(&current).unwrap(), ResultOutcome::Duplicate);
    assert_eq!(j.write_result(&late).unwrap(), ResultOutcome::Duplicate);
    assert_eq!(j.trial(RUN, 1).unwrap().unwrap(), done);

    let events = j.events(RUN).unwrap();
    assert_eq!(
        kinds(&events),
        ["issued", "reissued", "result", "duplicate", "duplicate"]
    );
    assert_eq!(events[2].attempt, 1);
    assert!(events[2].note.as_deref().unwrap().contains("late"));
    assert_eq!(events[3].worker, "w2");

    // A completed trial cannot be re-issued.
    let err = j.write_issue(&issue(RUN, 1, 3, "w3", 50_000)).unwrap_err();
    assert!(
        matches!(
            err,
            JournalError::TrialClosed {
                trial_id: 1,
                state: StoredTrialPhase::Completed,
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn issue_validation() {
    let mut j = journal_with_run();
    // First issue must be attempt 1.
    let err = j.write_issue(&issue(RUN, 1, 2, "w1", 100)).unwrap_err();
    assert!(
        matches!(
            err,
            JournalError::AttemptMismatch {
                expected: 1,
                found: 2,
                ..
            }
        ),
        "{err}"
    );
    j.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
    // Re-issue must be the next attempt.
    let err = j.write_issue(&issue(RUN, 1, 3, "w2", 200)).unwrap_err();
    assert!(
        matches!(
            err,
            JournalError::AttemptMismatch {
                expected: 2,
                found: 3,
                ..
            }
        ),
        "{err}"
    );
    let err = j.write_issue(&issue(RUN, 1, 1, "w2", 200)).unwrap_err();
    assert!(matches!(err, JournalError::AttemptMismatch { .. }), "{err}");
    // Re-issue with other parameters.
    let mut other = issue(RUN, 1, 2, "w2", 200);
    other.params[0] += 1e-12;
    let err = j.write_issue(&other).unwrap_err();
    assert!(
        matches!(err, JournalError::ParamsMismatch { trial_id: 1, .. }),
        "{err}"
    );
    // Wrong number of parameters for the run.
    let mut short = issue(RUN, 2, 1, "w1", 300);
    short.params.pop();
    let err = j.write_issue(&short).unwrap_err();
    assert!(
        matches!(
            err,
            JournalError::ParamCount {
                expected: 3,
                found: 2,
                ..
            }
        ),
        "{err}"
    );
    // Unknown run.
    let err = j.write_issue(&issue("ghost", 1, 1, "w1", 300)).unwrap_err();
    assert!(
        matches!(&err, JournalError::UnknownRun(r) if r == "ghost"),
        "{err}"
    );
    // Trial ids beyond i64 are refused.
    let err = j
        .write_issue(&issue(RUN, u64::MAX, 1, "w1", 300))
        .unwrap_err();
    assert!(matches!(err, JournalError::TrialIdRange(u64::MAX)), "{err}");

    // None of the refused issues wrote anything.
    let trials = j.trials(RUN).unwrap();
    assert_eq!(trials.len(), 1);
    assert_eq!(trials[0].attempts, 1);
    assert_eq!(trials[0].worker, "w1");
    assert_eq!(kinds(&j.events(RUN).unwrap()), ["issued"]);
}

#[test]
fn failure_is_final_and_once() {
    let mut j = journal_with_run();
    j.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
    j.write_issue(&issue(RUN, 2, 1, "w2", 100)).unwrap();
    j.write_result(&result(RUN, 2, 1, "w2", 200, 0.4)).unwrap();

    assert!(
        j.write_failure(RUN, 1, 1, "hand fault: tendon 3", 300)
            .unwrap()
    );
    let failed = j.trial(RUN, 1).unwrap().unwrap();
    assert_eq!(failed.state, StoredTrialPhase::Failed);
    assert_eq!(failed.error.as_deref(), Some("hand fault: tendon 3"));
    assert_eq!(failed.score, None);
    assert_eq!(failed.completed_ms, None);

    // Failing again, or failing a completed trial, changes nothing.
    assert!(!j.write_failure(RUN, 1, 1, "second message", 400).unwrap());
    assert!(!j.write_failure(RUN, 2, 1, "too late", 400).unwrap());
    assert_eq!(j.trial(RUN, 1).unwrap().unwrap(), failed);
    assert_eq!(
        j.trial(RUN, 2).unwrap().unwrap().state,
        StoredTrialPhase::Completed
    );
    assert_eq!(j.trial(RUN, 2).unwrap().unwrap().error, None);

    // A result after the failure is a duplicate: the trial already ended.
    assert_eq!(
        j.write_result(&result(RUN, 1, 1, "w1", 500, 0.9)).unwrap(),
        ResultOutcome::Duplicate
    );
    assert_eq!(j.trial(RUN, 1).unwrap().unwrap(), failed);
    // ... and it cannot be re-issued.
    let err = j.write_issue(&issue(RUN, 1, 2, "w3", 600)).unwrap_err();
    assert!(
        matches!(
            err,
            JournalError::TrialClosed {
                state: StoredTrialPhase::Failed,
                ..
            }
        ),
        "{err}"
    );

    let events = j.events(RUN).unwrap();
    assert_eq!(
        kinds(&events),
        ["issued", "issued", "result", "failed", "duplicate"]
    );
    assert_eq!(events[3].note.as_deref(), Some("hand fault: tendon 3"));
    assert_eq!(events[3].worker, "w1");
    assert_eq!(events[4].note.as_deref(), Some("trial already failed"));
}

#[test]
fn durability_reopen_and_wal_reader() {
    let dir = TempDir::new("durable");
    let db = dir.db();
    {
        let mut writer = Journal::open(&db).unwrap();
        assert_eq!(writer.path(), Some(db.as_path()));
        writer.create_run(&run_record(RUN)).unwrap();
        writer.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
        writer
            .write_result(&result(RUN, 1, 1, "w1", 200, 0.5))
            .unwrap();

        // A second connection while the first is open sees committed rows.
        let reader = Journal::open(&db).unwrap();
        assert_eq!(reader.trials(RUN).unwrap(), writer.trials(RUN).unwrap());
        assert_eq!(reader.trial(RUN, 1).unwrap().unwrap().score, Some(0.5));

        // The file is in WAL mode, with a -wal file beside it while open.
        let raw = rusqlite::Connection::open(&db).unwrap();
        let mode: String = raw
            .query_row("PRAGMA journal_mode", [], |r| r.get(0))
            .unwrap();
        assert_eq!(mode, "wal");
        let version: i64 = raw
            .query_row("PRAGMA user_version", [], |r| r.get(0))
            .unwrap();
        assert_eq!(version, SCHEMA_VERSION);
        drop(raw);
        let mut wal = db.clone().into_os_string();
        wal.push("-wal");
        assert!(Path::new(&wal).exists());

        // Later writes by the first are seen by the open second.
        writer.write_issue(&issue(RUN, 2, 1, "w2", 300)).unwrap();
        assert_eq!(reader.trials(RUN).unwrap().len(), 2);
        assert_eq!(reader.counts(RUN).unwrap().running, 1);
        writer
            .set_run_phase(RUN, StoredRunPhase::Finished, 900)
            .unwrap();
        assert_eq!(
            reader.run(RUN).unwrap().unwrap().status,
            StoredRunPhase::Finished
        );
    }
    let reopened = Journal::open(&db).unwrap();
    assert!(reopened.integrity_check().unwrap());
    let trials = reopened.trials(RUN).unwrap();
    assert_eq!(trials.len(), 2);
    assert_eq!(trials[0].state, StoredTrialPhase::Completed);
    assert_eq!(trials[0].score, Some(0.5));
    assert_eq!(bits(&trials[0].params), bits(&params_for(1)));
    assert_eq!(trials[1].state, StoredTrialPhase::Running);
    assert_eq!(
        kinds(&reopened.events(RUN).unwrap()),
        ["issued", "result", "issued"]
    );
    let run = reopened.run(RUN).unwrap().unwrap();
    assert_eq!(
        run,
        RunRow {
            status: StoredRunPhase::Finished,
            ..run_record(RUN)
        }
    );
}
