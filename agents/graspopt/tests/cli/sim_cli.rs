//! `graspopt trial` and `graspopt scan` as users run them.

use serde_json::Value;

use crate::support::{decode_png, graspopt, graspopt_ok, tempdir};

#[test]
fn trial_prints_contacts_and_metrics() {
    let out = graspopt_ok(&[
        // x = 0.01: inside the sphere's force-closure window (+0.005 to +0.02 with the corrected
        // BH8, whose bent fingertips meet the sphere first when farther).
        "trial", "--object", "sphere", "--at", "x=0.01", "--format", "json",
    ]);
    let e: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(e["params"], serde_json::json!([0.01]));
    // The score and what it was computed from sit at the top level, not nested.
    let m = &e["metrics"];
    assert_eq!(m["force_closure"], true);
    assert!(e["score"].is_f64(), "{e}");
    assert_eq!(e["score"], m["bw"]);
    assert!(e["contacts"].as_u64().unwrap() > 0, "{e}");
    assert_eq!(e["fingers_in_contact"], 3);
    assert_eq!(e["outcome"]["fingers"].as_array().unwrap().len(), 3);
    let text = graspopt(&["trial", "--object", "sphere", "--at", "x=0.01"]);
    let text = String::from_utf8(text.stdout).unwrap();
    assert!(
        text.contains("finger 3:") && text.contains("force closure true"),
        "{text}"
    );
}

/// Every objective of the metric table is a `--metric` (the isotropy index was refused by the
/// flag's own list while the metric agents scored by it).
#[test]
fn trial_scores_by_the_isotropy_index() {
    let out = graspopt_ok(&[
        "trial", "--object", "sphere", "--at", "x=0.01", "--metric", "isotropy", "--format", "json",
    ]);
    let e: Value = serde_json::from_slice(&out.stdout).unwrap();
    let isotropy = e["metrics"]["isotropy"].as_f64().unwrap();
    assert!(isotropy > 0.0 && isotropy <= 1.0, "{e}");
    assert_eq!(e["score"], e["metrics"]["isotropy"]);
}

#[test]
fn trial_bad_input_is_named() {
    // Exit code 1: the value was parsed, and refused by the library; 2: a choice among names,
    // checked with the flags (a usage error) and listing the names.
    for (args, code, expected) in [
        (
            vec!["trial", "--object", "teapot"],
            1,
            "unknown object `teapot`",
        ),
        (
            vec!["trial", "--at", "q=1"],
            1,
            "unknown trial parameter \"q\"",
        ),
        (vec!["trial", "--at", "x=abc"], 1, "x is not a number"),
        (
            vec!["trial", "--at", "x=NaN"],
            1,
            "--at: x (approach) = NaN is not a finite number",
        ),
        (vec!["trial", "--at", "x=5"], 1, "outside"),
        (
            vec!["trial", "--mesh", "/nonexistent.stl"],
            1,
            "cannot load the mesh /nonexistent.stl",
        ),
        (
            vec!["trial", "--metric", "area"],
            2,
            "[possible values: bw, epsilon, volume, isotropy]",
        ),
        (
            vec!["trial", "--contacts", "blob"],
            2,
            "[possible values: surface, patch, mean]",
        ),
        (
            vec!["trial", "--frame", "hand"],
            2,
            "[possible values: object, world, palm]",
        ),
        (
            vec!["run", "--method", "grid"],
            2,
            "[possible values: bo, random]",
        ),
        (
            vec!["run", "--params", "x,q"],
            2,
            "unknown trial parameter \"q\"",
        ),
    ] {
        let out = graspopt(&args);
        assert_eq!(out.status.code(), Some(code), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(expected), "{args:?}: {err}");
    }
}

#[test]
fn scan_writes_csv_and_svg() {
    let dir = tempdir("scan");
    let out = graspopt_ok(&[
        "scan",
        "--object",
        "cylinder",
        "--axes",
        "x,y",
        "--steps",
        "3,4",
        "--out",
        dir.to_str().unwrap(),
        "--threads",
        "2",
    ]);
    let csv = std::fs::read_to_string(dir.join("cylinder-bw-approach-vertical.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 1 + 12);
    assert!(lines[0].starts_with("approach,vertical,score,force_closure"));
    let svg = std::fs::read_to_string(dir.join("cylinder-bw-approach-vertical.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    // The best score reported is the maximum of the CSV's score column.
    let best = lines[1..]
        .iter()
        .map(|l| l.split(',').nth(2).unwrap().parse::<f64>().unwrap())
        .fold(f64::NEG_INFINITY, f64::max);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains(&format!("best bw {best:.6}")), "{stderr}");
    let bad = graspopt(&["scan", "--axes", "x,y", "--steps", "3,4,5"]);
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--steps has 3 values for 2 axes"));
}

#[test]
fn scan_2d_writes_a_png_heatmap_too() {
    let dir = tempdir("png");
    graspopt_ok(&[
        "scan",
        "--object",
        "sphere",
        "--axes",
        "x,y",
        "--steps",
        "4,3",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let (width, height, _) = decode_png(&dir.join("sphere-bw-approach-vertical.png"));
    // 4 x 3 cells of 8 px, plus the colour bar, the title and the legend.
    assert!(height > 3 * 8 + 30, "{height}");
    assert!(width > 4 * 8);
}

#[test]
fn a_one_axis_scan_writes_a_png_line_plot_with_its_misses_grey() {
    let dir = tempdir("scan-1d");
    let out = graspopt_ok(&[
        "scan",
        "--object",
        "sphere",
        "--axes",
        "x",
        "--steps",
        "9",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8(out.stdout).unwrap();
    let png = dir.join("sphere-bw-approach.png");
    assert!(stdout.contains(png.to_str().unwrap()), "{stdout}");
    let csv = std::fs::read_to_string(dir.join("sphere-bw-approach.csv")).unwrap();
    let contacts = column(&csv, "contacts");
    let misses = csv
        .lines()
        .skip(1)
        .filter(|l| l.split(',').nth(contacts) == Some("0"))
        .count();
    assert!(misses > 0 && misses < 9, "{csv}");
    let (w, h, px) = decode_png(&png);
    assert!(w >= 560 && h >= 280, "{w} x {h}");
    // A grey tick of 2 x 8 pixels per miss (9 points are far apart) and the legend's square;
    // the line in the first colour of the charts, and text.
    let grey = px.iter().filter(|c| **c == [128, 128, 128]).count();
    assert_eq!(grey, 16 * misses + 64);
    assert!(px.contains(&[31, 119, 180]));
    assert!(px.iter().filter(|c| **c == [20, 20, 20]).count() > 500);
    std::fs::remove_dir_all(&dir).ok();
}

/// The index of the column `name` of a CSV's header.
fn column(csv: &str, name: &str) -> usize {
    let header = csv.lines().next().unwrap_or_default();
    header.split(',').position(|h| h == name).unwrap()
}

#[test]
fn scan_marks_grasps_that_touch_nothing_grey_with_a_legend() {
    let dir = tempdir("misses");
    graspopt_ok(&[
        "scan",
        "--object",
        "sphere",
        "--axes",
        "x,y",
        "--steps",
        "6,5",
        "--out",
        dir.to_str().unwrap(),
    ]);
    // CSV: a grasp that touched nothing has empty metric cells, never NaN.
    let csv = std::fs::read_to_string(dir.join("sphere-bw-approach-vertical.csv")).unwrap();
    assert!(!csv.contains("NaN"), "{csv}");
    let contacts = column(&csv, "contacts");
    let misses: Vec<&str> = csv
        .lines()
        .skip(1)
        .filter(|l| l.split(',').nth(contacts) == Some("0"))
        .collect();
    assert!(!misses.is_empty() && misses.len() < 30, "{csv}");
    for l in &misses {
        // Every metric cell, between the score and the contacts, is empty.
        let f: Vec<&str> = l.split(',').collect();
        assert!(f[3..contacts].iter().all(|c| c.is_empty()), "{l}");
    }
    // SVG: grey cells, one per miss, the legend's grey square, and the legend's text.
    let svg = std::fs::read_to_string(dir.join("sphere-bw-approach-vertical.svg")).unwrap();
    assert_eq!(
        svg.matches(r##"fill="#808080" stroke="none"/>"##).count(),
        misses.len() + 1,
        "{svg}"
    );
    assert!(svg.contains("grey: no contact"), "{svg}");
    // PNG: the same grey, a title above the map and a legend below it.
    let (w, h, px) = decode_png(&dir.join("sphere-bw-approach-vertical.png"));
    assert!(h > 5 * 8 + 30 && w >= 6 * 8, "{w} x {h}");
    let grey = px.iter().filter(|c| **c == [128, 128, 128]).count();
    // 8 x 8 pixels per missing cell, and the legend's square.
    assert_eq!(grey, 64 * misses.len() + 64);
    assert!(px.iter().filter(|c| **c == [20, 20, 20]).count() > 200);
}

/// Runs `graspopt experiment ARGS --out DIR`, checks it succeeded and that its report has
/// every heading and names only files that exist; returns the report and the files named.
fn experiment_report(dir: &std::path::Path, args: &[&str], headings: &[&str]) -> (String, usize) {
    let mut all = vec!["experiment"];
    all.extend(args);
    all.extend(["--out", dir.to_str().unwrap()]);
    let out = graspopt(&all);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    for heading in headings {
        assert!(report.contains(heading), "report lacks {heading}");
    }
    let mut named = 0;
    for word in report.split(|c: char| c.is_whitespace() || c == ',' || c == '|') {
        if word.ends_with(".svg") || word.ends_with(".csv") {
            assert!(dir.join(word).exists(), "{word} missing");
            named += 1;
        }
    }
    (report, named)
}

#[test]
fn experiment_metrics_writes_every_figure_and_a_report() {
    let dir = tempdir("experiment");
    let (_, named) = experiment_report(
        &dir,
        &["metrics", "--steps", "4", "--steps-2d", "3"],
        &[
            "4.3-4.5",
            "Figure 4.6",
            "Figure 4.7",
            "Figure 4.8",
            "4.9-4.15",
        ],
    );
    // 4.3-4.5: 3 objects x (CSV + 3 SVG); 4.6: 2; 4.7: 2; 4.8: 1; 4.9-4.15: 7.
    assert_eq!(named, 12 + 2 + 2 + 1 + 7);
    for object in [
        "sphere",
        "wine_glass",
        "cylinder",
        "mug",
        "cuboid",
        "rotated_cuboid",
        "star_prism",
    ] {
        assert!(dir.join(format!("fig4.9-4.15-{object}.png")).exists());
    }
}

#[test]
fn experiment_bo_writes_the_figures_tables_and_per_seed_counts() {
    let dir = tempdir("experiment-bo");
    let (report, named) = experiment_report(
        &dir,
        &[
            "bo",
            "--seeds",
            "2",
            "--budget",
            "8",
            "--budget-6d",
            "12",
            "--steps",
            "5,3",
            "--objects",
            "sphere,mug,sphere",
        ],
        &[
            "Figures 4.16-4.17",
            "Table 4.1",
            "Figures 4.18-4.24",
            "Figures 4.25-4.27",
            "6D pose space",
        ],
    );
    // Table 4.1 has one row per object (the repeated name runs once) with the 15-point grid
    // and the thesis's figures beside.
    assert_eq!(report.matches("| sphere | 15 |").count(), 1, "{report}");
    assert!(report.contains("| mug | 15 |") && report.contains("331 / 55 / 55 / 1 |"));
    // 1D: 2 objects x (2 CSV + up to 4 SVG); 2D: 2 x (map + 2 CSV + SVG); 6D: 2 x 3.
    assert!(named >= 2 * 4 + 2 * 4 + 2 * 3, "{named} files named");
    // Per-seed counts: two seeds of BO and two of random search, each naming its seed.
    let seeds =
        std::fs::read_to_string(dir.join("fig4.25-4.27-mug-bo-vs-random-seeds.csv")).unwrap();
    let rows: Vec<&str> = seeds.lines().skip(1).collect();
    assert_eq!(rows.len(), 4, "{seeds}");
    assert!(rows[0].starts_with("bo,0,") && rows[3].starts_with("random,1,"));
    let curves = std::fs::read_to_string(dir.join("6d-sphere-bo-vs-random-curves.csv")).unwrap();
    assert_eq!(curves.lines().count(), 1 + 2 * 12);
    // The 1D samples name the EI at which the engine chose each trial from the third on.
    let samples = std::fs::read_to_string(dir.join("fig4.16-sphere-samples.csv")).unwrap();
    let rows: Vec<Vec<&str>> = samples
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert!(
        rows.len() >= 3 && rows[..2].iter().all(|r| r[3].is_empty()),
        "{samples}"
    );
    assert!(rows[2][3].parse::<f64>().unwrap() > 0.0, "{samples}");
}

/// `--model-cap` and `--workers` run, and the report's command line names them.
#[test]
fn experiment_bo_with_a_model_cap_and_workers_names_them_in_its_report() {
    let dir = tempdir("experiment-bo-cap");
    let (report, _) = experiment_report(
        &dir,
        &[
            "bo",
            "--seeds",
            "1",
            "--budget",
            "14",
            "--steps",
            "3",
            "--objects",
            "sphere",
            "--parts",
            "2d",
            "--model-cap",
            "8",
            "--workers",
            "2",
        ],
        &["Table 4.1"],
    );
    assert!(
        report.contains("--engine grasp --model-cap 8 --workers 2`"),
        "{report}"
    );
}

#[test]
fn experiment_bo_bad_input_is_named() {
    let dir = tempdir("experiment-bo-bad");
    for (args, expected) in [
        (
            vec!["--engine", "magic"],
            "invalid value 'magic' for '--engine",
        ),
        (vec!["--objects", "teapot"], "unknown object `teapot`"),
        (
            vec!["--objects", "sphere,,mug"],
            "--objects has an empty name",
        ),
        (
            vec!["--steps", "5,6,7"],
            "--steps \"5,6,7\": expected one count or two",
        ),
        (
            vec!["--steps", "1"],
            "each count must be between 2 and 1000",
        ),
        (
            vec!["--steps", "5,100000"],
            "each count must be between 2 and 1000",
        ),
        (
            vec!["--seeds", "0"],
            "'--seeds <SEEDS>': must be a whole number from 1 to 1,000",
        ),
        (
            vec!["--first-seed", "18446744073709551615"],
            "--first-seed + --seeds must stay below 2^64",
        ),
        (
            vec!["--parts", "2d", "--budget", "5"],
            "--budget must be more than the engine's 5 initial-design trials in 2D",
        ),
        (
            vec!["--parts", "6d", "--budget-6d", "10"],
            "--budget-6d must be more than the engine's 10 initial-design trials in 6D",
        ),
        (
            vec!["--model-cap", "7"],
            "--model-cap must be at least 8 observations, got 7",
        ),
        (
            vec!["--workers", "0"],
            "'--workers <WORKERS>': must be a whole number from 1 to 256",
        ),
    ] {
        let mut all = vec!["experiment", "bo", "--out", dir.to_str().unwrap()];
        all.extend(args);
        let out = graspopt(&all);
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(expected), "{err}");
    }
    assert!(
        !dir.join("report.md").exists(),
        "a refused run wrote a report"
    );
}

#[test]
fn a_mesh_in_millimetres_is_refused_until_scaled() {
    let dir = tempdir("mesh-mm");
    // A 40 mm cube standing on z = 0, written in millimetres.
    let obj = "v -20 -20 0\nv 20 -20 0\nv 20 20 0\nv -20 20 0\n\
               v -20 -20 40\nv 20 -20 40\nv 20 20 40\nv -20 20 40\n\
               f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    let path = dir.join("cube_mm.obj");
    std::fs::write(&path, obj).unwrap();
    let path = path.to_str().unwrap();
    let out = graspopt(&["trial", "--mesh", path, "--format", "json"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("cube_mm.obj") && err.contains("--mesh-scale 0.001"),
        "{err}"
    );
    let out = graspopt_ok(&[
        "trial",
        "--mesh",
        path,
        "--mesh-scale",
        "0.001",
        "--format",
        "json",
    ]);
    let e: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(!e["outcome"]["fingers"].as_array().unwrap().is_empty());
    // The scale needs a mesh.
    let out = graspopt(&["trial", "--mesh-scale", "0.001"]);
    assert_eq!(out.status.code(), Some(2));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn hands_lists_the_built_in_hands_and_describes_one() {
    let out = graspopt_ok(&["hands"]);
    let text = String::from_utf8(out.stdout).unwrap();
    for (name, fingers, joints, source) in [
        ("barrett", 3, 8, "common/sim/hands/bh8_280.urdf"),
        ("parallel_jaw", 2, 2, "common/sim/hands/parallel_jaw.urdf"),
        ("franka_hand", 2, 2, "common/sim/hands/franka_hand.urdf"),
    ] {
        let line = text
            .lines()
            .find(|l| l.starts_with(name))
            .unwrap_or_else(|| panic!("no {name}: {text}"));
        let cols: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(
            (cols[1], cols[2]),
            (&*fingers.to_string(), &*joints.to_string()),
            "{line}"
        );
        assert!(line.contains(source), "{line}");
    }
    let out = graspopt(&["hands", "bh8"]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.starts_with("barrett: 3 fingers"), "{text}");
    assert!(
        text.contains("f1_distal") && text.contains("open 0.8727"),
        "{text}"
    );
}

/// A two-jaw gripper in URDF, written by the test: two prismatic jaws, the second mimicking
/// the first, so they close together.
pub(crate) const JAWS_URDF: &str = r#"<robot name="two_jaws">
  <link name="base"><collision><origin xyz="0 0 -0.01"/><geometry><box size="0.04 0.16 0.02"/></geometry></collision></link>
  <link name="left"><collision><origin xyz="0 -0.005 0.03"/><geometry><box size="0.02 0.01 0.06"/></geometry></collision></link>
  <link name="right"><collision><origin xyz="0 0.005 0.03"/><geometry><box size="0.02 0.01 0.06"/></geometry></collision></link>
  <joint name="left" type="prismatic"><parent link="base"/><child link="left"/><origin xyz="0 -0.06 0"/><axis xyz="0 1 0"/><limit lower="0" upper="0.06" effort="1" velocity="1"/></joint>
  <joint name="right" type="prismatic"><parent link="base"/><child link="right"/><origin xyz="0 0.06 0"/><axis xyz="0 -1 0"/><limit lower="0" upper="0.06" effort="1" velocity="1"/><mimic joint="left"/></joint>
</robot>"#;

#[test]
fn trial_takes_a_urdf_hand_file_and_names_a_bad_one() {
    let dir = tempdir("urdf-hand");
    let path = dir.join("two_jaws.urdf");
    std::fs::write(&path, JAWS_URDF).unwrap();
    let hand = path.to_str().unwrap();
    let out = graspopt_ok(&[
        "trial", "--object", "cuboid", "--hand", hand, "--format", "json",
    ]);
    let e: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(e["outcome"]["grasp"]["hand"], "two_jaws");
    // The cuboid is 0.05 wide across the jaws: each jaw travels 0.06 - 0.025 less the gap.
    let joints = e["outcome"]["grasp"]["joints"].as_array().unwrap();
    let left = joints[0].as_f64().unwrap();
    assert!((0.035 - 2e-4..0.035).contains(&left), "{joints:?}");
    assert_eq!(joints[1], joints[0]);
    assert_eq!(e["outcome"]["fingers"].as_array().unwrap().len(), 2);
    // A missing file, and a bad one, are named.
    let missing = dir.join("nope.urdf");
    let out = graspopt(&["trial", "--hand", missing.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("nope.urdf"), "{err}");
    std::fs::write(
        &path,
        JAWS_URDF.replace("type=\"prismatic\"", "type=\"continuous\""),
    )
    .unwrap();
    let out = graspopt(&["trial", "--hand", hand]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("two_jaws.urdf") && err.contains("`left`") && err.contains("continuous"),
        "{err}"
    );
    let out = graspopt(&["trial", "--hand", "shadow"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("unknown hand `shadow`") && err.contains("franka_hand"),
        "{err}"
    );
}

#[test]
fn experiment_takes_the_hand_flag() {
    let dir = tempdir("experiment-hand");
    let csv = |hand: &str, tag: &str| {
        let out_dir = dir.join(tag);
        graspopt_ok(&[
            "experiment",
            "metrics",
            "--steps",
            "4",
            "--steps-2d",
            "3",
            "--hand",
            hand,
            "--out",
            out_dir.to_str().unwrap(),
        ]);
        std::fs::read_to_string(out_dir.join("fig4.3-sphere.csv")).unwrap()
    };
    let barrett = csv("barrett", "a");
    assert_eq!(barrett, csv("bh8", "b"), "the same hand, the same scan");
    assert_ne!(
        barrett,
        csv("parallel_jaw", "c"),
        "another hand, another scan"
    );
    let out = graspopt(&["experiment", "bo", "--hand", "teapot"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown hand `teapot`"));
    std::fs::remove_dir_all(&dir).ok();
}
