//! Contacts: the raw contact *cloud* of each finger (points on the object's surface where the
//! finger's links touch it, each with the object's normal pointing INTO the object), and the three
//! contact models of thesis section 4.3 built from a cloud:
//!
//! - **mean point**: `p_m` = mean of the cloud's positions, normal = normalised mean normal;
//! - **circular patch**: the grid points of a disc of radius `r` centred at `p_m` on the plane
//!   orthogonal to the mean normal, all carrying the mean normal;
//! - **surface** (section 2.3): through each grid point of that disc, a line segment parallel to
//!   the mean normal, bounded by the sphere of radius `r` centred at `p_m` (on both sides of the
//!   plane: the mean of a curved cloud lies inside the object, its surface outside the plane);
//!   its intersection with the object's surface closest to `p_m` becomes a contact with the
//!   object's inward normal there (the normal of the face hit). Segments that miss the object
//!   contribute nothing; if all miss (e.g. a cloud spread over two separate contact regions, whose
//!   mean lies in the air), the mean point alone is returned.
//!
//! Disc grid: a square grid of spacing `h = r / (k + 1/2)` with the points `(i h, j h)` such that
//! `i^2 + j^2 <= k^2 + 1` (`k` = [`ContactModelSettings::grid_half`]); the default `k = 2` gives 21
//! points, the outermost at `0.89 r`, so that every segment has a non-zero length.
//!
//! Raw clouds (contact regions): a link's cloud is the part of the object's surface within
//! [`CloudSettings::contact_distance`] (default 1 mm) of the link, computed from the two shapes
//! with no sampling of the link. The link is seen only through parry's point projection and ray
//! cast on its shape, so any link shape works. Each object part's surface is a set of triangles
//! that are exact (meshes, boxes) or map exactly onto the curved surface (sphere, cylinder side
//! and caps, see `SurfacePatch`). Each triangle near the link is subdivided adaptively:
//!
//! - a triangle is dropped when its centre is farther from the link than the contact distance
//!   plus the triangle's radius (the distance to the link changes by at most the distance moved),
//!   and kept whole when it is nearer than the contact distance minus that radius and one
//!   normal rule (below) holds over it;
//! - where the three corners see the link's closest points on one plane with one direction (one
//!   face of the link, whose offset is flat), the distance to the link is linear over a flat
//!   triangle, and clipping the triangle at the contact distance is **exact to round-off**;
//! - elsewhere (the offset of a link edge, vertex or curved face, a curved object, the rim where
//!   a union's parts meet) the triangle is subdivided down to [`CloudSettings::resolution`]
//!   (default 0.2 mm) and clipped on the linear interpolation of the distance: an error
//!   **second order in the resolution**, not exact. How much halving it moves BW on the 67 x 33
//!   grids of the seven objects is in docs/benchmarks.md.
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

use nalgebra::{Point3, Vector3};
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query::Ray;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::convert::{g2p, g2v, iso2pose, p2g, v2g};
use crate::error::{Result, SimError, ensure_finite};
use crate::hand::LinkGeometry;
use crate::object::{Object, SurfacePatch};

/// Default radius `r` of the circular patch and of the surface model (metres).
pub const DEFAULT_PATCH_RADIUS: f64 = 0.005;

/// A contact: a point on the object's surface and the unit normal pointing into the object.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactPoint {
    /// Position (world).
    pub position: Point3<f64>,
    /// Unit normal pointing INTO the object (the direction the finger pushes).
    pub normal: Vector3<f64>,
    /// The area this point stands for (square metres for the simulator's regions; 1 when all
    /// points count the same, the default of clouds written without it).
    #[serde(default = "unit_weight")]
    pub weight: f64,
}

fn unit_weight() -> f64 {
    1.0
}

impl ContactPoint {
    /// A contact of weight 1.
    pub fn new(position: Point3<f64>, normal: Vector3<f64>) -> Self {
        Self {
            position,
            normal,
            weight: 1.0,
        }
    }
}

/// The raw contact points of one finger (or of the palm).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactCloud {
    /// The points.
    pub points: Vec<ContactPoint>,
}

impl ContactCloud {
    /// Whether the cloud has no point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// The mean-point model of this cloud.
    pub fn mean_point(&self) -> Option<ContactPoint> {
        mean_point(&self.points)
    }
}

/// Which contact model to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactModel {
    /// One contact per finger at the cloud's mean.
    MeanPoint,
    /// Grid points on a disc around the mean, all with the mean normal.
    CircularPatch,
    /// The surface model of thesis section 2.3.
    Surface,
}

impl ContactModel {
    /// The name users type and see (`--contacts`): `mean`, `patch`, `surface`.
    pub fn name(self) -> &'static str {
        match self {
            ContactModel::MeanPoint => "mean",
            ContactModel::CircularPatch => "patch",
            ContactModel::Surface => "surface",
        }
    }
}

impl std::fmt::Display for ContactModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Default [`CloudSettings::resolution`] (metres).
pub const DEFAULT_RESOLUTION: f64 = 2e-4;

/// How raw clouds (contact regions) are computed from the touching links.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CloudSettings {
    /// The object's surface within this distance of a link is in contact (default 1 mm).
    pub contact_distance: f64,
    /// Size below which an object triangle is no longer subdivided where the region's boundary
    /// or normal rule changes inside it (default [`DEFAULT_RESOLUTION`]; see the module doc).
    pub resolution: f64,
}

impl Default for CloudSettings {
    fn default() -> Self {
        Self {
            contact_distance: 1e-3,
            resolution: DEFAULT_RESOLUTION,
        }
    }
}

/// Optional Gaussian noise on modelled contacts (for the noisy experiments of thesis 4.7).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct NoiseSettings {
    /// Standard deviation of each position coordinate (metres).
    pub position_std: f64,
    /// Standard deviation of each normal component before renormalisation (about radians).
    pub normal_std: f64,
    /// Seed of the ChaCha8 generator.
    pub seed: u64,
}

/// Parameters of the contact models.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactModelSettings {
    /// Radius `r` of the disc and of the bounding sphere (default [`DEFAULT_PATCH_RADIUS`]).
    pub radius: f64,
    /// Grid half-size `k` (default 2: 21 points).
    pub grid_half: usize,
    /// Noise on the modelled contacts, if any (default none).
    pub noise: Option<NoiseSettings>,
    /// Raw cloud extraction.
    pub cloud: CloudSettings,
}

impl Default for ContactModelSettings {
    fn default() -> Self {
        Self {
            radius: DEFAULT_PATCH_RADIUS,
            grid_half: 2,
            noise: None,
            cloud: CloudSettings::default(),
        }
    }
}

impl ContactModelSettings {
    /// Checks that every setting is finite and positive where it must be.
    pub fn validate(&self) -> Result<()> {
        let c = &self.cloud;
        ensure_finite(
            &[self.radius, c.contact_distance, c.resolution],
            "contact model settings",
        )?;
        if let Some(n) = &self.noise {
            ensure_finite(&[n.position_std, n.normal_std], "noise settings")?;
            if n.position_std < 0.0 || n.normal_std < 0.0 {
                return Err(SimError::InvalidInput(
                    "noise standard deviations must be >= 0".to_string(),
                ));
            }
        }
        if self.radius <= 0.0 || c.contact_distance <= 0.0 || c.resolution <= 0.0 {
            return Err(SimError::InvalidInput(
                "radius, contact distance and resolution must be > 0".to_string(),
            ));
        }
        if self.grid_half > 50 {
            return Err(SimError::InvalidInput("grid too dense".to_string()));
        }
        if c.resolution < 1e-7 {
            return Err(SimError::InvalidInput(
                "contact resolution below 0.1 micrometre".to_string(),
            ));
        }
        Ok(())
    }
}

/// The mean-point model: the weighted mean position and the normalised weighted mean normal
/// (`None` for an empty cloud, weights that sum to zero or normals that cancel out). Its weight
/// is the cloud's total weight.
pub fn mean_point(cloud: &[ContactPoint]) -> Option<ContactPoint> {
    let total: f64 = cloud.iter().map(|c| c.weight).sum();
    if cloud.is_empty() || total <= 0.0 || !total.is_finite() {
        return None;
    }
    let pos = cloud
        .iter()
        .fold(Vector3::zeros(), |a, c| a + c.position.coords * c.weight)
        / total;
    let nrm = cloud
        .iter()
        .fold(Vector3::zeros(), |a, c| a + c.normal * c.weight);
    let nrm = nrm.try_normalize(1e-12 * total)?;
    Some(ContactPoint {
        position: Point3::from(pos),
        normal: nrm,
        weight: total,
    })
}

/// Two unit vectors spanning the plane orthogonal to the unit vector `n`.
fn plane_basis(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let a = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = n.cross(&a).normalize();
    let e2 = n.cross(&e1);
    (e1, e2)
}

/// Grid points `(point, distance from centre)` of the disc of radius `r` around `centre`
/// orthogonal to `normal` (see the module doc).
pub fn disc_grid(
    centre: &Point3<f64>,
    normal: &Vector3<f64>,
    r: f64,
    k: usize,
) -> Vec<(Point3<f64>, f64)> {
    let (e1, e2) = plane_basis(normal);
    let h = r / (k as f64 + 0.5);
    let k = k as i64;
    let mut out = Vec::new();
    for i in -k..=k {
        for j in -k..=k {
            if i * i + j * j <= k * k + 1 {
                let (u, v) = (i as f64 * h, j as f64 * h);
                out.push((centre + e1 * u + e2 * v, u.hypot(v)));
            }
        }
    }
    out
}

/// The circular-patch model of a cloud (empty for an empty cloud).
pub fn circular_patch(
    cloud: &[ContactPoint],
    settings: &ContactModelSettings,
) -> Vec<ContactPoint> {
    let Some(m) = mean_point(cloud) else {
        return Vec::new();
    };
    disc_grid(&m.position, &m.normal, settings.radius, settings.grid_half)
        .into_iter()
        .map(|(p, _)| ContactPoint::new(p, m.normal))
        .collect()
}

/// The surface model of a cloud (section 2.3). Segments that miss the object contribute nothing;
/// if every segment misses (a degenerate cloud), the mean point alone is returned.
pub fn surface_model(
    cloud: &[ContactPoint],
    object: &Object,
    settings: &ContactModelSettings,
) -> Vec<ContactPoint> {
    let Some(m) = mean_point(cloud) else {
        return Vec::new();
    };
    let r = settings.radius;
    let dir = v2g(&m.normal);
    let mut out = Vec::new();
    for (g, rho) in disc_grid(&m.position, &m.normal, r, settings.grid_half) {
        let half = (r * r - rho * rho).max(0.0).sqrt();
        let origin = p2g(&g);
        let fwd = object.cast_ray_normal_g(origin, dir, half);
        let back = object.cast_ray_normal_g(origin, -dir, half);
        let mut hit = match (fwd, back) {
            (Some(a), Some(b)) => Some(if a.0 <= b.0 { (a.1, a.2) } else { (b.1, b.2) }),
            (Some(a), None) | (None, Some(a)) => Some((a.1, a.2)),
            (None, None) => None,
        };
        if hit.is_none() && half > 0.0 {
            // A segment through a sharp edge may graze it exactly at `g`, where rays starting on
            // the surface are numerically fragile: cast again from both ends of the segment.
            let from_out = object.cast_ray_normal_g(origin - dir * half, dir, 2.0 * half);
            let from_in = object.cast_ray_normal_g(origin + dir * half, -dir, 2.0 * half);
            hit = [from_out, from_in]
                .into_iter()
                .flatten()
                .map(|h| (h.1, h.2))
                .min_by(|a, b| (a.0 - origin).length().total_cmp(&(b.0 - origin).length()));
        }
        if hit.is_none() {
            // Last resort for a segment passing exactly through an edge at `g`.
            hit = object
                .closest_point_g(origin, 1e-7)
                .filter(|(_, _, sd)| sd.abs() <= 1e-7)
                .map(|(p, n, _)| (p, n));
        }
        if let Some((p, n_out)) = hit {
            out.push(ContactPoint::new(g2p(p), -g2v(n_out)));
        }
    }
    if out.is_empty() {
        out.push(ContactPoint::new(m.position, m.normal));
    }
    out
}

/// The given model of a cloud.
pub fn model_contacts(
    model: ContactModel,
    cloud: &[ContactPoint],
    object: &Object,
    settings: &ContactModelSettings,
) -> Vec<ContactPoint> {
    match model {
        ContactModel::MeanPoint => mean_point(cloud).into_iter().collect(),
        ContactModel::CircularPatch => circular_patch(cloud, settings),
        ContactModel::Surface => surface_model(cloud, object, settings),
    }
}

/// One standard normal sample (Box-Muller).
fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>(); // (0, 1]
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// Adds Gaussian noise to positions and normals (normals stay unit). `stream` separates the
/// random streams of different fingers/models under one seed.
pub fn add_noise(points: &mut [ContactPoint], noise: &NoiseSettings, stream: u64) {
    let mut rng =
        ChaCha8Rng::seed_from_u64(noise.seed ^ stream.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    for p in points {
        let dp = Vector3::new(gaussian(&mut rng), gaussian(&mut rng), gaussian(&mut rng))
            * noise.position_std;
        let dn = Vector3::new(gaussian(&mut rng), gaussian(&mut rng), gaussian(&mut rng))
            * noise.normal_std;
        p.position += dp;
        p.normal = (p.normal + dn).try_normalize(1e-12).unwrap_or(p.normal);
    }
}

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
    d_c: f64,
    h: f64,
}

impl RegionBuilder<'_> {
    fn probe(&self, patch: &SurfacePatch, pre: Vector) -> Probe {
        let q = patch.point(pre);
        let proj = self.shape.project_point(&self.link, q, true);
        let (d, u) = if proj.is_inside {
            (0.0, Vector::ZERO)
        } else {
            let v = q - proj.point;
            let d = v.length();
            (d, if d > 0.0 { v / d } else { Vector::ZERO })
        };
        let hidden = self.object.is_union()
            && self
                .object
                .inside_other_part(self.part, self.part_pose.transform_point(q));
        let mut p = Probe {
            pre,
            q,
            d,
            u,
            hidden,
            smooth: false,
        };
        if d <= self.d_c {
            p.smooth = self.smooth_at(&p);
        }
        p
    }

    /// Whether the link is smooth where it is closest to `p` (cached within the contact
    /// distance).
    fn link_smooth(&self, p: &Probe) -> bool {
        if p.d <= self.d_c {
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
            let k = match sums
                .sums
                .iter()
                .position(|s| sums.merging.is_some() || (s.0 - n).length() <= SAME_DIRECTION)
            {
                Some(k) => k,
                None => {
                    sums.sums.push((n, 0.0, Vector::ZERO, Vector::ZERO));
                    sums.sums.len() - 1
                }
            };
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
        let c = self.probe(patch, (v[0].pre + v[1].pre + v[2].pre) / 3.0);
        let reach = v.iter().map(|p| (p.q - c.q).length()).fold(0.0, f64::max) + patch.bulge(diam);
        let f = |p: &Probe| p.d - self.d_c;
        if f(&c) > reach {
            return; // the whole patch is farther than the contact distance
        }
        let flat = patch.is_flat();
        let same_u = c.d > 0.0 && v.iter().all(|p| (p.u - c.u).length() < SAME_DIRECTION);
        let same_hidden = v.iter().all(|p| p.hidden == c.hidden);
        let leaf = diam <= self.h || depth >= MAX_DEPTH;
        let [a, b, cc] = [v[0].q, v[1].q, v[2].q];
        let chord_area = 0.5 * (b - a).cross(cc - a).length();
        if f(&c) < -reach && same_hidden {
            // The whole patch is within the contact distance.
            if c.hidden {
                return;
            }
            let uniform = flat
                && (same_u || (!self.link_smooth(&c) && v.iter().all(|p| !self.link_smooth(p))));
            if uniform || leaf || (!flat && diam <= CURVED_MERGE * self.h) {
                let at = if flat { (a + b + cc) / 3.0 } else { c.q };
                self.add(sums, self.normal(patch, &c), chord_area, at);
                return;
            }
        } else if flat && same_u && same_hidden && !c.hidden && self.on_one_plane(&v) {
            // The link's closest points lie on one of its faces, so the distance is linear over
            // the triangle: clipping it where the distance is the contact distance is exact.
            if let Some((area, at)) = clip([a, b, cc], v.map(|p| p.d - self.d_c)) {
                self.add(sums, self.normal(patch, &c), area, at);
            }
            return;
        } else if leaf {
            if c.hidden {
                return;
            }
            if let Some((area, at)) = clip([a, b, cc], v.map(|p| p.d - self.d_c)) {
                self.add(sums, self.normal(patch, &c), area, at);
            }
            return;
        }
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
    let mut poly: Vec<Vector> = Vec::with_capacity(4);
    for i in 0..3 {
        let j = (i + 1) % 3;
        if f[i] <= 0.0 {
            poly.push(q[i]);
        }
        if (f[i] <= 0.0) != (f[j] <= 0.0) {
            let t = f[i] / (f[i] - f[j]);
            poly.push(q[i] + (q[j] - q[i]) * t);
        }
    }
    if poly.len() < 3 {
        return None;
    }
    let mut area = 0.0;
    let mut moment = Vector::ZERO;
    for k in 1..poly.len() - 1 {
        let a = 0.5 * (poly[k] - poly[0]).cross(poly[k + 1] - poly[0]).length();
        area += a;
        moment += (poly[0] + poly[k] + poly[k + 1]) * (a / 3.0);
    }
    (area > 0.0).then(|| (area, moment / area))
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
mod tests {
    use super::*;

    use crate::hand::{LinkShape, LinkSpec};
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};

    /// The region of one box link (half extents `half`) at `pose` against `object`.
    fn box_region(
        object: &Object,
        half: Vector3<f64>,
        pose: &Isometry3<f64>,
        resolution: f64,
    ) -> Vec<ContactPoint> {
        let links = [LinkSpec {
            name: "pad".into(),
            finger: Some(0),
            shape: LinkShape::Box { half_extents: half },
        }];
        let settings = CloudSettings {
            resolution,
            ..CloudSettings::default()
        };
        link_cloud(object, &LinkGeometry::new(&links), 0, pose, &settings).unwrap()
    }

    fn total_area(cloud: &[ContactPoint]) -> f64 {
        cloud.iter().map(|p| p.weight).sum()
    }

    #[test]
    fn a_box_pressed_on_a_cube_face_gives_the_offset_rectangle() {
        // The cuboid's top face is z = 0.12 over [-0.03, 0.03] x [-0.025, 0.025]. A pad of
        // 10 x 20 mm rests 0.2 mm above it at (0.005, -0.004): the region is the footprint
        // grown by rho = sqrt(d_c^2 - g^2) with rounded corners, centred under the pad.
        let cube = Object::by_name("cuboid").unwrap();
        let (a, b, hz, g, d_c): (f64, f64, f64, f64, f64) = (0.005, 0.01, 0.002, 2e-4, 1e-3);
        let pose = Isometry3::translation(0.005, -0.004, 0.12 + g + hz);
        let rho = (d_c * d_c - g * g).sqrt();
        let area = 4.0 * a * b + 4.0 * (a + b) * rho + std::f64::consts::PI * rho * rho;
        // The straight sides are exact; the rounded corners are second order in the resolution.
        let mut errors = Vec::new();
        for resolution in [DEFAULT_RESOLUTION, DEFAULT_RESOLUTION / 2.0] {
            let cloud = box_region(&cube, Vector3::new(a, b, hz), &pose, resolution);
            let m = mean_point(&cloud).unwrap();
            let rel = (total_area(&cloud) - area).abs() / area;
            assert!(rel < 1e-4, "area {} vs {area}: {rel:e}", total_area(&cloud));
            errors.push(rel);
            assert!(
                (m.position - Point3::new(0.005, -0.004, 0.12)).norm() < 1e-8,
                "{:?}",
                m.position
            );
            assert!(
                cloud
                    .iter()
                    .all(|p| (p.normal + Vector3::z()).norm() < 1e-12)
            );
        }
        assert!(errors[1] < errors[0] / 3.0, "{errors:?}");
        // A pad wider than the face covers it all, and the side faces' strips within d_c
        // below the top edges: every piece is clipped where the distance is linear, so the
        // area and the centroid are exact to round-off.
        let pose = Isometry3::translation(0.0, 0.0, 0.12 + g + hz);
        let cloud = box_region(&cube, Vector3::new(0.04, 0.04, hz), &pose, 1e-3);
        let (top, strips) = (0.06 * 0.05, 2.0 * (0.06 + 0.05) * (d_c - g));
        let area = top + strips;
        assert!((total_area(&cloud) - area).abs() < 1e-12 * area);
        let z = (top * 0.12 + strips * (0.12 - (d_c - g) / 2.0)) / area;
        let m = mean_point(&cloud).unwrap();
        assert!(
            (m.position - Point3::new(0.0, 0.0, z)).norm() < 1e-14,
            "{m:?}"
        );
        // Object edges against the pad's face: the pad's normal everywhere.
        assert!(
            cloud
                .iter()
                .all(|p| (p.normal + Vector3::z()).norm() < 1e-12)
        );
    }

    #[test]
    fn an_object_edge_against_a_link_face_takes_the_link_face_normal() {
        // A pad tilted 30 degrees about y touches the cuboid's top edge x = 0.03, z = 0.12
        // with the middle of its face, 0.2 mm away. The region: strips along the edge on the
        // top face (length L1 = (d_c - g) / sin 30) and the side face (L2 = (d_c - g) / cos 30)
        // and a right triangle with these legs on each end face; all with the pad's normal.
        let cube = Object::by_name("cuboid").unwrap();
        let (hz, g, d_c): (f64, f64, f64) = (0.002, 2e-4, 1e-3);
        let alpha = 30f64.to_radians();
        let rot = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), alpha);
        let z_link = rot * Vector3::z();
        let centre = Vector3::new(0.03, 0.0, 0.12) + z_link * (g + hz);
        let pose = Isometry3::from_parts(Translation3::from(centre), rot);
        let cloud = box_region(
            &cube,
            Vector3::new(0.01, 0.04, hz),
            &pose,
            DEFAULT_RESOLUTION,
        );
        let (l1, l2) = ((d_c - g) / alpha.sin(), (d_c - g) / alpha.cos());
        let area = 0.05 * (l1 + l2) + l1 * l2;
        assert!(
            (total_area(&cloud) - area).abs() < 1e-12 * area,
            "{} vs {area}",
            total_area(&cloud)
        );
        for p in &cloud {
            assert!((p.normal + z_link).norm() < 1e-12, "{p:?}");
        }
        // The same edge against the pad's own edge (the pad moved so that its edge is
        // closest): the region beyond the pad's edge takes the object's face normals.
        let pose = Isometry3::from_parts(
            Translation3::from(centre + rot * Vector3::x() * 0.0099),
            rot,
        );
        let cloud = box_region(
            &cube,
            Vector3::new(0.01, 0.04, hz),
            &pose,
            DEFAULT_RESOLUTION,
        );
        assert!(
            cloud
                .iter()
                .any(|p| (p.normal + Vector3::z()).norm() < 1e-12
                    || (p.normal + Vector3::x()).norm() < 1e-12)
        );
    }

    #[test]
    fn default_grid_has_21_points_inside_the_disc() {
        let g = disc_grid(&Point3::origin(), &Vector3::z(), 0.005, 2);
        assert_eq!(g.len(), 21);
        assert!(g.iter().all(|(p, rho)| p.z.abs() < 1e-15
            && *rho < 0.005
            && (p.coords.norm() - rho).abs() < 1e-15));
    }

    #[test]
    fn mean_point_and_noise_keep_unit_normals() {
        let cloud = vec![
            ContactPoint::new(Point3::new(0.0, 0.0, 0.0), Vector3::x()),
            ContactPoint::new(Point3::new(0.0, 0.002, 0.0), Vector3::y()),
        ];
        let m = mean_point(&cloud).unwrap();
        assert!((m.position.y - 0.001).abs() < 1e-15);
        assert!((m.normal - Vector3::new(1.0, 1.0, 0.0).normalize()).norm() < 1e-12);
        assert!(mean_point(&[]).is_none());
        let mut pts = circular_patch(&cloud, &ContactModelSettings::default());
        let before = pts.clone();
        let noise = NoiseSettings {
            position_std: 1e-3,
            normal_std: 0.1,
            seed: 7,
        };
        add_noise(&mut pts, &noise, 1);
        assert!(pts.iter().all(|p| (p.normal.norm() - 1.0).abs() < 1e-12));
        assert!(
            pts.iter()
                .zip(&before)
                .any(|(a, b)| (a.position - b.position).norm() > 1e-5)
        );
        let mut again = before.clone();
        add_noise(&mut again, &noise, 1);
        assert_eq!(pts, again, "same seed, same noise");
    }
}
