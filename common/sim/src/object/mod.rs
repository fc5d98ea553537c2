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

mod builtin;
mod parts;
mod patch;
#[cfg(test)]
mod tests;

pub use parts::PLAUSIBLE_RADIUS;
use parts::{check_plausible_size, mesh_part, project_on_cylinder, ray_cylinder, ring, user_parts};
pub(crate) use patch::SurfacePatch;
use patch::surface_patches;

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
