//! A grasp scene for 3D viewers: a grasp's object, hand links, contact points and contact
//! normals as a Wavefront OBJ (with an MTL of one colour per group) or a glTF 2.0 JSON file
//! built with `gltf-json`'s types, its buffer embedded as a base64 data URI.
//!
//! Compile cost of `gltf-json` on the 2-core build machine (`cargo clean -p gltf-json -p
//! gltf-derive -p inflections -p graspopt-scene`, then `cargo build -p graspopt-scene
//! --timings`, dev profile): gltf-json 39.9 s (mostly its serde derives), gltf-derive and
//! inflections 0.4 s each, this crate 3.8 s instead of 2.3 s with the hand-written JSON.
//! gltf-json also turns on serde_json's `raw_value` feature for every crate built with it.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use base64::prelude::{BASE64_STANDARD, Engine as _};
use gltf_json as json;
use graspopt_sim::ContactPoint;
use graspopt_sim::scene::NamedMesh;
use json::validation::Checked::Valid;
use nalgebra::{Point3, Vector3};

mod error;

pub use error::SceneError;

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
) -> Result<(), SceneError> {
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
    std::fs::write(path, out).map_err(|e| SceneError::Write {
        path: path.to_path_buf(),
        source: Box::new(e),
    })?;
    std::fs::write(&mtl, mtl_text(&materials)).map_err(|source| SceneError::WriteMaterials {
        path: mtl.clone(),
        source,
    })?;
    Ok(())
}

/// The MTL file of the scene's `materials` (name, diffuse colour).
fn mtl_text(materials: &[(String, [f64; 3])]) -> String {
    let mut mtl_text = String::from("# graspopt grasp scene colours\n");
    for (name, kd) in materials {
        let _ = writeln!(
            mtl_text,
            "newmtl {name}\nKa 0 0 0\nKd {} {} {}\nKs 0 0 0\nd 1\nillum 1",
            kd[0], kd[1], kd[2]
        );
    }
    mtl_text
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

/// The glTF document being built: the JSON root, the bytes of its one buffer, and the root
/// node the parts hang from.
struct Gltf {
    root: json::Root,
    buffer: Vec<u8>,
    top: json::Index<json::Node>,
}

impl Gltf {
    fn new() -> Self {
        let mut root = json::Root {
            asset: json::Asset {
                generator: Some("graspopt".into()),
                ..Default::default()
            },
            ..Default::default()
        };
        let h = std::f32::consts::FRAC_1_SQRT_2;
        let top = root.push(json::Node {
            name: Some("graspopt scene (world frame, z up)".into()),
            rotation: Some(json::scene::UnitQuaternion([-h, 0.0, 0.0, h])),
            children: Some(Vec::new()),
            ..Default::default()
        });
        Self {
            root,
            buffer: Vec::new(),
            top,
        }
    }

    /// Appends `bytes` to the buffer as a view for `target`.
    fn view(
        &mut self,
        bytes: &[u8],
        target: json::buffer::Target,
    ) -> json::Index<json::buffer::View> {
        let offset = self.buffer.len();
        self.buffer.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: bytes.len().into(),
            byte_offset: Some(offset.into()),
            byte_stride: None,
            name: None,
            target: Some(Valid(target)),
            extensions: None,
            extras: Default::default(),
        })
    }

    /// An accessor of `count` elements of `kind` over `view`.
    fn accessor(
        &mut self,
        view: json::Index<json::buffer::View>,
        count: usize,
        (component, kind): (json::accessor::ComponentType, json::accessor::Type),
        bounds: Option<([f32; 3], [f32; 3])>,
    ) -> json::Index<json::Accessor> {
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: count.into(),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            type_: Valid(kind),
            min: bounds.map(|b| json::Value::from(b.0.to_vec())),
            max: bounds.map(|b| json::Value::from(b.1.to_vec())),
            name: None,
            normalized: false,
            sparse: None,
            extensions: None,
            extras: Default::default(),
        })
    }

    /// Positions as `f32` triples with their bounds (required by glTF for positions).
    fn positions(&mut self, points: &[Point3<f64>]) -> json::Index<json::Accessor> {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        let mut bytes = Vec::with_capacity(12 * points.len());
        for p in points {
            for k in 0..3 {
                let x = p[k] as f32;
                lo[k] = lo[k].min(x);
                hi[k] = hi[k].max(x);
                bytes.extend_from_slice(&x.to_le_bytes());
            }
        }
        let view = self.view(&bytes, json::buffer::Target::ArrayBuffer);
        let kind = (
            json::accessor::ComponentType::F32,
            json::accessor::Type::Vec3,
        );
        self.accessor(view, points.len(), kind, Some((lo, hi)))
    }

    /// Triangle vertex indices as `u32`.
    fn indices(&mut self, triangles: &[[u32; 3]]) -> json::Index<json::Accessor> {
        let bytes: Vec<u8> = triangles
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let view = self.view(&bytes, json::buffer::Target::ElementArrayBuffer);
        let kind = (
            json::accessor::ComponentType::U32,
            json::accessor::Type::Scalar,
        );
        self.accessor(view, 3 * triangles.len(), kind, None)
    }

    /// A part: its material of colour `kd`, a mesh of one primitive, a node under the top one.
    fn part(
        &mut self,
        name: &str,
        kd: [f64; 3],
        (positions, indices, mode): (
            json::Index<json::Accessor>,
            Option<json::Index<json::Accessor>>,
            json::mesh::Mode,
        ),
    ) {
        let material = self.root.push(json::Material {
            name: Some(name.into()),
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor([
                    kd[0] as f32,
                    kd[1] as f32,
                    kd[2] as f32,
                    1.0,
                ]),
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(0.8),
                ..Default::default()
            },
            double_sided: true,
            ..Default::default()
        });
        let primitive = json::mesh::Primitive {
            attributes: [(Valid(json::mesh::Semantic::Positions), positions)].into(),
            indices,
            material: Some(material),
            mode: Valid(mode),
            targets: None,
            extensions: None,
            extras: Default::default(),
        };
        let mesh = self.root.push(json::Mesh {
            name: Some(name.into()),
            primitives: vec![primitive],
            weights: None,
            extensions: None,
            extras: Default::default(),
        });
        let node = self.root.push(json::Node {
            name: Some(name.into()),
            mesh: Some(mesh),
            ..Default::default()
        });
        let top = self.top.value();
        self.root.nodes[top]
            .children
            .get_or_insert_with(Vec::new)
            .push(node);
    }

    /// The finished document: the buffer as a base64 data URI, one scene of the top node.
    fn finish(mut self) -> json::Root {
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            BASE64_STANDARD.encode(&self.buffer)
        );
        self.root.push(json::Buffer {
            byte_length: self.buffer.len().into(),
            uri: Some(uri),
            name: None,
            extensions: None,
            extras: Default::default(),
        });
        let scene = self.root.push(json::Scene {
            name: Some("grasp".into()),
            nodes: vec![self.top],
            extensions: None,
            extras: Default::default(),
        });
        self.root.scene = Some(scene);
        self.root
    }
}

/// The scene of [`write_gltf`] as a glTF 2.0 document (see there), or what is wrong with the
/// meshes.
pub fn gltf_document(
    meshes: &[NamedMesh],
    contacts: &[ContactPoint],
    normal_length: f64,
) -> Result<json::Root, SceneError> {
    let mut doc = Gltf::new();
    for (name, kd, vertices, triangles) in parts(meshes, contacts, normal_length) {
        if vertices.is_empty() || triangles.is_empty() {
            continue;
        }
        if let Some(t) = triangles
            .iter()
            .flatten()
            .find(|&&i| i as usize >= vertices.len())
        {
            return Err(SceneError::VertexIndex { name, index: *t });
        }
        let positions = doc.positions(&vertices);
        let indices = doc.indices(&triangles);
        doc.part(
            &name,
            kd,
            (positions, Some(indices), json::mesh::Mode::Triangles),
        );
    }
    if !contacts.is_empty() {
        let ends: Vec<Point3<f64>> = contacts
            .iter()
            .flat_map(|c| [c.position, c.position - c.normal * normal_length])
            .collect();
        let positions = doc.positions(&ends);
        doc.part(
            "normals",
            NORMAL_KD,
            (positions, None, json::mesh::Mode::Lines),
        );
    }
    Ok(doc.finish())
}

/// Writes the same scene as [`write_obj`] as glTF 2.0 (JSON, buffer embedded as a base64 data
/// URI), built with `gltf-json`'s types: one mesh, material and node per part (the meshes in
/// order, `contacts` with the octahedral markers, and `normals` as a lines primitive), each
/// with its own colour. The world's `z` (up) becomes glTF's `y` (up) through a rotation on
/// the root node. Parts with nothing to draw (no contacts, an empty mesh) are left out.
/// Errors name the path.
pub fn write_gltf(
    path: &Path,
    meshes: &[NamedMesh],
    contacts: &[ContactPoint],
    normal_length: f64,
) -> Result<(), SceneError> {
    let write = || -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
        let doc = gltf_document(meshes, contacts, normal_length)?;
        let text = json::serialize::to_string(&doc)?;
        std::fs::write(path, text)?;
        Ok(())
    };
    write().map_err(|source| SceneError::Write {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests;
