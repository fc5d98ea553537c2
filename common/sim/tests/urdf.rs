//! Hands from URDF: the shipped BH8-280 and parallel-jaw descriptions against the Rust oracles,
//! the Franka hand, settings, and every bad input (the hand the tests write themselves is in
//! graspopt-trial's tests, where its grasp is scored).

use graspopt_sim::hand::urdf::{HandDescription, HandSettings};
use graspopt_sim::hand::{BarrettOracle, Hand, ParallelJawOracle, UrdfHand};
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
    let (oracle, urdf) = (BarrettOracle::default(), bh8());
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
    let oracle = ParallelJawOracle::default();
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

/// The name a run knows a hand by: a built-in hand's own name for any alias, the name a
/// URDF file's settings give (the test hand of the journeys test says `claw`, its robot
/// `claw_urdf`), any other text unchanged (a hand only its agent knows); a file that cannot
/// be read is an error naming it.
#[test]
fn a_hand_is_known_by_its_name_whether_given_by_name_alias_or_file() {
    let claw = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/hands/claw/claw.urdf"
    );
    assert_eq!(graspopt_sim::hand_name("bh8").unwrap(), "barrett");
    assert_eq!(
        graspopt_sim::hand_name("Franka-Hand").unwrap(),
        "franka_hand"
    );
    assert_eq!(graspopt_sim::hand_name(claw).unwrap(), "claw");
    assert_eq!(
        graspopt_sim::hand_name("my_robot_hand").unwrap(),
        "my_robot_hand"
    );
    let missing = graspopt_sim::hand_name("no/such/hand.urdf")
        .unwrap_err()
        .to_string();
    assert!(missing.contains("no/such/hand.urdf"), "{missing}");
    assert!(graspopt_sim::same_hand("gripper", "parallel_jaw"));
    assert!(graspopt_sim::same_hand("claw", "claw"));
    assert!(!graspopt_sim::same_hand("claw", "barrett"));
}

/// Two jaws written by the test that slide along the palm's `x` (unlike the built-in
/// gripper's, along `y`): open 0.16 m apart, each 0.08 deep along the approach axis.
const X_JAWS_URDF: &str = r#"<robot name="x_jaws">
  <link name="palm"><collision><origin xyz="0 0 -0.01"/><geometry><box size="0.2 0.04 0.02"/></geometry></collision></link>
  <link name="a"><collision><origin xyz="0 0 0.04"/><geometry><box size="0.01 0.02 0.08"/></geometry></collision></link>
  <link name="b"><collision><origin xyz="0 0 0.04"/><geometry><box size="0.01 0.02 0.08"/></geometry></collision></link>
  <joint name="a" type="prismatic"><parent link="palm"/><child link="a"/><origin xyz="-0.085 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.08" effort="1" velocity="1"/></joint>
  <joint name="b" type="prismatic"><parent link="palm"/><child link="b"/><origin xyz="0.085 0 0"/><axis xyz="-1 0 0"/><limit lower="0" upper="0.08" effort="1" velocity="1"/></joint>
</robot>"#;

/// Each jaw's mean contact normal (world) on the cylinder, the palm 2 cm into its default
/// approach range.
fn jaw_normals(hand: &UrdfHand) -> Vec<nalgebra::Vector3<f64>> {
    let cylinder = Object::by_name("cylinder").unwrap();
    let space = TrialSpace::approach_1d(&cylinder);
    let out = trial(&cylinder, hand, &space.palm_pose(&[0.02]).unwrap());
    assert_eq!(out.fingers_in_contact(), 2, "{:?}", out.grasp.joints);
    assert!(!out.palm.touches());
    out.fingers
        .iter()
        .map(|f| f.mean_point().unwrap().normal)
        .collect()
}

#[test]
fn rz_degrees_turns_a_hand_about_its_approach_axis() {
    // As written, the jaws close along the palm's x, which the reference pose puts vertical:
    // they pinch the cylinder's end faces.
    let plain = UrdfHand::from_strs("x_jaws.urdf", X_JAWS_URDF, None, None).unwrap();
    assert_eq!(plain.rz(), 0.0);
    for n in jaw_normals(&plain) {
        assert!(n.z.abs() > 0.9, "{n}");
    }
    // Turned by 90 degrees, they close horizontally: on the cylinder's side.
    let turned =
        UrdfHand::from_strs("x_jaws.urdf", X_JAWS_URDF, Some("rz_degrees = 90"), None).unwrap();
    assert!((turned.rz() - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    let normals = jaw_normals(&turned);
    for n in &normals {
        assert!(n.z.abs() < 1e-6 && n.y.abs() > 0.99, "{n}");
    }
    assert!(
        normals[0].y * normals[1].y < 0.0,
        "opposite sides: {normals:?}"
    );
    // The turn is about the approach axis: the open hand's links keep their distance along it.
    let (p, t) = (
        plain.link_poses(&plain.open_configuration()).unwrap(),
        turned.link_poses(&turned.open_configuration()).unwrap(),
    );
    for (a, b) in p.iter().zip(&t) {
        let (a, b) = (a.translation.vector, b.translation.vector);
        assert!((a.z - b.z).abs() < 1e-15 && (a.xy().norm() - b.xy().norm()).abs() < 1e-15);
        assert!(
            (b.x + a.y).abs() < 1e-15 && (b.y - a.x).abs() < 1e-15,
            "{a} {b}"
        );
    }
    // Finite and within a turn, or refused by name.
    for bad in [
        "rz_degrees = 361",
        "rz_degrees = -400.5",
        "rz_degrees = nan",
        "rz_degrees = inf",
    ] {
        let e = UrdfHand::from_strs("x_jaws.urdf", X_JAWS_URDF, Some(bad), None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("x_jaws.urdf") && e.contains("rz_degrees") && e.contains("-360 to 360"),
            "{bad}: {e}"
        );
    }
    UrdfHand::from_strs("x_jaws.urdf", X_JAWS_URDF, Some("rz_degrees = -360"), None).unwrap();
}

#[test]
fn a_hand_says_along_which_world_axis_it_closes_and_which_joints_are_mimics() {
    let plain = UrdfHand::from_strs("x_jaws.urdf", X_JAWS_URDF, None, None).unwrap();
    let axis = plain.closing_axis().unwrap();
    // Palm x is world -z at the reference pose.
    assert!((axis.palm.x.abs() - 1.0).abs() < 1e-12, "{axis:?}");
    assert!((axis.world.z.abs() - 1.0).abs() < 1e-12, "{axis:?}");
    assert!((axis.share - 1.0).abs() < 1e-12);
    let text = plain.summary();
    assert!(text.contains("mimic joints: none"), "{text}");
    assert!(
        text.contains(
            "fingers close along world z (vertical) at the reference pose; rz_degrees = 90 in \
             the hand's settings would make them close along world y (horizontal)"
        ),
        "{text}"
    );
    let turned =
        UrdfHand::from_strs("x_jaws.urdf", X_JAWS_URDF, Some("rz_degrees = 90"), None).unwrap();
    let text = turned.summary();
    assert!(
        text.contains(
            "fingers close along world y (horizontal) at the reference pose (turned by \
             rz_degrees = 90); rz_degrees = 0 in the hand's settings would make them close \
             along world z (vertical)"
        ),
        "{text}"
    );
    let oblique =
        UrdfHand::from_strs("x_jaws.urdf", X_JAWS_URDF, Some("rz_degrees = 30"), None).unwrap();
    assert!(
        oblique.summary().contains(
            "a line -60 degrees above world y at the reference pose (turned by rz_degrees = 30); \
             rz_degrees = 90 in the hand's settings would make it world y (horizontal), 0 world \
             z (vertical)"
        ),
        "{}",
        oblique.summary()
    );
    // Three jaws 120 degrees apart have no single closing axis.
    let jaw = |name: &str, deg: f64| {
        let (c, s) = (deg.to_radians().cos(), deg.to_radians().sin());
        format!(
            r#"<link name="{name}"><collision><origin xyz="0 0 0.04"/><geometry><box size="0.01 0.01 0.08"/></geometry></collision></link>
<joint name="{name}" type="prismatic"><parent link="palm"/><child link="{name}"/><origin xyz="{} {} 0"/><axis xyz="{} {} 0"/><limit lower="0" upper="0.05" effort="1" velocity="1"/></joint>"#,
            0.06 * c,
            0.06 * s,
            -c,
            -s
        )
    };
    let three = format!(
        r#"<robot name="three"><link name="palm"><collision><geometry><box size="0.1 0.1 0.02"/></geometry></collision></link>{}{}{}</robot>"#,
        jaw("j1", 90.0),
        jaw("j2", 210.0),
        jaw("j3", 330.0)
    );
    let three = UrdfHand::from_strs("three.urdf", &three, None, None).unwrap();
    assert!((three.closing_axis().unwrap().share - 0.5).abs() < 1e-9);
    let text = three.summary();
    assert!(
        text.contains("closing: fingers close from several directions across the approach axis (no single axis; 50% of"),
        "{text}"
    );
    // The Barrett's F3 faces F1 and F2 across the palm's y: horizontal; its mimic joints.
    let text = bh8().summary();
    assert!(text.contains("along world y (horizontal)"), "{text}");
    assert!(
        text.contains(
            "f1_distal        follows f1_medial as 0.3333 * f1_medial + 0.8727 rad, breaks away"
        ),
        "{text}"
    );
    assert!(
        text.contains("f2_spread        follows spread as 1 * spread + 0 rad\n"),
        "{text}"
    );
    assert_eq!(bh8().mimic_joints().len(), 4);
    let franka = UrdfHand::from_strs("f.urdf", FRANKA_URDF, Some(FRANKA_TOML), None).unwrap();
    let m = franka.mimic_joints();
    assert_eq!(m.len(), 1);
    assert_eq!(
        (
            m[0].joint.as_str(),
            m[0].follows.as_str(),
            m[0].multiplier,
            m[0].offset,
            m[0].unit
        ),
        ("finger_joint2", "finger_joint1", 1.0, 0.0, "m")
    );
}

/// An error in a hand's settings file names that file, not the URDF beside it.
#[test]
fn an_error_in_a_hands_settings_names_the_settings_file() {
    let dir = tempfile::tempdir().unwrap();
    let claw = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/hands/claw");
    std::fs::create_dir(dir.path().join("meshes")).unwrap();
    std::fs::copy(
        claw.join("meshes/finger.obj"),
        dir.path().join("meshes/finger.obj"),
    )
    .unwrap();
    std::fs::copy(claw.join("claw.urdf"), dir.path().join("grip.urdf")).unwrap();
    std::fs::write(dir.path().join("grip.toml"), "finger = []\n").unwrap();
    let e = UrdfHand::from_file(&dir.path().join("grip.urdf"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("grip.toml"), "{e}");
    assert!(e.contains("finger"), "{e}");
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
