//! `graspopt quality` as users run it: the reference file, both formats, bad input.

use std::path::PathBuf;
use std::process::Output;

use serde_json::Value;

use crate::scratch::Scratch;
use crate::support::{graspopt, graspopt_ok, tempdir};

fn reference_file() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/metric-cases.json")
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-7 || (a - b).abs() <= 1e-6 * b.abs()
}

#[test]
fn reference_file_matches_expected_values() {
    let path = reference_file();
    let out = graspopt_ok(&[
        "quality",
        "--input",
        path.to_str().unwrap(),
        "--format",
        "json",
    ]);
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
        (
            5,
            "case 5: contacts[0].position: invalid length 2, expected an array of length 3",
        ),
        (6, "case 6: contacts: no contacts given"),
        (7, "case 7: params: torque_scale = 0 is invalid"),
        (
            8,
            "case 8: wrenches[0]: invalid length 3, expected an array of length 6",
        ),
        (9, "case 9: contacts: contact 0: normal has length 2"),
        (10, "case 10: params.model: unknown variant `sticky`"),
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

/// Writes `cases` (JSON objects) as a quality input file in a fresh folder.
/// (The folder is deleted when the first value is dropped.)
fn case_file(name: &str, cases: &[&str]) -> (Scratch, PathBuf) {
    let dir = tempdir(name);
    let file = dir.join("cases.json");
    std::fs::write(&file, format!("{{\"cases\": [{}]}}", cases.join(","))).unwrap();
    (dir, file)
}

/// Runs `graspopt quality` on `file` with extra arguments: exit code, JSON rows, stderr.
fn quality(file: &std::path::Path, extra: &[&str]) -> (Option<i32>, Vec<Value>, String) {
    let mut args = vec!["quality", "--input", file.to_str().unwrap()];
    args.extend_from_slice(extra);
    let out = graspopt(&args);
    let stdout = String::from_utf8(out.stdout).unwrap();
    let rows = stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    (
        out.status.code(),
        rows,
        String::from_utf8(out.stderr).unwrap(),
    )
}

const TRIANGLE: &str = r#"[{"position": [1,0,0], "normal": [-1,0,0]},
    {"position": [-0.5,0.8660254037844386,0], "normal": [0.5,-0.8660254037844386,0]},
    {"position": [-0.5,-0.8660254037844386,0], "normal": [0.5,0.8660254037844386,0]}]"#;

#[test]
fn huge_counts_and_magnitudes_are_errors_with_both_solvers() {
    let edges = format!(
        r#"{{"params": {{"model": "point_friction", "mu": 0.5, "edges": 100000000}}, "contacts": {TRIANGLE}}}"#
    );
    let mu = format!(
        r#"{{"params": {{"model": "point_friction", "mu": 1e308, "edges": 8}}, "contacts": {TRIANGLE}}}"#
    );
    let soft = format!(
        r#"{{"params": {{"model": "soft_finger", "mu": 0.5, "edges": 5000, "gamma": 0.1}}, "contacts": {TRIANGLE}}}"#
    );
    let rho = format!(
        r#"{{"params": {{"model": "point_friction", "mu": 0.5, "edges": 8, "torque_scale": 1e-300}}, "contacts": {TRIANGLE}}}"#
    );
    let good = format!(
        r#"{{"params": {{"model": "point_friction", "mu": 0.5, "edges": 8}}, "contacts": {TRIANGLE}}}"#
    );
    let (_dir, file) = case_file(
        "huge",
        &[
            &edges,
            &mu,
            r#"{"wrenches": [[1e308,0,0,0,0,0],[-1e308,0,0,0,0,0],[0,1,0,0,0,0],[0,-1,0,0,0,0]]}"#,
            &soft,
            &rho,
            &good,
        ],
    );
    let expect = [
        "case 0: params: edges = 100000000 is invalid: the friction cone needs at least 3 and at most 4096 edges",
        "case 1: params: mu = 1e308 is invalid: the friction coefficient must be finite, >= 0 and <= 1e6",
        "case 2: wrenches: wrench 0: component 0 = 1e308 is out of range: each component must be at most 1e12 in absolute value",
        "case 3: params: edges = 5000 is invalid",
        "case 4: contacts: contact 0: its wrench component",
    ];
    for solver in ["min-norm", "clarabel"] {
        let (code, rows, stderr) = quality(&file, &["--solver", solver]);
        assert_eq!(code, Some(1), "{solver}: {stderr}");
        assert_eq!(rows.len(), 6);
        for (i, text) in expect.iter().enumerate() {
            let message = rows[i]["error"].as_str().unwrap_or_default();
            assert!(message.starts_with(text), "{solver} row {i}: {message}");
            assert!(stderr.contains(text), "{solver}: {stderr}");
        }
        // The good case is evaluated (the 8-edge equator grasp, mu 0.5) and nothing
        // prints as null.
        assert!((rows[5]["epsilon"].as_f64().unwrap() - 0.275925156).abs() < 1e-8);
        for row in &rows {
            let nulls = row.as_object().unwrap().values().filter(|v| v.is_null());
            assert_eq!(nulls.count(), 0, "{solver}: {row}");
        }
        assert!(stderr.contains("5 of 6 cases failed"), "{stderr}");
    }
}

#[test]
fn unknown_fields_are_errors_and_descriptive_keys_are_accepted() {
    let contact = r#"{"position": [1,0,0], "normal": [-1,0,0]}"#;
    let (_dir, file) = case_file(
        "unknown",
        &[
            &format!(
                r#"{{"params": {{"model": "point_friction", "mu": 0.5, "edges": 8, "torque_scal": 5}}, "contacts": [{contact}]}}"#
            ),
            &format!(
                r#"{{"params": {{"model": "frictionless"}}, "contacts": [{contact}], "wrench": [[1,0,0,0,0,0]]}}"#
            ),
            r#"{"params": {"model": "frictionless"}, "contacts": [{"position": [1,0,0], "normal": [-1,0,0], "force": 2}]}"#,
            r#"{"params": {"model": "frictionless", "edge": 8}, "wrenches": [[1,0,0,0,0,0]]}"#,
            // Descriptive keys (as in the reference file: kind, expected) and keys the
            // model does not use (gamma of a point contact) are accepted.
            &format!(
                r#"{{"kind": "one_contact", "name": "one", "description": "d", "notes": "n", "comment": "c",
                    "expected": {{"bw": -1}},
                    "params": {{"model": "point_friction", "mu": 0.5, "edges": 8, "gamma": 0.2,
                                "reference_point": [0,0,0], "torque_scale": 2}},
                    "contacts": [{contact}]}}"#
            ),
        ],
    );
    let (code, rows, stderr) = quality(&file, &[]);
    assert_eq!(code, Some(1));
    let expect = [
        "case 0: params.torque_scal: unknown field `torque_scal`, expected one of `model`, `mu`, `edges`, `gamma`, `reference_point`, `torque_scale`",
        "case 1: wrench: unknown field `wrench`, expected one of `params`, `contacts`, `wrenches`, `expected`, `kind`, `name`, `description`, `notes`, `comment`",
        "case 2: contacts[0].force: unknown field `force`, expected `position` or `normal`",
        "case 3: params.edge: unknown field `edge`",
    ];
    for (i, text) in expect.iter().enumerate() {
        let message = rows[i]["error"].as_str().unwrap_or_default();
        assert!(message.starts_with(text), "row {i}: {message}");
        assert!(stderr.contains(text), "{stderr}");
    }
    // One contact at distance 1 from the reference point; torque_scale 2 was used.
    assert!(
        (rows[4]["bw"].as_f64().unwrap() + 1.0).abs() < 1e-12,
        "{}",
        rows[4]
    );
    assert!(stderr.contains("4 of 5 cases failed"), "{stderr}");
}

#[test]
fn zero_is_printed_without_a_sign_and_solvers_agree_at_large_scale() {
    let (_dir, file) = case_file(
        "zero",
        &[
            // Antipodal frictionless contacts: the origin is on the hull, bw = 0.
            r#"{"params": {"model": "frictionless"}, "contacts": [
                {"position": [1,0,0], "normal": [-1,0,0]}, {"position": [-1,0,0], "normal": [1,0,0]}]}"#,
            // +-1e12 e_x, +-e_y: the origin is inside the hull (distance 0).
            r#"{"wrenches": [[1e12,0,0,0,0,0],[-1e12,0,0,0,0,0],[0,1,0,0,0,0],[0,-1,0,0,0,0]]}"#,
        ],
    );
    for solver in ["min-norm", "clarabel"] {
        let out = graspopt(&[
            "quality",
            "--input",
            file.to_str().unwrap(),
            "--solver",
            solver,
        ]);
        assert!(out.status.success(), "{solver}");
        let stdout = String::from_utf8(out.stdout).unwrap();
        assert!(!stdout.contains("-0.0"), "{solver}: {stdout}");
        let rows: Vec<Value> = stdout
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert!(
            stdout
                .lines()
                .next()
                .unwrap()
                .contains(r#""distance":0.0,"bw":0.0"#),
            "{solver}: {stdout}"
        );
        let d = rows[1]["distance"].as_f64().unwrap();
        assert!(d < 1e-3, "{solver}: distance {d}");
        assert_eq!(rows[1]["force_closure"], false);
        let out = graspopt(&[
            "quality",
            "--input",
            file.to_str().unwrap(),
            "--solver",
            solver,
            "--format",
            "table",
        ]);
        let table = String::from_utf8(out.stdout).unwrap();
        assert!(!table.contains("-0.000"), "{solver}: {table}");
    }
}

#[test]
fn a_hull_too_large_for_memory_is_refused_with_a_hint() {
    // 3 contacts x 256 edges: the full hull for the volume needs more than 5 million
    // facets (the old code used 2 GB here, and 24 GB at 1,024 edges).
    let case = format!(
        r#"{{"params": {{"model": "point_friction", "mu": 0.5, "edges": 256}}, "contacts": {TRIANGLE}}}"#
    );
    let (_dir, file) = case_file("dense", &[&case]);
    let (code, rows, stderr) = quality(&file, &[]);
    assert_eq!(code, Some(1));
    let message = rows[0]["error"].as_str().unwrap_or_default();
    assert!(
        message.starts_with(
            "case 0: the volume of 768 wrenches needs a hull of more than 5000000 facets"
        ) && message.ends_with("or pass --no-volume"),
        "{message}"
    );
    assert!(stderr.contains("more than 5000000 facets"), "{stderr}");
    let (code, rows, _) = quality(&file, &["--no-volume"]);
    assert_eq!(code, Some(0));
    assert!((rows[0]["epsilon"].as_f64().unwrap() - 0.287_685_384).abs() < 1e-8);
    assert!(rows[0]["volume"].is_null());
}
