//! Triangle meshes: the crate's plain mesh type, closed-mesh validation, small generators used by
//! the built-in objects and hands (box, revolved profile, tube, extruded star-shaped polygon), and
//! loading user meshes from OBJ and STL (ASCII and binary) files or buffers.
//!
//! This is the only module that reads files. Every defect (empty mesh, open or inconsistently
//! oriented mesh, malformed line) is a typed [`SimError`], never a panic.

use std::collections::HashMap;
use std::path::Path;

use nalgebra::{Isometry3, Point3, Vector3};

use crate::error::{Result, SimError};

/// An indexed triangle mesh (vertices in metres, counter-clockwise triangles seen from outside
/// for closed meshes built or accepted by this crate).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub vertices: Vec<Point3<f64>>,
    /// Triangles as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// A mesh from its parts (no validation; see [`TriangleMesh::validate_closed`]).
    pub fn new(vertices: Vec<Point3<f64>>, triangles: Vec<[u32; 3]>) -> Self {
        Self {
            vertices,
            triangles,
        }
    }

    /// The mesh with every vertex transformed by `iso`.
    pub fn transformed(&self, iso: &Isometry3<f64>) -> Self {
        Self {
            vertices: self.vertices.iter().map(|v| iso * v).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// Appends another mesh (indices shifted).
    pub fn append(&mut self, other: &TriangleMesh) {
        let base = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }

    fn corners(&self, t: &[u32; 3]) -> [Point3<f64>; 3] {
        [
            self.vertices[t[0] as usize],
            self.vertices[t[1] as usize],
            self.vertices[t[2] as usize],
        ]
    }

    /// Signed enclosed volume (positive for outward-oriented closed meshes). Indices must be valid.
    pub fn signed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = self.corners(t);
                a.coords.dot(&b.coords.cross(&c.coords)) / 6.0
            })
            .sum()
    }

    /// Centroid of the enclosed solid (uniform density) of a closed mesh, `None` if the volume
    /// is (numerically) zero.
    pub fn solid_centroid(&self) -> Option<Point3<f64>> {
        let mut vol = 0.0;
        let mut acc = Vector3::zeros();
        for t in &self.triangles {
            let [a, b, c] = self.corners(t);
            let v = a.coords.dot(&b.coords.cross(&c.coords)) / 6.0;
            vol += v;
            acc += v * (a.coords + b.coords + c.coords) / 4.0;
        }
        (vol.abs() > 1e-18).then(|| Point3::from(acc / vol))
    }

    /// Unit normal of triangle `i` from its winding (zero vector for a degenerate triangle).
    pub fn triangle_normal(&self, i: usize) -> Vector3<f64> {
        match self.triangles.get(i) {
            Some(t) => {
                let [a, b, c] = self.corners(t);
                (b - a)
                    .cross(&(c - a))
                    .try_normalize(0.0)
                    .unwrap_or_else(Vector3::zeros)
            }
            None => Vector3::zeros(),
        }
    }

    /// Axis-aligned bounds `(min, max)`, `None` for a mesh without vertices.
    pub fn bounds(&self) -> Option<(Point3<f64>, Point3<f64>)> {
        let first = *self.vertices.first()?;
        Some(
            self.vertices
                .iter()
                .fold((first, first), |(lo, hi), v| (lo.inf(v), hi.sup(v))),
        )
    }

    /// Merges vertices with bit-identical coordinates (STL stores each triangle's corners
    /// separately) and drops triangles that become degenerate.
    pub fn welded(&self) -> Self {
        let mut map: HashMap<[u64; 3], u32> = HashMap::new();
        let mut vertices = Vec::new();
        let mut remap = Vec::with_capacity(self.vertices.len());
        for v in &self.vertices {
            // +0.0 normalises -0.0 so that both weld together.
            let key = [
                (v.x + 0.0).to_bits(),
                (v.y + 0.0).to_bits(),
                (v.z + 0.0).to_bits(),
            ];
            let idx = *map.entry(key).or_insert_with(|| {
                vertices.push(*v);
                (vertices.len() - 1) as u32
            });
            remap.push(idx);
        }
        let triangles = self
            .triangles
            .iter()
            .filter_map(|t| {
                let r = [
                    *remap.get(t[0] as usize)?,
                    *remap.get(t[1] as usize)?,
                    *remap.get(t[2] as usize)?,
                ];
                (r[0] != r[1] && r[1] != r[2] && r[0] != r[2]).then_some(r)
            })
            .collect();
        Self {
            vertices,
            triangles,
        }
    }

    /// Checks that the mesh is non-empty, finite, has valid indices and is closed and
    /// consistently oriented: every directed edge occurs exactly once and its reverse exactly once.
    pub fn validate_closed(&self, name: &str) -> Result<()> {
        if self.vertices.is_empty() || self.triangles.is_empty() {
            return Err(SimError::EmptyMesh {
                name: name.to_string(),
                vertices: self.vertices.len(),
                triangles: self.triangles.len(),
            });
        }
        if let Some(i) = self
            .vertices
            .iter()
            .position(|v| !v.coords.iter().all(|c| c.is_finite()))
        {
            return Err(SimError::NonFinite {
                what: format!("vertex {i} of mesh `{name}`"),
            });
        }
        let n = self.vertices.len() as u32;
        let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(self.triangles.len() * 3);
        for (ti, t) in self.triangles.iter().enumerate() {
            if t.iter().any(|&i| i >= n) {
                return Err(SimError::MeshParse {
                    name: name.to_string(),
                    reason: format!("triangle {ti} has a vertex index out of range ({n} vertices)"),
                });
            }
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                return Err(SimError::NotWatertight {
                    name: name.to_string(),
                    reason: format!("triangle {ti} repeats a vertex"),
                });
            }
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &count) in &edges {
            if count > 1 {
                return Err(SimError::NotWatertight {
                    name: name.to_string(),
                    reason: format!(
                        "edge {a}-{b} is used {count} times in the same direction (non-manifold or inconsistently oriented)"
                    ),
                });
            }
            if !edges.contains_key(&(b, a)) {
                return Err(SimError::NotWatertight {
                    name: name.to_string(),
                    reason: format!("edge {a}-{b} borders only one triangle (the mesh has a hole)"),
                });
            }
        }
        Ok(())
    }

    /// Validates a user mesh ([`TriangleMesh::validate_closed`] after welding) and returns it
    /// oriented outward (flipped if its winding encloses a negative volume).
    pub fn into_closed_solid(self, name: &str) -> Result<Self> {
        let mut mesh = self.welded();
        if mesh.triangles.is_empty() && !self.triangles.is_empty() {
            return Err(SimError::NotWatertight {
                name: name.to_string(),
                reason: "every triangle is degenerate".to_string(),
            });
        }
        mesh.validate_closed(name)?;
        let vol = mesh.signed_volume();
        if vol.abs() < 1e-15 {
            return Err(SimError::NotWatertight {
                name: name.to_string(),
                reason: "the mesh encloses no volume".to_string(),
            });
        }
        if vol < 0.0 {
            for t in &mut mesh.triangles {
                t.swap(1, 2);
            }
        }
        Ok(mesh)
    }

    /// Flips the winding if the enclosed volume is negative (for generated meshes).
    pub(crate) fn oriented_outward(mut self) -> Self {
        if self.signed_volume() < 0.0 {
            for t in &mut self.triangles {
                t.swap(1, 2);
            }
        }
        self
    }
}

// ---------------------------------------------------------------------------------------------
// Generators
// ---------------------------------------------------------------------------------------------

/// A closed box centred at the origin with the given half extents.
pub fn box_mesh(half: &Vector3<f64>) -> TriangleMesh {
    let mut vertices = Vec::with_capacity(8);
    for i in 0..8u32 {
        let sx = if i & 1 == 0 { -1.0 } else { 1.0 };
        let sy = if i & 2 == 0 { -1.0 } else { 1.0 };
        let sz = if i & 4 == 0 { -1.0 } else { 1.0 };
        vertices.push(Point3::new(sx * half.x, sy * half.y, sz * half.z));
    }
    let quads: [[u32; 4]; 6] = [
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
    ];
    let mut triangles = Vec::with_capacity(12);
    for q in quads {
        triangles.push([q[0], q[1], q[2]]);
        triangles.push([q[0], q[2], q[3]]);
    }
    TriangleMesh::new(vertices, triangles).oriented_outward()
}

/// A closed solid of revolution about the `z` axis. `profile` lists `(radius, z)` pairs; its first
/// and last points must lie on the axis (radius 0) and all others off it. `segments` >= 3.
pub fn revolve(profile: &[(f64, f64)], segments: usize) -> TriangleMesh {
    let segments = segments.max(3);
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    if profile.len() < 3 {
        return TriangleMesh::default();
    }
    let inner = &profile[1..profile.len() - 1];
    let bottom = 0u32;
    vertices.push(Point3::new(0.0, 0.0, profile[0].1));
    for &(r, z) in inner {
        for s in 0..segments {
            let a = std::f64::consts::TAU * s as f64 / segments as f64;
            vertices.push(Point3::new(r * a.cos(), r * a.sin(), z));
        }
    }
    let top = vertices.len() as u32;
    vertices.push(Point3::new(0.0, 0.0, profile[profile.len() - 1].1));
    let ring = |i: usize, s: usize| -> u32 { (1 + i * segments + s % segments) as u32 };
    for s in 0..segments {
        triangles.push([bottom, ring(0, s + 1), ring(0, s)]);
    }
    for i in 0..inner.len().saturating_sub(1) {
        for s in 0..segments {
            triangles.push([ring(i, s), ring(i, s + 1), ring(i + 1, s + 1)]);
            triangles.push([ring(i, s), ring(i + 1, s + 1), ring(i + 1, s)]);
        }
    }
    let last = inner.len() - 1;
    for s in 0..segments {
        triangles.push([top, ring(last, s), ring(last, s + 1)]);
    }
    TriangleMesh::new(vertices, triangles).oriented_outward()
}

/// A closed tube of circular cross-section `radius` along the open polyline `path` (at least two
/// points), with flat end caps. `binormal` must not be parallel to any path segment; it fixes the
/// cross-section frame (use the normal of the plane the path lies in).
pub fn tube(
    path: &[Point3<f64>],
    radius: f64,
    sides: usize,
    binormal: &Vector3<f64>,
) -> TriangleMesh {
    let sides = sides.max(3);
    let n = path.len();
    if n < 2 {
        return TriangleMesh::default();
    }
    let mut vertices = Vec::with_capacity(n * sides + 2);
    for j in 0..n {
        let prev = path[j.saturating_sub(1)];
        let next = path[(j + 1).min(n - 1)];
        let t = (next - prev).try_normalize(0.0).unwrap_or_else(Vector3::z);
        let b = (binormal - t * t.dot(binormal))
            .try_normalize(0.0)
            .unwrap_or_else(Vector3::x);
        let nrm = t.cross(&b);
        for s in 0..sides {
            let a = std::f64::consts::TAU * s as f64 / sides as f64;
            vertices.push(path[j] + radius * (a.cos() * nrm + a.sin() * b));
        }
    }
    let start = vertices.len() as u32;
    vertices.push(path[0]);
    let end = vertices.len() as u32;
    vertices.push(path[n - 1]);
    let ring = |j: usize, s: usize| -> u32 { (j * sides + s % sides) as u32 };
    let mut triangles = Vec::new();
    for j in 0..n - 1 {
        for s in 0..sides {
            triangles.push([ring(j, s), ring(j + 1, s), ring(j + 1, s + 1)]);
            triangles.push([ring(j, s), ring(j + 1, s + 1), ring(j, s + 1)]);
        }
    }
    for s in 0..sides {
        triangles.push([start, ring(0, s), ring(0, s + 1)]);
        triangles.push([end, ring(n - 1, s + 1), ring(n - 1, s)]);
    }
    TriangleMesh::new(vertices, triangles).oriented_outward()
}

/// A prism from a polygon in the `xy` plane that is star-shaped about the origin (every vertex
/// visible from it, counter-clockwise), extruded from `z0` to `z1`.
pub fn extrude_star_shaped(polygon: &[(f64, f64)], z0: f64, z1: f64) -> TriangleMesh {
    let m = polygon.len();
    if m < 3 {
        return TriangleMesh::default();
    }
    let mut vertices = Vec::with_capacity(2 * m + 2);
    for &(x, y) in polygon {
        vertices.push(Point3::new(x, y, z0));
    }
    for &(x, y) in polygon {
        vertices.push(Point3::new(x, y, z1));
    }
    let cb = vertices.len() as u32;
    vertices.push(Point3::new(0.0, 0.0, z0));
    let ct = vertices.len() as u32;
    vertices.push(Point3::new(0.0, 0.0, z1));
    let m32 = m as u32;
    let mut triangles = Vec::with_capacity(4 * m);
    for i in 0..m32 {
        let j = (i + 1) % m32;
        triangles.push([cb, j, i]);
        triangles.push([ct, m32 + i, m32 + j]);
        triangles.push([i, j, m32 + j]);
        triangles.push([i, m32 + j, m32 + i]);
    }
    TriangleMesh::new(vertices, triangles).oriented_outward()
}

/// The convex hull of `points` as a closed mesh oriented outward, `None` when the points span
/// no volume (fewer than four, or all in a plane).
pub fn convex_hull(points: &[Point3<f64>]) -> Option<TriangleMesh> {
    if points.len() < 4
        || points
            .iter()
            .any(|p| !p.coords.iter().all(|c| c.is_finite()))
    {
        return None;
    }
    let pts: Vec<_> = points.iter().map(crate::convert::p2g).collect();
    let (vertices, triangles) = parry3d_f64::transformation::convex_hull(&pts);
    let hull = TriangleMesh::new(
        vertices.into_iter().map(crate::convert::g2p).collect(),
        triangles,
    );
    (hull.triangles.len() >= 4 && hull.signed_volume().abs() > 0.0).then(|| hull.oriented_outward())
}

// ---------------------------------------------------------------------------------------------
// Loading
// ---------------------------------------------------------------------------------------------

/// Loads a closed mesh from an `.obj` or `.stl` file (ASCII or binary STL), validated and
/// oriented outward. Units are taken as metres.
pub fn load(path: &Path) -> Result<TriangleMesh> {
    let name = path.display().to_string();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let bytes = std::fs::read(path).map_err(|source| SimError::Io {
        path: name.clone(),
        source,
    })?;
    let mesh = match ext.as_str() {
        "obj" => {
            let text = String::from_utf8_lossy(&bytes);
            parse_obj(&name, &text)?
        }
        "stl" => parse_stl(&name, &bytes)?,
        _ => return Err(SimError::UnsupportedFormat { path: name }),
    };
    mesh.into_closed_solid(&name)
}

/// Parses Wavefront OBJ text: `v` and `f` records (polygons are fan-triangulated, `a/b/c` and
/// negative indices accepted); everything else is ignored. No validation of closedness.
pub fn parse_obj(name: &str, text: &str) -> Result<TriangleMesh> {
    let err = |line: usize, reason: &str| SimError::MeshParse {
        name: name.to_string(),
        reason: format!("line {line}: {reason}"),
    };
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for (ln, raw) in text.lines().enumerate() {
        let line_no = ln + 1;
        let line = raw.split('#').next().unwrap_or("").trim();
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let mut c = [0.0; 3];
                for slot in &mut c {
                    let tok = it
                        .next()
                        .ok_or_else(|| err(line_no, "vertex with fewer than 3 coordinates"))?;
                    *slot = tok
                        .parse::<f64>()
                        .map_err(|_| err(line_no, "bad vertex coordinate"))?;
                }
                vertices.push(Point3::new(c[0], c[1], c[2]));
            }
            Some("f") => {
                let mut idx = Vec::new();
                for tok in it {
                    let first = tok.split('/').next().unwrap_or("");
                    let i: i64 = first.parse().map_err(|_| err(line_no, "bad face index"))?;
                    let n = vertices.len() as i64;
                    let resolved = if i > 0 {
                        i - 1
                    } else if i < 0 {
                        n + i
                    } else {
                        -1
                    };
                    if resolved < 0 || resolved >= n {
                        return Err(err(line_no, "face index out of range"));
                    }
                    idx.push(resolved as u32);
                }
                if idx.len() < 3 {
                    return Err(err(line_no, "face with fewer than 3 vertices"));
                }
                for k in 1..idx.len() - 1 {
                    triangles.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Ok(TriangleMesh::new(vertices, triangles))
}

/// Parses an STL buffer, binary (detected by its exact size) or ASCII. Corners are not welded.
pub fn parse_stl(name: &str, bytes: &[u8]) -> Result<TriangleMesh> {
    let err = |reason: String| SimError::MeshParse {
        name: name.to_string(),
        reason,
    };
    if bytes.len() >= 84 {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if bytes.len() == 84 + 50 * count {
            let mut mesh = TriangleMesh::default();
            for t in 0..count {
                let rec = &bytes[84 + 50 * t..84 + 50 * (t + 1)];
                let f = |k: usize| {
                    let o = 12 + 4 * k;
                    f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]) as f64
                };
                let base = mesh.vertices.len() as u32;
                for c in 0..3 {
                    mesh.vertices
                        .push(Point3::new(f(3 * c), f(3 * c + 1), f(3 * c + 2)));
                }
                mesh.triangles.push([base, base + 1, base + 2]);
            }
            return Ok(mesh);
        }
    }
    let text = std::str::from_utf8(bytes)
        .map_err(|_| err("neither a binary STL (size mismatch) nor ASCII text".to_string()))?;
    if !text.trim_start().starts_with("solid") {
        return Err(err(
            "neither a binary STL (size mismatch) nor an ASCII STL (no `solid`)".to_string(),
        ));
    }
    let mut mesh = TriangleMesh::default();
    let mut corners: Vec<Point3<f64>> = Vec::with_capacity(3);
    for (ln, raw) in text.lines().enumerate() {
        let mut it = raw.split_whitespace();
        match it.next() {
            Some("vertex") => {
                let mut c = [0.0; 3];
                for slot in &mut c {
                    *slot = it
                        .next()
                        .and_then(|t| t.parse::<f64>().ok())
                        .ok_or_else(|| err(format!("line {}: bad vertex", ln + 1)))?;
                }
                corners.push(Point3::new(c[0], c[1], c[2]));
            }
            Some("endfacet") => {
                if corners.len() != 3 {
                    return Err(err(format!(
                        "line {}: facet with {} vertices",
                        ln + 1,
                        corners.len()
                    )));
                }
                let base = mesh.vertices.len() as u32;
                mesh.vertices.append(&mut corners);
                mesh.triangles.push([base, base + 1, base + 2]);
            }
            _ => {}
        }
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generated_meshes_are_closed_and_outward() {
        let b = box_mesh(&Vector3::new(0.01, 0.02, 0.03));
        b.validate_closed("box").unwrap();
        assert!((b.signed_volume() - 0.02 * 0.04 * 0.06).abs() < 1e-12);
        let cyl = revolve(&[(0.0, 0.0), (0.02, 0.0), (0.02, 0.1), (0.0, 0.1)], 64);
        cyl.validate_closed("cyl").unwrap();
        let exact = std::f64::consts::PI * 0.02 * 0.02 * 0.1;
        assert!((cyl.signed_volume() - exact).abs() / exact < 0.01);
        let t = tube(
            &[
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(0.0, 0.05, 0.0),
                Point3::new(0.0, 0.05, 0.05),
            ],
            0.005,
            12,
            &Vector3::x(),
        );
        t.validate_closed("tube").unwrap();
        assert!(t.signed_volume() > 0.0);
        let star = extrude_star_shaped(
            &[(0.02, 0.0), (0.0, 0.02), (-0.02, 0.0), (0.0, -0.02)],
            0.0,
            0.1,
        );
        star.validate_closed("star").unwrap();
        assert!((star.signed_volume() - 0.0008 * 0.1).abs() < 1e-12);
    }

    #[test]
    fn open_mesh_is_rejected() {
        let mut b = box_mesh(&Vector3::new(0.01, 0.01, 0.01));
        b.triangles.pop();
        let e = b.into_closed_solid("holey").unwrap_err();
        assert!(matches!(e, SimError::NotWatertight { .. }), "{e}");
        assert!(e.to_string().contains("holey"));
        let e = TriangleMesh::default()
            .into_closed_solid("nothing")
            .unwrap_err();
        assert!(matches!(e, SimError::EmptyMesh { .. }), "{e}");
    }

    #[test]
    fn inward_mesh_is_flipped() {
        let mut b = box_mesh(&Vector3::new(0.01, 0.01, 0.01));
        for t in &mut b.triangles {
            t.swap(1, 2);
        }
        assert!(b.signed_volume() < 0.0);
        let fixed = b.into_closed_solid("inward").unwrap();
        assert!(fixed.signed_volume() > 0.0);
    }
}
