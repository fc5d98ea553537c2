use super::*;
use graspopt_protocol::{RunId, TrialResult};

/// A result of attempt 1 of run `r`.
pub(crate) fn result(trial_id: u64, worker: &str, score: f64) -> TrialResult {
    TrialResult {
        run_id: RunId::new("r").unwrap(),
        trial_id,
        attempt: 1,
        worker: worker.into(),
        scorer: "m".into(),
        score,
        metrics: None,
        contacts: 1,
        fingers_in_contact: 1,
        cloud_points: 1,
        cloud_transport: String::new(),
        error: None,
        forces: None,
    }
}

/// (completed, failed, queued or running) counted over every trial, and the open set
/// checked against it.
fn scanned(s: &RunState) -> (u64, u64, u64) {
    let n = |f: fn(&TrialPhase) -> bool| s.trials.values().filter(|t| f(&t.phase)).count();
    let open: BTreeSet<u64> = s
        .trials
        .iter()
        .filter(|(_, t)| {
            matches!(
                t.phase,
                TrialPhase::Queued { .. } | TrialPhase::Running { .. }
            )
        })
        .map(|(id, _)| *id)
        .collect();
    assert_eq!(open, s.open);
    (
        n(|p| matches!(p, TrialPhase::Completed { .. })) as u64,
        n(|p| matches!(p, TrialPhase::Failed { .. })) as u64,
        open.len() as u64,
    )
}

#[test]
fn the_counts_kept_follow_every_change_of_phase() {
    let mut s = RunState::new(6);
    let counts = |s: &RunState| (s.completed(), s.failed(), s.running());
    // A resumed run: one trial completed, one failed, one running, the last replaced.
    let restored = |phase| Trial {
        params: vec![0.0],
        attempts: 1,
        issued_to: BTreeMap::from([(1, "a".to_string())]),
        phase,
    };
    s.restore_trial(1, restored(TrialPhase::Completed { score: 0.1 }));
    s.restore_trial(2, restored(TrialPhase::Failed { error: "x".into() }));
    s.restore_trial(3, restored(TrialPhase::Completed { score: 0.2 }));
    s.restore_trial(3, restored(TrialPhase::Queued { reason: None }));
    assert_eq!(counts(&s), (1, 1, 1));
    assert_eq!(counts(&s), scanned(&s));
    s.worker_up("a", "h");
    s.worker_up("b", "h");
    let t4 = s.add_trial(vec![0.4]);
    assert_eq!(s.assign(3, "a", 0, 100), Some(2));
    assert_eq!(s.assign(t4, "b", 0, 100), Some(1));
    assert_eq!(counts(&s), (1, 1, 2));
    // b is lost, a's lease expires: both trials queued, still open.
    assert_eq!(s.worker_down("b"), Some(t4));
    assert_eq!(s.expire_leases(101, 0), [3]);
    assert_eq!(s.queued().len(), 2);
    assert_eq!(counts(&s), scanned(&s));
    // Trial 3 completes (late, from a), trial 4 fails, a duplicate changes nothing.
    let mut r = result(3, "a", 0.9);
    r.attempt = 2;
    assert_eq!(s.on_result(&r, 102), Disposition::Completed);
    assert_eq!(s.on_result(&r, 103), Disposition::Duplicate);
    assert_eq!(s.assign(t4, "a", 104, 200), Some(2));
    let mut f = result(t4, "a", 0.0);
    f.attempt = 2;
    f.error = Some("unreachable".into());
    assert_eq!(s.on_result(&f, 105), Disposition::Failed);
    assert_eq!(counts(&s), (2, 2, 0));
    assert_eq!(counts(&s), scanned(&s));
    assert!(s.running_trials().is_empty() && s.pending_points().is_empty());
}

#[test]
fn a_lost_worker_trial_is_requeued_and_completed_once() {
    let mut s = RunState::new(2);
    s.worker_up("a", "h");
    s.worker_up("b", "h");
    assert_eq!(s.proposals_needed(), 2);
    let t1 = s.add_trial(vec![0.1]);
    let t2 = s.add_trial(vec![0.2]);
    assert_eq!((t1, t2), (1, 2));
    assert_eq!(s.assign(t1, "a", 0, 100), Some(1));
    assert_eq!(s.assign(t2, "b", 0, 100), Some(1));
    assert_eq!(s.proposals_needed(), 0);
    // Worker a dies holding trial 1.
    assert_eq!(s.worker_down("a"), Some(1));
    assert_eq!(s.queued().len(), 1);
    assert_eq!(s.on_result(&result(2, "b", 0.5), 0), Disposition::Completed);
    assert_eq!(s.idle_workers(), vec!["b".to_string()]);
    assert_eq!(s.assign(1, "b", 0, 200), Some(2));
    let mut r = result(1, "b", 0.7);
    r.attempt = 2;
    assert_eq!(s.on_result(&r, 0), Disposition::Completed);
    r.score = 0.9;
    assert_eq!(s.on_result(&r, 0), Disposition::Duplicate);
    assert!(s.finished());
    assert_eq!(s.completed(), 2);
    assert_eq!(s.errors.duplicates, 1);
    assert_eq!(s.errors.reissued, 1);
    assert_eq!(s.best.as_ref().unwrap().trial_id, 1);
    assert_eq!(s.best_history, vec![0.5, 0.7]);
}

#[test]
fn expired_leases_requeue_and_keep_the_slow_worker_busy() {
    let mut s = RunState::new(1);
    s.worker_up("a", "h");
    let t = s.add_trial(vec![0.0]);
    s.assign(t, "a", 0, 1000);
    assert!(s.expire_leases(999, 500).is_empty());
    assert_eq!(s.expire_leases(1001, 500), vec![t]);
    assert!(s.idle_workers().is_empty());
    // The slow worker's late result still completes the trial.
    assert_eq!(s.on_result(&result(t, "a", 1.0), 0), Disposition::Completed);
    assert!(s.finished());
    assert_eq!(s.on_result(&result(42, "a", 1.0), 0), Disposition::Unknown);
    assert_eq!(s.errors.unknown_trial, 1);
}

#[test]
fn a_silent_worker_is_freed_after_the_grace_and_gets_the_trial_again() {
    let mut s = RunState::new(1);
    s.worker_up("only", "h");
    let t = s.add_trial(vec![0.0]);
    assert_eq!(s.assign(t, "only", 0, 1000), Some(1));
    assert_eq!(s.expire_leases(1001, 500), vec![t]);
    // Still busy during the grace...
    assert!(s.expire_leases(1400, 500).is_empty());
    assert!(s.idle_workers().is_empty());
    // ...then free: the lone worker takes its trial again (attempt 2).
    assert!(s.expire_leases(1502, 500).is_empty());
    assert_eq!(s.idle_workers(), ["only"]);
    assert_eq!(s.assign(t, "only", 0, 3000), Some(2));
    assert_eq!(
        s.on_result(&result(t, "only", 0.5), 0),
        Disposition::Completed
    );
    assert!(s.finished());
}

#[test]
fn a_result_is_accepted_only_from_the_worker_and_attempt_issued() {
    let mut s = RunState::new(1);
    s.worker_up("a", "h");
    s.worker_up("b", "h");
    let t = s.add_trial(vec![0.0]);
    assert_eq!(s.assign(t, "a", 0, 1000), Some(1));
    // Another worker, an attempt never issued, a trial never proposed.
    assert_eq!(s.on_result(&result(t, "b", 9.0), 0), Disposition::NotIssued);
    let mut r = result(t, "a", 9.0);
    r.attempt = 2;
    assert_eq!(s.on_result(&r, 0), Disposition::NotIssued);
    assert_eq!(s.on_result(&result(7, "a", 9.0), 0), Disposition::Unknown);
    assert_eq!((s.errors.not_issued, s.errors.unknown_trial), (2, 1));
    // Worker a still holds its trial; its own result completes it.
    assert!(s.idle_workers() == ["b"]);
    assert_eq!(s.on_result(&result(t, "a", 0.5), 0), Disposition::Completed);
    assert_eq!(s.best.as_ref().unwrap().score, 0.5);
}

#[test]
fn trials_orphaned_by_the_metric_agent_are_requeued_when_it_is_back() {
    let mut s = RunState::new(4);
    s.grace_ms = 60_000;
    s.worker_up("a", "h");
    s.worker_up("b", "h");
    s.worker_up("c", "h");
    // One trial took 100 ms: a typical trial.
    let t0 = s.add_trial(vec![0.0]);
    s.assign(t0, "c", 0, 60_000);
    assert_eq!(
        s.on_result(&result(t0, "c", 0.1), 100),
        Disposition::Completed
    );
    let t1 = s.add_trial(vec![0.1]);
    let t2 = s.add_trial(vec![0.2]);
    let t3 = s.add_trial(vec![0.3]);
    s.assign(t1, "a", 1000, 61_000);
    s.assign(t2, "b", 1000, 61_000);
    s.assign(t3, "c", 1150, 61_150);
    let orphaned = s.running_trials();
    assert_eq!(orphaned, [t1, t2, t3]);
    // Trial 2's result made it before the metric agent went away.
    assert_eq!(
        s.on_result(&result(t2, "b", 0.5), 1100),
        Disposition::Completed
    );
    // Back at 1250: a is done with trial 1 (issued at 1000, 2 x 100 ms); c may still be
    // executing trial 3 until 1350.
    assert_eq!(s.requeue_orphaned(&orphaned, 1250), [t1]);
    assert_eq!(s.idle_workers(), ["a", "b"]);
    assert!(s.expire_leases(1300, 60_000).is_empty());
    assert_eq!(s.expire_leases(1351, 60_000), [t3]);
    assert_eq!(s.idle_workers(), ["a", "b", "c"]);
    assert_eq!(s.assign(t1, "b", 1400, 61_400), Some(2));
    // The first attempt's result, late, still counts.
    assert_eq!(
        s.on_result(&result(t1, "a", 0.7), 1500),
        Disposition::Completed
    );
    assert_eq!(s.errors.reissued, 2);
}

#[test]
fn a_late_failure_does_not_beat_a_live_attempt_and_other_holders_are_freed() {
    let mut s = RunState::new(1);
    s.grace_ms = 100;
    s.worker_up("a", "h");
    s.worker_up("b", "h");
    let t = s.add_trial(vec![0.0]);
    s.assign(t, "a", 0, 1000);
    assert_eq!(s.expire_leases(1001, 100), vec![t]);
    assert_eq!(s.assign(t, "b", 0, 5000), Some(2));
    // Attempt 1 reports a failure late: ignored, a is free again, b goes on.
    let mut late = result(t, "a", 0.0);
    late.error = Some("invalid contact clouds".into());
    assert_eq!(s.on_result(&late, 1050), Disposition::StaleFailure);
    assert_eq!(s.idle_workers(), ["a"]);
    // Attempt 1 succeeding instead would complete the trial, and b, which can only
    // produce a duplicate now, is freed after the grace.
    let mut s2 = s.clone();
    assert_eq!(
        s2.on_result(&result(t, "a", 0.4), 1060),
        Disposition::Completed
    );
    assert!(s2.expire_leases(1100, 100).is_empty());
    assert_eq!(s2.idle_workers(), ["a"]);
    s2.expire_leases(1161, 100);
    assert_eq!(s2.idle_workers(), ["a", "b"]);
    // In s, b's own result completes the trial.
    let mut r = result(t, "b", 0.6);
    r.attempt = 2;
    assert_eq!(s.on_result(&r, 1100), Disposition::Completed);
    assert_eq!(s.errors.failed, 0);
}

#[test]
fn failures_count_against_the_budget() {
    let mut s = RunState::new(1);
    s.worker_up("a", "h");
    let t = s.add_trial(vec![0.0]);
    s.assign(t, "a", 0, 10);
    let mut r = result(t, "a", 0.0);
    r.error = Some("unreachable".into());
    assert_eq!(s.on_result(&r, 0), Disposition::Failed);
    assert!(s.finished());
    assert!(s.observations.is_empty());
}
