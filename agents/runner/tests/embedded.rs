//! An embedded run, in-process: every agent on one loopback bus, no binary spawned.

use graspopt_bus::BusConfig;
use graspopt_coordinator::{CoordinatorConfig, RunSpec};
use graspopt_protocol::{PlannerMethod, RunId, RunPhase};
use graspopt_runner::{Embedded, run_embedded};
use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{Object, ParamKind, TrialSpace};
use graspopt_trial::Evaluator;

fn mug_run(out: &std::path::Path, trials: u64) -> Embedded {
    let object = Object::by_name("mug").unwrap();
    let space = TrialSpace::approach_vertical_2d(&object);
    let evaluator = Evaluator::new(object, hand_by_name("barrett").unwrap(), space);
    let run = RunId::new("inproc").unwrap();
    let bus = graspopt_runner::embedded::own_bus(BusConfig::default(), &run).unwrap();
    Embedded {
        spec: RunSpec {
            object: "mug".into(),
            hand: "barrett".into(),
            params: vec![ParamKind::Approach, ParamKind::Vertical],
            bounds: None,
            trials,
            seed: 7,
            method: PlannerMethod::Random,
            initial: None,
            settings: None,
        },
        workers: 2,
        resume: false,
        perception: graspopt_perception::PerceptionConfig {
            object: "mug".into(),
            period_ms: 200,
            ..Default::default()
        },
        metric: graspopt_metric::MetricConfig {
            score: evaluator.score,
            contacts: evaluator.contacts,
            ..Default::default()
        },
        hand: graspopt_hand::HandConfig {
            hand: "barrett".into(),
            ..Default::default()
        },
        coordinator: CoordinatorConfig {
            journal: out.join("journal.sqlite"),
            ..Default::default()
        },
        out: out.to_path_buf(),
        run,
        bus,
        evaluator,
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_embedded_run_records_every_trial_in_its_journal() {
    let dir = tempfile::tempdir().unwrap();
    let e = mug_run(dir.path(), 6);
    let status = run_embedded(&e, None).await.unwrap();
    assert_eq!(status.phase, RunPhase::Finished, "{status:?}");
    assert_eq!((status.completed, status.failed), (6, 0));
    let journal = graspopt_journal::Journal::open(&e.coordinator.journal).unwrap();
    let trials = journal.export("inproc").unwrap().trials;
    assert_eq!(trials.len(), 6);
    // Every trial was scored, and the status's best is the journal's best.
    let best = trials
        .iter()
        .filter_map(|t| t.score)
        .fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(trials.iter().filter(|t| t.score.is_some()).count(), 6);
    assert_eq!(status.best.map(|b| b.score), Some(best));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_resumed_run_restores_its_recorded_settings_and_refuses_contrary_ones() {
    use graspopt_runner::RunSettings;
    use graspopt_sim::ContactModel;
    use graspopt_trial::TrialSettings;

    let dir = tempfile::tempdir().unwrap();
    let first = RunSettings {
        run: "again".into(),
        trial: TrialSettings {
            contacts: ContactModel::CircularPatch,
            ..TrialSettings::default()
        },
        workers: 1,
        trials: 3,
        method: PlannerMethod::Random,
        seed: 3,
        out: Some(dir.path().to_path_buf()),
        ..RunSettings::default()
    };
    let e = first.embedded().unwrap();
    let status = run_embedded(&e, None).await.unwrap();
    assert_eq!((status.phase, status.completed), (RunPhase::Finished, 3));

    // Resumed with the defaults and a larger budget: the record wins where nothing was given.
    let again = RunSettings {
        trials: 5,
        resume: true,
        out: Some(dir.path().to_path_buf()),
        ..RunSettings::default()
    };
    let given = |name: &str| name == "trials";
    let e = again.resolve(&given).unwrap();
    assert_eq!(e.run.as_str(), "again");
    assert_eq!(e.metric.score.contacts, ContactModel::CircularPatch);
    assert_eq!((e.workers, e.spec.trials, e.spec.seed), (1, 5, 3));
    assert_eq!(e.spec.method, PlannerMethod::Random);
    let status = run_embedded(&e, None).await.unwrap();
    assert_eq!((status.phase, status.completed), (RunPhase::Finished, 5));

    // A contact model given explicitly that contradicts the record is refused by name.
    let contrary = RunSettings {
        trial: TrialSettings {
            contacts: ContactModel::MeanPoint,
            ..TrialSettings::default()
        },
        ..again.clone()
    };
    let err = contrary
        .resolve(&|name| name == "contacts")
        .err()
        .expect("a contrary contact model must be refused");
    let msg = graspopt_runner::error::chain(&err);
    assert!(
        msg.contains("--contacts mean") && msg.contains("patch"),
        "{msg}"
    );

    // A new run in the same folder would overwrite the recorded one's files.
    let other = RunSettings {
        run: "other".into(),
        out: Some(dir.path().to_path_buf()),
        ..RunSettings::default()
    };
    let msg = graspopt_runner::error::chain(&other.embedded().err().expect("the folder is taken"));
    assert!(msg.contains("holds run \"again\" already"), "{msg}");
}

/// A lease of 0 (every trial expired at once) or beyond a week (the millisecond clock's
/// arithmetic would overflow) is refused by its flag's name before anything is written.
#[test]
fn a_lease_out_of_range_is_refused_by_name() {
    use graspopt_runner::RunSettings;

    for lease_ms in [0, u64::MAX, graspopt_coordinator::MAX_WAIT_MS + 1] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("run");
        let settings = RunSettings {
            lease_ms,
            out: Some(out.clone()),
            ..RunSettings::default()
        };
        let msg = graspopt_runner::error::chain(&settings.embedded().err().expect("refused"));
        assert_eq!(
            msg,
            format!("--lease-ms is {lease_ms}: it must be between 1 and 604800000 (a week)")
        );
        assert!(!out.exists(), "a refused run wrote {}", out.display());
    }
    let settings = RunSettings {
        lease_ms: graspopt_coordinator::MAX_WAIT_MS,
        out: Some(tempfile::tempdir().unwrap().path().join("run")),
        ..RunSettings::default()
    };
    assert!(settings.embedded().is_ok());
    // A budget past a billion trials is a typo (2^64 - 1 ran until killed).
    for trials in [0, u64::MAX] {
        let settings = RunSettings {
            trials,
            out: Some(tempfile::tempdir().unwrap().path().join("run")),
            ..RunSettings::default()
        };
        let msg = graspopt_runner::error::chain(&settings.embedded().err().expect("refused"));
        assert_eq!(
            msg,
            format!("--trials is {trials}: it must be between 1 and 1000000000")
        );
    }
    // A trial longer than its lease would be re-issued forever.
    let settings = RunSettings {
        trial_cost_ms: 40_000,
        out: Some(tempfile::tempdir().unwrap().path().join("run")),
        ..RunSettings::default()
    };
    let msg = graspopt_runner::error::chain(&settings.embedded().err().expect("refused"));
    assert!(
        msg.starts_with(
            "--trial-cost-ms 40000 is not shorter than the lease of a trial (--lease-ms 30000)"
        ),
        "{msg}"
    );
}

/// A run's ranges reach its planner and its journal; resumed, the run keeps them (its
/// evaluator too, which draws the pictures), and a contrary range is refused by name.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_run_records_its_ranges_and_a_resumed_run_keeps_them() {
    use graspopt_runner::RunSettings;
    use graspopt_sim::ParamSpec;
    use graspopt_trial::TrialSettings;

    let dir = tempfile::tempdir().unwrap();
    let rz = ParamSpec::parse_range("rz=-3:3").unwrap();
    let first = RunSettings {
        run: "turns".into(),
        trial: TrialSettings {
            object: "cylinder".into(),
            ranges: vec![rz],
            ..TrialSettings::default()
        },
        params: vec![ParamKind::Approach, ParamKind::RotZ],
        workers: 1,
        trials: 4,
        method: PlannerMethod::Random,
        seed: 5,
        out: Some(dir.path().to_path_buf()),
        ..RunSettings::default()
    };
    let e = first.embedded().unwrap();
    let status = run_embedded(&e, None).await.unwrap();
    assert_eq!((status.phase, status.completed), (RunPhase::Finished, 4));
    let journal = graspopt_journal::Journal::open(&e.coordinator.journal).unwrap();
    let record = journal.run("turns").unwrap().unwrap();
    let spec: RunSpec = serde_json::from_str(&record.config_json).unwrap();
    assert_eq!(spec.bounds, Some(vec![[-0.16, 0.02], [-3.0, 3.0]]));
    // The planner drew rz from the range, beyond the default 45 degrees.
    let trials = journal.export("turns").unwrap().trials;
    let turns: Vec<f64> = trials.iter().map(|t| t.params[1]).collect();
    assert!(turns.iter().all(|r| r.abs() <= 3.0), "{turns:?}");
    assert!(
        turns.iter().any(|r| r.abs() > std::f64::consts::FRAC_PI_4),
        "{turns:?}"
    );
    drop(journal);

    let again = RunSettings {
        trials: 5,
        resume: true,
        out: Some(dir.path().to_path_buf()),
        ..RunSettings::default()
    };
    let e = again.resolve(&|name| name == "trials").unwrap();
    assert_eq!(e.evaluator.space.params[1], rz);
    assert_eq!(e.spec.bounds, spec.bounds);
    let contrary = RunSettings {
        trial: TrialSettings {
            ranges: vec![ParamSpec::parse_range("rz=-2:2").unwrap()],
            ..TrialSettings::default()
        },
        ..again.clone()
    };
    let msg = graspopt_runner::error::chain(
        &contrary
            .resolve(&|name| name == "range")
            .err()
            .expect("a contrary range must be refused"),
    );
    assert!(
        msg.contains("--range rz=-2:2 (the run has rz=-3:3)"),
        "{msg}"
    );
}
