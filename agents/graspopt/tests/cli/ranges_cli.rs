//! Parameter ranges (`--range`) in every command that takes trial parameters, and a hand of
//! the user's turned by its settings and described by `graspopt hands FILE`.

use serde_json::Value;

use crate::support::{graspopt, graspopt_ok, tempdir};

/// The commands that take `--range`, each with the flags that make it short.
const COMMANDS: [&[&str]; 5] = [
    &["run", "--trials", "1", "--quiet"],
    &["scan", "--steps", "2"],
    &["record", "--steps", "2", "--out", "unused.jsonl"],
    &["trial"],
    &["agent", "coordinator", "--trials", "1"],
];

#[test]
fn every_command_with_parameters_shows_the_default_ranges_and_refuses_one_beyond_the_limits() {
    for command in COMMANDS {
        let mut help = command[..if command[0] == "agent" { 2 } else { 1 }].to_vec();
        help.push("--help");
        let text = String::from_utf8(graspopt_ok(&help).stdout).unwrap();
        for part in [
            "--range <NAME=LO:HI>",
            "approach (x) -0.16:0.02 m (limits -0.5:0.5)",
            "the object's half extent + 0.01 m",
            "rz -0.7854:0.7854 rad (limits -6.2832:6.2832)",
        ] {
            assert!(text.contains(part), "{help:?}: {part:?} not in {text}");
        }
        let mut args = command.to_vec();
        args.extend(["--range", "rz=-7:7"]);
        let out = graspopt(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(
                "range \"rz=-7:7\": rz must stay within the simulator's limits -6.2832:6.2832 rad"
            ),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn a_run_takes_ranges_records_them_and_refuses_a_contrary_one_on_resume() {
    let dir = tempdir("ranges-run");
    let out = dir.join("run");
    let o = out.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec![
            "run",
            "--object",
            "cylinder",
            "--params",
            "x,rz",
            "--trials",
            "3",
            "--workers",
            "1",
            "--method",
            "random",
            "--out",
            o,
            "--quiet",
        ];
        args.extend(extra);
        graspopt(&args)
    };
    // A range for a parameter the run does not search is named.
    let refused = run(&["--range", "lateral=-0.1:0.1"]);
    assert_eq!(refused.status.code(), Some(1));
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(
        err.contains("lateral is not one of this command's trial parameters (approach, rz)"),
        "{err}"
    );
    assert!(!out.exists(), "a refused run wrote {o}");
    let done = run(&["--range", "rz=-3.1416:3.1416"]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let journal = out.join("journal.sqlite");
    let export = graspopt_ok(&[
        "export",
        "run",
        "--journal",
        journal.to_str().unwrap(),
        "--format",
        "json",
    ]);
    let export: Value = serde_json::from_slice(&export.stdout).unwrap();
    let spec: Value = serde_json::from_str(export["run"]["config_json"].as_str().unwrap()).unwrap();
    // The README's example range, as typed.
    let recorded: Value = serde_json::from_str("[[-0.16, 0.02], [-3.1416, 3.1416]]").unwrap();
    assert_eq!(spec["bounds"], recorded);
    // Resumed with its range it continues; with another, it is refused by name.
    let more = run(&["--resume", "--range", "rz=-3.1416:3.1416"]);
    assert!(
        more.status.success(),
        "{}",
        String::from_utf8_lossy(&more.stderr)
    );
    let resumed = run(&["--resume", "--range", "rz=-1:1"]);
    assert_eq!(resumed.status.code(), Some(1));
    let err = String::from_utf8_lossy(&resumed.stderr);
    assert!(
        err.contains("--range rz=-1:1 (the run has rz=-3.1416:3.1416)"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_trial_beyond_the_default_bounds_says_how_to_widen_them() {
    let out = graspopt(&["trial", "--object", "cylinder", "--at", "rz=1.5"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(
            "rz = 1.5 is outside [-0.7854, 0.7854] rad for the cylinder (--range rz=LO:HI sets \
             other bounds, within -6.2832:6.2832)"
        ),
        "{err}"
    );
    let out = graspopt_ok(&[
        "trial",
        "--object",
        "cylinder",
        "--at",
        "rz=1.5",
        "--range",
        "rz=-1.6:1.6",
        "--format",
        "json",
    ]);
    let e: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(e["params"], serde_json::json!([1.5]));
}

/// Two jaws written by the test sliding along the palm's `x` (the second mimics the first),
/// and its settings file.
const X_JAWS_URDF: &str = r#"<robot name="x_jaws">
  <link name="palm"><collision><origin xyz="0 0 -0.01"/><geometry><box size="0.2 0.04 0.02"/></geometry></collision></link>
  <link name="a"><collision><origin xyz="0 0 0.04"/><geometry><box size="0.01 0.02 0.08"/></geometry></collision></link>
  <link name="b"><collision><origin xyz="0 0 0.04"/><geometry><box size="0.01 0.02 0.08"/></geometry></collision></link>
  <joint name="a" type="prismatic"><parent link="palm"/><child link="a"/><origin xyz="-0.085 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.08" effort="1" velocity="1"/></joint>
  <joint name="b" type="prismatic"><parent link="palm"/><child link="b"/><origin xyz="0.085 0 0"/><axis xyz="-1 0 0"/><limit lower="0" upper="0.08" effort="1" velocity="1"/><mimic joint="a"/></joint>
</robot>"#;

#[test]
fn hands_file_names_the_closing_axis_and_the_mimic_joints_and_rz_degrees_turns_the_hand() {
    let dir = tempdir("ranges-hand");
    let path = dir.join("x_jaws.urdf");
    std::fs::write(&path, X_JAWS_URDF).unwrap();
    let hand = path.to_str().unwrap();
    let text = String::from_utf8(graspopt_ok(&["hands", hand]).stdout).unwrap();
    assert!(text.starts_with("x_jaws: 2 fingers"), "{text}");
    assert!(
        text.contains("mimic joints:\n  b                follows a as 1 * a + 0 m\n"),
        "{text}"
    );
    assert!(
        text.contains(
            "closing: fingers close along world z (vertical) at the reference pose; rz_degrees = \
             90 in the hand's settings would make them close along world y (horizontal)"
        ),
        "{text}"
    );
    // The pinch on the cylinder: the end faces, as written.
    let normals = |hand: &str| -> Vec<Value> {
        let out = graspopt_ok(&[
            "trial",
            "--object",
            "cylinder",
            "--hand",
            hand,
            "--at",
            "x=0.02",
            "--contacts",
            "mean",
            "--format",
            "json",
        ]);
        let e: Value = serde_json::from_slice(&out.stdout).unwrap();
        e["outcome"]["fingers"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f["mean_point"]["normal"].clone())
            .collect()
    };
    let z = |n: &Value| n[2].as_f64().unwrap().abs();
    for n in normals(hand) {
        assert!(z(&n) > 0.9, "{n}");
    }
    // Turned by its settings, the same file closes horizontally, on the cylinder's side.
    std::fs::write(dir.join("x_jaws.toml"), "rz_degrees = 90\n").unwrap();
    let text = String::from_utf8(graspopt_ok(&["hands", hand]).stdout).unwrap();
    assert!(
        text.contains(
            "along world y (horizontal) at the reference pose (turned by rz_degrees = 90)"
        ),
        "{text}"
    );
    for n in normals(hand) {
        assert!(z(&n) < 1e-6, "{n}");
    }
    std::fs::write(dir.join("x_jaws.toml"), "rz_degrees = 720\n").unwrap();
    let out = graspopt(&["hands", hand]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("rz_degrees = 720 must be a finite angle within a turn"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
