//! `graspopt trial --scene FILE`: the exported OBJ and glTF hold the object, every hand link,
//! a marker per modelled contact and a normal segment per contact.

use graspopt_sim::hand::hand_by_name;
use graspopt_sim::scene::scene_meshes;
use graspopt_sim::{ContactModel, Object, TrialOutcome};
use serde_json::Value;

use crate::support::{graspopt, tempdir};

/// Runs a sphere trial with JSON output and `extra` flags; returns the outcome.
fn sphere_trial(extra: &[&str]) -> TrialOutcome {
    let mut args = vec![
        "trial", "--object", "sphere", "--at", "x=-0.1", "--format", "json",
    ];
    args.extend_from_slice(extra);
    let out = graspopt(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // stdout stays pure JSON; the written paths go to stderr.
    let e: Value = serde_json::from_slice(&out.stdout).unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    for f in extra.iter().filter(|f| !f.starts_with("--")) {
        assert!(stderr.contains(&format!("wrote {f}")), "{stderr}");
    }
    serde_json::from_value(e["outcome"].clone()).unwrap()
}

#[test]
fn obj_scene_has_every_mesh_contact_and_normal() {
    let dir = tempdir("obj");
    let path = dir.join("grasp.obj");
    let outcome = sphere_trial(&["--scene", path.to_str().unwrap()]);
    let object = Object::by_name("sphere").unwrap();
    let hand = hand_by_name("barrett").unwrap();
    let meshes = scene_meshes(&object, hand.as_ref(), &outcome.grasp).unwrap();
    let contacts = outcome.contacts(ContactModel::Surface, true).len();
    assert!(contacts >= 3, "{contacts}");

    let text = std::fs::read_to_string(&path).unwrap();
    let count = |p: &str| text.lines().filter(|l| l.starts_with(p)).count();
    let verts: usize = meshes.iter().map(|m| m.mesh.vertices.len()).sum();
    let faces: usize = meshes.iter().map(|m| m.mesh.triangles.len()).sum();
    // Octahedral markers (6 vertices, 8 faces) and two vertices per normal segment.
    assert_eq!(count("v "), verts + 6 * contacts + 2 * contacts);
    assert_eq!(count("f "), faces + 8 * contacts);
    assert_eq!(count("l "), contacts);
    assert_eq!(count("o "), meshes.len() + 2);
    for m in &meshes {
        assert!(
            text.contains(&format!("\no {}\n", m.name.replace(' ', "_"))),
            "{}",
            m.name
        );
    }
    assert!(text.contains("\no contacts\n") && text.contains("\no normals\n"));
    // Every face and line index refers to an existing vertex (1-based).
    let n = count("v ");
    for l in text
        .lines()
        .filter(|l| l.starts_with("f ") || l.starts_with("l "))
    {
        for i in l.split_whitespace().skip(1) {
            let i: usize = i.parse().unwrap();
            assert!((1..=n).contains(&i), "{l}");
        }
    }
    assert!(text.contains("mtllib grasp.mtl"));
    let mtl = std::fs::read_to_string(dir.join("grasp.mtl")).unwrap();
    assert_eq!(mtl.matches("newmtl ").count(), meshes.len() + 2);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn gltf_scene_is_chosen_by_extension() {
    let dir = tempdir("gltf");
    let path = dir.join("grasp.gltf");
    let outcome = sphere_trial(&["--scene", path.to_str().unwrap()]);
    let object = Object::by_name("sphere").unwrap();
    let hand = hand_by_name("barrett").unwrap();
    let meshes = scene_meshes(&object, hand.as_ref(), &outcome.grasp).unwrap();
    let contacts = outcome.contacts(ContactModel::Surface, true).len();
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert_eq!(doc["asset"]["version"], "2.0");
    let gl = doc["meshes"].as_array().unwrap();
    assert_eq!(gl.len(), meshes.len() + 2);
    let accessor = |m: &Value| {
        let i = m["primitives"][0]["attributes"]["POSITION"]
            .as_u64()
            .unwrap();
        doc["accessors"][i as usize]["count"].as_u64().unwrap() as usize
    };
    for (g, m) in gl.iter().zip(&meshes) {
        assert_eq!(accessor(g), m.mesh.vertices.len());
    }
    assert_eq!(accessor(&gl[meshes.len()]), 6 * contacts);
    assert_eq!(accessor(&gl[meshes.len() + 1]), 2 * contacts);
    assert_eq!(gl[meshes.len() + 1]["primitives"][0]["mode"], 1);
    assert!(
        doc["buffers"][0]["uri"]
            .as_str()
            .unwrap()
            .starts_with("data:application/octet-stream;base64,")
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_scene_paths_are_named() {
    for path in [
        "/nonexistent-graspopt-dir/grasp.obj",
        "/nonexistent-graspopt-dir/grasp.gltf",
        "/tmp/grasp.glb",
    ] {
        let out = graspopt(&[
            "trial", "--object", "sphere", "--at", "x=-0.1", "--scene", path,
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{path}: {stderr}");
        assert!(stderr.contains(path), "{path}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}
