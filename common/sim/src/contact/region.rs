//! Raw clouds (contact regions): a link's cloud is the part of the object's surface within
//! [`CloudSettings::contact_distance`] (default 1 mm) of the link, computed from the two shapes
//! with no sampling of the link. Each object part's surface is a set of triangles that are exact
//! (meshes, boxes) or map exactly onto the curved surface (sphere, cylinder side and caps, see
//! `SurfacePatch`).
//!
//! - A **box link over a flat triangle** (every link of the built-in hands against meshes,
//!   boxes, prisms): the region in closed form, exact to round-off (`cuboid.rs`).
//! - Otherwise (a ball, cylinder or mesh link, a curved object, a triangle partly inside another
//!   part of a union) each triangle near the link is subdivided adaptively. A triangle is
//!   dropped when its centre is farther from the link than the contact distance plus the
//!   triangle's radius; kept whole when it is within the contact distance (its corners are, on a
//!   flat triangle: the distance to a convex link is convex) and one face of the link is closest
//!   over it; clipped exactly where the corners see one face of the link (the distance is linear
//!   there); elsewhere subdivided down to [`CloudSettings::resolution`] (default 0.2 mm) and
//!   clipped on the linear interpolation of the distance, an error second order in the
//!   resolution. How much halving it moves BW on the 67 x 33 grids of the seven objects is in
//!   docs/benchmarks.md.
//!
//! The distance to a box, cylinder or ball link is computed in closed form, to a convex mesh
//! link and any other shape by parry's point projection (see `LinkQuery`).
//!
//! Each kept piece is a point with a weight, its area; on a flat triangle the pieces with the
//! same normal are merged into one point (the area-weighted centroid, the summed area), so the
//! mean-point model is the region's area-weighted centroid. On a curved patch the pieces within
//! one sub-triangle of at most 16 resolutions across are merged and moved onto the surface (by
//! their sag, second order in the resolution) with the object's normal there.
//!
//! Normals (into the object): on a curved object surface (sphere, cylinder), the object's normal
//! (face against face). On a flat object triangle, where the link's surface is smooth at its
//! point closest to a region point (a face of a box, the side of a cylinder, a sphere), the
//! normal is the link's there,
//! the direction from the link to the point; so an object edge or vertex touching a link face
//! gets the link face's normal, the only well-defined one. Where the closest link point is on a
//! link edge or vertex, the normal is the object's face normal: a link edge touching an object
//! face gets the object's. Face against face, the two agree (the object's face normal). Not
//! resolved: a link face tilted against an object face whose closest feature is the link's edge
//! gives the part of the region under the link face the link's normal, which differs from the
//! object's by the tilt angle.

use parry3d_f64::math::{Matrix, Pose, Vector};
use parry3d_f64::query::Ray;

use super::{CloudSettings, ContactPoint, cuboid};
use crate::convert::{g2p, g2v, iso2pose};
use crate::error::{Result, SimError};
use crate::hand::LinkGeometry;
use crate::object::{Object, SurfacePatch};

/// The deepest subdivision of an object triangle (a safety net: leaves reach
/// [`CloudSettings::resolution`] long before).
const MAX_DEPTH: usize = 30;

/// Two link directions closer than this are the same (the same face of the link).
const SAME_DIRECTION: f64 = 1e-12;

/// A link surface normal within this of the direction to the link is smooth there.
const SMOOTH_TOLERANCE: f64 = 1e-6;

/// What the link looks like from one surface point of the object.
#[derive(Clone, Copy, Debug)]
struct Probe {
    /// The point of the patch's corner triangle (pre-image).
    pre: Vector,
    /// The surface point (part frame).
    q: Vector,
    /// Distance to the link (0 inside it).
    d: f64,
    /// Unit direction from the link's closest point to `q` (zero when `d` is 0).
    u: Vector,
    /// Inside another part of a union (not a surface point of the object).
    hidden: bool,
    /// Whether the link is smooth where it is closest (computed for probes within the contact
    /// distance only; see [`RegionBuilder::link_smooth`]).
    smooth: bool,
}

/// Region pieces of one object triangle (or of one small piece of a curved one): on a flat
/// patch merged when their normals agree, on a curved one all merged.
#[derive(Default)]
struct PatchSums {
    /// Normal of the first piece, area, area-weighted position, area-weighted normal.
    sums: Vec<(Vector, f64, Vector, Vector)>,
    /// Index in `sums` of each normal, rounded to [`SAME_DIRECTION`] (a curved link's pieces
    /// each have their own normal: a linear search made a palm against the mug quadratic).
    by_normal: std::collections::HashMap<[i64; 3], usize>,
    /// Set inside a curved patch's merged piece.
    merging: Option<()>,
}

/// On curved patches, pieces within one sub-triangle of at most this many resolutions across are
/// merged into one point (and whole sub-triangles this small within the contact distance are
/// kept whole).
const CURVED_MERGE: f64 = 16.0;

/// Computes the region of one link against one part of the object.
struct RegionBuilder<'a> {
    object: &'a Object,
    part: usize,
    part_pose: Pose,
    shape: &'a dyn parry3d_f64::shape::Shape,
    /// The link shape's pose in the part frame.
    link: Pose,
    query: LinkQuery,
    d_c: f64,
    h: f64,
}

/// How the distance to a link is computed. A box, a cylinder or a ball (every link of the
/// built-in hands) in closed form: the distance, the direction and whether the closest link
/// point lies on a face come from the point's coordinates in the link frame. A convex mesh and
/// any other shape through parry's point projection. Two measured reasons: the closed forms cut
/// the region's probes (most of a trial's time) several times over, and parry's ray cast on a
/// support-map shape (cylinder, convex mesh) returns the ray's own direction as the normal at an
/// edge, so it cannot tell a face from an edge (the tests compare both).
enum LinkQuery {
    /// A box: the link frame's rotation (columns: its axes in the part frame), its origin and
    /// the half extents.
    Cuboid {
        axes: Matrix,
        origin: Vector,
        half: Vector,
    },
    /// A ball.
    Ball { centre: Vector, radius: f64 },
    /// A cylinder along the link frame's `y` (parry's convention): its axes, origin, radius
    /// and half height.
    Cylinder {
        axes: Matrix,
        origin: Vector,
        radius: f64,
        half_height: f64,
    },
    /// A convex polyhedron (a mesh link): distances by parry; the link is smooth where the
    /// direction to the point is one of its face normals (here in the part frame). Parry's ray
    /// cast returns a normal equal to the ray's direction at an edge or a vertex, so it cannot
    /// tell.
    Polyhedron { normals: Vec<Vector> },
    /// Any other shape (parry).
    General,
}

impl LinkQuery {
    fn new(shape: &dyn parry3d_f64::shape::Shape, link: &Pose) -> Self {
        if let Some(c) = shape.as_cuboid() {
            LinkQuery::Cuboid {
                axes: Matrix::from_quat(link.rotation),
                origin: link.translation,
                half: c.half_extents,
            }
        } else if let Some(b) = shape.as_ball() {
            LinkQuery::Ball {
                centre: link.translation,
                radius: b.radius,
            }
        } else if let Some(c) = shape.as_cylinder() {
            LinkQuery::Cylinder {
                axes: Matrix::from_quat(link.rotation),
                origin: link.translation,
                radius: c.radius,
                half_height: c.half_height,
            }
        } else if let Some(c) = shape.as_convex_polyhedron() {
            LinkQuery::Polyhedron {
                normals: c.faces().iter().map(|f| link.rotation * f.normal).collect(),
            }
        } else {
            LinkQuery::General
        }
    }
}

/// The distance from the probe's point to a box link (axes, origin and half extents in the
/// part frame), its direction and whether the box is smooth there.
fn probe_cuboid(p: &mut Probe, axes: &Matrix, origin: Vector, half: Vector) {
    let local = axes.transpose() * (p.q - origin);
    let excess = (local.abs() - half).max(Vector::ZERO);
    let d2 = excess.length_squared();
    if d2 > 0.0 {
        p.d = d2.sqrt();
        p.u = *axes * (excess * local.signum() / p.d);
        // Smooth where one axis holds the excess: the face's normal then differs
        // from the direction by the other axes' share (the ray test's tolerance).
        let largest = excess.max_element();
        p.smooth = d2 - largest * largest < (SMOOTH_TOLERANCE * p.d) * (SMOOTH_TOLERANCE * p.d);
    }
}

/// The distance from the probe's point to a cylinder link (along its frame's `y`), its
/// direction and whether the cylinder is smooth there.
fn probe_cylinder(p: &mut Probe, axes: &Matrix, origin: Vector, radius: f64, half_height: f64) {
    let local = axes.transpose() * (p.q - origin);
    let rho = local.x.hypot(local.z);
    let side = (rho - radius).max(0.0);
    let cap = (local.y.abs() - half_height).max(0.0);
    let d2 = side * side + cap * cap;
    if d2 > 0.0 {
        p.d = d2.sqrt();
        let radial = if rho > 0.0 {
            Vector::new(local.x / rho, 0.0, local.z / rho)
        } else {
            Vector::ZERO
        };
        let dir = radial * side + Vector::Y * (cap * local.y.signum());
        p.u = *axes * (dir / p.d);
        let smaller = side.min(cap);
        p.smooth = smaller < SMOOTH_TOLERANCE * p.d;
    }
}

impl RegionBuilder<'_> {
    fn probe(&self, patch: &SurfacePatch, pre: Vector) -> Probe {
        let q = patch.point(pre);
        let hidden = self.object.is_union()
            && self
                .object
                .inside_other_part(self.part, self.part_pose.transform_point(q));
        let mut p = Probe {
            pre,
            q,
            d: 0.0,
            u: Vector::ZERO,
            hidden,
            smooth: false,
        };
        match &self.query {
            LinkQuery::Cuboid { axes, origin, half } => probe_cuboid(&mut p, axes, *origin, *half),
            LinkQuery::Cylinder {
                axes,
                origin,
                radius,
                half_height,
            } => probe_cylinder(&mut p, axes, *origin, *radius, *half_height),
            LinkQuery::Ball { centre, radius } => {
                let v = q - *centre;
                let l = v.length();
                if l > *radius {
                    p.d = l - radius;
                    p.u = v / l;
                    p.smooth = true;
                }
            }
            LinkQuery::Polyhedron { .. } | LinkQuery::General => {
                let proj = self.shape.project_point(&self.link, q, true);
                if !proj.is_inside {
                    let v = q - proj.point;
                    p.d = v.length();
                    p.u = if p.d > 0.0 { v / p.d } else { Vector::ZERO };
                }
                if let LinkQuery::Polyhedron { normals } = &self.query {
                    p.smooth = p.d > 0.0
                        && normals
                            .iter()
                            .any(|n| (*n - p.u).length() < SMOOTH_TOLERANCE);
                } else if p.d <= self.d_c {
                    p.smooth = self.smooth_at(&p);
                }
            }
        }
        p
    }

    /// Whether the link is smooth where it is closest to `p` (computed with the probe in closed
    /// form, or by parry within the contact distance).
    fn link_smooth(&self, p: &Probe) -> bool {
        if p.d <= self.d_c || !matches!(self.query, LinkQuery::General) {
            p.smooth
        } else {
            self.smooth_at(p)
        }
    }

    /// Whether the link's surface is smooth (a face, not an edge or vertex) where it is closest
    /// to the probe: its own normal there is the direction to the probe.
    fn smooth_at(&self, p: &Probe) -> bool {
        if p.d <= 0.0 {
            return false;
        }
        let ray = Ray::new(p.q, -p.u);
        self.shape
            .cast_ray_and_get_normal(&self.link, &ray, p.d * (1.0 + 1e-6) + 1e-12, true)
            .is_some_and(|hit| (hit.normal - p.u).length() < SMOOTH_TOLERANCE)
    }

    /// The contact normal (into the object) at a probe (see the module doc).
    fn normal(&self, patch: &SurfacePatch, p: &Probe) -> Vector {
        if patch.is_flat() && self.link_smooth(p) {
            p.u
        } else {
            -patch.outward_normal(p.q)
        }
    }

    fn add(&self, sums: &mut PatchSums, n: Vector, area: f64, at: Vector) {
        if area > 0.0 {
            let key = if sums.merging.is_some() {
                [0; 3]
            } else {
                (n / SAME_DIRECTION).round().as_i64vec3().to_array()
            };
            let k = *sums.by_normal.entry(key).or_insert_with(|| {
                sums.sums.push((n, 0.0, Vector::ZERO, Vector::ZERO));
                sums.sums.len() - 1
            });
            let s = &mut sums.sums[k];
            s.1 += area;
            s.2 += at * area;
            s.3 += n * area;
        }
    }

    /// The region of a patch (or sub-triangle) with corner probes `v`, as points: one per normal
    /// rule on a flat patch; on a curved patch one per sub-triangle of diameter at most
    /// [`CURVED_MERGE`] resolutions, moved onto the surface.
    fn region(&self, patch: &SurfacePatch, v: [Probe; 3], out: &mut Vec<ContactPoint>) {
        let mut sums = PatchSums::default();
        self.refine(patch, v, 0, &mut sums, out);
        self.flush(patch, &sums, out);
    }

    fn flush(&self, patch: &SurfacePatch, sums: &PatchSums, out: &mut Vec<ContactPoint>) {
        for &(_, area, moment, nsum) in &sums.sums {
            if area > 0.0 {
                let at = moment / area;
                let (at, n) = if patch.is_flat() {
                    (at, nsum.normalize_or_zero())
                } else {
                    // The centroid of a small curved piece, moved onto the surface (by its sag,
                    // second order in its size), with the object's normal there.
                    let q = patch.point(at);
                    (q, -patch.outward_normal(q))
                };
                if n != Vector::ZERO {
                    out.push(ContactPoint {
                        position: g2p(self.part_pose.transform_point(at)),
                        normal: g2v(self.part_pose.transform_vector(n)),
                        weight: area,
                    });
                }
            }
        }
    }

    fn refine(
        &self,
        patch: &SurfacePatch,
        v: [Probe; 3],
        depth: usize,
        sums: &mut PatchSums,
        out: &mut Vec<ContactPoint>,
    ) {
        let diam = (v[0].q - v[1].q)
            .length()
            .max((v[1].q - v[2].q).length())
            .max((v[2].q - v[0].q).length());
        if !patch.is_flat() && depth > 0 && diam <= CURVED_MERGE * self.h && sums.merging.is_none()
        {
            let mut own = PatchSums {
                merging: Some(()),
                ..PatchSums::default()
            };
            self.refine(patch, v, depth, &mut own, out);
            self.flush(patch, &own, out);
            return;
        }
        if self.cuboid_closed_form(patch, &v, sums) || self.settled(patch, &v, depth, diam, sums) {
            return;
        }
        self.subdivide(patch, v, depth, sums, out);
    }

    /// A flat patch under a box link, not hidden by another part: its exact region in closed
    /// form (`cuboid.rs`). Whether it applied.
    fn cuboid_closed_form(
        &self,
        patch: &SurfacePatch,
        v: &[Probe; 3],
        sums: &mut PatchSums,
    ) -> bool {
        if patch.is_flat()
            && let LinkQuery::Cuboid { axes, origin, half } = &self.query
            && v.iter().all(|p| !p.hidden)
            && !(self.object.is_union()
                && self.object.inside_other_part(
                    self.part,
                    self.part_pose
                        .transform_point((v[0].q + v[1].q + v[2].q) / 3.0),
                ))
        {
            self.cuboid_region(patch, v.map(|p| p.q), axes, *origin, *half, sums);
            return true;
        }
        false
    }

    /// Settles the patch with corners `v` without subdividing it where a rule allows: the whole
    /// patch within the contact distance and closest to one face, none of it within reach, or
    /// its region clipped exactly (or at the finest level). Whether it did.
    fn settled(
        &self,
        patch: &SurfacePatch,
        v: &[Probe; 3],
        depth: usize,
        diam: f64,
        sums: &mut PatchSums,
    ) -> bool {
        let flat = patch.is_flat();
        let [a, b, cc] = [v[0].q, v[1].q, v[2].q];
        let chord_area = 0.5 * (b - a).cross(cc - a).length();
        // Every link is convex, so the distance to it is a convex function: a flat triangle
        // whose corners are within the contact distance is within it everywhere.
        let corners_within = flat && v.iter().all(|p| p.d <= self.d_c);
        if corners_within
            && v.iter().all(|p| !p.hidden)
            && v[0].d > 0.0
            && v.iter()
                .all(|p| self.link_smooth(p) && (p.u - v[0].u).length() < SAME_DIRECTION)
        {
            // ... and closest to one face of the link everywhere (its region is convex too).
            self.add(sums, v[0].u, chord_area, (a + b + cc) / 3.0);
            return true;
        }
        let c = self.probe(patch, (v[0].pre + v[1].pre + v[2].pre) / 3.0);
        let reach = v.iter().map(|p| (p.q - c.q).length()).fold(0.0, f64::max) + patch.bulge(diam);
        let f = |p: &Probe| p.d - self.d_c;
        if f(&c) > reach {
            return true; // the whole patch is farther than the contact distance
        }
        let same_u = c.d > 0.0 && v.iter().all(|p| (p.u - c.u).length() < SAME_DIRECTION);
        let same_hidden = v.iter().all(|p| p.hidden == c.hidden);
        let leaf = diam <= self.h || depth >= MAX_DEPTH;
        if (corners_within || f(&c) < -reach) && same_hidden {
            // The whole patch is within the contact distance.
            if c.hidden {
                return true;
            }
            // One face of the link closest over the whole triangle (its cell is convex). No
            // such rule holds for edges and corners: a face's cell can pass between corners
            // that all see an edge.
            let uniform = flat && same_u;
            if uniform || leaf || (!flat && diam <= CURVED_MERGE * self.h) {
                let at = if flat { (a + b + cc) / 3.0 } else { c.q };
                self.add(sums, self.normal(patch, &c), chord_area, at);
                return true;
            }
        } else if flat && same_u && same_hidden && !c.hidden && self.on_one_plane(v) {
            // The link's closest points lie on one of its faces, so the distance is linear over
            // the triangle: clipping it where the distance is the contact distance is exact.
            if let Some((area, at)) = clip([a, b, cc], v.map(|p| p.d - self.d_c)) {
                self.add(sums, self.normal(patch, &c), area, at);
            }
            return true;
        } else if leaf {
            if c.hidden {
                return true;
            }
            if let Some((area, at)) = clip([a, b, cc], v.map(|p| p.d - self.d_c)) {
                self.add(sums, self.normal(patch, &c), area, at);
            }
            return true;
        }
        false
    }

    /// Refines the four sub-triangles through the edges' midpoints.
    fn subdivide(
        &self,
        patch: &SurfacePatch,
        v: [Probe; 3],
        depth: usize,
        sums: &mut PatchSums,
        out: &mut Vec<ContactPoint>,
    ) {
        let mid = |i: usize, j: usize| self.probe(patch, (v[i].pre + v[j].pre) * 0.5);
        let (m01, m12, m20) = (mid(0, 1), mid(1, 2), mid(2, 0));
        for t in [
            [v[0], m01, m20],
            [m01, v[1], m12],
            [m20, m12, v[2]],
            [m01, m12, m20],
        ] {
            self.refine(patch, t, depth + 1, sums, out);
        }
    }

    /// The exact region of a box link over a flat triangle (part frame), see `cuboid.rs`.
    fn cuboid_region(
        &self,
        patch: &SurfacePatch,
        tri: [Vector; 3],
        axes: &Matrix,
        origin: Vector,
        half: Vector,
        sums: &mut PatchSums,
    ) {
        let to_link = axes.transpose();
        let mut pieces = Vec::new();
        cuboid::region(
            tri.map(|q| to_link * (q - origin)),
            half,
            self.d_c,
            &mut pieces,
        );
        if pieces.is_empty() {
            return;
        }
        let object_normal = -patch.outward_normal(tri[0]);
        for piece in pieces {
            let faces = piece.cell.iter().filter(|s| **s != 0).count();
            let normal = if faces == 1 {
                // A face of the link is closest: its normal (see the module doc).
                let k = piece.cell.iter().position(|s| *s != 0).unwrap_or(0);
                *axes * (Vector::AXES[k] * f64::from(piece.cell[k]))
            } else {
                object_normal
            };
            self.add(sums, normal, piece.area, origin + *axes * piece.centroid);
        }
    }

    /// Whether the link's closest points of the three probes lie on one plane orthogonal to
    /// their common direction.
    fn on_one_plane(&self, v: &[Probe; 3]) -> bool {
        let y = v.map(|p| p.q - p.u * p.d);
        let u = v[0].u;
        let scale = self
            .d_c
            .max((y[1] - y[0]).length())
            .max((y[2] - y[0]).length());
        (y[1] - y[0]).dot(u).abs() <= 1e-9 * scale && (y[2] - y[0]).dot(u).abs() <= 1e-9 * scale
    }
}

/// The part of the triangle `q` where the linear interpolation of `f` is at most 0: area and
/// centroid (`None` when empty).
fn clip(q: [Vector; 3], f: [f64; 3]) -> Option<(f64, Vector)> {
    cuboid::clip_where(&q, &f).and_then(|poly| cuboid::polygon_area(&poly))
}

/// The contact region of one link at `link_world` (world pose of the link frame): the object's
/// surface within the contact distance of the link, as weighted points (see the module doc).
pub(crate) fn link_cloud(
    object: &Object,
    geometry: &LinkGeometry,
    index: usize,
    link_world: &nalgebra::Isometry3<f64>,
    settings: &CloudSettings,
) -> Result<Vec<ContactPoint>> {
    let pose: Pose = iso2pose(link_world);
    let Some((shape, shape_pose)) = geometry.shape_at(index, &pose) else {
        return Err(SimError::InvalidInput(format!("no link {index}")));
    };
    let d_c = settings.contact_distance;
    let mut out = Vec::new();
    for (part, part_pose, patches) in object.surface_patches() {
        let link = part_pose.inverse() * shape_pose;
        let bb = shape.compute_aabb(&link);
        let (lo, hi) = (bb.mins - Vector::splat(d_c), bb.maxs + Vector::splat(d_c));
        let builder = RegionBuilder {
            object,
            part,
            part_pose,
            shape,
            link,
            query: LinkQuery::new(shape, &link),
            d_c,
            h: settings.resolution,
        };
        for patch in patches {
            let (a, b) = patch.aabb;
            if a.cmpgt(hi).any() || b.cmplt(lo).any() {
                continue;
            }
            let v = patch.corners.map(|c| builder.probe(patch, c));
            builder.region(patch, v, &mut out);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
