use graspopt_journal::{Journal, StoredRunPhase, TrialIssue};
use graspopt_protocol::{RunId, TrialResult};
use graspopt_sim::Object;

use super::*;
use crate::state::Disposition;

/// A one-parameter run of `trials` random trials on the sphere (the crate's test run).
pub(crate) fn spec(trials: u64) -> RunSpec {
    RunSpec {
        object: "sphere".into(),
        hand: "barrett".into(),
        params: vec![ParamKind::Approach],
        bounds: None,
        trials,
        seed: 1,
        method: PlannerMethod::Random,
        initial: None,
        settings: None,
    }
}

#[test]
fn resuming_keeps_the_record_names_contradicting_flags_and_may_raise_the_budget() {
    let run = RunId::new("r").unwrap();
    let recorded = spec(20);
    let given = RunSpec {
        object: "mug".into(),
        seed: 4,
        ..spec(10)
    };
    // Flags left at their defaults are not contradictions: the record wins.
    let none = |_: &str| false;
    assert_eq!(reconcile(&run, &recorded, &given, &none).unwrap(), recorded);
    // Given explicitly, they are, each named with both values.
    let all = |_: &str| true;
    let e = reconcile(&run, &recorded, &given, &all)
        .unwrap_err()
        .to_string();
    for part in [
        "--object mug (the run has sphere)",
        "--seed 4 (the run has 1)",
        "--trials 10 (the run has a budget of 20",
    ] {
        assert!(e.contains(part), "{part:?} not in {e}");
    }
    assert!(!e.contains("--hand"), "{e}");
    // A larger budget is taken; the rest stays recorded.
    let trials_only = |f: &str| f == "trials";
    let raised = reconcile(&run, &recorded, &spec(35), &trials_only).unwrap();
    assert_eq!(raised.trials, 35);
    assert_eq!(
        RunSpec {
            trials: 20,
            ..raised
        },
        recorded
    );
}

#[test]
fn open_run_raises_a_finished_runs_budget() {
    let mut journal = Journal::open_in_memory().unwrap();
    let run = RunId::new("r").unwrap();
    // Resuming a run never recorded starts it (a supervised restart's command line).
    let (started, _) = open_run(&mut journal, &run, &spec(5), true).unwrap();
    assert_eq!(started.trials, 5);
    journal
        .set_run_phase("r", StoredRunPhase::Finished, 10)
        .unwrap();
    let (resumed, state) = open_run(&mut journal, &run, &spec(8), true).unwrap();
    assert_eq!(resumed.trials, 8);
    assert!(!state.finished());
    let record = journal.run("r").unwrap().unwrap();
    assert_eq!(record.status, StoredRunPhase::Running);
    let stored: RunSpec = serde_json::from_str(&record.config_json).unwrap();
    assert_eq!(stored.trials, 8);
    // The same budget again (or less) leaves the record as it is.
    let (again, _) = open_run(&mut journal, &run, &spec(3), true).unwrap();
    assert_eq!(again.trials, 8);
}

/// A resumed run gives the planner its observations in the order their results were
/// recorded, also when they were recorded in the same millisecond.
#[test]
fn a_resumed_run_keeps_the_order_results_were_recorded_in() {
    let mut journal = Journal::open_in_memory().unwrap();
    let run = RunId::new("r").unwrap();
    let spec = spec(5);
    open_run(&mut journal, &run, &spec, false).unwrap();
    for id in 1..=4 {
        journal
            .write_issue(&TrialIssue {
                params: vec![0.01 * id as f64],
                ..issue(id)
            })
            .unwrap();
    }
    // Recorded in one millisecond, in another order than the trial ids.
    for id in [3, 1, 4, 2] {
        let r = crate::state::tests::result(id, "a", 0.1 * id as f64);
        journal
            .write_result(&crate::core::journal_result(&r, 50))
            .unwrap();
    }
    let (_, state) = open_run(&mut journal, &run, &spec, true).unwrap();
    let order: Vec<(f64, f64)> = state.observations().iter().map(|o| (o.x[0], o.y)).collect();
    let recorded = [3, 1, 4, 2].map(|id: u64| (0.01 * id as f64, 0.1 * id as f64));
    assert_eq!(order, recorded);
}

/// A standalone coordinator's new run records its bounds (a range in place of its
/// parameter's default); resumed, it keeps them, and a range that contradicts them is
/// refused with the recorded one.
#[test]
fn a_run_records_its_ranges_and_a_contrary_range_is_refused_on_resume() {
    let dir = tempfile::tempdir().unwrap();
    let config = crate::CoordinatorConfig {
        journal: dir.path().join("journal.sqlite"),
        ..Default::default()
    };
    let sphere = Object::by_name("sphere").unwrap();
    let rz = ParamSpec::parse_range("rz=-3:3").unwrap();
    let given = RunSpec {
        params: vec![ParamKind::Approach, ParamKind::RotZ],
        ..spec(4)
    };
    let none = |_: &str| false;
    let (run, started) =
        standalone_run("r", &config, given.clone(), &sphere, &[rz], false, &none).unwrap();
    let approach = TrialSpace::full_6d(&sphere).params[0];
    assert_eq!(
        started.bounds,
        Some(vec![[approach.lower, approach.upper], [-3.0, 3.0]])
    );
    assert_eq!(started.ranges()[1], rz);
    let mut journal = Journal::open(&config.journal).unwrap();
    open_run(&mut journal, &run, &started, false).unwrap();
    drop(journal);
    // Resumed without ranges, or with the recorded one: the record's bounds.
    let range = |f: &str| f == "range";
    for ranges in [&[][..], &[rz][..]] {
        let (_, resumed) =
            standalone_run("r", &config, given.clone(), &sphere, ranges, true, &range).unwrap();
        assert_eq!(resumed.bounds, started.bounds);
    }
    let other = ParamSpec::parse_range("rz=-2:2").unwrap();
    let lateral = ParamSpec::parse_range("lateral=-0.1:0.1").unwrap();
    let e = standalone_run(
        "r",
        &config,
        given,
        &sphere,
        &[other, lateral],
        true,
        &range,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("--range rz=-2:2 (the run has rz=-3:3)"), "{e}");
    assert!(
        e.contains("--range lateral=-0.1:0.1 (the run's parameters are approach, rz)"),
        "{e}"
    );
    // A run recorded before runs recorded their bounds has the simulator's defaults.
    let old = spec(4);
    assert_eq!(
        range_conflicts(&old, &[ParamSpec::parse_range("x=-0.1:0").unwrap()]),
        ["--range approach=-0.1:0 (the run has the simulator's default range of approach)"]
    );
    assert!(old.ranges().is_empty());
}

/// A trial issued for run `r`, attempt 1.
fn issue(trial_id: u64) -> TrialIssue {
    TrialIssue {
        run_id: "r".into(),
        trial_id,
        attempt: 1,
        params: vec![0.01],
        worker: "a".into(),
        at_ms: 10,
        lease_until_ms: 1000,
        reason: None,
    }
}

/// A run stopped before its first trial (a wrong address) is started afresh by the same
/// command, with the settings given now; once a trial is issued, it must be resumed.
#[test]
fn a_run_without_trials_starts_afresh_and_one_with_trials_must_be_resumed() {
    let mut journal = Journal::open_in_memory().unwrap();
    let run = RunId::new("r").unwrap();
    open_run(&mut journal, &run, &spec(5), false).unwrap();
    journal.set_planner_state("r", &[1, 2, 3], 5).unwrap();
    journal
        .set_run_phase("r", StoredRunPhase::Stopped, 10)
        .unwrap();
    let (again, state) = open_run(&mut journal, &run, &spec(7), false).unwrap();
    assert_eq!(again, spec(7));
    assert_eq!(state.trial_count(), 0);
    let record = journal.run("r").unwrap().unwrap();
    assert_eq!(record.status, StoredRunPhase::Running);
    assert_eq!(
        serde_json::from_str::<RunSpec>(&record.config_json).unwrap(),
        spec(7)
    );
    assert_eq!(journal.planner_state("r").unwrap(), None);
    journal.write_issue(&issue(1)).unwrap();
    let e = open_run(&mut journal, &run, &spec(7), false).unwrap_err();
    let e = e.to_string();
    assert!(
        e.contains("run \"r\" already exists") && e.contains("with 1 trial:"),
        "{e}"
    );
    assert!(e.contains("--resume"), "{e}");
    assert_eq!(journal.trials("r").unwrap().len(), 1);
}

/// A coordinator restarted with `--resume` still accepts the late result of an attempt
/// issued before the restart (who got each attempt comes back from the journal's events).
#[test]
fn a_resumed_run_accepts_results_of_attempts_issued_before_the_restart() {
    let mut journal = Journal::open_in_memory().unwrap();
    let run = RunId::new("r").unwrap();
    let spec = spec(2);
    open_run(&mut journal, &run, &spec, false).unwrap();
    for (attempt, worker) in [(1, "a"), (2, "b")] {
        journal
            .write_issue(&TrialIssue {
                attempt,
                worker: worker.into(),
                at_ms: 10 * attempt as i64,
                ..issue(1)
            })
            .unwrap();
    }
    let (_, mut state) = open_run(&mut journal, &run, &spec, true).unwrap();
    let result = |attempt: u32, worker: &str| TrialResult {
        attempt,
        ..crate::state::tests::result(1, worker, 0.5)
    };
    assert!(!state.was_issued(&result(1, "b")));
    assert!(state.was_issued(&result(2, "b")));
    assert_eq!(state.on_result(&result(1, "a"), 0), Disposition::Completed);
}
