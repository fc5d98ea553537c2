//! The CSV and JSON exports of a run: fields, quoting, the metric columns of the metric
//! table, and a JSON export that parses back.

use graspopt_journal::RunExport;
use graspopt_journal::export::{write_csv, write_json};
use graspopt_quality::metrics::TABLE;

use super::{
    RUN, bits, issue, journal_with_run, metrics_for, params_for, parse_csv, result, run_record,
};

#[test]
fn csv_export_fields() {
    let mut j = journal_with_run();
    j.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
    j.write_result(&result(RUN, 1, 1, "w1", 250, 0.1 + 0.2))
        .unwrap();
    j.write_issue(&issue(RUN, 2, 1, "w,2", 300)).unwrap();
    let message = "hand error: finger 2, \"jammed\" at 3 N";
    assert!(j.write_failure(RUN, 2, 1, message, 400).unwrap());
    j.write_issue(&issue(RUN, 3, 1, "w3", 500)).unwrap();
    let mut r3 = result(RUN, 3, 1, "w3", 600, 1.0);
    r3.metrics = None;
    j.write_result(&r3).unwrap();
    j.write_issue(&issue(RUN, 4, 1, "w4", 700)).unwrap();

    let mut out = Vec::new();
    write_csv(&j, RUN, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    // The message is quoted and its quotes doubled, per RFC 4180.
    assert!(
        text.contains(r#","hand error: finger 2, ""jammed"" at 3 N""#),
        "{text}"
    );
    assert!(text.contains(r#","w,2","#), "{text}");

    let records = parse_csv(&text);
    assert_eq!(records.len(), 5, "{text}");
    // The metric columns are the metric table's keys, in its order.
    let mut header = vec![
        "trial",
        "state",
        "attempts",
        "worker",
        "issued_ms",
        "completed_ms",
        "approach_x",
        "roll",
        "aperture",
        "score",
    ];
    header.extend(TABLE.iter().map(|d| d.key));
    header.extend([
        "contacts",
        "fingers_in_contact",
        "cloud_points",
        "can_resist",
        "resisting_force",
        "resisting_max",
        "net_force",
        "min_slip_margin",
        "forces_unavailable",
        "error",
    ]);
    assert_eq!(
        &header[10..16],
        [
            "rank",
            "force_closure",
            "epsilon",
            "volume",
            "distance",
            "bw"
        ]
    );
    assert_eq!(records[0], header);
    assert!(
        records.iter().all(|r| r.len() == header.len()),
        "{records:?}"
    );
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let f64_at = |rec: &[String], i: usize| rec[i].parse::<f64>().unwrap().to_bits();

    let done = &records[1];
    assert_eq!(&done[..6], ["1", "completed", "1", "w1", "100", "250"]);
    for (k, p) in params_for(1).iter().enumerate() {
        assert_eq!(
            f64_at(done, 6 + k),
            p.to_bits(),
            "param {k}: {}",
            done[6 + k]
        );
    }
    let m = metrics_for(1);
    assert_eq!(f64_at(done, 9), (0.1f64 + 0.2).to_bits());
    assert_eq!(done[col("rank")], "6");
    assert_eq!(done[col("force_closure")], "false");
    for key in ["epsilon", "volume", "distance", "bw"] {
        assert_eq!(f64_at(done, col(key)), m.real(key).unwrap().to_bits());
    }
    let counts = col("contacts");
    assert_eq!(
        &done[counts..],
        ["7", "3", "4096", "", "", "", "", "", "", ""]
    );

    let failed = &records[2];
    assert_eq!(&failed[..6], ["2", "failed", "1", "w,2", "300", ""]);
    assert!(
        failed[9..col("error")].iter().all(String::is_empty),
        "{failed:?}"
    );
    assert_eq!(failed[col("error")], message);

    let no_metrics = &records[3];
    assert_eq!(no_metrics[9], "1.0");
    assert!(
        no_metrics[10..counts].iter().all(String::is_empty),
        "{no_metrics:?}"
    );
    assert_eq!(
        &no_metrics[counts..],
        ["7", "3", "4096", "", "", "", "", "", "", ""]
    );

    let running = &records[4];
    assert_eq!(&running[..6], ["4", "running", "1", "w4", "700", ""]);
    assert!(running[9..].iter().all(String::is_empty), "{running:?}");
}

#[test]
fn csv_export_leaves_out_a_volume_no_trial_has() {
    // Runs not scored by the volume never compute it: no always-empty column.
    let mut j = journal_with_run();
    j.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
    let mut r1 = result(RUN, 1, 1, "w1", 250, 0.5);
    r1.metrics.as_mut().unwrap().set("volume", None);
    j.write_result(&r1).unwrap();
    j.write_issue(&issue(RUN, 2, 1, "w2", 300)).unwrap();
    let mut out = Vec::new();
    write_csv(&j, RUN, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    let records = parse_csv(&text);
    assert_eq!(records.len(), 3, "{text}");
    assert!(!records[0].contains(&"volume".to_string()), "{text}");
    // 20 columns besides the metrics', and every metric but the volume.
    let width = 20 + TABLE.len() - 1;
    assert!(records.iter().all(|r| r.len() == width), "{records:?}");
    let column = |name: &str| records[0].iter().position(|h| h == name).unwrap();
    let m = metrics_for(1);
    assert_eq!(
        records[1][column("epsilon")],
        format!("{:?}", m.real("epsilon").unwrap())
    );
    assert_eq!(
        records[1][column("distance")],
        format!("{:?}", m.real("distance").unwrap())
    );
    assert_eq!(records[1][column("contacts")], "7");
    assert!(
        records[2][column("score")..column("error")]
            .iter()
            .all(String::is_empty)
    );
}

#[test]
fn json_export_parses_back() {
    let mut j = journal_with_run();
    j.write_issue(&issue(RUN, 1, 1, "w1", 100)).unwrap();
    j.write_result(&result(RUN, 1, 1, "w1", 250, 0.1 + 0.2))
        .unwrap();
    j.write_issue(&issue(RUN, 2, 1, "w2", 300)).unwrap();
    j.write_failure(RUN, 2, 1, "hand error, \"jammed\"", 400)
        .unwrap();

    let mut out = Vec::new();
    write_json(&j, RUN, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains("\n  \"run\": {"), "pretty: {text}");

    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(value["run"]["run_id"], RUN);
    assert_eq!(value["run"]["status"], "running");
    assert_eq!(value["trials"][0]["state"], "completed");
    assert_eq!(value["trials"][1]["state"], "failed");
    assert_eq!(value["trials"].as_array().unwrap().len(), 2);

    let back: RunExport = serde_json::from_str(&text).unwrap();
    assert_eq!(back.run, run_record(RUN));
    assert_eq!(back.trials, j.trials(RUN).unwrap());
    assert_eq!(
        bits(&back.trials[0].params),
        bits(&params_for(1)),
        "exact f64 through JSON"
    );
    assert_eq!(
        back.trials[0].score.unwrap().to_bits(),
        (0.1f64 + 0.2).to_bits()
    );
}
