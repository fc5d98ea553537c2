//! Hands from URDF: the shipped BH8-280 and parallel-jaw descriptions against the Rust oracles,
//! the Franka hand, settings, and every bad input (the hand the tests write themselves is in
//! graspopt-trial's tests, where its grasp is scored).

use graspopt_sim::hand::urdf::{HandDescription, HandSettings};
use graspopt_sim::hand::{BarrettHand, Hand, ParallelJawGripper, UrdfHand};
use graspopt_sim::pose::{TrialSpace, reference_pose};
use graspopt_sim::{ContactModel, ContactModelSettings, Object, SimError, TrialOutcome, run_trial};
use nalgebra::Isometry3;

const BH8_URDF: &str = include_str!("../hands/bh8_280.urdf");
const BH8_TOML: &str = include_str!("../hands/bh8_280.toml");
const JAW_URDF: &str = include_str!("../hands/parallel_jaw.urdf");
const FRANKA_URDF: &str = include_str!("../hands/franka_hand.urdf");
const FRANKA_TOML: &str = include_str!("../hands/franka_hand.toml");

const OBJECTS: [&str; 7] = [
    "sphere",
    "wine_glass",
    "cylinder",
    "mug",
    "cuboid",
    "rotated_cuboid",
    "star_prism",
];

fn bh8() -> UrdfHand {
    UrdfHand::from_strs("bh8_280.urdf", BH8_URDF, Some(BH8_TOML), None).unwrap()
}

fn trial(object: &Object, hand: &dyn Hand, pose: &Isometry3<f64>) -> TrialOutcome {
    run_trial(object, hand, pose, &ContactModelSettings::default()).unwrap()
}

/// Poses of each object: the reference pose and points of its approach x vertical space.
fn poses(object: &Object) -> Vec<Isometry3<f64>> {
    let space = TrialSpace::approach_vertical_2d(object);
    let mut v = vec![reference_pose(object)];
    for a in [-0.12, -0.07, -0.03, 0.0, 0.015] {
        for y in [-0.02, 0.0, 0.013] {
            v.push(space.palm_pose(&[a, y]).unwrap());
        }
    }
    v
}

/// The two trials are the same: joints (matched by name), touching links, and every contact of
/// every model within `tol`.
fn assert_same_trial(
    a: &TrialOutcome,
    ha: &dyn Hand,
    b: &TrialOutcome,
    hb: &dyn Hand,
    tol: f64,
    what: &str,
) {
    let names_b = hb.joint_names();
    for (name, va) in ha.joint_names().iter().zip(&a.grasp.joints) {
        let k = names_b
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("no joint {name}"));
        assert!(
            (va - b.grasp.joints[k]).abs() <= tol,
            "{what}: joint {name}: oracle {va}, URDF {}",
            b.grasp.joints[k]
        );
    }
    assert_eq!(a.grasp.link_touching, b.grasp.link_touching, "{what}");
    assert!((a.grasp.retreat - b.grasp.retreat).abs() <= tol, "{what}");
    assert_eq!(a.fingers.len(), b.fingers.len(), "{what}");
    for model in [
        ContactModel::MeanPoint,
        ContactModel::CircularPatch,
        ContactModel::Surface,
    ] {
        let (ca, cb) = (a.contacts(model, true), b.contacts(model, true));
        assert_eq!(ca.len(), cb.len(), "{what} {model:?}");
        for (p, q) in ca.iter().zip(&cb) {
            let (dp, dn) = (
                (p.position - q.position).norm(),
                (p.normal - q.normal).norm(),
            );
            assert!(
                dp <= tol && dn <= tol,
                "{what} {model:?}: position {dp:e}, normal {dn:e}\n{:?}\n{:?}",
                a.grasp.joints,
                b.grasp.joints
            );
        }
    }
}

#[test]
fn the_bh8_urdf_gives_the_oracle_s_trials_on_the_seven_objects() {
    let (oracle, urdf) = (BarrettHand::default(), bh8());
    assert_eq!(urdf.name(), "barrett");
    assert_eq!(urdf.finger_count(), 3);
    let names: Vec<String> = urdf.links().iter().map(|l| l.name.clone()).collect();
    let oracle_names: Vec<String> = oracle.links().iter().map(|l| l.name.clone()).collect();
    assert_eq!(names, oracle_names);
    let mut touching = 0;
    for name in OBJECTS {
        let object = Object::by_name(name).unwrap();
        for (i, pose) in poses(&object).iter().enumerate() {
            let (a, b) = (trial(&object, &oracle, pose), trial(&object, &urdf, pose));
            assert_same_trial(&a, &oracle, &b, &urdf, 1e-9, &format!("{name} pose {i}"));
            touching += usize::from(a.touched());
        }
    }
    // The comparison covers grasps, not only empty trials.
    assert!(touching >= 70, "{touching} touching trials");
}

#[test]
fn the_parallel_jaw_urdf_gives_the_oracle_s_trials() {
    let oracle = ParallelJawGripper::default();
    let urdf = UrdfHand::from_strs("parallel_jaw.urdf", JAW_URDF, None, None).unwrap();
    assert_eq!(urdf.finger_count(), 2);
    for name in OBJECTS {
        let object = Object::by_name(name).unwrap();
        for (i, pose) in poses(&object).iter().enumerate() {
            let (a, b) = (trial(&object, &oracle, pose), trial(&object, &urdf, pose));
            assert_same_trial(&a, &oracle, &b, &urdf, 1e-9, &format!("{name} pose {i}"));
        }
    }
}

#[test]
fn the_franka_hand_closes_towards_its_lower_limits_with_coupled_fingers() {
    let hand =
        UrdfHand::from_strs("franka_hand.urdf", FRANKA_URDF, Some(FRANKA_TOML), None).unwrap();
    assert_eq!(hand.open_configuration(), vec![0.04, 0.04]);
    assert_eq!(hand.closing_joints(), vec!["finger_joint1".to_string()]);
    // The cuboid is 0.05 wide along the closing axis: each finger stops 0.025 from the centre
    // line, within the contact tolerance.
    let cuboid = Object::by_name("cuboid").unwrap();
    let out = trial(&cuboid, &hand, &reference_pose(&cuboid));
    assert_eq!(out.fingers_in_contact(), 2, "{:?}", out.grasp.joints);
    let q = out.grasp.joints[0];
    assert!(
        q > 0.025 && q <= 0.025 + graspopt_sim::CONTACT_TOLERANCE,
        "{q}"
    );
    assert_eq!(out.grasp.joints[1], q);
    // Without its settings the URDF alone still works, by the convention: the fingers are
    // open at their lower limits (closed together) and would close towards 0.04 (apart).
    let plain = UrdfHand::from_strs("franka_hand.urdf", FRANKA_URDF, None, None).unwrap();
    assert_eq!(plain.open_configuration(), vec![0.0, 0.0]);
    assert_eq!(plain.closing_joints(), ["finger_joint1"]);
    assert!(
        run_trial(
            &cuboid,
            &plain,
            &reference_pose(&cuboid),
            &ContactModelSettings::default()
        )
        .is_ok()
    );
}

#[test]
fn the_barrett_settings_make_the_spread_hold_and_the_distal_joints_break_away() {
    let hand = bh8();
    assert_eq!(
        hand.closing_joints(),
        ["f1_medial", "f2_medial", "f3_medial"]
    );
    let open = hand.open_configuration();
    assert_eq!(open, vec![0.0, 0.0, 0.8727, 0.0, 0.0, 0.8727, 0.0, 0.8727]);
    // Without the settings the spread would close too (and F2's follows it), and the distal
    // joints would never leave the coupling.
    let plain = UrdfHand::from_strs("bh8_280.urdf", BH8_URDF, None, None).unwrap();
    assert_eq!(
        plain.closing_joints(),
        ["spread", "f1_medial", "f2_medial", "f3_medial"]
    );
}

fn parse_err(urdf: &str, settings: Option<&str>) -> String {
    let settings = settings.map(|s| HandSettings::parse(s, "t.toml").unwrap());
    match HandDescription::parse("t.urdf", urdf, settings.as_ref()) {
        Err(e @ SimError::BadHand { .. }) => e.to_string(),
        Err(e) => panic!("not a BadHand error: {e}"),
        Ok(_) => panic!("accepted"),
    }
}

const PALM: &str = r#"<link name="palm"><collision><geometry><box size="0.1 0.1 0.02"/></geometry></collision></link>
<link name="f"><collision><geometry><box size="0.01 0.01 0.05"/></geometry></collision></link>"#;

fn one_joint(joint: &str) -> String {
    format!(r#"<robot name="r">{PALM}{joint}</robot>"#)
}

#[test]
fn bad_urdf_gives_errors_that_name_the_joint_link_or_file() {
    // A closing joint without limits (URDF's default is lower = upper = 0).
    let e = parse_err(
        &one_joint(
            r#"<joint name="j1" type="revolute"><parent link="palm"/><child link="f"/><axis xyz="1 0 0"/><limit effort="1" velocity="1"/></joint>"#,
        ),
        None,
    );
    assert!(
        e.contains("t.urdf") && e.contains("`j1`") && e.contains("no limits"),
        "{e}"
    );
    // A continuous joint has no limits either.
    let e = parse_err(
        &one_joint(
            r#"<joint name="spin" type="continuous"><parent link="palm"/><child link="f"/><axis xyz="1 0 0"/></joint>"#,
        ),
        None,
    );
    assert!(e.contains("`spin`") && e.contains("continuous"), "{e}");
    // Unsupported joint type and geometry.
    let e = parse_err(
        &one_joint(
            r#"<joint name="free" type="floating"><parent link="palm"/><child link="f"/></joint>"#,
        ),
        None,
    );
    assert!(e.contains("`free`") && e.contains("unsupported"), "{e}");
    let e = parse_err(
        r#"<robot name="r"><link name="palm"><collision><geometry><capsule radius="0.01" length="0.05"/></geometry></collision></link></robot>"#,
        None,
    );
    assert!(e.contains("`palm`") && e.contains("capsule"), "{e}");
    // A kinematic loop: a link that is the child of two joints.
    let e = parse_err(
        &format!(
            r#"<robot name="r">{PALM}<link name="g"/>
<joint name="j1" type="fixed"><parent link="palm"/><child link="f"/></joint>
<joint name="j2" type="fixed"><parent link="f"/><child link="g"/></joint>
<joint name="j3" type="fixed"><parent link="g"/><child link="f"/></joint></robot>"#
        ),
        None,
    );
    assert!(
        e.contains("loop") && e.contains("`f`") && e.contains("`j3`"),
        "{e}"
    );
    // A loop with no root at all.
    let e = parse_err(
        &format!(
            r#"<robot name="r">{PALM}
<joint name="j1" type="fixed"><parent link="palm"/><child link="f"/></joint>
<joint name="j2" type="fixed"><parent link="f"/><child link="palm"/></joint></robot>"#
        ),
        None,
    );
    assert!(e.contains("loop") && e.contains("root"), "{e}");
    // A joint naming a missing link.
    let e = parse_err(
        &one_joint(
            r#"<joint name="j1" type="fixed"><parent link="palm"/><child link="ghost"/></joint>"#,
        ),
        None,
    );
    assert!(e.contains("`j1`") && e.contains("`ghost`"), "{e}");
    // A mimic of a missing joint.
    let e = parse_err(
        &one_joint(
            r#"<joint name="j1" type="revolute"><parent link="palm"/><child link="f"/><limit lower="0" upper="1" effort="1" velocity="1"/><mimic joint="nobody"/></joint>"#,
        ),
        None,
    );
    assert!(e.contains("`j1`") && e.contains("`nobody`"), "{e}");
    // Settings naming a joint that does not exist, or with an unknown key.
    let good = one_joint(
        r#"<joint name="j1" type="revolute"><parent link="palm"/><child link="f"/><limit lower="0" upper="1" effort="1" velocity="1"/></joint>"#,
    );
    let e = parse_err(&good, Some("[joints.j9]\nhold = true\n"));
    assert!(e.contains("`j9`"), "{e}");
    let e = HandSettings::parse("[joints.j1]\nclosing = 1\n", "t.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("t.toml") && e.contains("closing"), "{e}");
    let e = parse_err(&good, Some("[joints.j1]\nopen = 2.0\n"));
    assert!(e.contains("`j1`") && e.contains("outside"), "{e}");
    // Malformed XML names the file.
    let e = parse_err("<robot name=\"r\"><link name=\"palm\">", None);
    assert!(e.contains("t.urdf"), "{e}");
    // The good one parses.
    assert!(HandDescription::parse("t.urdf", &good, None).is_ok());
}

#[test]
fn a_file_that_is_not_urdf_says_so() {
    for text in ["", "not xml at all", "<robot name=\"r\"><link"] {
        let e = parse_err(text, None);
        assert!(e.starts_with("hand `t.urdf`: "), "{e}");
        assert!(!e.contains("custom:"), "{e}");
    }
    assert_eq!(
        parse_err("", None),
        "hand `t.urdf`: the file is empty or not XML (no element found): not a URDF robot"
    );
    // A joint limit without its velocity: urdf-rs's serde message, without its prefix.
    let e = parse_err(
        &one_joint(
            r#"<joint name="j" type="revolute"><parent link="palm"/><child link="f"/><axis xyz="0 0 1"/><limit lower="0" upper="1" effort="1"/></joint>"#,
        ),
        None,
    );
    assert!(
        e.contains("not a valid URDF robot: missing field `velocity`"),
        "{e}"
    );
}

#[test]
fn missing_and_unsupported_meshes_are_errors_that_name_the_file() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path().to_path_buf();
    let urdf = |file: &str| {
        format!(
            r#"<robot name="r"><link name="palm"><collision><geometry><mesh filename="{file}"/></geometry></collision></link></robot>"#
        )
    };
    let e = UrdfHand::from_strs("t.urdf", &urdf("missing.stl"), None, Some(&dir))
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.stl") && e.contains("`palm`"), "{e}");
    std::fs::write(dir.join("part.dae"), "<COLLADA/>").unwrap();
    let e = UrdfHand::from_strs("t.urdf", &urdf("part.dae"), None, Some(&dir))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("part.dae") && e.contains("expected .obj or .stl"),
        "{e}"
    );
    // A flat link mesh (one square) has no hull: an error naming the link and the file,
    // not parry's panic.
    std::fs::write(
        dir.join("plate.obj"),
        "v 0 0 0\nv 0.1 0 0\nv 0.1 0.1 0\nv 0 0.1 0\nv 0.05 0.05 0\nf 1 2 3 4\n",
    )
    .unwrap();
    let e = UrdfHand::from_strs("t.urdf", &urdf("plate.obj"), None, Some(&dir))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`palm`") && e.contains("plate.obj") && e.contains("flat"),
        "{e}"
    );
    // Parsed from a string with no folder to look in.
    let e = UrdfHand::from_strs("t.urdf", &urdf("cube.obj"), None, None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("cube.obj"), "{e}");
    // A missing URDF file names itself.
    let e = UrdfHand::from_file(&dir.join("nope.urdf"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("nope.urdf"), "{e}");
}

/// A mesh that is not there is named as the URDF writes it, where it was looked for
/// (absolute, whatever the folder the URDF was loaded from) and why it cannot be read.
#[test]
fn a_missing_mesh_names_its_written_and_resolved_paths_and_the_system_s_reason() {
    let scratch = tempfile::tempdir().unwrap();
    let urdf = r#"<robot name="r"><link name="palm"><collision><geometry><mesh filename="meshes/palm.stl"/></geometry></collision></link></robot>"#;
    std::fs::write(scratch.path().join("gripper.urdf"), urdf).unwrap();
    let e = UrdfHand::from_file(&scratch.path().join("gripper.urdf"))
        .unwrap_err()
        .to_string();
    let resolved = scratch.path().join("meshes/palm.stl");
    assert!(resolved.is_absolute());
    assert_eq!(
        e,
        format!(
            "hand `{}`: link `palm`: cannot read the mesh `meshes/palm.stl` (looked for at `{}`): \
             No such file or directory (os error 2)",
            scratch.path().join("gripper.urdf").display(),
            resolved.display()
        )
    );
}
