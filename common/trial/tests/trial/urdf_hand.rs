//! A hand the test writes itself (two revolute fingers, each with a mimic joint; mesh and
//! primitive links) loads from its URDF file, closes as its kinematics say and grasps the
//! cylinder with force closure.

use graspopt_sim::hand::{Hand, LinkShape, UrdfHand};
use graspopt_sim::{Object, TrialSpace};
use graspopt_trial::Evaluator;

/// A hand written by the test: a box palm and two fingers, each a proximal revolute joint that
/// closes and a distal joint that mimics it (half its angle plus 0.2 rad). Finger A: a box
/// proximal link and a mesh distal link (a cube OBJ scaled to 20 x 10 x 40 mm). Finger B: a
/// cylinder proximal link and a distal link of two collision elements (a sphere and a box).
fn test_hand_urdf(mesh: &str) -> String {
    format!(
        r#"<robot name="test_hand">
  <link name="palm"><collision><origin xyz="0 0 -0.01"/><geometry><box size="0.04 0.16 0.02"/></geometry></collision></link>
  <link name="a_prox"><collision><origin xyz="0 0 0.03"/><geometry><box size="0.02 0.01 0.06"/></geometry></collision></link>
  <link name="a_tip"><collision><origin xyz="0 0 0.02"/><geometry><mesh filename="{mesh}" scale="0.02 0.01 0.04"/></geometry></collision></link>
  <link name="b_prox"><collision><origin xyz="0 0 0.03"/><geometry><cylinder radius="0.006" length="0.06"/></geometry></collision></link>
  <link name="b_tip">
    <collision><origin xyz="0 0 0.03"/><geometry><sphere radius="0.008"/></geometry></collision>
    <collision><origin xyz="0 0 0.015"/><geometry><box size="0.02 0.01 0.03"/></geometry></collision>
  </link>
  <joint name="a" type="revolute"><parent link="palm"/><child link="a_prox"/><origin xyz="0 -0.055 0"/><axis xyz="-1 0 0"/><limit lower="0" upper="1.5" effort="1" velocity="1"/></joint>
  <joint name="a_tip" type="revolute"><parent link="a_prox"/><child link="a_tip"/><origin xyz="0 0 0.06"/><axis xyz="-1 0 0"/><limit lower="0" upper="1.2" effort="1" velocity="1"/><mimic joint="a" multiplier="0.5" offset="0.2"/></joint>
  <joint name="b" type="revolute"><parent link="palm"/><child link="b_prox"/><origin xyz="0 0.055 0"/><axis xyz="1 0 0"/><limit lower="0" upper="1.5" effort="1" velocity="1"/></joint>
  <joint name="b_tip" type="revolute"><parent link="b_prox"/><child link="b_tip"/><origin xyz="0 0 0.06"/><axis xyz="1 0 0"/><limit lower="0" upper="1.2" effort="1" velocity="1"/><mimic joint="b" multiplier="0.5" offset="0.2"/></joint>
</robot>"#
    )
}

const CUBE_OBJ: &str = "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n\
v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n\
f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";

#[test]
fn a_urdf_hand_written_here_loads_and_grasps_the_cylinder_with_force_closure() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path().to_path_buf();
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    std::fs::write(dir.join("meshes/cube.obj"), CUBE_OBJ).unwrap();
    let path = dir.join("test_hand.urdf");
    std::fs::write(&path, test_hand_urdf("meshes/cube.obj")).unwrap();
    let hand = UrdfHand::from_file(&path).unwrap();
    assert_eq!(hand.finger_count(), 2);
    assert_eq!(hand.joint_names(), ["a", "a_tip", "b", "b_tip"]);
    assert_eq!(hand.closing_joints(), ["a", "b"]);
    // Open: proximal joints at their lower limits, the mimic joints at 0.5 * 0 + 0.2.
    assert_eq!(hand.open_configuration(), vec![0.0, 0.2, 0.0, 0.2]);
    let names: Vec<&str> = hand.links().iter().map(|l| l.name.as_str()).collect();
    assert_eq!(
        names,
        ["palm", "a_prox", "a_tip", "b_prox", "b_tip", "b_tip#2"]
    );
    let fingers: Vec<Option<usize>> = hand.links().iter().map(|l| l.finger).collect();
    assert_eq!(fingers, [None, Some(0), Some(0), Some(1), Some(1), Some(1)]);
    // The mesh link is the scaled cube (its convex hull): 8 corners at (+-0.01, +-0.005, +-0.02).
    let LinkShape::Mesh { mesh } = &hand.links()[2].shape else {
        panic!("a_tip is no mesh");
    };
    assert_eq!(mesh.vertices.len(), 8);
    for v in &mesh.vertices {
        assert!((v.x.abs() - 0.01).abs() < 1e-12 && (v.y.abs() - 0.005).abs() < 1e-12);
        assert!((v.z.abs() - 0.02).abs() < 1e-12);
    }
    // Forward kinematics: with a at 0.4 (and a_tip following at 0.4), the tip's mesh frame is
    // 0.06 up finger A, then 0.02 up the tip, both turned about -x towards +y.
    let poses = hand.link_poses(&[0.4, 0.4, 0.0, 0.2]).unwrap();
    let tip = poses[2].translation.vector;
    let (s1, c1, s2, c2) = (0.4_f64.sin(), 0.4_f64.cos(), 0.8_f64.sin(), 0.8_f64.cos());
    assert!(
        (tip.y - (-0.055 + 0.06 * s1 + 0.02 * s2)).abs() < 1e-12,
        "{tip}"
    );
    assert!((tip.z - (0.06 * c1 + 0.02 * c2)).abs() < 1e-12, "{tip}");
    assert!(tip.x.abs() < 1e-15);
    // It grasps the cylinder (palm 20 mm from its side): both fingers touch, the mimic joints
    // stayed coupled, nothing penetrates, and the grasp is force-closure (default scoring).
    let cylinder = Object::by_name("cylinder").unwrap();
    let space = TrialSpace::approach_1d(&cylinder);
    let ev = Evaluator::new(cylinder, Box::new(hand), space);
    let e = ev.evaluate(&[0.0]).unwrap();
    let out = &e.outcome;
    assert_eq!(out.fingers_in_contact(), 2, "{:?}", out.grasp.joints);
    let j = &out.grasp.joints;
    assert!((j[1] - (0.5 * j[0] + 0.2)).abs() < 1e-12 && (j[3] - (0.5 * j[2] + 0.2)).abs() < 1e-12);
    assert!(out.grasp.link_distances.iter().all(|d| *d > 0.0));
    let m = e.score.metrics.expect("contacts");
    assert!(m.force_closure() && m.epsilon() > 0.0, "{m:?}");
}
