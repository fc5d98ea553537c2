//! Triangle meshes: the crate's plain mesh type, closed-mesh validation, small generators used by
//! the built-in objects and hands (box, revolved profile, tube, extruded star-shaped polygon), and
//! loading user meshes from OBJ and STL (ASCII and binary) files or buffers.
//!
//! This is the only module that reads files: OBJ through `tobj`, STL through `stl_io`. Every
//! defect (empty mesh, open or inconsistently oriented mesh, malformed file) is a typed
//! [`SimError`], never a panic, and the same file always gives the same message.
//!
//! Welding: formats that store each triangle's corners apart (STL) or exporters that write
//! each face patch apart (CAD) give coincident vertices that differ in their last bits. Vertices
//! closer than [`WELD_TOLERANCE`] times the mesh's bounding-box diagonal are merged before the
//! closedness check, so a float32 STL of a closed solid loads.

use std::collections::HashMap;
use std::path::Path;

use nalgebra::{Isometry3, Point3, Vector3};

use crate::error::{HullError, Result, SimError};

/// Vertices closer than this fraction of a loaded mesh's bounding-box diagonal are one vertex
/// ([`TriangleMesh::welded`]): about 16 float32 rounding steps, far below any feature a hand
/// can feel (1 nm on a 1 m mesh).
pub const WELD_TOLERANCE: f64 = 1e-6;

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

    /// Merges vertices closer than [`WELD_TOLERANCE`] times the bounding-box diagonal (STL
    /// stores each triangle's corners separately, and float32 files round them apart) and drops
    /// triangles that become degenerate.
    pub fn welded(&self) -> Self {
        let diagonal = self.bounds().map_or(0.0, |(lo, hi)| (hi - lo).norm());
        self.welded_within(WELD_TOLERANCE * diagonal)
    }

    /// Merges vertices at most `tolerance` apart (metres; 0 merges bit-identical ones only),
    /// each onto the first one of its neighbourhood in vertex order, and drops triangles that
    /// become degenerate. Deterministic: the same mesh gives the same result.
    pub fn welded_within(&self, tolerance: f64) -> Self {
        let tol = if tolerance.is_finite() && tolerance > 0.0 {
            tolerance
        } else {
            0.0
        };
        // Cells of side `tol`: two vertices within `tol` are in the same or adjacent cells.
        let cell = |v: &Point3<f64>| -> [i64; 3] {
            if tol > 0.0 {
                [
                    (v.x / tol).floor() as i64,
                    (v.y / tol).floor() as i64,
                    (v.z / tol).floor() as i64,
                ]
            } else {
                // +0.0 normalises -0.0 so that both weld together.
                [
                    (v.x + 0.0).to_bits() as i64,
                    (v.y + 0.0).to_bits() as i64,
                    (v.z + 0.0).to_bits() as i64,
                ]
            }
        };
        let reach: i64 = if tol > 0.0 { 1 } else { 0 };
        let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        let mut vertices: Vec<Point3<f64>> = Vec::new();
        let mut remap = Vec::with_capacity(self.vertices.len());
        for v in &self.vertices {
            let c = cell(v);
            let mut found: Option<u32> = None;
            for dx in -reach..=reach {
                for dy in -reach..=reach {
                    for dz in -reach..=reach {
                        let key = [
                            c[0].wrapping_add(dx),
                            c[1].wrapping_add(dy),
                            c[2].wrapping_add(dz),
                        ];
                        for &r in cells.get(&key).into_iter().flatten() {
                            let w = &vertices[r as usize];
                            let close = if tol > 0.0 {
                                (w - v).norm() <= tol
                            } else {
                                cell(w) == c
                            };
                            if close && found.is_none_or(|f| r < f) {
                                found = Some(r);
                            }
                        }
                    }
                }
            }
            let idx = found.unwrap_or_else(|| {
                vertices.push(*v);
                let i = (vertices.len() - 1) as u32;
                cells.entry(c).or_default().push(i);
                i
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

    /// The mesh with its vertices scaled about the origin, per axis (URDF's `scale`; a
    /// unit change is the same factor on every axis). A negative factor mirrors the mesh,
    /// which reverses its orientation.
    pub fn scaled(&self, scale: &Vector3<f64>) -> Self {
        Self {
            vertices: self
                .vertices
                .iter()
                .map(|v| Point3::from(v.coords.component_mul(scale)))
                .collect(),
            triangles: self.triangles.clone(),
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
        self.check_indices(name)?;
        let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(self.triangles.len() * 3);
        for (ti, t) in self.triangles.iter().enumerate() {
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
        // Defects are reported in triangle order, so a file always gives the same message.
        let at = |i: u32| {
            let v = self.vertices[i as usize];
            format!("{i} ({:.6}, {:.6}, {:.6})", v.x, v.y, v.z)
        };
        for (ti, t) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let count = edges.get(&(a, b)).copied().unwrap_or(0);
                if count > 1 {
                    return Err(SimError::NotWatertight {
                        name: name.to_string(),
                        reason: format!(
                            "the edge from vertex {} to vertex {} (triangle {ti}) is used by {count} triangles in the same direction (non-manifold or inconsistently oriented)",
                            at(a),
                            at(b)
                        ),
                    });
                }
                if !edges.contains_key(&(b, a)) {
                    return Err(SimError::NotWatertight {
                        name: name.to_string(),
                        reason: format!(
                            "the edge from vertex {} to vertex {} borders only triangle {ti} (the mesh has a hole)",
                            at(a),
                            at(b)
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// Refuses a triangle that names a vertex the mesh does not have.
    fn check_indices(&self, name: &str) -> Result<()> {
        let n = self.vertices.len();
        match self
            .triangles
            .iter()
            .position(|t| t.iter().any(|&i| i as usize >= n))
        {
            Some(ti) => Err(SimError::MeshParse {
                name: name.to_string(),
                reason: format!("triangle {ti} has a vertex index out of range ({n} vertices)"),
            }),
            None => Ok(()),
        }
    }

    /// Validates a user mesh ([`TriangleMesh::validate_closed`] after welding) and returns it
    /// oriented outward (flipped if its winding encloses a negative volume).
    pub fn into_closed_solid(self, name: &str) -> Result<Self> {
        // Before welding, which drops a triangle it cannot map (the mesh would then be
        // reported open instead of malformed).
        self.check_indices(name)?;
        let mut mesh = self.welded();
        if mesh.triangles.is_empty() && !self.triangles.is_empty() {
            return Err(SimError::NotWatertight {
                name: name.to_string(),
                reason: "every triangle is degenerate".to_string(),
            });
        }
        mesh.validate_closed(name)?;
        let vol = mesh.signed_volume();
        // Flat relative to its own size (a tiny but solid mesh is refused later, by size,
        // with the unit scale that fits).
        let diagonal = mesh.bounds().map_or(0.0, |(lo, hi)| (hi - lo).norm());
        if vol.is_nan() || vol.abs() <= 1e-12 * diagonal.powi(3) {
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

/// The convex hull of `points` as a closed mesh oriented outward, or why there is none
/// (fewer than four points, a coordinate not finite, points that span no volume, or parry
/// unable to build it from degenerate input: its `convex_hull` would panic there).
pub fn convex_hull(points: &[Point3<f64>]) -> Result<TriangleMesh, HullError> {
    if points.len() < 4 {
        return Err(HullError::TooFewPoints(points.len()));
    }
    if let Some(p) = points
        .iter()
        .find(|p| !p.coords.iter().all(|c| c.is_finite()))
    {
        return Err(HullError::NotFinite(format!("{p:?}")));
    }
    let pts: Vec<_> = points.iter().map(crate::convert::p2g).collect();
    let (vertices, triangles) = parry3d_f64::transformation::try_convex_hull(&pts)
        .map_err(|e| HullError::Degenerate(format!("{e:?}")))?;
    let hull = TriangleMesh::new(
        vertices.into_iter().map(crate::convert::g2p).collect(),
        triangles,
    );
    if hull.triangles.len() >= 4 && hull.signed_volume().abs() > 0.0 {
        Ok(hull.oriented_outward())
    } else {
        Err(HullError::Flat)
    }
}

// ---------------------------------------------------------------------------------------------
// Loading
// ---------------------------------------------------------------------------------------------

/// Loads a closed mesh from an `.obj` or `.stl` file (ASCII or binary STL), welded, validated
/// and oriented outward. Units are taken as metres.
pub fn load(path: &Path) -> Result<TriangleMesh> {
    read(path)?.into_closed_solid(&path.display().to_string())
}

/// Reads an `.obj` or `.stl` file (ASCII or binary STL) as it is: no welding, no validation
/// (link meshes of a hand need not be closed).
pub fn read(path: &Path) -> Result<TriangleMesh> {
    let name = path.display().to_string();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    if ext != "obj" && ext != "stl" {
        return Err(SimError::UnsupportedFormat { path: name });
    }
    let bytes = std::fs::read(path).map_err(|source| SimError::Io {
        path: name.clone(),
        source,
    })?;
    if ext == "obj" {
        parse_obj(&name, &String::from_utf8_lossy(&bytes))
    } else {
        parse_stl(&name, &bytes)
    }
}

/// Parses Wavefront OBJ text with `tobj`: every object and group, polygons fan-triangulated,
/// points and lines ignored. No validation of closedness.
pub fn parse_obj(name: &str, text: &str) -> Result<TriangleMesh> {
    let options = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let mut reader = std::io::BufReader::new(text.as_bytes());
    // Materials are irrelevant to collision geometry: every `mtllib` is answered empty.
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Ok((Vec::new(), Default::default()))
    })
    .map_err(|e| SimError::MeshParse {
        name: name.to_string(),
        reason: format!("not a valid OBJ file: {e}"),
    })?;
    let mut mesh = TriangleMesh::default();
    for model in &models {
        let m = &model.mesh;
        let vertices: Vec<Point3<f64>> = m
            .positions
            .chunks_exact(3)
            .map(|c| Point3::new(c[0], c[1], c[2]))
            .collect();
        let triangles = m
            .indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        mesh.append(&TriangleMesh::new(vertices, triangles));
    }
    Ok(mesh)
}

/// Parses an STL buffer, binary or ASCII, with `stl_io`. Corners are not welded.
///
/// A binary file is recognised by its size (84 bytes plus 50 per triangle) even when its
/// 80-byte header begins with `solid`, as some CAD exporters write it (`stl_io` alone would read
/// such a file as ASCII and fail); an ASCII file may have a bare `solid` line.
pub fn parse_stl(name: &str, bytes: &[u8]) -> Result<TriangleMesh> {
    let err = |reason: String| SimError::MeshParse {
        name: name.to_string(),
        reason,
    };
    let binary = bytes.len() >= 84 && {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        bytes.len() as u64 == 84 + 50 * count
    };
    let mut owned;
    let input: &[u8] = if binary && bytes.starts_with(b"solid") {
        owned = bytes.to_vec();
        owned[..5].copy_from_slice(b"     ");
        &owned
    } else if !binary && (bytes.starts_with(b"solid\n") || bytes.starts_with(b"solid\r\n")) {
        owned = b"solid ".to_vec();
        owned.extend_from_slice(&bytes[5..]);
        &owned
    } else {
        bytes
    };
    if !binary && !input.starts_with(b"solid ") {
        return Err(err(
            "neither a binary STL (its size is not 84 bytes plus 50 per triangle) nor an ASCII STL (no `solid` line)"
                .to_string(),
        ));
    }
    let mut cursor = std::io::Cursor::new(input);
    let indexed = stl_io::read_stl(&mut cursor).map_err(|e| {
        err(format!(
            "not a valid {} STL file: {e}",
            if binary { "binary" } else { "ASCII" }
        ))
    })?;
    let vertices = indexed
        .vertices
        .iter()
        .map(|v| Point3::new(v[0] as f64, v[1] as f64, v[2] as f64))
        .collect();
    let triangles = indexed
        .faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.vertices;
            [a as u32, b as u32, c as u32]
        })
        .collect();
    Ok(TriangleMesh::new(vertices, triangles))
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
    fn a_triangle_naming_a_missing_vertex_is_malformed_not_open() {
        let mut cube = box_mesh(&Vector3::new(0.1, 0.1, 0.1));
        cube.triangles[3][1] = 99;
        let e = cube.into_closed_solid("cube").unwrap_err().to_string();
        assert!(
            e.contains("triangle 3 has a vertex index out of range (8 vertices)"),
            "{e}"
        );
    }

    #[test]
    fn a_hull_of_degenerate_points_is_an_error_not_a_panic() {
        let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
        let same = vec![p(0.1, 0.2, 0.3); 12];
        let line: Vec<_> = (0..12).map(|i| p(f64::from(i) * 0.01, 0.0, 0.0)).collect();
        let flat: Vec<_> = (0..12)
            .map(|i| p(f64::from(i % 4) * 0.01, f64::from(i / 4) * 0.01, 0.0))
            .collect();
        for (what, points) in [("same", same), ("line", line), ("flat", flat)] {
            assert!(convex_hull(&points).is_err(), "{what}: a hull");
        }
        let e = convex_hull(&[p(0.0, 0.0, 0.0); 3]).unwrap_err().to_string();
        assert!(e.contains("3 points are fewer than the four"), "{e}");
        let mut cube: Vec<_> = box_mesh(&Vector3::new(0.1, 0.1, 0.1)).vertices;
        assert_eq!(convex_hull(&cube).unwrap().vertices.len(), 8);
        cube[2].y = f64::NAN;
        assert!(
            convex_hull(&cube)
                .unwrap_err()
                .to_string()
                .contains("not finite")
        );
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
