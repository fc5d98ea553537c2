//! A grasp scene for 3D viewers: a grasp's object, hand links, contact points and contact
//! normals as a Wavefront OBJ (with an MTL of one colour per group) or a glTF 2.0 JSON file
//! with its buffer embedded (base64).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use base64::prelude::{BASE64_STANDARD, Engine as _};
use graspopt_sim::ContactPoint;
use graspopt_sim::scene::NamedMesh;
use nalgebra::{Point3, Vector3};

/// Vertices of one contact marker (an octahedron).
pub const MARKER_VERTICES: usize = 6;
/// Triangles of one contact marker.
pub const MARKER_TRIANGLES: usize = 8;

/// Diffuse colours (0..1) of the groups: the first mesh (the object), the other meshes (the
/// hand's links), the contact markers, the normals.
const OBJECT_KD: [f64; 3] = [0.35, 0.55, 0.86];
const LINK_KD: [f64; 3] = [0.90, 0.59, 0.24];
const CONTACT_KD: [f64; 3] = [0.90, 0.08, 0.08];
const NORMAL_KD: [f64; 3] = [0.08, 0.63, 0.16];

/// A name usable in OBJ/MTL statements (no whitespace; never empty).
fn obj_name(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| if c.is_whitespace() { '_' } else { c })
        .collect();
    if s.is_empty() { "unnamed".into() } else { s }
}

/// The MTL file written next to an OBJ: same name, extension `.mtl`.
pub fn mtl_path(obj: &Path) -> PathBuf {
    obj.with_extension("mtl")
}

/// An octahedron of circumradius `r` around `p`, outward-oriented.
fn octahedron(
    p: Point3<f64>,
    r: f64,
) -> ([Point3<f64>; MARKER_VERTICES], [[u32; 3]; MARKER_TRIANGLES]) {
    let v = [
        p + Vector3::x() * r,
        p - Vector3::x() * r,
        p + Vector3::y() * r,
        p - Vector3::y() * r,
        p + Vector3::z() * r,
        p - Vector3::z() * r,
    ];
    let t = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    (v, t)
}

fn vertex(out: &mut String, p: &Point3<f64>) {
    let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
}

/// Writes the scene as a Wavefront OBJ at `path`: one `o`/`g` group per mesh (in order; the
/// first is coloured as the object, the others as hand links), a group `contacts` with an
/// octahedron of radius `normal_length / 8` at each contact, and a group `normals` with one
/// line element per contact from its position `normal_length` outward (along `-normal`, as
/// contact normals point into the object). Colours go to an MTL next to it (see
/// [`mtl_path`]), referenced with `mtllib`. Errors name the path.
pub fn write_obj(
    path: &Path,
    meshes: &[NamedMesh],
    contacts: &[ContactPoint],
    normal_length: f64,
) -> Result<()> {
    let mtl = mtl_path(path);
    let mtl_name = mtl
        .file_name()
        .map_or_else(|| "scene.mtl".into(), |n| n.to_string_lossy().into_owned());
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# graspopt grasp scene: {} meshes, {} contacts (metres, world frame)",
        meshes.len(),
        contacts.len()
    );
    let _ = writeln!(out, "mtllib {}", obj_name(&mtl_name));
    let mut materials = Vec::new();
    // OBJ indices are 1-based and global.
    let mut base = 1usize;
    for (k, m) in meshes.iter().enumerate() {
        let name = obj_name(&m.name);
        let material = format!("m{k}_{name}");
        let _ = writeln!(out, "o {name}\ng {name}\nusemtl {material}");
        materials.push((material, if k == 0 { OBJECT_KD } else { LINK_KD }));
        for v in &m.mesh.vertices {
            vertex(&mut out, v);
        }
        for t in &m.mesh.triangles {
            let _ = writeln!(
                out,
                "f {} {} {}",
                t[0] as usize + base,
                t[1] as usize + base,
                t[2] as usize + base
            );
        }
        base += m.mesh.vertices.len();
    }
    let _ = writeln!(out, "o contacts\ng contacts\nusemtl contacts");
    materials.push(("contacts".into(), CONTACT_KD));
    for c in contacts {
        let (v, t) = octahedron(c.position, normal_length / 8.0);
        for p in &v {
            vertex(&mut out, p);
        }
        for f in &t {
            let _ = writeln!(
                out,
                "f {} {} {}",
                f[0] as usize + base,
                f[1] as usize + base,
                f[2] as usize + base
            );
        }
        base += v.len();
    }
    let _ = writeln!(out, "o normals\ng normals\nusemtl normals");
    materials.push(("normals".into(), NORMAL_KD));
    for c in contacts {
        vertex(&mut out, &c.position);
        vertex(&mut out, &(c.position - c.normal * normal_length));
        let _ = writeln!(out, "l {} {}", base, base + 1);
        base += 2;
    }
    let mut mtl_text = String::from("# graspopt grasp scene colours\n");
    for (name, kd) in &materials {
        let _ = writeln!(
            mtl_text,
            "newmtl {name}\nKa 0 0 0\nKd {} {} {}\nKs 0 0 0\nd 1\nillum 1",
            kd[0], kd[1], kd[2]
        );
    }
    std::fs::write(path, out)
        .with_context(|| format!("cannot write the scene {}", path.display()))?;
    std::fs::write(&mtl, mtl_text)
        .with_context(|| format!("cannot write the scene's materials {}", mtl.display()))?;
    Ok(())
}

/// The scene's triangle parts (name, colour, vertices, triangles): the meshes, then the contact
/// markers as one part `contacts` (the normals, line segments, are handled separately).
type Part = (String, [f64; 3], Vec<Point3<f64>>, Vec<[u32; 3]>);

fn parts(meshes: &[NamedMesh], contacts: &[ContactPoint], normal_length: f64) -> Vec<Part> {
    let mut out: Vec<Part> = meshes
        .iter()
        .enumerate()
        .map(|(k, m)| {
            (
                obj_name(&m.name),
                if k == 0 { OBJECT_KD } else { LINK_KD },
                m.mesh.vertices.clone(),
                m.mesh.triangles.clone(),
            )
        })
        .collect();
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for c in contacts {
        let (v, t) = octahedron(c.position, normal_length / 8.0);
        let base = vertices.len() as u32;
        vertices.extend(v);
        triangles.extend(t.map(|f| f.map(|i| i + base)));
    }
    out.push(("contacts".into(), CONTACT_KD, vertices, triangles));
    out
}

/// Writes the same scene as [`write_obj`] as glTF 2.0 (JSON, buffer embedded as base64): one
/// mesh and node per part (the meshes in order, `contacts` with the octahedral markers, and
/// `normals` as a lines primitive), each with its own colour. The world's `z` (up) becomes
/// glTF's `y` (up) through a rotation on the root node. Parts with nothing to draw (no
/// contacts, an empty mesh) are left out. Errors name the path.
pub fn write_gltf(
    path: &Path,
    meshes: &[NamedMesh],
    contacts: &[ContactPoint],
    normal_length: f64,
) -> Result<()> {
    use serde_json::{Value, json};
    let mut buffer: Vec<u8> = Vec::new();
    let mut views: Vec<Value> = Vec::new();
    let mut accessors: Vec<Value> = Vec::new();
    let mut gl_meshes: Vec<Value> = Vec::new();
    let mut materials: Vec<Value> = Vec::new();
    let mut nodes: Vec<Value> = vec![json!({
        "name": "graspopt scene (world frame, z up)",
        "rotation": [-std::f64::consts::FRAC_1_SQRT_2, 0.0, 0.0, std::f64::consts::FRAC_1_SQRT_2],
        "children": [],
    })];
    // Appends positions (f32) as a buffer view and accessor; returns the accessor index.
    let add_positions = |buffer: &mut Vec<u8>,
                         views: &mut Vec<Value>,
                         accessors: &mut Vec<Value>,
                         points: &[Point3<f64>]| {
        let offset = buffer.len();
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for p in points {
            for k in 0..3 {
                let x = p[k] as f32;
                lo[k] = lo[k].min(x);
                hi[k] = hi[k].max(x);
                buffer.extend_from_slice(&x.to_le_bytes());
            }
        }
        views.push(json!({
            "buffer": 0, "byteOffset": offset, "byteLength": buffer.len() - offset,
            "target": 34962,
        }));
        accessors.push(json!({
            "bufferView": views.len() - 1, "componentType": 5126, "count": points.len(),
            "type": "VEC3", "min": lo, "max": hi,
        }));
        accessors.len() - 1
    };
    let mut add_part = |name: &str, kd: [f64; 3], primitive: Value, nodes: &mut Vec<Value>| {
        let mut primitive = primitive;
        primitive["material"] = json!(materials.len());
        materials.push(json!({
            "name": name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [kd[0], kd[1], kd[2], 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 0.8,
            },
            "doubleSided": true,
        }));
        gl_meshes.push(json!({"name": name, "primitives": [primitive]}));
        nodes.push(json!({"name": name, "mesh": gl_meshes.len() - 1}));
        let child = nodes.len() - 1;
        nodes[0]["children"]
            .as_array_mut()
            .expect("children")
            .push(json!(child));
    };
    for (name, kd, vertices, triangles) in parts(meshes, contacts, normal_length) {
        if vertices.is_empty() || triangles.is_empty() {
            continue;
        }
        if let Some(t) = triangles
            .iter()
            .flatten()
            .find(|&&i| i as usize >= vertices.len())
        {
            anyhow::bail!(
                "cannot write the scene {}: mesh {name} has a vertex index {t} out of range",
                path.display()
            );
        }
        let position = add_positions(&mut buffer, &mut views, &mut accessors, &vertices);
        let offset = buffer.len();
        for i in triangles.iter().flatten() {
            buffer.extend_from_slice(&i.to_le_bytes());
        }
        views.push(json!({
            "buffer": 0, "byteOffset": offset, "byteLength": buffer.len() - offset,
            "target": 34963,
        }));
        accessors.push(json!({
            "bufferView": views.len() - 1, "componentType": 5125,
            "count": triangles.len() * 3, "type": "SCALAR",
        }));
        let primitive = json!({
            "attributes": {"POSITION": position},
            "indices": accessors.len() - 1,
            "mode": 4,
        });
        add_part(&name, kd, primitive, &mut nodes);
    }
    if !contacts.is_empty() {
        let ends: Vec<Point3<f64>> = contacts
            .iter()
            .flat_map(|c| [c.position, c.position - c.normal * normal_length])
            .collect();
        let position = add_positions(&mut buffer, &mut views, &mut accessors, &ends);
        let primitive = json!({"attributes": {"POSITION": position}, "mode": 1});
        add_part("normals", NORMAL_KD, primitive, &mut nodes);
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "graspopt"},
        "scene": 0,
        "scenes": [{"name": "grasp", "nodes": [0]}],
        "nodes": nodes,
        "meshes": gl_meshes,
        "materials": materials,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{
            "byteLength": buffer.len(),
            "uri": format!(
                "data:application/octet-stream;base64,{}",
                BASE64_STANDARD.encode(&buffer)
            ),
        }],
    });
    let text = serde_json::to_string(&doc)?;
    std::fs::write(path, text).with_context(|| format!("cannot write the scene {}", path.display()))
}

#[cfg(test)]
mod tests {
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

    #[test]
    fn obj_groups_counts_and_normals() {
        let dir = std::env::temp_dir().join(format!("graspopt-export-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("scene.obj");
        let meshes = vec![
            NamedMesh {
                name: "sphere".into(),
                mesh: tetra(0.0),
            },
            NamedMesh {
                name: "finger 1".into(),
                mesh: tetra(5.0),
            },
        ];
        let contacts = vec![
            ContactPoint {
                position: Point3::new(1.0, 2.0, 3.0),
                normal: Vector3::z(),
                weight: 1.0,
            },
            ContactPoint {
                position: Point3::new(0.0, 0.0, 0.0),
                normal: -Vector3::x(),
                weight: 1.0,
            },
        ];
        write_obj(&path, &meshes, &contacts, 0.5).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let count = |p: &str| lines.iter().filter(|l| l.starts_with(p)).count();
        assert_eq!(count("v "), 8 + 2 * MARKER_VERTICES + 2 * 2);
        assert_eq!(count("f "), 8 + 2 * MARKER_TRIANGLES);
        assert_eq!(count("l "), 2);
        for g in ["g sphere", "g finger_1", "g contacts", "g normals"] {
            assert!(lines.contains(&g), "{g}");
        }
        assert!(lines.contains(&"mtllib scene.mtl"));
        // Every index refers to a vertex.
        let vs: Vec<[f64; 3]> = lines
            .iter()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|l| {
                let c: Vec<f64> = l.split(' ').map(|x| x.parse().unwrap()).collect();
                [c[0], c[1], c[2]]
            })
            .collect();
        for l in lines
            .iter()
            .filter(|l| l.starts_with("f ") || l.starts_with("l "))
        {
            for i in l[2..].split(' ') {
                let i: usize = i.parse().unwrap();
                assert!(i >= 1 && i <= vs.len(), "{l}");
            }
        }
        // The first normal line goes from the contact outward (against the normal).
        let l: Vec<usize> = lines
            .iter()
            .find(|l| l.starts_with("l "))
            .unwrap()
            .split(' ')
            .skip(1)
            .map(|i| i.parse().unwrap())
            .collect();
        assert_eq!(vs[l[0] - 1], [1.0, 2.0, 3.0]);
        assert_eq!(vs[l[1] - 1], [1.0, 2.0, 2.5]);
        // The second mesh's faces are shifted past the first mesh's vertices.
        assert!(lines.contains(&"f 5 7 6"));
        let mtl = std::fs::read_to_string(dir.join("scene.mtl")).unwrap();
        assert_eq!(mtl.matches("newmtl ").count(), 4);
        for l in lines.iter().filter_map(|l| l.strip_prefix("usemtl ")) {
            assert!(mtl.contains(&format!("newmtl {l}\n")), "{l}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn unbase64(s: &str) -> Vec<u8> {
        BASE64_STANDARD.decode(s).unwrap()
    }

    #[test]
    fn gltf_holds_every_part() {
        let dir = std::env::temp_dir().join(format!("graspopt-gltf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("scene.gltf");
        let meshes = vec![
            NamedMesh {
                name: "sphere".into(),
                mesh: tetra(0.0),
            },
            NamedMesh {
                name: "palm".into(),
                mesh: tetra(5.0),
            },
        ];
        let contacts = vec![ContactPoint {
            position: Point3::new(1.0, 2.0, 3.0),
            normal: Vector3::z(),
            weight: 1.0,
        }];
        write_gltf(&path, &meshes, &contacts, 0.5).unwrap();
        let doc: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        assert_eq!(doc["asset"]["version"], "2.0");
        let names: Vec<&str> = doc["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m["name"].as_str().unwrap())
            .collect();
        assert_eq!(names, ["sphere", "palm", "contacts", "normals"]);
        assert_eq!(doc["nodes"][0]["children"], serde_json::json!([1, 2, 3, 4]));
        let uri = doc["buffers"][0]["uri"].as_str().unwrap();
        let data = unbase64(
            uri.strip_prefix("data:application/octet-stream;base64,")
                .unwrap(),
        );
        assert_eq!(
            data.len() as u64,
            doc["buffers"][0]["byteLength"].as_u64().unwrap()
        );
        let acc = |i: &serde_json::Value| &doc["accessors"][i.as_u64().unwrap() as usize];
        let mut total = 0;
        for (m, (verts, indices, mode)) in doc["meshes"].as_array().unwrap().iter().zip([
            (4, 12, 4),
            (4, 12, 4),
            (6, 24, 4),
            (2, 0, 1),
        ]) {
            let p = &m["primitives"][0];
            assert_eq!(p["mode"], mode);
            let pos = acc(&p["attributes"]["POSITION"]);
            assert_eq!(pos["count"], verts);
            if indices > 0 {
                assert_eq!(acc(&p["indices"])["count"], indices);
            }
            total += verts * 12 + indices * 4;
        }
        assert_eq!(data.len(), total);
        // The normal segment: from the contact outward, against the normal.
        let view =
            &doc["bufferViews"]
                [acc(&doc["meshes"][3]["primitives"][0]["attributes"]["POSITION"])["bufferView"]
                    .as_u64()
                    .unwrap() as usize];
        let off = view["byteOffset"].as_u64().unwrap() as usize;
        let floats: Vec<f32> = data[off..off + 24]
            .chunks(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        assert_eq!(floats, [1.0, 2.0, 3.0, 1.0, 2.0, 2.5]);
        std::fs::remove_dir_all(&dir).unwrap();
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
}
