//! Several writes in one transaction (`Journal::record`): the same rows as the writes one
//! by one, a refused write refused alone, and whole batches or nothing after a kill -9.

use std::io::{BufRead, BufReader, Write as _};
use std::path::Path;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use graspopt_journal::{
    Journal, JournalError, ResultOutcome, StoredTrialPhase, Write, Written, event_kind,
};

use super::{
    RUN, TempDir, bits, issue, journal_with_run, kinds, params_for, result, run_record, score_for,
    spawn_writer,
};

/// A batch with every kind of write, two of them refused (a NaN parameter, a failure of an
/// unknown trial is not recorded).
fn mixed_batch() -> Vec<Write> {
    let mut bad = issue(RUN, 2, 1, "w2", 10);
    bad.params[1] = f64::NAN;
    vec![
        Write::Issue(issue(RUN, 1, 1, "w1", 10)),
        Write::Issue(bad),
        Write::Issue(issue(RUN, 3, 1, "w3", 10)),
        Write::Result(Box::new(result(RUN, 1, 1, "w1", 20, score_for(1)))),
        Write::Failure {
            trial_id: 99,
            attempt: 1,
            error: "never issued".into(),
            at_ms: 20,
        },
        Write::Failure {
            trial_id: 3,
            attempt: 1,
            error: "the hand dropped it".into(),
            at_ms: 21,
        },
        Write::Result(Box::new(result(RUN, 1, 1, "w1", 22, score_for(1)))),
        Write::PlannerState {
            engine: vec![1, 2, 3],
            at_ms: 23,
        },
    ]
}

#[test]
fn a_batch_refuses_a_write_alone_and_commits_the_rest() {
    let mut j = journal_with_run();
    let outcomes = j.write(RUN, &mixed_batch()).unwrap();
    assert_eq!(outcomes.len(), 8);
    assert!(matches!(outcomes[0], Ok(Written::Issue)));
    assert!(
        matches!(&outcomes[1], Err(JournalError::NonFinite { field }) if field == "params[1]"),
        "{:?}",
        outcomes[1]
    );
    assert!(matches!(outcomes[2], Ok(Written::Issue)));
    assert!(matches!(
        outcomes[3],
        Ok(Written::Result(ResultOutcome::Accepted))
    ));
    assert!(matches!(outcomes[4], Ok(Written::Failure(false))));
    assert!(matches!(outcomes[5], Ok(Written::Failure(true))));
    assert!(matches!(
        outcomes[6],
        Ok(Written::Result(ResultOutcome::Duplicate))
    ));
    assert!(matches!(outcomes[7], Ok(Written::PlannerState)));

    let trials = j.trials(RUN).unwrap();
    let states: Vec<(u64, StoredTrialPhase)> =
        trials.iter().map(|t| (t.trial_id, t.state)).collect();
    assert_eq!(
        states,
        [
            (1, StoredTrialPhase::Completed),
            (3, StoredTrialPhase::Failed)
        ],
        "trial 2 was refused and left nothing"
    );
    assert_eq!(j.planner_state(RUN).unwrap(), Some(vec![1, 2, 3]));
    let events = j.events(RUN).unwrap();
    assert_eq!(
        kinds(&events),
        [
            event_kind::ISSUED,
            event_kind::ISSUED,
            event_kind::RESULT,
            event_kind::FAILED,
            event_kind::DUPLICATE
        ]
    );
}

#[test]
fn a_batch_leaves_the_journal_its_writes_one_by_one_leave() {
    let mut batched = journal_with_run();
    batched.write(RUN, &mixed_batch()).unwrap();
    let mut single = journal_with_run();
    for write in mixed_batch() {
        let _ = match write {
            Write::Issue(i) => single.write_issue(&i).map(|_| ()),
            Write::Result(r) => single.write_result(&r).map(|_| ()),
            Write::Failure {
                trial_id,
                attempt,
                error,
                at_ms,
            } => single
                .write_failure(RUN, trial_id, attempt, &error, at_ms)
                .map(|_| ()),
            Write::PlannerState { engine, at_ms } => single.set_planner_state(RUN, &engine, at_ms),
        };
    }
    assert_eq!(batched.trials(RUN).unwrap(), single.trials(RUN).unwrap());
    assert_eq!(batched.events(RUN).unwrap(), single.events(RUN).unwrap());
    assert_eq!(
        batched.planner_state(RUN).unwrap(),
        single.planner_state(RUN).unwrap()
    );
}

#[test]
fn a_batch_of_an_unknown_run_writes_nothing() {
    let mut j = journal_with_run();
    let outcomes = j
        .write("nobody", &[Write::Issue(issue("nobody", 1, 1, "w", 0))])
        .unwrap();
    assert!(matches!(&outcomes[0], Err(JournalError::UnknownRun(r)) if r == "nobody"));
    assert!(j.trials(RUN).unwrap().is_empty());
}

const BATCH_CHILD_ENV: &str = "JOURNAL_BATCH_CHILD_DB";
const BATCH_RUN: &str = "batch-kill-run";
/// Trials per batch, as a coordinator with 32 workers issues them.
const WIDTH: u64 = 32;

/// Not a test on its own: the child process of `kill9_mid_batch_leaves_whole_batches`.
/// It writes like a coordinator with 32 workers: each batch records the results of the
/// trials running and issues the next 32 (one of its writes refused), and only after the
/// commit prints `sent N` (the commands of trials up to N go out).
#[test]
fn batch_child_writer() {
    let Ok(path) = std::env::var(BATCH_CHILD_ENV) else {
        return;
    };
    let mut j = Journal::open(Path::new(&path)).unwrap();
    j.create_run(&run_record(BATCH_RUN)).unwrap();
    let mut issued = j.max_trial_id(BATCH_RUN).unwrap().unwrap_or(0);
    let mut running: Vec<u64> = j
        .trials(BATCH_RUN)
        .unwrap()
        .iter()
        .filter(|t| t.state == StoredTrialPhase::Running)
        .map(|t| t.trial_id)
        .collect();
    let mut out = std::io::stdout();
    writeln!(out, "sent {issued}").unwrap();
    let deadline = Instant::now() + Duration::from_secs(30);
    while Instant::now() < deadline {
        let mut batch: Vec<Write> = running
            .iter()
            .map(|&t| Write::Result(Box::new(result(BATCH_RUN, t, 1, "child", 0, score_for(t)))))
            .collect();
        let mut refused = issue(BATCH_RUN, issued + 1, 1, "child", 0);
        refused.params[0] = f64::INFINITY;
        batch.push(Write::Issue(refused));
        running = (issued + 1..=issued + WIDTH).collect();
        batch.extend(
            running
                .iter()
                .map(|&t| Write::Issue(issue(BATCH_RUN, t, 1, "child", 0))),
        );
        let outcomes = j.write(BATCH_RUN, &batch).unwrap();
        assert_eq!(outcomes.iter().filter(|o| o.is_err()).count(), 1);
        issued += WIDTH;
        writeln!(out, "sent {issued}").unwrap();
        out.flush().unwrap();
    }
    panic!("batch child writer was not killed within 30 s");
}

#[test]
fn kill9_mid_batch_leaves_whole_batches() {
    let dir = TempDir::new("kill9-batch");
    let db = dir.db();
    let mut previous = 0;
    // Kills at moments spread over a batch's duration (a batch takes about a millisecond).
    for (round, delay_us) in [150_000u64, 150_300, 150_700, 151_100, 151_900, 153_100]
        .into_iter()
        .enumerate()
    {
        let (mut child, stdout) = spawn_writer("batch::batch_child_writer", BATCH_CHILD_ENV, &db);
        let (tx, rx) = mpsc::channel();
        let reader = std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if let Some(n) = line
                    .trim_start_matches("test batch::batch_child_writer ... ")
                    .strip_prefix("sent ")
                {
                    let _ = tx.send(n.trim().parse::<u64>().unwrap());
                }
            }
        });
        // The first line says the child is ready.
        let start = rx.recv_timeout(Duration::from_secs(30)).unwrap();
        assert_eq!(
            start, previous,
            "round {round}: the child starts where the journal is"
        );
        // Its first batch committed (so every round makes progress, however loaded the
        // machine), the kill comes at a moment spread over the batches that follow.
        let first = rx.recv_timeout(Duration::from_secs(30)).unwrap();
        assert_eq!(first, start + WIDTH, "round {round}");
        std::thread::sleep(Duration::from_micros(delay_us));
        child.kill().unwrap(); // SIGKILL on Unix
        let status = child.wait().unwrap();
        assert!(!status.success(), "round {round}: child was not killed");
        reader.join().unwrap();
        let sent = rx.try_iter().last().unwrap_or(start);

        let j = Journal::open(&db).unwrap();
        assert!(j.integrity_check().unwrap(), "round {round}");
        let trials = j.trials(BATCH_RUN).unwrap();
        let n = trials.len() as u64;
        // Whole batches: the trials are 1..=n with n a multiple of the width, the last
        // batch's trials running and every earlier one completed by its result.
        assert_eq!(n % WIDTH, 0, "round {round}: {n} trials, not whole batches");
        assert!(
            n >= sent,
            "round {round}: trials up to {sent} were sent, {n} recorded"
        );
        for (i, t) in trials.iter().enumerate() {
            let id = i as u64 + 1;
            assert_eq!(t.trial_id, id);
            assert_eq!(bits(&t.params), bits(&params_for(id)));
            let expected = if id + WIDTH > n {
                StoredTrialPhase::Running
            } else {
                StoredTrialPhase::Completed
            };
            assert_eq!(t.state, expected, "round {round}: trial {id} of {n}");
            if expected == StoredTrialPhase::Completed {
                assert_eq!(t.score.map(f64::to_bits), Some(score_for(id).to_bits()));
            }
        }
        let events = j.events(BATCH_RUN).unwrap();
        let completed = n.saturating_sub(WIDTH);
        assert_eq!(events.len() as u64, n + completed, "round {round}: events");
        println!("round {round}: killed after {delay_us} us, {sent} sent, {n} recorded");
        assert!(
            n > previous,
            "round {round}: no progress ({n}, {previous} before)"
        );
        previous = n;
    }
}
