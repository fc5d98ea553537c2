//! User mesh files as CAD tools and scanners write them: float32 STL whose shared corners were
//! rounded apart, binary STL with a `solid` header, meshes in millimetres, and meshes with
//! holes (a precise message, the same every time).

use graspopt_sim::hand::BarrettOracle;
use graspopt_sim::mesh::{self, TriangleMesh};
use graspopt_sim::pose::reference_pose;
use graspopt_sim::{Object, SimError};
use nalgebra::{Isometry3, Point3, Vector3};

use crate::trials::trial;

/// A binary STL of `mesh` in float32; `nudge(t, c)` is added to the bits of each coordinate
/// of corner `c` of triangle `t` (a CAD exporter that writes each face apart rounds shared
/// corners differently by an ulp or two).
fn binary_stl(mesh: &TriangleMesh, header: &[u8], nudge: impl Fn(usize, usize) -> i32) -> Vec<u8> {
    let mut bytes = vec![b' '; 80];
    bytes[..header.len()].copy_from_slice(header);
    bytes.extend_from_slice(&(mesh.triangles.len() as u32).to_le_bytes());
    for (ti, t) in mesh.triangles.iter().enumerate() {
        bytes.extend_from_slice(&[0u8; 12]);
        for (c, &i) in t.iter().enumerate() {
            let v = mesh.vertices[i as usize];
            for x in [v.x, v.y, v.z] {
                let f = x as f32;
                let bits = f.to_bits() as i64 + nudge(ti, c) as i64;
                let g = if f == 0.0 {
                    f
                } else {
                    f32::from_bits(bits as u32)
                };
                bytes.extend_from_slice(&g.to_le_bytes());
            }
        }
        bytes.extend_from_slice(&[0u8; 2]);
    }
    bytes
}

fn write(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn a_float32_stl_whose_shared_corners_differ_by_an_ulp_loads_closed() {
    let sphere = Object::by_name("sphere").unwrap();
    let surface = sphere.surface_mesh();
    let dir = tempfile::tempdir().unwrap();
    // Odd triangles' corners one ulp up, even ones' one ulp down: no shared corner is
    // bit-identical any more.
    let stl = binary_stl(
        &surface,
        b"exported",
        |t, _| if t % 2 == 0 { -1 } else { 1 },
    );
    let path = write(&dir, "sphere.stl", &stl);
    let loaded = Object::from_file(&path).expect("a closed float32 STL loads");
    let exact = 4.0 / 3.0 * std::f64::consts::PI * 0.035_f64.powi(3);
    let volume = mesh::load(&path).unwrap().signed_volume();
    // The tessellated sphere is a little smaller than the exact one.
    assert!(
        volume > 0.98 * exact && volume < exact,
        "volume {volume} against {exact}"
    );
    assert!((loaded.bounding_sphere().1 - 0.035 * 3f64.sqrt()).abs() < 1e-3);
    // Welding merged the corners: as many vertices as the generated mesh.
    assert_eq!(
        mesh::load(&path).unwrap().vertices.len(),
        surface.welded_within(0.0).vertices.len()
    );
}

#[test]
fn a_binary_stl_whose_header_begins_with_solid_loads() {
    let cube = mesh::box_mesh(&Vector3::new(0.02, 0.02, 0.02));
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        &dir,
        "cad.stl",
        &binary_stl(&cube, b"solid part1", |_, _| 0),
    );
    let o = Object::from_file(&path).unwrap();
    let (lo, hi) = o.aabb();
    assert!((hi - lo - Vector3::repeat(0.04)).norm() < 1e-6);
    // An ASCII file with a bare `solid` line.
    let mut ascii = String::from("solid\n");
    for t in &cube.triangles {
        ascii.push_str("facet normal 0 0 0\nouter loop\n");
        for &i in t {
            let v = cube.vertices[i as usize];
            ascii.push_str(&format!("vertex {} {} {}\n", v.x, v.y, v.z));
        }
        ascii.push_str("endloop\nendfacet\n");
    }
    ascii.push_str("endsolid\n");
    let path = write(&dir, "bare.stl", ascii.as_bytes());
    assert!(Object::from_file(&path).is_ok());
}

#[test]
fn a_mesh_in_millimetres_is_refused_with_the_scale_that_fits() {
    // A 40 mm cube written in millimetres.
    let cube = mesh::box_mesh(&Vector3::new(20.0, 20.0, 20.0));
    let dir = tempfile::tempdir().unwrap();
    let path = write(&dir, "cube_mm.stl", &binary_stl(&cube, b"mm", |_, _| 0));
    let e = Object::from_file(&path).unwrap_err();
    assert!(matches!(e, SimError::ImplausibleSize { .. }), "{e}");
    let msg = e.to_string();
    assert!(msg.contains("cube_mm.stl"), "{msg}");
    assert!(
        msg.contains("millimetres") && msg.contains("--mesh-scale 0.001"),
        "{msg}"
    );
    let o = Object::from_file_scaled(&path, 0.001).unwrap();
    let (lo, hi) = o.aabb();
    assert!((hi - lo - Vector3::repeat(0.04)).norm() < 1e-9, "{lo} {hi}");
    // A wrong factor: the advice is the factor for the file, not one on top of the given one.
    let msg = Object::from_file_scaled(&path, 1000.0)
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("after scaling by 1000")
            && msg
                .contains("if the file is in millimetres, scale it by 0.001 (--mesh-scale 0.001)"),
        "{msg}"
    );
    // A file in metres scaled as if in millimetres.
    let metres = mesh::box_mesh(&Vector3::new(0.02, 0.02, 0.02));
    let path_m = write(&dir, "cube_m.stl", &binary_stl(&metres, b"m", |_, _| 0));
    let msg = Object::from_file_scaled(&path_m, 0.001)
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("if the file is in metres, scale it by 1 (--mesh-scale 1)"),
        "{msg}"
    );
    // Too small: 0.2 mm across.
    let tiny = mesh::box_mesh(&Vector3::new(1e-4, 1e-4, 1e-4));
    let path = write(&dir, "tiny.stl", &binary_stl(&tiny, b"tiny", |_, _| 0));
    let e = Object::from_file(&path).unwrap_err();
    assert!(matches!(e, SimError::ImplausibleSize { .. }), "{e}");
    // Far too small, but solid: refused for its size, not as a mesh that encloses nothing.
    for half in [1e-8, 5e-12] {
        let speck = mesh::box_mesh(&Vector3::new(half, half, half));
        let path = write(&dir, "speck.stl", &binary_stl(&speck, b"speck", |_, _| 0));
        let e = Object::from_file(&path).unwrap_err();
        assert!(matches!(e, SimError::ImplausibleSize { .. }), "{half}: {e}");
    }
    // A bad factor is named.
    for bad in [0.0, -1.0, f64::NAN] {
        let e = Object::from_file_scaled(&path, bad).unwrap_err();
        assert!(e.to_string().contains("mesh scale"), "{e}");
    }
}

#[test]
fn a_mesh_with_holes_gets_the_same_precise_message_every_time() {
    let sphere = Object::by_name("sphere").unwrap().surface_mesh();
    let mut holey = sphere.clone();
    // Five holes far apart.
    for k in 0..5 {
        holey.triangles.remove(k * 300);
    }
    let dir = tempfile::tempdir().unwrap();
    let path = write(&dir, "holey.stl", &binary_stl(&holey, b"holey", |_, _| 0));
    let first = Object::from_file(&path).unwrap_err().to_string();
    assert!(
        first.contains("holey.stl") && first.contains("hole"),
        "{first}"
    );
    assert!(first.contains("repair"), "{first}");
    for _ in 0..8 {
        assert_eq!(Object::from_file(&path).unwrap_err().to_string(), first);
    }
}

#[test]
fn obj_and_stl_meshes_load_and_can_be_grasped() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path().to_path_buf();
    // A 4 cm cube standing on z = 0, as OBJ with quads (1-based indices, one `v/vt/vn` face).
    let obj = "# cube\nv -0.02 -0.02 0\nv 0.02 -0.02 0\nv 0.02 0.02 0\nv -0.02 0.02 0\n\
               v -0.02 -0.02 0.04\nv 0.02 -0.02 0.04\nv 0.02 0.02 0.04\nv -0.02 0.02 0.04\n\
               f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2/1/1 3/1/1 7/1/1 6/1/1\nf 3 4 8 7\nf 4 1 5 8\n";
    let obj_path = dir.join("cube.obj");
    std::fs::write(&obj_path, obj).unwrap();
    // The same cube as binary and ASCII STL (triangles from the generator, each corner repeated).
    let cube = mesh::box_mesh(&Vector3::new(0.02, 0.02, 0.02))
        .transformed(&Isometry3::translation(0.0, 0.0, 0.02));
    let mut bin = vec![0u8; 80];
    bin.extend_from_slice(&(cube.triangles.len() as u32).to_le_bytes());
    let mut ascii = String::from("solid cube\n");
    for t in &cube.triangles {
        bin.extend_from_slice(&[0u8; 12]);
        ascii.push_str(" facet normal 0 0 0\n  outer loop\n");
        for &i in t {
            let v = cube.vertices[i as usize];
            for c in [v.x, v.y, v.z] {
                bin.extend_from_slice(&(c as f32).to_le_bytes());
            }
            ascii.push_str(&format!("   vertex {} {} {}\n", v.x, v.y, v.z));
        }
        bin.extend_from_slice(&[0u8; 2]);
        ascii.push_str("  endloop\n endfacet\n");
    }
    ascii.push_str("endsolid cube\n");
    let bin_path = dir.join("cube_bin.stl");
    let ascii_path = dir.join("cube_ascii.STL");
    std::fs::write(&bin_path, &bin).unwrap();
    std::fs::write(&ascii_path, &ascii).unwrap();

    let hand = BarrettOracle::default();
    for path in [&obj_path, &bin_path, &ascii_path] {
        let o = Object::from_file(path).unwrap();
        let (lo, hi) = o.aabb();
        assert!(
            (lo - Point3::new(-0.02, -0.02, 0.0)).norm() < 1e-6,
            "{path:?}: {lo:?}"
        );
        assert!(
            (hi - Point3::new(0.02, 0.02, 0.04)).norm() < 1e-6,
            "{path:?}: {hi:?}"
        );
        assert!((o.centre_of_mass() - Point3::new(0.0, 0.0, 0.02)).norm() < 1e-6);
        let out = trial(&o, &hand, &reference_pose(&o));
        assert!(out.fingers_in_contact() >= 2, "{path:?}");
    }
    // Errors: unknown extension, missing file, garbage, an open mesh.
    let txt = dir.join("cube.txt");
    std::fs::write(&txt, obj).unwrap();
    assert!(matches!(
        Object::from_file(&txt).unwrap_err(),
        SimError::UnsupportedFormat { .. }
    ));
    assert!(matches!(
        Object::from_file(&dir.join("missing.obj")).unwrap_err(),
        SimError::Io { .. }
    ));
    let junk = dir.join("junk.stl");
    std::fs::write(&junk, b"not a mesh").unwrap();
    assert!(matches!(
        Object::from_file(&junk).unwrap_err(),
        SimError::MeshParse { .. }
    ));
    let holey = dir.join("holey.obj");
    std::fs::write(&holey, obj.replace("f 5 6 7 8\n", "")).unwrap();
    assert!(matches!(
        Object::from_file(&holey).unwrap_err(),
        SimError::NotWatertight { .. }
    ));
    let empty = dir.join("empty.obj");
    std::fs::write(&empty, "# nothing\n").unwrap();
    assert!(matches!(
        Object::from_file(&empty).unwrap_err(),
        SimError::EmptyMesh { .. }
    ));
}
