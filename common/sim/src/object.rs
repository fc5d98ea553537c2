//! The objects grasped in trials: the seven objects of thesis chapter 4 at household scale and
//! user meshes. An object is a union of solid parts (parry shapes), a frame (its pose in the world)
//! and a centre of mass; it answers ray casts, closest-point / signed-distance queries and gives
//! its outward surface normal at a surface point.
//!
//! Object frames: `z` up, origin at the centre of the object's footprint on the table (`z = 0` is
//! the bottom of the object), except user meshes which keep the file's own frame.
//!
//! Built-in objects (metres):
//! - `sphere`: radius 0.035 (exact ball).
//! - `wine_glass`: height 0.15, a solid revolved profile (the bowl is closed and filled): foot
//!   (radius 0.035), stem (radius 0.005), bowl (largest radius 0.037); 48 segments.
//! - `cylinder`: radius 0.03, height 0.12 (exact cylinder).
//! - `mug`: a hollow revolved cup (outer radius 0.035, height 0.095, wall 4 mm, bottom 6 mm, 32
//!   segments) plus a handle (tube of radius 5 mm on a half-ellipse on the `+x` side, away from
//!   the default approach, its ends embedded in the wall).
//! - `cuboid`: 0.06 (x) by 0.05 (y) by 0.12 (z) (exact box).
//! - `rotated_cuboid`: the same box, its frame rotated 45 degrees about the vertical axis.
//! - `star_prism`: a five-pointed star (outer radius 0.04, inner 0.018, one point towards `-x`)
//!   extruded to 0.10 high.
//!
//! User meshes (OBJ/STL, see [`crate::mesh`]) must be closed; a convex one collides through its
//! convex hull, a non-convex one through its triangle mesh (correct, but slower).
//!
//! Unions: for the mug (two overlapping parts) distances and projections are the minimum over the
//! parts, which is exact outside the object; a ray hit on one part that lies inside another part
//! is discarded (only each part's first hit is considered).
//!
//! Two representations: point queries (ray casts, projections, normals) use exact primitives or
//! the triangle mesh; shape-vs-object queries (a hand link's distance and closest points) use a
//! decomposition into convex pieces with the same surface (frusta between the rings of a revolved
//! profile, the blocks of the mug's wall, the star's pentagon and points), because GJK on a few
//! convex pieces is far faster than parry's composite-shape distance on a fine mesh.

use std::path::Path;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query::{self, PointQueryWithLocation, Ray, RayCast};
use parry3d_f64::shape::{Ball, Cuboid, Cylinder, Shape, SharedShape, TriMesh, TriMeshFlags};

use crate::convert::{g2p, iso2pose, p2g, v2g};
use crate::error::{Result, SimError, ensure_finite};
use crate::mesh::{self, TriangleMesh};

/// Segments used for the revolved built-in meshes and for drawing round shapes.
const ROUND_SEGMENTS: usize = 48;

/// The kind of an object: one of the seven built-in objects or a user mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObjectKind {
    /// Ball of radius 0.035.
    Sphere,
    /// Revolved wine glass, 0.15 high.
    WineGlass,
    /// Cylinder, radius 0.03, 0.12 high.
    Cylinder,
    /// Hollow mug with a handle.
    Mug,
    /// Box 0.06 x 0.05 x 0.12.
    Cuboid,
    /// The same box rotated 45 degrees about `z`.
    RotatedCuboid,
    /// Five-pointed star prism.
    StarPrism,
    /// A mesh loaded from a file or given by the caller.
    UserMesh,
}

impl ObjectKind {
    /// The seven built-in objects, in thesis order.
    pub const BUILTIN: [ObjectKind; 7] = [
        ObjectKind::Sphere,
        ObjectKind::WineGlass,
        ObjectKind::Cylinder,
        ObjectKind::Mug,
        ObjectKind::Cuboid,
        ObjectKind::RotatedCuboid,
        ObjectKind::StarPrism,
    ];

    /// The name used by [`Object::by_name`].
    pub fn name(self) -> &'static str {
        match self {
            ObjectKind::Sphere => "sphere",
            ObjectKind::WineGlass => "wine_glass",
            ObjectKind::Cylinder => "cylinder",
            ObjectKind::Mug => "mug",
            ObjectKind::Cuboid => "cuboid",
            ObjectKind::RotatedCuboid => "rotated_cuboid",
            ObjectKind::StarPrism => "star_prism",
            ObjectKind::UserMesh => "user_mesh",
        }
    }
}

/// Parry geometry of one part, in the part's frame.
#[derive(Clone)]
enum PartGeom {
    Ball(Ball),
    Cuboid(Cuboid),
    /// parry's cylinder axis is `y`; the part frame maps it to the object's `z`.
    Cylinder(Cylinder),
    Mesh(Box<MeshGeom>),
}

/// A triangle-mesh part: parry's mesh, the source mesh and its per-triangle outward normals.
#[derive(Clone)]
struct MeshGeom {
    shape: TriMesh,
    mesh: TriangleMesh,
    normals: Vec<Vector>,
}

impl PartGeom {
    fn shape(&self) -> &dyn Shape {
        match self {
            PartGeom::Ball(s) => s,
            PartGeom::Cuboid(s) => s,
            PartGeom::Cylinder(s) => s,
            PartGeom::Mesh(m) => &m.shape,
        }
    }
}

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
fn surface_patches(geom: &PartGeom) -> Vec<SurfacePatch> {
    let flat = |a: Vector, b: Vector, c: Vector| {
        let n = (b - a).cross(c - a).normalize_or(Vector::Z);
        SurfacePatch::new([a, b, c], PatchMap::Flat, n)
    };
    match geom {
        PartGeom::Mesh(m) => m
            .mesh
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
            .collect(),
        PartGeom::Cuboid(c) => {
            let m = mesh::box_mesh(&crate::convert::g2v(c.half_extents));
            m.triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|k| p2g(&m.vertices[k as usize]));
                    flat(a, b, c)
                })
                .collect()
        }
        PartGeom::Ball(b) => {
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
        PartGeom::Cylinder(c) => {
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
    }
}

/// One solid part of an object.
#[derive(Clone)]
struct Part {
    geom: PartGeom,
    /// The exact surface as patches (part frame).
    patches: Vec<SurfacePatch>,
    /// Part frame in the object frame.
    local: Isometry3<f64>,
    /// Part frame in the world (cached from the object pose).
    world: Pose,
    /// World AABB `(mins, maxs)` (cached).
    aabb: (Vector, Vector),
}

impl Part {
    fn new(geom: PartGeom, local: Isometry3<f64>) -> Self {
        let mut part = Self {
            patches: surface_patches(&geom),
            geom,
            world: iso2pose(&local),
            local,
            aabb: (Vector::ZERO, Vector::ZERO),
        };
        part.place(&Isometry3::identity());
        part
    }

    /// Updates the cached world pose and AABB for the object at `object_pose`.
    fn place(&mut self, object_pose: &Isometry3<f64>) {
        self.world = iso2pose(&(object_pose * self.local));
        let a = self.geom.shape().compute_aabb(&self.world);
        self.aabb = (a.mins, a.maxs);
    }

    /// Projection of a world point on this part's surface within `max_dist`:
    /// `(surface point, outward normal, query point inside)`, all in the world.
    fn project(&self, pt: Vector, max_dist: f64) -> Option<(Vector, Vector, bool)> {
        let local = self.world.inverse_transform_point(pt);
        let (proj, normal) = match &self.geom {
            PartGeom::Mesh(m) => {
                let (shape, normals) = (&m.shape, &m.normals);
                let (proj, (tri, _)) = if max_dist == f64::MAX {
                    Some(shape.project_local_point_and_get_location(local, false))
                } else {
                    shape.project_local_point_and_get_location_with_max_dist(local, false, max_dist)
                }?;
                (
                    proj,
                    normals.get(tri as usize).copied().unwrap_or(Vector::Z),
                )
            }
            PartGeom::Cylinder(c) => {
                // Analytic (parry's generic cylinder projection runs GJK).
                let (p, n, inside) = project_on_cylinder(c.radius, c.half_height, local);
                if (p - local).length() > max_dist {
                    return None;
                }
                return Some((
                    self.world.transform_point(p),
                    self.world.transform_vector(n),
                    inside,
                ));
            }
            other => {
                let proj = if max_dist == f64::MAX {
                    Some(other.shape().project_local_point(local, false))
                } else {
                    other
                        .shape()
                        .project_local_point_with_max_dist(local, false, max_dist)
                }?;
                (proj, self.local_normal(proj.point))
            }
        };
        Some((
            self.world.transform_point(proj.point),
            self.world.transform_vector(normal),
            proj.is_inside,
        ))
    }

    /// Outward unit normal at `p_local` (a point on or near this part's surface, part frame).
    fn local_normal(&self, p: Vector) -> Vector {
        match &self.geom {
            PartGeom::Ball(_) => p.normalize_or(Vector::Z),
            PartGeom::Cuboid(c) => {
                let h = c.half_extents;
                let e = [p.x.abs() - h.x, p.y.abs() - h.y, p.z.abs() - h.z];
                let mut k = 0;
                for i in 1..3 {
                    if e[i] > e[k] {
                        k = i;
                    }
                }
                let mut n = Vector::ZERO;
                n[k] = if p[k] >= 0.0 { 1.0 } else { -1.0 };
                n
            }
            PartGeom::Cylinder(c) => {
                let radial = Vector::new(p.x, 0.0, p.z);
                let rho = radial.length();
                if p.y.abs() - c.half_height > rho - c.radius || rho < 1e-12 {
                    Vector::new(0.0, p.y.signum(), 0.0)
                } else {
                    radial / rho
                }
            }
            PartGeom::Mesh(m) => {
                let (_, (tri, _)) = m.shape.project_local_point_and_get_location(p, false);
                m.normals.get(tri as usize).copied().unwrap_or(Vector::Z)
            }
        }
    }
}

/// A convex piece (or, for non-convex user meshes, the whole mesh) used for shape-vs-object
/// distance queries: parry's composite-shape distance on a fine triangle mesh is two orders of
/// magnitude slower than GJK on a few convex pieces.
#[derive(Clone)]
struct CollisionPart {
    shape: SharedShape,
    local: Isometry3<f64>,
    world: Pose,
    /// World AABB (mins, maxs).
    aabb_world: (Vector, Vector),
}

impl CollisionPart {
    fn new(shape: SharedShape, local: Isometry3<f64>) -> Self {
        let world = iso2pose(&local);
        let wa = shape.compute_aabb(&world);
        Self {
            shape,
            world,
            local,
            aabb_world: (wa.mins, wa.maxs),
        }
    }

    /// A convex piece from points in the object frame.
    fn hull(points: &[Point3<f64>], what: &str) -> Result<Self> {
        let pts: Vec<Vector> = points.iter().map(p2g).collect();
        let shape = SharedShape::convex_hull(&pts)
            .ok_or_else(|| SimError::InvalidInput(format!("degenerate convex piece of {what}")))?;
        Ok(Self::new(shape, Isometry3::identity()))
    }
}

/// A graspable rigid object.
#[derive(Clone)]
pub struct Object {
    name: String,
    kind: ObjectKind,
    pose: Isometry3<f64>,
    parts: Vec<Part>,
    collision: Vec<CollisionPart>,
    com_local: Point3<f64>,
    /// Bounding sphere in the object frame (centre, radius), for cheap distance bounds.
    bsphere_local: (Point3<f64>, f64),
    bsphere_world: (Vector, f64),
}

impl std::fmt::Debug for Object {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Object")
            .field("name", &self.name)
            .field("kind", &self.kind)
            .field("pose", &self.pose)
            .field("parts", &self.parts.len())
            .finish()
    }
}

/// A ray hit on an object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// Distance along the (unit) ray direction.
    pub distance: f64,
    /// The hit point (world).
    pub point: Point3<f64>,
    /// The object's OUTWARD unit surface normal there (world).
    pub outward_normal: Vector3<f64>,
}

/// The projection of a point onto an object's surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// Closest surface point (world).
    pub point: Point3<f64>,
    /// Outward unit surface normal at `point` (world).
    pub outward_normal: Vector3<f64>,
    /// Signed distance of the query point (negative inside the object).
    pub signed_distance: f64,
}

impl Object {
    /// Names of the built-in objects.
    pub fn names() -> Vec<&'static str> {
        ObjectKind::BUILTIN.iter().map(|k| k.name()).collect()
    }

    /// A built-in object by name (`sphere`, `wine_glass`, `cylinder`, `mug`, `cuboid`,
    /// `rotated_cuboid`, `star_prism`; `-` and `_` are interchangeable, case is ignored).
    pub fn by_name(name: &str) -> Result<Object> {
        let norm = name.trim().to_ascii_lowercase().replace('-', "_");
        ObjectKind::BUILTIN
            .iter()
            .find(|k| k.name() == norm)
            .map(|k| Object::builtin(*k))
            .unwrap_or_else(|| {
                Err(SimError::UnknownObject {
                    name: name.to_string(),
                    valid: Object::names().join(", "),
                })
            })
    }

    /// A built-in object (errors only for [`ObjectKind::UserMesh`], which needs a mesh).
    pub fn builtin(kind: ObjectKind) -> Result<Object> {
        let id = Isometry3::identity();
        let up = |z: f64| Isometry3::translation(0.0, 0.0, z);
        let (parts, collision, pose) = match kind {
            ObjectKind::Sphere => {
                let local = up(0.035);
                let part = Part::new(PartGeom::Ball(Ball::new(0.035)), local);
                (
                    vec![part],
                    vec![CollisionPart::new(SharedShape::ball(0.035), local)],
                    id,
                )
            }
            ObjectKind::Cylinder => {
                // parry's cylinder axis is y: rotate it onto z.
                let local = Isometry3::from_parts(
                    Translation3::new(0.0, 0.0, 0.06),
                    UnitQuaternion::from_axis_angle(
                        &Vector3::x_axis(),
                        std::f64::consts::FRAC_PI_2,
                    ),
                );
                let part = Part::new(PartGeom::Cylinder(Cylinder::new(0.06, 0.03)), local);
                (
                    vec![part],
                    vec![CollisionPart::new(SharedShape::cylinder(0.06, 0.03), local)],
                    id,
                )
            }
            ObjectKind::Cuboid | ObjectKind::RotatedCuboid => {
                let local = up(0.06);
                let part = Part::new(
                    PartGeom::Cuboid(Cuboid::new(Vector::new(0.03, 0.025, 0.06))),
                    local,
                );
                let coll = CollisionPart::new(SharedShape::cuboid(0.03, 0.025, 0.06), local);
                let pose = if kind == ObjectKind::RotatedCuboid {
                    Isometry3::rotation(Vector3::z() * std::f64::consts::FRAC_PI_4)
                } else {
                    id
                };
                (vec![part], vec![coll], pose)
            }
            ObjectKind::WineGlass => {
                let profile = [
                    (0.0, 0.0),
                    (0.035, 0.0),
                    (0.035, 0.003),
                    (0.02, 0.005),
                    (0.006, 0.009),
                    (0.005, 0.015),
                    (0.005, 0.068),
                    (0.012, 0.074),
                    (0.024, 0.082),
                    (0.033, 0.095),
                    (0.037, 0.11),
                    (0.036, 0.13),
                    (0.033, 0.15),
                    (0.0, 0.15),
                ];
                let part = mesh_part(mesh::revolve(&profile, ROUND_SEGMENTS), "wine_glass")?;
                // Convex pieces: the frusta between consecutive rings of the profile.
                let mut coll = Vec::new();
                for w in profile.windows(2) {
                    let ((r0, z0), (r1, z1)) = (w[0], w[1]);
                    if (z1 - z0).abs() > 1e-12 {
                        let mut pts = ring(r0, z0, ROUND_SEGMENTS);
                        pts.extend(ring(r1, z1, ROUND_SEGMENTS));
                        coll.push(CollisionPart::hull(&pts, "wine_glass")?);
                    }
                }
                (vec![part], coll, id)
            }
            ObjectKind::Mug => {
                let (ro, ri, h, tb, seg) = (0.035, 0.031, 0.095, 0.006, 32);
                let body = mesh::revolve(
                    &[(0.0, 0.0), (ro, 0.0), (ro, h), (ri, h), (ri, tb), (0.0, tb)],
                    seg,
                );
                let n = 12;
                let sides = 10;
                let path: Vec<Point3<f64>> = (0..=n)
                    .map(|j| {
                        let phi = std::f64::consts::PI * j as f64 / n as f64;
                        Point3::new(
                            ro - 0.002 + 0.025 * phi.sin(),
                            0.0,
                            h / 2.0 + 0.028 * phi.cos(),
                        )
                    })
                    .collect();
                let handle = mesh::tube(&path, 0.005, sides, &Vector3::y());
                let mut coll = Vec::new();
                // Bottom disc, then one convex block per wall segment.
                let mut pts = ring(ro, 0.0, seg);
                pts.extend(ring(ro, tb, seg));
                coll.push(CollisionPart::hull(&pts, "mug")?);
                let outer_lo = ring(ro, tb, seg);
                let outer_hi = ring(ro, h, seg);
                let inner_lo = ring(ri, tb, seg);
                let inner_hi = ring(ri, h, seg);
                for k in 0..seg {
                    let k1 = (k + 1) % seg;
                    let pts: Vec<Point3<f64>> = [&outer_lo, &outer_hi, &inner_lo, &inner_hi]
                        .iter()
                        .flat_map(|r| [r[k], r[k1]])
                        .collect();
                    coll.push(CollisionPart::hull(&pts, "mug")?);
                }
                // Handle: the hull of each pair of consecutive cross-section rings.
                for j in 0..n {
                    let pts = &handle.vertices[j * sides..(j + 2) * sides];
                    coll.push(CollisionPart::hull(pts, "mug handle")?);
                }
                (
                    vec![
                        mesh_part(body, "mug body")?,
                        mesh_part(handle, "mug handle")?,
                    ],
                    coll,
                    id,
                )
            }
            ObjectKind::StarPrism => {
                let (outer, inner, h) = (0.04, 0.018, 0.10);
                let polygon: Vec<(f64, f64)> = (0..10)
                    .map(|i| {
                        let a = std::f64::consts::PI + std::f64::consts::PI * i as f64 / 5.0;
                        let r = if i % 2 == 0 { outer } else { inner };
                        (r * a.cos(), r * a.sin())
                    })
                    .collect();
                let prism = |idx: &[usize]| -> Vec<Point3<f64>> {
                    idx.iter()
                        .flat_map(|&i| {
                            let (x, y) = polygon[i % 10];
                            [Point3::new(x, y, 0.0), Point3::new(x, y, h)]
                        })
                        .collect()
                };
                // Convex pieces: the inner pentagon and the five triangular points.
                let mut coll = vec![CollisionPart::hull(&prism(&[1, 3, 5, 7, 9]), "star_prism")?];
                for t in (0..10).step_by(2) {
                    coll.push(CollisionPart::hull(
                        &prism(&[t + 9, t, t + 1]),
                        "star_prism",
                    )?);
                }
                (
                    vec![mesh_part(
                        mesh::extrude_star_shaped(&polygon, 0.0, h),
                        "star_prism",
                    )?],
                    coll,
                    id,
                )
            }
            ObjectKind::UserMesh => {
                return Err(SimError::InvalidInput(
                    "a user mesh object needs a mesh: use Object::from_mesh or Object::from_file"
                        .to_string(),
                ));
            }
        };
        Object::assemble(kind.name().to_string(), kind, parts, collision, pose)
    }

    /// An object from a closed triangle mesh (validated, oriented outward), in the mesh's frame.
    pub fn from_mesh(name: &str, mesh: TriangleMesh) -> Result<Object> {
        let mesh = mesh.into_closed_solid(name)?;
        let (part, coll) = user_parts(mesh, name)?;
        Object::assemble(
            name.to_string(),
            ObjectKind::UserMesh,
            vec![part],
            coll,
            Isometry3::identity(),
        )
    }

    /// An object from an `.obj` or `.stl` file in metres (see [`mesh::load`]); named after the
    /// file stem. The same as [`Object::from_file_scaled`] with scale 1.
    pub fn from_file(path: &Path) -> Result<Object> {
        Object::from_file_scaled(path, 1.0)
    }

    /// An object from an `.obj` or `.stl` file whose coordinates are multiplied by `scale` (0.001
    /// for a file in millimetres), named after the file stem. A mesh whose bounding radius is
    /// then outside [`PLAUSIBLE_RADIUS`] is refused with [`SimError::ImplausibleSize`], which
    /// names the scale that would fit.
    pub fn from_file_scaled(path: &Path, scale: f64) -> Result<Object> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(SimError::InvalidInput(format!(
                "the mesh scale must be a finite factor > 0, got {scale}"
            )));
        }
        let mut mesh = mesh::load(path)?;
        if scale != 1.0 {
            mesh = mesh.scaled(&Vector3::repeat(scale));
        }
        check_plausible_size(&mesh, &path.display().to_string(), scale)?;
        let name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("user_mesh")
            .to_string();
        let (part, coll) = user_parts(mesh, &name)?;
        Object::assemble(
            name,
            ObjectKind::UserMesh,
            vec![part],
            coll,
            Isometry3::identity(),
        )
    }

    fn assemble(
        name: String,
        kind: ObjectKind,
        parts: Vec<Part>,
        collision: Vec<CollisionPart>,
        pose: Isometry3<f64>,
    ) -> Result<Object> {
        // Centre of mass (uniform density) from parry's mass properties; overlaps of the parts of a
        // union are counted twice (small for the mug's handle ends).
        let mut mass = 0.0;
        let mut acc = Vector3::zeros();
        let mut lo = Point3::new(f64::MAX, f64::MAX, f64::MAX);
        let mut hi = Point3::new(f64::MIN, f64::MIN, f64::MIN);
        for p in &parts {
            let mp = p.geom.shape().mass_properties(1.0);
            let m = mp.mass();
            let c = p.local * g2p(mp.local_com);
            mass += m;
            acc += m * c.coords;
            let aabb = p.geom.shape().compute_aabb(&p.world);
            lo = lo.inf(&g2p(aabb.mins));
            hi = hi.sup(&g2p(aabb.maxs));
        }
        if mass.is_nan() || mass <= 0.0 || !mass.is_finite() {
            return Err(SimError::InvalidInput(format!(
                "object `{name}` has no volume"
            )));
        }
        let centre = nalgebra::center(&lo, &hi);
        let radius = (hi - lo).norm() / 2.0;
        let mut obj = Object {
            name,
            kind,
            pose: Isometry3::identity(),
            parts,
            collision,
            com_local: Point3::from(acc / mass),
            bsphere_local: (centre, radius),
            bsphere_world: (p2g(&centre), radius),
        };
        obj.set_pose(pose)?;
        Ok(obj)
    }

    /// Places the object in the world (its frame's pose).
    pub fn set_pose(&mut self, pose: Isometry3<f64>) -> Result<()> {
        ensure_finite(pose.to_homogeneous().as_slice(), "object pose")?;
        self.pose = pose;
        for p in &mut self.parts {
            p.place(&pose);
        }
        for c in &mut self.collision {
            c.world = iso2pose(&(pose * c.local));
            let wa = c.shape.compute_aabb(&c.world);
            c.aabb_world = (wa.mins, wa.maxs);
        }
        self.bsphere_world = (p2g(&(pose * self.bsphere_local.0)), self.bsphere_local.1);
        Ok(())
    }

    /// The object moved to `pose`.
    pub fn with_pose(mut self, pose: Isometry3<f64>) -> Result<Object> {
        self.set_pose(pose)?;
        Ok(self)
    }

    /// The object's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The object's kind.
    pub fn kind(&self) -> ObjectKind {
        self.kind
    }

    /// The object frame in the world.
    pub fn pose(&self) -> &Isometry3<f64> {
        &self.pose
    }

    /// Centre of mass (uniform density) in the world.
    pub fn centre_of_mass(&self) -> Point3<f64> {
        self.pose * self.com_local
    }

    /// Centre of mass in the object frame.
    pub fn centre_of_mass_local(&self) -> Point3<f64> {
        self.com_local
    }

    /// A characteristic size: the radius of the bounding sphere of the object's box.
    pub fn scale(&self) -> f64 {
        self.bsphere_local.1
    }

    /// Bounding-sphere centre (world) and radius.
    pub fn bounding_sphere(&self) -> (Point3<f64>, f64) {
        (g2p(self.bsphere_world.0), self.bsphere_world.1)
    }

    /// World axis-aligned bounds `(min, max)`.
    pub fn aabb(&self) -> (Point3<f64>, Point3<f64>) {
        let mut lo = Point3::new(f64::MAX, f64::MAX, f64::MAX);
        let mut hi = Point3::new(f64::MIN, f64::MIN, f64::MIN);
        for p in &self.parts {
            let a = p.geom.shape().compute_aabb(&p.world);
            lo = lo.inf(&g2p(a.mins));
            hi = hi.sup(&g2p(a.maxs));
        }
        (lo, hi)
    }

    /// First intersection of the ray `origin + t * dir` (t in `[0, max_distance]`, `dir` need not
    /// be unit) with the object's surface. A ray starting inside hits the surface on its way out.
    pub fn cast_ray(
        &self,
        origin: &Point3<f64>,
        dir: &Vector3<f64>,
        max_distance: f64,
    ) -> Result<Option<RayHit>> {
        ensure_finite(
            &[
                origin.x,
                origin.y,
                origin.z,
                dir.x,
                dir.y,
                dir.z,
                max_distance,
            ],
            "ray",
        )?;
        let Some(u) = dir.try_normalize(1e-300) else {
            return Err(SimError::InvalidInput("ray direction is zero".to_string()));
        };
        Ok(self
            .cast_ray_normal_g(p2g(origin), v2g(&u), max_distance)
            .map(|(t, p, n)| RayHit {
                distance: t,
                point: g2p(p),
                outward_normal: crate::convert::g2v(n),
            }))
    }

    /// Ray cast in parry types with a unit direction: `(t, point, outward normal)` of the first
    /// valid hit (also for rays starting inside the object).
    pub(crate) fn cast_ray_normal_g(
        &self,
        origin: Vector,
        dir: Vector,
        max_t: f64,
    ) -> Option<(f64, Vector, Vector)> {
        let ray = Ray::new(origin, dir);
        let mut best: Option<(f64, Vector, Vector)> = None;
        for (i, p) in self.parts.iter().enumerate() {
            let o = p.world.inverse_transform_point(origin);
            let d = p.world.inverse_transform_vector(dir);
            // Outward normals from the part's own geometry (the triangle's winding for meshes),
            // so that hits from inside the object get outward normals too.
            let hit = match &p.geom {
                PartGeom::Cylinder(c) => ray_cylinder(c.radius, c.half_height, o, d)
                    .filter(|t| *t <= max_t)
                    .map(|t| (t, p.local_normal(o + d * t))),
                PartGeom::Mesh(m) => m
                    .shape
                    .cast_local_ray_and_get_normal(&Ray::new(o, d), max_t, false)
                    .map(|h| {
                        let n = m
                            .normals
                            .get(h.subshape as usize)
                            .copied()
                            .unwrap_or(h.normal);
                        (h.time_of_impact, n)
                    }),
                PartGeom::Cuboid(c) => c
                    .cast_local_ray_and_get_normal(&Ray::new(o, d), max_t, false)
                    .map(|h| {
                        // The face the ray crossed (robust at edges), oriented outward.
                        let hp = o + d * h.time_of_impact;
                        let a = h.normal.abs().max_position();
                        let mut n = Vector::ZERO;
                        n[a] = if hp[a] >= 0.0 { 1.0 } else { -1.0 };
                        (h.time_of_impact, n)
                    }),
                g => g
                    .shape()
                    .cast_local_ray(&Ray::new(o, d), max_t, false)
                    .map(|t| (t, p.local_normal(o + d * t))),
            };
            if let Some((t, n_local)) = hit {
                let point = ray.point_at(t);
                if best.is_some_and(|(bt, _, _)| bt <= t) {
                    continue;
                }
                if self.parts.len() > 1 && self.inside_other_part(i, point) {
                    continue;
                }
                let n = p.world.transform_vector(n_local);
                best = Some((t, point, n));
            }
        }
        best
    }

    /// Each part's index, world pose and surface patches (part frame).
    pub(crate) fn surface_patches(&self) -> impl Iterator<Item = (usize, Pose, &[SurfacePatch])> {
        self.parts
            .iter()
            .enumerate()
            .map(|(i, p)| (i, p.world, p.patches.as_slice()))
    }

    /// Whether the object has more than one part (then surface points of one part may lie inside
    /// another and are not surface points of the object).
    pub(crate) fn is_union(&self) -> bool {
        self.parts.len() > 1
    }

    /// Whether the world point `pt` lies inside a part other than `skip`.
    pub(crate) fn inside_other_part(&self, skip: usize, pt: Vector) -> bool {
        self.parts.iter().enumerate().any(|(j, q)| {
            j != skip && pt.cmpge(q.aabb.0).all() && pt.cmple(q.aabb.1).all() && {
                let proj = q.geom.shape().project_point(&q.world, pt, false);
                proj.is_inside && (proj.point - pt).length() > 1e-9
            }
        })
    }

    /// Closest surface point, outward normal there and signed distance of `p` (negative inside).
    pub fn closest_point(&self, p: &Point3<f64>) -> Result<SurfacePoint> {
        ensure_finite(&[p.x, p.y, p.z], "query point")?;
        let (sp, n, d) = self
            .closest_point_g(p2g(p), f64::MAX)
            .ok_or_else(|| SimError::InvalidInput("closest point query failed".to_string()))?;
        Ok(SurfacePoint {
            point: g2p(sp),
            outward_normal: crate::convert::g2v(n),
            signed_distance: d,
        })
    }

    /// Signed distance from `p` to the surface (negative inside).
    pub fn signed_distance(&self, p: &Point3<f64>) -> Result<f64> {
        Ok(self.closest_point(p)?.signed_distance)
    }

    /// Closest point within `max_dist` in parry types: `(surface point, outward normal, signed distance)`.
    pub(crate) fn closest_point_g(
        &self,
        pt: Vector,
        max_dist: f64,
    ) -> Option<(Vector, Vector, f64)> {
        let mut best: Option<(Vector, Vector, f64, bool)> = None;
        let mut inside_any = false;
        for p in &self.parts {
            if let Some((sp, n, inside)) = p.project(pt, max_dist) {
                let d = (sp - pt).length();
                inside_any |= inside;
                // Outside: nearest part surface. Inside: the deepest part decides (min of SDFs).
                let better = match best {
                    None => true,
                    Some((_, _, bd, binside)) => match (inside, binside) {
                        (true, false) => true,
                        (false, true) => false,
                        (true, true) => d > bd,
                        (false, false) => d < bd,
                    },
                };
                if better {
                    best = Some((sp, n, d, inside));
                }
            }
        }
        let (sp, n, d, _) = best?;
        Some((sp, n, if inside_any { -d } else { d }))
    }

    /// Lower bound of the distance between the object and a ball (centre, radius), cheap.
    pub(crate) fn distance_lower_bound(&self, centre: Vector, radius: f64) -> f64 {
        (centre - self.bsphere_world.0).length() - radius - self.bsphere_world.1
    }

    /// Collision pieces that may lie within `max_dist` of a shape with world AABB `(lo, hi)`,
    /// nearest (by the AABB lower bound) first, with their lower bounds.
    fn candidates(&self, lo: Vector, hi: Vector, max_dist: f64) -> Vec<(f64, usize)> {
        let mut v: Vec<(f64, usize)> = self
            .collision
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let (a, b) = c.aabb_world;
                let gap = (a - hi).max(lo - b).max(Vector::ZERO);
                (gap.length(), i)
            })
            .filter(|(lb, _)| *lb <= max_dist)
            .collect();
        v.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        v
    }

    /// Exact distance (0 when intersecting) between the object and a shape at `pose`.
    pub(crate) fn distance_to_shape(&self, pose: &Pose, shape: &dyn Shape) -> Result<f64> {
        let mut best = f64::MAX;
        let aabb = shape.compute_aabb(pose);
        for (lb, i) in self.candidates(aabb.mins, aabb.maxs, f64::MAX) {
            if lb >= best {
                break;
            }
            let c = &self.collision[i];
            let d = query::distance(pose, shape, &c.world, c.shape.as_ref())
                .map_err(|_| {
                    SimError::UnsupportedQuery(format!("a hand link and `{}`", self.name))
                })?
                .distance;
            best = best.min(d);
            if best <= 0.0 {
                break;
            }
        }
        Ok(best)
    }

    /// The object's surface as a triangle mesh in the world (round shapes tessellated).
    pub fn surface_mesh(&self) -> TriangleMesh {
        let mut out = TriangleMesh::default();
        for p in &self.parts {
            let local = match &p.geom {
                PartGeom::Ball(b) => {
                    let n = ROUND_SEGMENTS / 2;
                    let profile: Vec<(f64, f64)> = (0..=n)
                        .map(|i| {
                            let a = std::f64::consts::PI * i as f64 / n as f64;
                            (b.radius * a.sin(), -b.radius * a.cos())
                        })
                        .collect();
                    mesh::revolve(&profile, ROUND_SEGMENTS)
                }
                PartGeom::Cuboid(c) => mesh::box_mesh(&crate::convert::g2v(c.half_extents)),
                PartGeom::Cylinder(c) => {
                    // Revolved about z, then mapped onto parry's y axis.
                    let m = mesh::revolve(
                        &[
                            (0.0, -c.half_height),
                            (c.radius, -c.half_height),
                            (c.radius, c.half_height),
                            (0.0, c.half_height),
                        ],
                        ROUND_SEGMENTS,
                    );
                    m.transformed(&Isometry3::rotation(
                        Vector3::x() * -std::f64::consts::FRAC_PI_2,
                    ))
                }
                PartGeom::Mesh(m) => m.mesh.clone(),
            };
            out.append(&local.transformed(&(self.pose * p.local)));
        }
        out
    }
}

/// Closest point on the surface of a cylinder (axis `y`), outward normal there, and whether `p`
/// is inside.
fn project_on_cylinder(r: f64, hh: f64, p: Vector) -> (Vector, Vector, bool) {
    let rho = p.x.hypot(p.z);
    let radial = if rho > 1e-300 {
        Vector::new(p.x / rho, 0.0, p.z / rho)
    } else {
        Vector::X
    };
    let sy = if p.y >= 0.0 { 1.0 } else { -1.0 };
    let inside = rho <= r && p.y.abs() <= hh;
    if inside {
        let to_side = r - rho;
        let to_cap = hh - p.y.abs();
        if to_side <= to_cap {
            (Vector::new(radial.x * r, p.y, radial.z * r), radial, true)
        } else {
            (
                Vector::new(p.x, sy * hh, p.z),
                Vector::new(0.0, sy, 0.0),
                true,
            )
        }
    } else {
        let cr = rho.min(r);
        let cy = p.y.clamp(-hh, hh);
        let q = Vector::new(radial.x * cr, cy, radial.z * cr);
        let n = if p.y.abs() - hh > rho - r {
            Vector::new(0.0, sy, 0.0)
        } else {
            radial
        };
        (q, n, false)
    }
}

/// First `t >= 0` where the ray `o + t d` crosses the surface of a cylinder (axis `y`), analytic
/// (parry's generic cylinder ray cast runs GJK).
fn ray_cylinder(r: f64, hh: f64, o: Vector, d: Vector) -> Option<f64> {
    let mut best: Option<f64> = None;
    let mut consider = |t: f64| {
        if t >= 0.0 && t.is_finite() && best.is_none_or(|b| t < b) {
            best = Some(t);
        }
    };
    let a = d.x * d.x + d.z * d.z;
    if a > 1e-300 {
        let b = o.x * d.x + o.z * d.z;
        let c = o.x * o.x + o.z * o.z - r * r;
        let disc = b * b - a * c;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            for t in [(-b - sq) / a, (-b + sq) / a] {
                if (o.y + t * d.y).abs() <= hh {
                    consider(t);
                }
            }
        }
    }
    if d.y.abs() > 1e-300 {
        for y in [-hh, hh] {
            let t = (y - o.y) / d.y;
            let (x, z) = (o.x + t * d.x, o.z + t * d.z);
            if x * x + z * z <= r * r {
                consider(t);
            }
        }
    }
    best
}

/// Points of a horizontal ring of `segments` points (the same angles as [`mesh::revolve`]).
fn ring(r: f64, z: f64, segments: usize) -> Vec<Point3<f64>> {
    (0..segments)
        .map(|s| {
            let a = std::f64::consts::TAU * s as f64 / segments as f64;
            Point3::new(r * a.cos(), r * a.sin(), z)
        })
        .collect()
}

/// Query part and collision pieces of a user mesh: its convex hull when the mesh is convex
/// (hull volume within 0.1 % of the mesh's), else the mesh itself (correct but slower).
fn user_parts(mesh: TriangleMesh, name: &str) -> Result<(Part, Vec<CollisionPart>)> {
    let volume = mesh.signed_volume();
    let hull = CollisionPart::hull(&mesh.vertices, name).ok().filter(|h| {
        let hv = h.shape.mass_properties(1.0).mass();
        (hv - volume).abs() <= 1e-3 * volume.abs()
    });
    let part = mesh_part(mesh, name)?;
    let coll = match hull {
        Some(h) => h,
        None => match &part.geom {
            PartGeom::Mesh(m) => {
                CollisionPart::new(SharedShape::new(m.shape.clone()), Isometry3::identity())
            }
            _ => {
                return Err(SimError::InvalidInput(format!(
                    "mesh `{name}` has no triangle mesh part"
                )));
            }
        },
    };
    Ok((part, vec![coll]))
}

/// The bounding radius (half the bounding box's diagonal, metres) a user mesh may have: from
/// a 1 cm marble to a 1 m box, what the hands here can close on.
pub const PLAUSIBLE_RADIUS: (f64, f64) = (0.005, 0.5);

/// Refuses a user mesh whose size is implausible for a hand, naming a unit scale that fits.
fn check_plausible_size(mesh: &TriangleMesh, name: &str, scale: f64) -> Result<()> {
    let Some((lo, hi)) = mesh.bounds() else {
        return Ok(());
    };
    let radius = (hi - lo).norm() / 2.0;
    let (min, max) = PLAUSIBLE_RADIUS;
    if (min..=max).contains(&radius) {
        return Ok(());
    }
    let units = [
        (0.001, "millimetres"),
        (0.01, "centimetres"),
        (0.0254, "inches"),
        (1000.0, "kilometres"),
    ];
    let advice = units
        .iter()
        .find(|(f, _)| (min..=max).contains(&(radius * f)))
        .map(|(f, unit)| {
            format!(
                "if the file is in {unit}, scale it by {} (--mesh-scale {})",
                f * scale,
                f * scale
            )
        })
        .unwrap_or_else(|| {
            "give the factor from the file's units to metres (--mesh-scale S)".to_string()
        });
    let scaled = if scale == 1.0 {
        String::new()
    } else {
        format!(" after scaling by {scale}")
    };
    Err(SimError::ImplausibleSize {
        name: name.to_string(),
        radius,
        scaled,
        min,
        max,
        advice,
    })
}

/// A mesh part (identity frame) from a closed, outward mesh.
fn mesh_part(mesh: TriangleMesh, name: &str) -> Result<Part> {
    mesh.validate_closed(name)?;
    let vertices: Vec<Vector> = mesh.vertices.iter().map(p2g).collect();
    let normals = (0..mesh.triangles.len())
        .map(|i| v2g(&mesh.triangle_normal(i)))
        .collect();
    let shape = TriMesh::with_flags(vertices, mesh.triangles.clone(), TriMeshFlags::ORIENTED)
        .map_err(|e| SimError::NotWatertight {
            name: name.to_string(),
            reason: e.to_string(),
        })?;
    Ok(Part::new(
        PartGeom::Mesh(Box::new(MeshGeom {
            shape,
            mesh,
            normals,
        })),
        Isometry3::identity(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_builtins_build_and_unknown_name_lists_valid_ones() {
        for name in Object::names() {
            let o = Object::by_name(name).unwrap();
            assert_eq!(o.name(), name);
            let (lo, hi) = o.aabb();
            let size = hi - lo;
            assert!(size.max() <= 0.16 && size.min() >= 0.02, "{name}: {size:?}");
            let com = o.centre_of_mass();
            assert!(com.z > 0.0 && com.z < hi.z, "{name}: com {com:?}");
        }
        let e = Object::by_name("teapot").unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, SimError::UnknownObject { .. }));
        assert!(
            msg.contains("teapot") && msg.contains("mug") && msg.contains("star_prism"),
            "{msg}"
        );
        assert!(Object::by_name("Rotated-Cuboid").is_ok());
    }

    #[test]
    fn sphere_queries_are_exact() {
        let s = Object::by_name("sphere").unwrap();
        let c = Point3::new(0.0, 0.0, 0.035);
        let hit = s
            .cast_ray(&Point3::new(-1.0, 0.0, 0.035), &Vector3::x(), 10.0)
            .unwrap()
            .unwrap();
        assert!((hit.point - Point3::new(-0.035, 0.0, 0.035)).norm() < 1e-12);
        assert!((hit.outward_normal + Vector3::x()).norm() < 1e-12);
        assert!((hit.distance - 0.965).abs() < 1e-12);
        let q = Point3::new(0.01, 0.02, 0.05);
        let sp = s.closest_point(&q).unwrap();
        let expect = (q - c).norm() - 0.035;
        assert!((sp.signed_distance - expect).abs() < 1e-12);
        assert!(((sp.point - c).norm() - 0.035).abs() < 1e-12);
        assert!(
            s.cast_ray(&Point3::new(-1.0, 1.0, 0.0), &Vector3::x(), 10.0)
                .unwrap()
                .is_none()
        );
        assert!(s.closest_point(&Point3::new(f64::NAN, 0.0, 0.0)).is_err());
    }

    #[test]
    fn rotated_cuboid_normals_follow_the_frame() {
        let o = Object::by_name("rotated_cuboid").unwrap();
        let hit = o
            .cast_ray(&Point3::new(0.0, -1.0, 0.06), &Vector3::y(), 2.0)
            .unwrap()
            .unwrap();
        // The first hit from -y is the edge region; normals are one of the two rotated faces.
        let n = hit.outward_normal;
        assert!((n.z).abs() < 1e-12 && (n.norm() - 1.0).abs() < 1e-12);
        let c = std::f64::consts::FRAC_1_SQRT_2;
        assert!(
            (n.x.abs() - c).abs() < 1e-9 && (n.y.abs() - c).abs() < 1e-9,
            "{n:?}"
        );
    }

    #[test]
    fn mug_is_hollow_and_has_a_handle() {
        let o = Object::by_name("mug").unwrap();
        // Straight down into the cup: hits the inner bottom at z = 0.006.
        let hit = o
            .cast_ray(&Point3::new(0.0, 0.0, 0.5), &-Vector3::z(), 1.0)
            .unwrap()
            .unwrap();
        assert!((hit.point.z - 0.006).abs() < 1e-9, "{hit:?}");
        // The handle on +x at mid height reaches out to x = 0.033 + 0.025 + 0.005 = 0.063.
        let hit = o
            .cast_ray(&Point3::new(0.5, 0.0, 0.0475), &-Vector3::x(), 1.0)
            .unwrap()
            .unwrap();
        assert!((hit.point.x - 0.063).abs() < 1e-3, "{hit:?}");
        // In the wall (radius 0.031..0.035): inside; in the cup's hollow: outside.
        assert!(o.signed_distance(&Point3::new(0.0, 0.033, 0.05)).unwrap() < 0.0);
        assert!(o.signed_distance(&Point3::new(0.0, 0.0, 0.05)).unwrap() > 0.0);
    }

    #[test]
    fn convex_pieces_match_the_query_surface() {
        // The distance from a tiny ball to the collision pieces must equal the distance to the
        // (mesh) surface used by point queries, for points around each decomposed object.
        let probe = Ball::new(1e-5);
        for name in [
            "wine_glass",
            "mug",
            "star_prism",
            "cylinder",
            "rotated_cuboid",
        ] {
            let o = Object::by_name(name).unwrap();
            let (lo, hi) = o.aabb();
            let mut checked = 0;
            for i in 0..9 {
                for j in 0..9 {
                    for k in 0..9 {
                        let f =
                            |a: f64, b: f64, t: usize| a - 0.01 + (b - a + 0.02) * t as f64 / 8.0;
                        let p = Point3::new(f(lo.x, hi.x, i), f(lo.y, hi.y, j), f(lo.z, hi.z, k));
                        let sd = o.signed_distance(&p).unwrap();
                        if sd <= 2e-3 {
                            continue;
                        }
                        let pose = iso2pose(&Isometry3::translation(p.x, p.y, p.z));
                        let d = o.distance_to_shape(&pose, &probe).unwrap() + 1e-5;
                        assert!(
                            (d - sd).abs() < 1e-6,
                            "{name} at {p:?}: pieces {d}, surface {sd}"
                        );
                        checked += 1;
                    }
                }
            }
            assert!(checked > 100, "{name}: {checked}");
        }
    }
}
