//! Each trial's contact-force analysis: stored with its result, read back, exported, and
//! absent from journals written before it existed.

use graspopt_journal::export::{write_csv, write_json};
use graspopt_journal::{ForceAnalysis, Journal, JournalError, SCHEMA_VERSION};

use super::{RUN, TempDir, issue, result, run_record};

fn analysis() -> ForceAnalysis {
    ForceAnalysis {
        external: [0.0, 0.0, -4.905, 0.0, 0.0, 0.0],
        resisting_norm: Some(5.5),
        resisting_max: Some(3.25),
        net_wrench: Some([3.0, 0.0, 4.0, 0.0, 0.0, 0.0]),
        slip_margins: vec![0.5, -0.125, 2.0],
        unavailable: None,
    }
}

/// Why the least forces of a trial were unavailable, as the solver reports it.
const UNAVAILABLE: &str = "the conic solver stopped without an answer in each of the 4 ways it was tried (as posed: InsufficientProgress; scaled to a unit load: NumericalError)";

#[test]
fn a_result_keeps_its_force_analysis_and_the_csv_shows_it() {
    let mut j = Journal::open_in_memory().unwrap();
    j.create_run(&run_record(RUN)).unwrap();
    for t in 1..=3 {
        j.write_issue(&issue(RUN, t, 1, "w1", 100)).unwrap();
    }
    let mut with = result(RUN, 1, 1, "w1", 200, 0.5);
    with.forces = Some(analysis());
    j.write_result(&with).unwrap();
    let mut cannot = result(RUN, 2, 1, "w1", 300, -0.25);
    cannot.forces = Some(ForceAnalysis {
        resisting_norm: None,
        resisting_max: None,
        net_wrench: None,
        slip_margins: Vec::new(),
        ..analysis()
    });
    j.write_result(&cannot).unwrap();
    // The least forces unknown: the score stands, the measured forces too.
    let unknown = ForceAnalysis {
        resisting_norm: None,
        resisting_max: None,
        unavailable: Some(UNAVAILABLE.into()),
        ..analysis()
    };
    let mut unavailable = result(RUN, 3, 1, "w1", 400, 0.125);
    unavailable.forces = Some(unknown.clone());
    j.write_result(&unavailable).unwrap();
    assert_eq!(j.trial(RUN, 1).unwrap().unwrap().forces, Some(analysis()));
    assert_eq!(j.trial(RUN, 3).unwrap().unwrap().forces, Some(unknown));
    assert_eq!(j.trial(RUN, 3).unwrap().unwrap().score, Some(0.125));

    let mut csv = Vec::new();
    write_csv(&j, RUN, &mut csv).unwrap();
    let csv = String::from_utf8(csv).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |row: &str, name: &str| {
        let i = header.iter().position(|h| *h == name).unwrap();
        row.split(',').nth(i).unwrap().to_string()
    };
    let (first, second, third) = (
        lines.next().unwrap(),
        lines.next().unwrap(),
        lines.next().unwrap(),
    );
    assert_eq!(column(first, "can_resist"), "true");
    assert_eq!(column(first, "resisting_force"), "5.5");
    assert_eq!(column(first, "resisting_max"), "3.25");
    assert_eq!(column(first, "net_force"), "5.0");
    assert_eq!(column(first, "min_slip_margin"), "-0.125");
    assert_eq!(column(second, "can_resist"), "false");
    assert_eq!(column(second, "resisting_force"), "");
    assert_eq!(column(second, "net_force"), "");
    assert_eq!(column(first, "forces_unavailable"), "");
    assert_eq!(column(second, "forces_unavailable"), "");
    // Unavailable: neither "can" nor "cannot", the reason in its column.
    assert_eq!(column(third, "score"), "0.125");
    assert_eq!(column(third, "can_resist"), "");
    assert_eq!(column(third, "resisting_force"), "");
    assert_eq!(column(third, "resisting_max"), "");
    assert_eq!(column(third, "net_force"), "5.0");
    assert_eq!(column(third, "forces_unavailable"), UNAVAILABLE);

    let mut json = Vec::new();
    write_json(&j, RUN, &mut json).unwrap();
    let json: serde_json::Value = serde_json::from_slice(&json).unwrap();
    assert_eq!(json["trials"][0]["forces"]["resisting_norm"], 5.5);
    assert_eq!(
        json["trials"][1]["forces"]["resisting_norm"],
        serde_json::Value::Null
    );
    assert_eq!(json["trials"][2]["forces"]["unavailable"], UNAVAILABLE);
    assert_eq!(
        json["trials"][0]["forces"]["unavailable"],
        serde_json::Value::Null
    );
}

#[test]
fn a_non_finite_force_is_refused_and_nothing_is_written() {
    let mut j = Journal::open_in_memory().unwrap();
    j.create_run(&run_record(RUN)).unwrap();
    j.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
    let mut bad = result(RUN, 1, 1, "w1", 200, 0.5);
    bad.forces = Some(ForceAnalysis {
        slip_margins: vec![1.0, f64::NAN],
        ..analysis()
    });
    let err = j.write_result(&bad).unwrap_err();
    assert!(matches!(err, JournalError::Invalid(_)), "{err}");
    assert!(err.to_string().contains("forces.slip_margins[1]"), "{err}");
    assert_eq!(j.trial(RUN, 1).unwrap().unwrap().score, None);
}

#[test]
fn a_version_2_journal_is_upgraded_and_its_trials_have_no_forces() {
    let dir = TempDir::new("upgrade-v2");
    let db = dir.db();
    {
        let mut j = Journal::open(&db).unwrap();
        j.create_run(&run_record(RUN)).unwrap();
        j.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
        j.write_result(&result(RUN, 1, 1, "w1", 200, 0.5)).unwrap();
        j.write_issue(&issue(RUN, 2, 1, "w1", 100)).unwrap();
    }
    // Version 2 is version 3 without the forces column.
    {
        let raw = rusqlite::Connection::open(&db).unwrap();
        raw.execute_batch("ALTER TABLE trials DROP COLUMN forces_json; PRAGMA user_version = 2")
            .unwrap();
    }
    let mut j = Journal::open(&db).unwrap();
    let version: i64 = rusqlite::Connection::open(&db)
        .unwrap()
        .query_row("PRAGMA user_version", [], |r| r.get(0))
        .unwrap();
    assert_eq!(version, SCHEMA_VERSION);
    let first = j.trial(RUN, 1).unwrap().unwrap();
    assert_eq!((first.score, first.forces), (Some(0.5), None));
    let mut with = result(RUN, 2, 1, "w1", 300, 0.75);
    with.forces = Some(analysis());
    j.write_result(&with).unwrap();
    drop(j);
    let j = Journal::open(&db).unwrap();
    assert_eq!(j.trial(RUN, 2).unwrap().unwrap().forces, Some(analysis()));
}
