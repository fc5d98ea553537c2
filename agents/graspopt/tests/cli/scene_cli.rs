//! `graspopt trial --scene FILE`: the exported OBJ and glTF hold the object, every hand link,
//! a marker per modelled contact and a normal segment per contact. The files are read back
//! by other parsers: `tobj` for OBJ + MTL, the `gltf` crate (which validates the document)
//! for glTF.

use base64::prelude::{BASE64_STANDARD, Engine as _};
use graspopt_sim::hand::hand_by_name;
use graspopt_sim::scene::{NamedMesh, scene_meshes};
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

/// The meshes and the number of modelled contacts of a trial's outcome.
fn expected(outcome: &TrialOutcome) -> (Vec<NamedMesh>, usize) {
    let object = Object::by_name("sphere").unwrap();
    let hand = hand_by_name("barrett").unwrap();
    let meshes = scene_meshes(&object, hand.as_ref(), &outcome.grasp).unwrap();
    let contacts = outcome.contacts(ContactModel::Surface, true).len();
    assert!(contacts >= 3, "{contacts}");
    (meshes, contacts)
}

#[test]
fn obj_scene_has_every_mesh_contact_and_normal() {
    let dir = tempdir("obj");
    let path = dir.join("grasp.obj");
    let outcome = sphere_trial(&["--scene", path.to_str().unwrap()]);
    let (meshes, contacts) = expected(&outcome);

    let options = tobj::LoadOptions {
        single_index: true,
        ..Default::default()
    };
    let (models, materials) = tobj::load_obj(&path, &options).unwrap();
    let materials = materials.expect("the MTL next to the OBJ loads");
    assert_eq!(models.len(), meshes.len() + 2);
    for (model, m) in models.iter().zip(&meshes) {
        assert_eq!(model.name, m.name.replace(' ', "_"));
        assert_eq!(
            model.mesh.indices.len(),
            3 * m.mesh.triangles.len(),
            "{}",
            m.name
        );
    }
    // Octahedral markers (8 triangles each) and a two-point segment per contact.
    let (markers, normals) = (&models[meshes.len()], &models[meshes.len() + 1]);
    assert_eq!(
        (markers.name.as_str(), normals.name.as_str()),
        ("contacts", "normals")
    );
    assert_eq!(markers.mesh.indices.len(), 3 * 8 * contacts);
    assert_eq!(markers.mesh.positions.len(), 3 * 6 * contacts);
    assert_eq!(normals.mesh.face_arities, vec![2; contacts]);
    // Every group has its own material, as named in the MTL.
    assert_eq!(materials.len(), meshes.len() + 2);
    let mut used: Vec<usize> = models.iter().map(|m| m.mesh.material_id.unwrap()).collect();
    used.dedup();
    assert_eq!(used.len(), models.len());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn gltf_scene_is_chosen_by_extension() {
    let dir = tempdir("gltf");
    let path = dir.join("grasp.gltf");
    let outcome = sphere_trial(&["--scene", path.to_str().unwrap()]);
    let (meshes, contacts) = expected(&outcome);

    let gltf = gltf::Gltf::from_slice(&std::fs::read(&path).unwrap()).expect("a valid glTF");
    let buffer = gltf.buffers().next().unwrap();
    let gltf::buffer::Source::Uri(uri) = buffer.source() else {
        panic!("the buffer is not embedded");
    };
    let data = BASE64_STANDARD
        .decode(
            uri.strip_prefix("data:application/octet-stream;base64,")
                .unwrap(),
        )
        .unwrap();
    assert_eq!(data.len(), buffer.length());
    let gl: Vec<gltf::Mesh> = gltf.meshes().collect();
    assert_eq!(gl.len(), meshes.len() + 2);
    let positions = |m: &gltf::Mesh| -> Vec<[f32; 3]> {
        let p = m.primitives().next().unwrap();
        p.reader(|_| Some(&data))
            .read_positions()
            .unwrap()
            .collect()
    };
    for (g, m) in gl.iter().zip(&meshes) {
        let read = positions(g);
        assert_eq!(read.len(), m.mesh.vertices.len(), "{}", m.name);
        let first = m.mesh.vertices[0].map(|v| v as f32);
        assert_eq!(read[0], [first.x, first.y, first.z]);
    }
    assert_eq!(positions(&gl[meshes.len()]).len(), 6 * contacts);
    let normals = gl[meshes.len() + 1].primitives().next().unwrap();
    assert_eq!(normals.mode(), gltf::mesh::Mode::Lines);
    assert_eq!(positions(&gl[meshes.len() + 1]).len(), 2 * contacts);
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
