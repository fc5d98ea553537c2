//! User mesh files as CAD tools and scanners write them: float32 STL whose shared corners were
//! rounded apart, binary STL with a `solid` header, meshes in millimetres, and meshes with
//! holes (a precise message, the same every time).

use graspopt_sim::mesh::{self, TriangleMesh};
use graspopt_sim::{Object, SimError};
use nalgebra::Vector3;

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
    // Too small: 0.2 mm across.
    let tiny = mesh::box_mesh(&Vector3::new(1e-4, 1e-4, 1e-4));
    let path = write(&dir, "tiny.stl", &binary_stl(&tiny, b"tiny", |_, _| 0));
    let e = Object::from_file(&path).unwrap_err();
    assert!(matches!(e, SimError::ImplausibleSize { .. }), "{e}");
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
