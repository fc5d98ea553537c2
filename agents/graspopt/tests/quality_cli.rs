//! `graspopt quality` as users run it: the reference file, both formats, bad input.

use std::path::PathBuf;
use std::process::Output;

use serde_json::Value;

mod support;
use support::{graspopt, tempdir};

fn reference_file() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/metric-cases.json")
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-7 || (a - b).abs() <= 1e-6 * b.abs()
}

#[test]
fn reference_file_matches_expected_values() {
    let path = reference_file();
    let out = graspopt(&[
        "quality",
        "--input",
        path.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let cases = doc["cases"].as_array().unwrap();
    let stdout = String::from_utf8(out.stdout).unwrap();
    let rows: Vec<Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(rows.len(), cases.len());
    for (i, (row, case)) in rows.iter().zip(cases).enumerate() {
        let e = &case["expected"];
        assert_eq!(row["rank"], e["rank"], "case {i}");
        assert_eq!(row["force_closure"], e["force_closure"], "case {i}");
        for key in ["epsilon", "volume", "distance", "bw"] {
            let (a, b) = (row[key].as_f64().unwrap(), e[key].as_f64().unwrap());
            assert!(close(a, b), "case {i} {key}: {a} vs {b}");
        }
    }
    // Keys in the documented order.
    assert!(stdout.starts_with("{\"rank\":"), "{}", &stdout[..60]);
}

#[test]
fn timing_and_table_output() {
    let dir = tempdir("timing");
    let file = dir.join("two.json");
    std::fs::write(
        &file,
        r#"{"cases": [
            {"wrenches": [[1,0,0,0,0,0],[-1,0,0,0,0,0],[0,1,0,0,0,0],[0,-1,0,0,0,0],
                          [0,0,1,0,0,0],[0,0,-1,0,0,0],[0,0,0,1,0,0],[0,0,0,-1,0,0],
                          [0,0,0,0,1,0],[0,0,0,0,-1,0],[0,0,0,0,0,1],[0,0,0,0,0,-1]]},
            {"params": {"model": "point_friction", "mu": 0.5, "edges": 8},
             "contacts": [{"position": [1,0,0], "normal": [-1,0,0]}],
             "wrenches": [[9,9,9,9,9,9]]}
        ]}"#,
    )
    .unwrap();
    let out = graspopt(&["quality", "--input", file.to_str().unwrap(), "--timing"]);
    assert!(out.status.success());
    let rows: Vec<Value> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert!((rows[0]["epsilon"].as_f64().unwrap() - 1.0 / 6f64.sqrt()).abs() < 1e-12);
    assert!(rows[0]["micros"].as_f64().unwrap() > 0.0);
    // Contacts win over wrenches: one contact at distance 1.
    assert!((rows[1]["bw"].as_f64().unwrap() + 1.0).abs() < 1e-12);
    let out = graspopt(&[
        "quality",
        "--input",
        file.to_str().unwrap(),
        "--format",
        "table",
    ]);
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3);
    assert!(
        lines[0].contains("epsilon") && lines[2].contains("-1.000000000e0"),
        "{text}"
    );
}

#[test]
fn bad_cases_name_the_case_and_field_and_the_rest_still_run() {
    let dir = tempdir("bad");
    let file = dir.join("bad.json");
    let good = r#"{"params": {"model": "frictionless"}, "contacts": [{"position": [0,1,0], "normal": [0,-1,0]}]}"#;
    let cases = [
        good.to_string(),
        r#"{"params": {"model": "point_friction", "mu": -1, "edges": 8}, "contacts": [{"position": [0,1,0], "normal": [0,-1,0]}]}"#.into(),
        r#"{"params": {"model": "point_friction", "mu": 0.5, "edges": 2}, "contacts": [{"position": [0,1,0], "normal": [0,-1,0]}]}"#.into(),
        r#"{"params": {"model": "soft_finger", "mu": 0.5, "edges": 8}, "contacts": [{"position": [0,1,0], "normal": [0,-1,0]}]}"#.into(),
        r#"{"params": {"model": "frictionless"}, "contacts": [{"position": [0,1,0], "normal": [0,0,0]}]}"#.into(),
        r#"{"params": {"model": "frictionless"}, "contacts": [{"position": [0,1], "normal": [0,-1,0]}]}"#.into(),
        r#"{"params": {"model": "frictionless"}, "contacts": []}"#.into(),
        r#"{"params": {"model": "frictionless", "torque_scale": 0}, "contacts": [{"position": [0,1,0], "normal": [0,-1,0]}]}"#.into(),
        r#"{"wrenches": [[1,2,3]]}"#.into(),
        r#"{"params": {"model": "frictionless"}, "contacts": [{"position": [0,1,0], "normal": [0,-2,0]}]}"#.into(),
        r#"{"params": {"model": "sticky"}, "contacts": []}"#.into(),
        r#"{"params": {"model": "frictionless"}, "contacts": [{"position": [0,1e999,0], "normal": [0,-1,0]}]}"#.into(),
        good.to_string(),
    ];
    std::fs::write(&file, format!("{{\"cases\": [{}]}}", cases.join(","))).unwrap();
    let out = graspopt(&["quality", "--input", file.to_str().unwrap()]);
    let stderr = String::from_utf8(out.stderr).unwrap();
    let stdout = String::from_utf8(out.stdout).unwrap();
    if stderr.contains("is not valid JSON") {
        // serde_json refuses 1e999: drop that case and try again.
        let cases: Vec<String> = cases
            .iter()
            .filter(|c| !c.contains("1e999"))
            .cloned()
            .collect();
        std::fs::write(&file, format!("{{\"cases\": [{}]}}", cases.join(","))).unwrap();
        return check_bad_output(
            &graspopt(&["quality", "--input", file.to_str().unwrap()]),
            false,
        );
    }
    check_bad_output(
        &Output {
            status: out.status,
            stdout: stdout.into(),
            stderr: stderr.into(),
        },
        true,
    );
}

fn check_bad_output(out: &Output, with_infinity: bool) {
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let rows: Vec<Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let n = if with_infinity { 13 } else { 12 };
    assert_eq!(rows.len(), n);
    assert!((rows[0]["bw"].as_f64().unwrap() + 1.0).abs() < 1e-12);
    assert!((rows[n - 1]["bw"].as_f64().unwrap() + 1.0).abs() < 1e-12);
    let expect = [
        (1, "case 1: params: mu = -1 is invalid"),
        (2, "case 2: params: edges = 2 is invalid"),
        (3, "case 3: params.gamma: missing"),
        (4, "case 4: contacts: contact 0: normal is zero"),
        (5, "case 5: contacts[0].position: expected 3 numbers, got 2"),
        (6, "case 6: contacts: no contacts given"),
        (7, "case 7: params: torque_scale = 0 is invalid"),
        (8, "case 8: wrenches[0]: expected 6 numbers, got 3"),
        (9, "case 9: contacts: contact 0: normal has length 2"),
        (10, "case 10: params.model: unknown model \"sticky\""),
    ];
    for (i, text) in expect {
        let message = rows[i]["error"].as_str().unwrap_or_default();
        assert!(message.starts_with(text), "row {i}: {message}");
        assert!(stderr.contains(text), "stderr lacks {text}: {stderr}");
    }
    if with_infinity {
        let message = rows[11]["error"].as_str().unwrap_or_default();
        assert!(
            message.contains("case 11") && message.contains("not finite"),
            "{message}"
        );
    }
    assert!(
        stderr.contains(&format!("{} of {n} cases failed", n - 2)),
        "{stderr}"
    );
}

#[test]
fn unreadable_input_is_a_clear_error() {
    let out = graspopt(&["quality", "--input", "/nonexistent/cases.json"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot read /nonexistent/cases.json"));
    let dir = tempdir("garbage");
    let file = dir.join("garbage.json");
    std::fs::write(&file, "{\"cases\": [1, 2").unwrap();
    let out = graspopt(&["quality", "--input", file.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("is not valid JSON"));
    std::fs::write(&file, "[]").unwrap();
    let out = graspopt(&["quality", "--input", file.to_str().unwrap()]);
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("expected an object with a `cases` array")
    );
}
