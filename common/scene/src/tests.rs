//! The written files are read back by other parsers: OBJ + MTL by `tobj`, glTF by the `gltf`
//! crate (which validates the document's references and the positions' bounds) with its
//! accessor reader over the decoded data URI.

use super::*;
use graspopt_sim::TriangleMesh;

fn tetra(offset: f64) -> TriangleMesh {
    TriangleMesh::new(
        vec![
            Point3::new(offset, 0.0, 0.0),
            Point3::new(offset + 1.0, 0.0, 0.0),
            Point3::new(offset, 1.0, 0.0),
            Point3::new(offset, 0.0, 1.0),
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
}

fn named(name: &str, mesh: TriangleMesh) -> NamedMesh {
    NamedMesh {
        name: name.into(),
        mesh,
    }
}

fn contact(p: [f64; 3], normal: Vector3<f64>) -> ContactPoint {
    ContactPoint {
        position: Point3::new(p[0], p[1], p[2]),
        normal,
        weight: 1.0,
    }
}

/// A fresh directory for one test, removed by the test.
fn dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("graspopt-scene-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// tobj's positions (f64: the features of the sim crate's tobj) as triples.
fn points(flat: &[f64]) -> Vec<[f64; 3]> {
    flat.chunks(3).map(|c| [c[0], c[1], c[2]]).collect()
}

fn f32s(points: &[Point3<f64>]) -> Vec<[f32; 3]> {
    points
        .iter()
        .map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect()
}

#[test]
fn obj_reads_back_with_every_group_its_faces_normals_and_colours() {
    let dir = dir("obj");
    let path = dir.join("scene.obj");
    let meshes = vec![named("sphere", tetra(0.0)), named("finger 1", tetra(5.0))];
    let contacts = vec![
        contact([1.0, 2.0, 3.0], Vector3::z()),
        contact([0.0, 0.0, 0.0], -Vector3::x()),
    ];
    write_obj(&path, &meshes, &contacts, 0.5).unwrap();
    let options = tobj::LoadOptions {
        single_index: true,
        ..Default::default()
    };
    let (models, materials) = tobj::load_obj(&path, &options).unwrap();
    let materials = materials.expect("the MTL loads");
    let names: Vec<&str> = models.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["sphere", "finger_1", "contacts", "normals"]);
    // Each mesh as given: its vertices, and its triangles in order.
    for (model, given) in models.iter().zip(&meshes) {
        let m = &model.mesh;
        let corners: Vec<[f64; 3]> = m
            .indices
            .iter()
            .map(|&i| points(&m.positions)[i as usize])
            .collect();
        let want: Vec<[f64; 3]> = given
            .mesh
            .triangles
            .iter()
            .flatten()
            .map(|&i| given.mesh.vertices[i as usize].coords.into())
            .collect();
        assert_eq!(corners, want, "{}", model.name);
    }
    // An octahedron (8 triangles) around each contact.
    let markers = &models[2].mesh;
    assert_eq!(markers.indices.len(), 3 * 2 * MARKER_TRIANGLES);
    assert!(markers.face_arities.iter().all(|&a| a == 3));
    // One segment per contact, from the contact outward (against the normal).
    let normals = &models[3].mesh;
    assert_eq!(normals.face_arities, [2, 2]);
    let ends: Vec<[f64; 3]> = normals
        .indices
        .iter()
        .map(|&i| points(&normals.positions)[i as usize])
        .collect();
    assert_eq!(
        ends,
        [
            [1.0, 2.0, 3.0],
            [1.0, 2.0, 2.5],
            [0.0, 0.0, 0.0],
            [0.5, 0.0, 0.0]
        ]
    );
    // Each group's material: the object's colour, then the links', contacts', normals'.
    let kd: Vec<[f64; 3]> = models
        .iter()
        .map(|m| {
            materials[m.mesh.material_id.expect("a material")]
                .diffuse
                .unwrap()
        })
        .collect();
    assert_eq!(kd, [OBJECT_KD, LINK_KD, CONTACT_KD, NORMAL_KD]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Reads a written glTF with the `gltf` crate: the document (validated) and its buffer.
fn read_gltf(path: &Path) -> (gltf::Document, Vec<u8>) {
    let text = std::fs::read(path).unwrap();
    let gltf = gltf::Gltf::from_slice(&text).expect("a valid glTF document");
    let buffer = gltf.buffers().next().expect("a buffer");
    let gltf::buffer::Source::Uri(uri) = buffer.source() else {
        panic!("the buffer is not embedded");
    };
    let data = BASE64_STANDARD
        .decode(
            uri.strip_prefix("data:application/octet-stream;base64,")
                .expect("a data URI"),
        )
        .unwrap();
    assert_eq!(data.len(), buffer.length());
    (gltf.document, data)
}

#[test]
fn gltf_reads_back_with_every_part_its_bounds_and_colours() {
    let dir = dir("gltf");
    let path = dir.join("scene.gltf");
    let meshes = vec![named("sphere", tetra(0.0)), named("palm", tetra(5.0))];
    let contacts = vec![contact([1.0, 2.0, 3.0], Vector3::z())];
    write_gltf(&path, &meshes, &contacts, 0.5).unwrap();
    let (doc, data) = read_gltf(&path);
    let names: Vec<&str> = doc.meshes().map(|m| m.name().unwrap()).collect();
    assert_eq!(names, ["sphere", "palm", "contacts", "normals"]);
    // The scene: one root node turning z up into y up, with a child node per part.
    let scene = doc.default_scene().expect("a default scene");
    let roots: Vec<gltf::Node> = scene.nodes().collect();
    assert_eq!(roots.len(), 1);
    let (_, rotation, _) = roots[0].transform().decomposed();
    let h = std::f32::consts::FRAC_1_SQRT_2;
    assert_eq!(rotation, [-h, 0.0, 0.0, h]);
    let children: Vec<Option<&str>> = roots[0]
        .children()
        .map(|n| n.mesh().unwrap().name())
        .collect();
    assert_eq!(
        children,
        [
            Some("sphere"),
            Some("palm"),
            Some("contacts"),
            Some("normals")
        ]
    );
    let kds = [OBJECT_KD, LINK_KD, CONTACT_KD, NORMAL_KD];
    for (k, mesh) in doc.meshes().enumerate() {
        let p = mesh.primitives().next().unwrap();
        let reader = p.reader(|_| Some(&data));
        let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
        // The bounds written are those of the positions.
        let bounds = p.bounding_box();
        for axis in 0..3 {
            let lo = positions
                .iter()
                .map(|q| q[axis])
                .fold(f32::INFINITY, f32::min);
            let hi = positions
                .iter()
                .map(|q| q[axis])
                .fold(f32::NEG_INFINITY, f32::max);
            assert_eq!(
                (bounds.min[axis], bounds.max[axis]),
                (lo, hi),
                "{names:?}[{k}]"
            );
        }
        let colour = p.material().pbr_metallic_roughness().base_color_factor();
        assert_eq!(
            colour,
            [kds[k][0] as f32, kds[k][1] as f32, kds[k][2] as f32, 1.0]
        );
        if k < 2 {
            assert_eq!(p.mode(), gltf::mesh::Mode::Triangles);
            assert_eq!(positions, f32s(&meshes[k].mesh.vertices));
            let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
            let want: Vec<u32> = meshes[k].mesh.triangles.iter().flatten().copied().collect();
            assert_eq!(indices, want);
        } else if k == 2 {
            assert_eq!(positions.len(), MARKER_VERTICES);
            let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
            assert_eq!(indices.len(), 3 * MARKER_TRIANGLES);
            // The marker is centred on the contact.
            let centre: Vec<f32> = (0..3)
                .map(|a| positions.iter().map(|q| q[a]).sum::<f32>() / 6.0)
                .collect();
            assert_eq!(centre, [1.0, 2.0, 3.0]);
            // Outward-oriented: each face's normal points away from the centre.
            for t in indices.chunks(3) {
                let [a, b, c] = [0, 1, 2].map(|k| Vector3::from(positions[t[k] as usize]));
                let centroid = (a + b + c) / 3.0 - Vector3::new(1.0, 2.0, 3.0);
                assert!((b - a).cross(&(c - a)).dot(&centroid) > 0.0, "{t:?}");
            }
        } else {
            // The normal segment: from the contact outward, against the normal.
            assert_eq!(p.mode(), gltf::mesh::Mode::Lines);
            assert!(p.indices().is_none());
            assert_eq!(positions, [[1.0, 2.0, 3.0], [1.0, 2.0, 2.5]]);
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn gltf_without_contacts_leaves_out_markers_and_normals() {
    let dir = dir("gltf-empty");
    let path = dir.join("scene.gltf");
    let empty = TriangleMesh::new(Vec::new(), Vec::new());
    let meshes = vec![named("sphere", tetra(0.0)), named("nothing", empty)];
    write_gltf(&path, &meshes, &[], 0.5).unwrap();
    let (doc, _) = read_gltf(&path);
    let names: Vec<&str> = doc.meshes().map(|m| m.name().unwrap()).collect();
    assert_eq!(names, ["sphere"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_bad_vertex_index_is_refused_with_the_mesh_and_path_named() {
    let bad = TriangleMesh::new(vec![Point3::origin(); 3], vec![[0, 1, 7]]);
    let path = Path::new("/tmp/graspopt-scene-never-written.gltf");
    let err = write_gltf(path, &[named("cup", bad)], &[], 0.1).unwrap_err();
    // The error and its sources, as `{:#}` of an `anyhow::Error` prints them.
    let chain = std::iter::successors(Some(&err as &dyn std::error::Error), |e| e.source());
    let message = chain.map(|e| e.to_string()).collect::<Vec<_>>().join(": ");
    assert_eq!(
        message,
        "cannot write the scene /tmp/graspopt-scene-never-written.gltf: mesh cup has a vertex index 7 out of range"
    );
    assert!(
        message.contains("cup")
            && message.contains("7")
            && message.contains(&path.display().to_string()),
        "{message}"
    );
    assert!(!path.exists());
}

#[test]
fn bad_path_is_named() {
    let path = Path::new("/nonexistent-graspopt-dir/scene.obj");
    let err = write_obj(path, &[], &[], 0.01).unwrap_err();
    assert!(format!("{err:#}").contains("/nonexistent-graspopt-dir/scene.obj"));
    let path = Path::new("/nonexistent-graspopt-dir/scene.gltf");
    let err = write_gltf(path, &[], &[], 0.01).unwrap_err();
    assert!(format!("{err:#}").contains("/nonexistent-graspopt-dir/scene.gltf"));
}
