//! The object's surface as patches: triangles that are exact (meshes, boxes) or map exactly
//! onto a curved surface (sphere, cylinder side and caps).

use super::*;

/// How the corner triangle of a [`SurfacePatch`] maps onto the exact surface (part frame). A
/// point of the corner triangle (a linear combination of the corners) maps to the surface point
/// [`SurfacePatch::point`]; subdividing the corner triangle and mapping the new corners gives
/// triangles that approach the exact surface (second order in their size).
#[derive(Clone, Copy, Debug)]
pub(crate) enum PatchMap {
    /// The triangle is the surface (meshes, boxes, cylinder caps inside the rim polygon).
    Flat,
    /// Central projection onto a sphere of this radius centred at the origin.
    Sphere(f64),
    /// Radial projection onto the side of a cylinder of this radius whose axis is `y`.
    CylinderSide(f64),
    /// A fan triangle (centre, rim point, next rim point) of a cylinder's cap stretched radially
    /// onto the circular sector: `radius`, the unit direction `mid` of the sector's middle and
    /// the distance `chord` from the centre to the fan triangle's outer edge.
    CylinderCap {
        radius: f64,
        mid: Vector,
        chord: f64,
    },
}

/// A triangle of an object part's surface (part frame), exact through its [`PatchMap`].
#[derive(Clone, Debug)]
pub(crate) struct SurfacePatch {
    /// Corners (on the exact surface).
    pub(crate) corners: [Vector; 3],
    /// How points between the corners map onto the surface.
    pub(crate) map: PatchMap,
    /// Outward unit normal of a flat patch or cap.
    normal: Vector,
    /// Bounds `(mins, maxs)` of the mapped patch (part frame).
    pub(crate) aabb: (Vector, Vector),
}

impl SurfacePatch {
    fn new(corners: [Vector; 3], map: PatchMap, normal: Vector) -> Self {
        let mut patch = Self {
            corners,
            map,
            normal,
            aabb: (Vector::ZERO, Vector::ZERO),
        };
        let [a, b, c] = corners;
        let diam = (a - b).length().max((b - c).length()).max((c - a).length());
        let e = Vector::splat(patch.bulge(diam));
        patch.aabb = (a.min(b).min(c) - e, a.max(b).max(c) + e);
        patch
    }

    /// Whether the patch is its corner triangle.
    pub(crate) fn is_flat(&self) -> bool {
        matches!(self.map, PatchMap::Flat)
    }

    /// The surface point of a point `a` of the corner triangle (or of a sub-triangle).
    pub(crate) fn point(&self, a: Vector) -> Vector {
        match self.map {
            PatchMap::Flat => a,
            PatchMap::Sphere(r) => a.normalize_or(Vector::Z) * r,
            PatchMap::CylinderSide(r) => {
                let rho = a.x.hypot(a.z);
                if rho < 1e-300 {
                    a
                } else {
                    Vector::new(a.x * r / rho, a.y, a.z * r / rho)
                }
            }
            PatchMap::CylinderCap { radius, mid, chord } => {
                let rho = a.x.hypot(a.z);
                if rho < 1e-300 {
                    a
                } else {
                    let s = radius * (a.x * mid.x + a.z * mid.z) / (rho * chord);
                    Vector::new(a.x * s, a.y, a.z * s)
                }
            }
        }
    }

    /// Outward unit normal at the surface point `q` of this patch.
    pub(crate) fn outward_normal(&self, q: Vector) -> Vector {
        match self.map {
            PatchMap::Flat | PatchMap::CylinderCap { .. } => self.normal,
            PatchMap::Sphere(_) => q.normalize_or(Vector::Z),
            PatchMap::CylinderSide(_) => Vector::new(q.x, 0.0, q.z).normalize_or(Vector::X),
        }
    }

    /// A bound on how far the mapped surface of a sub-triangle of diameter `diam` lies from the
    /// sub-triangle's corners' plane (0 for flat patches).
    pub(crate) fn bulge(&self, diam: f64) -> f64 {
        match self.map {
            PatchMap::Flat => 0.0,
            PatchMap::Sphere(r) | PatchMap::CylinderSide(r) => {
                if diam < 0.8 * r {
                    diam * diam / r
                } else {
                    r
                }
            }
            PatchMap::CylinderCap { radius, chord, .. } => 2.0 * (radius / chord - 1.0) * radius,
        }
    }
}

/// Surface patches of a part's geometry (part frame).
pub(super) fn surface_patches(geom: &PartGeom) -> Vec<SurfacePatch> {
    match geom {
        PartGeom::Mesh(m) => mesh_patches(m),
        PartGeom::Cuboid(c) => cuboid_patches(c),
        PartGeom::Ball(b) => ball_patches(b),
        PartGeom::Cylinder(c) => cylinder_patches(c),
    }
}

/// A mesh's triangles, each with its outward normal.
fn mesh_patches(m: &MeshGeom) -> Vec<SurfacePatch> {
    m.mesh
        .triangles
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let [a, b, c] = t.map(|k| p2g(&m.mesh.vertices[k as usize]));
            SurfacePatch::new(
                [a, b, c],
                PatchMap::Flat,
                m.normals.get(i).copied().unwrap_or(Vector::Z),
            )
        })
        .collect()
}

/// A box's twelve triangles.
fn cuboid_patches(c: &Cuboid) -> Vec<SurfacePatch> {
    let flat = |a: Vector, b: Vector, c: Vector| {
        let n = (b - a).cross(c - a).normalize_or(Vector::Z);
        SurfacePatch::new([a, b, c], PatchMap::Flat, n)
    };
    let m = mesh::box_mesh(&crate::convert::g2v(c.half_extents));
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| p2g(&m.vertices[k as usize]));
            flat(a, b, c)
        })
        .collect()
}

/// A sphere's patches.
fn ball_patches(b: &Ball) -> Vec<SurfacePatch> {
    // An octahedron subdivided twice (128 triangles), centrally projected.
    let r = b.radius;
    let axes = [Vector::X, Vector::Y, Vector::Z];
    let mut tris: Vec<[Vector; 3]> = Vec::new();
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                tris.push([axes[0] * sx * r, axes[1] * sy * r, axes[2] * sz * r]);
            }
        }
    }
    for _ in 0..2 {
        let mid = |a: Vector, b: Vector| ((a + b) * 0.5).normalize() * r;
        tris = tris
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
            })
            .collect();
    }
    tris.into_iter()
        .map(|t| SurfacePatch::new(t, PatchMap::Sphere(r), Vector::Z))
        .collect()
}

/// A cylinder's patches.
fn cylinder_patches(c: &Cylinder) -> Vec<SurfacePatch> {
    // parry's axis is y. Side: near-square cells; caps: fans of sectors.
    let (r, hh) = (c.radius, c.half_height);
    let n = 32;
    let rows = ((2.0 * hh) / (std::f64::consts::TAU * r / n as f64))
        .ceil()
        .max(1.0) as usize;
    let at = |k: usize, y: f64| {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        Vector::new(r * a.cos(), y, r * a.sin())
    };
    let mut out = Vec::new();
    for k in 0..n {
        for j in 0..rows {
            let y0 = -hh + 2.0 * hh * j as f64 / rows as f64;
            let y1 = -hh + 2.0 * hh * (j + 1) as f64 / rows as f64;
            let (a, b, c2, d) = (at(k, y0), at(k + 1, y0), at(k + 1, y1), at(k, y1));
            out.push(SurfacePatch::new(
                [a, b, c2],
                PatchMap::CylinderSide(r),
                Vector::X,
            ));
            out.push(SurfacePatch::new(
                [a, c2, d],
                PatchMap::CylinderSide(r),
                Vector::X,
            ));
        }
        let a = std::f64::consts::TAU * (k as f64 + 0.5) / n as f64;
        let map = PatchMap::CylinderCap {
            radius: r,
            mid: Vector::new(a.cos(), 0.0, a.sin()),
            chord: r * (std::f64::consts::PI / n as f64).cos(),
        };
        for y in [-hh, hh] {
            out.push(SurfacePatch::new(
                [Vector::new(0.0, y, 0.0), at(k, y), at(k + 1, y)],
                map,
                Vector::new(0.0, y.signum(), 0.0),
            ));
        }
    }
    out
}
