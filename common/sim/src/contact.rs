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
//! Raw clouds: for each link within [`CloudSettings::contact_distance`] of the object, parry gives
//! the closest point pairs (per convex piece of the object); the link's surface is sampled on a
//! grid of spacing [`CloudSettings::spacing`] within [`CloudSettings::window_radius`] of each
//! separate closest point, and each sample casts a ray along the link's outward surface normal:
//! a hit within the contact distance is a cloud point, with the normal of the object's face that
//! was hit (pointing into the object). The cloud is thus the object's surface facing the link
//! within 1 mm of it. When fewer than three rays hit (a link face against an object edge or tip),
//! the samples' closest object points within the contact distance are used instead, each with the
//! direction from the sample to that point as its inward normal; if there are none either (a
//! contact at a link corner, between samples), the exact closest points are used. Contact regions
//! farther apart than the window radius on the same convex piece are reported by their nearest
//! region only.

use nalgebra::{Point3, Vector3};
use parry3d_f64::math::{Pose, Vector};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::convert::{g2p, g2v, iso2pose, p2g, v2g};
use crate::error::{Result, SimError, ensure_finite};
use crate::hand::{LinkGeometry, LinkShape, LinkSpec};
use crate::object::Object;

/// Below this many ray hits on a link, the cloud falls back to closest points (edge contacts).
const MIN_RAY_POINTS: usize = 3;

/// Default radius `r` of the circular patch and of the surface model (metres).
pub const DEFAULT_PATCH_RADIUS: f64 = 0.005;

/// A contact: a point on the object's surface and the unit normal pointing into the object.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactPoint {
    /// Position (world).
    pub position: Point3<f64>,
    /// Unit normal pointing INTO the object (the direction the finger pushes).
    pub normal: Vector3<f64>,
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

/// How raw clouds are extracted from the touching links.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CloudSettings {
    /// A link point within this distance of the object is in contact (default 1 mm).
    pub contact_distance: f64,
    /// Sampling window radius around a link's closest point (default 10 mm).
    pub window_radius: f64,
    /// Sampling grid spacing on the link surface (default 2.5 mm).
    pub spacing: f64,
}

impl Default for CloudSettings {
    fn default() -> Self {
        Self {
            contact_distance: 1e-3,
            window_radius: 0.010,
            spacing: 0.0025,
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
            &[self.radius, c.contact_distance, c.window_radius, c.spacing],
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
        if self.radius <= 0.0
            || c.contact_distance <= 0.0
            || c.window_radius <= 0.0
            || c.spacing <= 0.0
        {
            return Err(SimError::InvalidInput(
                "radius, distances and spacing must be > 0".to_string(),
            ));
        }
        if self.grid_half > 50 || c.window_radius / c.spacing > 100.0 {
            return Err(SimError::InvalidInput("grid too dense".to_string()));
        }
        Ok(())
    }
}

/// The mean-point model: mean position and normalised mean normal (`None` for an empty cloud or
/// normals that cancel out).
pub fn mean_point(cloud: &[ContactPoint]) -> Option<ContactPoint> {
    if cloud.is_empty() {
        return None;
    }
    let n = cloud.len() as f64;
    let pos = cloud
        .iter()
        .fold(Vector3::zeros(), |a, c| a + c.position.coords)
        / n;
    let nrm = cloud.iter().fold(Vector3::zeros(), |a, c| a + c.normal);
    let nrm = nrm.try_normalize(1e-12)?;
    Some(ContactPoint {
        position: Point3::from(pos),
        normal: nrm,
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
        .map(|(p, _)| ContactPoint {
            position: p,
            normal: m.normal,
        })
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
            out.push(ContactPoint {
                position: g2p(p),
                normal: -g2v(n_out),
            });
        }
    }
    if out.is_empty() {
        out.push(m);
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

/// Samples of a link's surface within `radius` of `centre` with spacing `h`: points and the
/// link's outward unit normal there, in the link frame.
fn sample_link_surface(
    shape: &LinkShape,
    centre: &Point3<f64>,
    radius: f64,
    h: f64,
) -> Vec<(Point3<f64>, Vector3<f64>)> {
    let mut out = Vec::new();
    // Grid coordinates on [-half, half] with at most spacing h (ends included), restricted to
    // [lo, hi].
    let axis = |half: f64, lo: f64, hi: f64| -> Vec<f64> {
        let n = ((2.0 * half / h).ceil() as i64).max(1);
        let step = 2.0 * half / n as f64;
        (0..=n)
            .map(|i| -half + i as f64 * step)
            .filter(|u| *u >= lo && *u <= hi)
            .collect()
    };
    match shape {
        LinkShape::Box { half_extents } => {
            for a in 0..3 {
                let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                for s in [-1.0, 1.0] {
                    let plane = s * half_extents[a];
                    let delta = (centre[a] - plane).abs();
                    if delta > radius {
                        continue;
                    }
                    let w = (radius * radius - delta * delta).sqrt();
                    for u in axis(half_extents[b], centre[b] - w, centre[b] + w) {
                        for v in axis(half_extents[c], centre[c] - w, centre[c] + w) {
                            let mut p = Point3::origin();
                            p[a] = plane;
                            p[b] = u;
                            p[c] = v;
                            if (p - centre).norm() <= radius {
                                let mut n = Vector3::zeros();
                                n[a] = s;
                                out.push((p, n));
                            }
                        }
                    }
                }
            }
        }
        LinkShape::Cylinder {
            radius: cr,
            half_height,
        } => {
            for s in [-1.0, 1.0] {
                let z = s * half_height;
                for x in axis(*cr, centre.x - radius, centre.x + radius) {
                    for y in axis(*cr, centre.y - radius, centre.y + radius) {
                        let p = Point3::new(x, y, z);
                        if x.hypot(y) <= *cr && (p - centre).norm() <= radius {
                            out.push((p, Vector3::z() * s));
                        }
                    }
                }
            }
            let n = ((std::f64::consts::TAU * cr / h).ceil() as usize).max(3);
            for i in 0..n {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                for z in axis(*half_height, centre.z - radius, centre.z + radius) {
                    let p = Point3::new(cr * a.cos(), cr * a.sin(), z);
                    if (p - centre).norm() <= radius {
                        out.push((p, Vector3::new(a.cos(), a.sin(), 0.0)));
                    }
                }
            }
        }
        LinkShape::Sphere { radius: r } => {
            // Rings of latitude about h apart, points on each about h apart.
            let rings = ((std::f64::consts::PI * r / h).ceil() as usize).max(2);
            for i in 0..=rings {
                let lat = std::f64::consts::PI * (i as f64 / rings as f64 - 0.5);
                let n = ((std::f64::consts::TAU * r * lat.cos() / h).ceil() as usize).max(1);
                for k in 0..n {
                    let lon = std::f64::consts::TAU * k as f64 / n as f64;
                    let normal =
                        Vector3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin());
                    let p = Point3::from(normal * *r);
                    if (p - centre).norm() <= radius {
                        out.push((p, normal));
                    }
                }
            }
        }
        LinkShape::Mesh { mesh } => {
            // A barycentric grid of spacing about h on each triangle, with its normal.
            for (t, tri) in mesh.triangles.iter().enumerate() {
                let corner = |k: usize| mesh.vertices.get(tri[k] as usize).copied();
                let (Some(a), Some(b), Some(c)) = (corner(0), corner(1), corner(2)) else {
                    continue;
                };
                let normal = mesh.triangle_normal(t);
                let longest = (b - a).norm().max((c - a).norm()).max((c - b).norm());
                let m = ((longest / h).ceil() as usize).max(1);
                for i in 0..=m {
                    for j in 0..=(m - i) {
                        let p =
                            a + (b - a) * (i as f64 / m as f64) + (c - a) * (j as f64 / m as f64);
                        if (p - centre).norm() <= radius {
                            out.push((p, normal));
                        }
                    }
                }
            }
        }
    }
    out
}

/// The raw contact points of one link at `link_world` (world pose of the link frame).
pub(crate) fn link_cloud(
    object: &Object,
    geometry: &LinkGeometry,
    index: usize,
    spec: &LinkSpec,
    link_world: &nalgebra::Isometry3<f64>,
    settings: &CloudSettings,
) -> Result<Vec<ContactPoint>> {
    let pose: Pose = iso2pose(link_world);
    let Some((shape, shape_pose)) = geometry.shape_at(index, &pose) else {
        return Err(SimError::InvalidInput(format!("no link {index}")));
    };
    let d_c = settings.contact_distance;
    let pairs = object.closest_points_to_shape(&shape_pose, shape, d_c)?;
    // One sampling window per separate contact region: pieces of a decomposed object touched in
    // the same region give nearby witnesses, which share the nearest one's window.
    let mut windows: Vec<(Point3<f64>, Vector)> = Vec::new();
    for (on_link, on_object, _) in pairs {
        let local = link_world.inverse_transform_point(&g2p(on_link));
        if windows
            .iter()
            .all(|(w, _)| (w - local).norm() > settings.window_radius)
        {
            windows.push((local, on_object));
        }
    }
    let mut samples: Vec<(Point3<f64>, Vector3<f64>)> = windows
        .iter()
        .flat_map(|(w, _)| {
            sample_link_surface(&spec.shape, w, settings.window_radius, settings.spacing)
        })
        .collect();
    if windows.len() > 1 {
        let key = |s: &(Point3<f64>, Vector3<f64>)| [s.0.x, s.0.y, s.0.z, s.1.x, s.1.y, s.1.z];
        samples.sort_by(|a, b| {
            key(a)
                .partial_cmp(&key(b))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        samples.dedup_by(|a, b| (a.0 - b.0).norm() < 1e-12 && (a.1 - b.1).norm() < 1e-12);
    }
    // Each sample looks along its link-surface normal: the object's surface within the contact
    // distance in that direction is where this piece of the link touches (or nearly touches) it.
    let mut out = Vec::new();
    for (s, n) in &samples {
        let q: Vector = p2g(&(link_world * s));
        let dir: Vector = v2g(&(link_world * n));
        if let Some((_, p, n_out)) = object.cast_ray_normal_g(q, dir, d_c) {
            out.push(ContactPoint {
                position: g2p(p),
                normal: -g2v(n_out),
            });
        }
    }
    if out.len() < MIN_RAY_POINTS {
        // A link face against an object edge or tip (few rays hit): use the object's points
        // within the contact distance of the samples instead, with the direction from the
        // sample to its closest object point as the inward normal (the contact normal of an
        // edge against a face).
        let mut near = Vec::new();
        for (s, _) in &samples {
            let q: Vector = p2g(&(link_world * s));
            if let Some((p, n_out, sd)) = object.closest_point_g(q, d_c)
                && sd > 0.0
                && sd <= d_c
            {
                let inward = (p - q).normalize_or(-n_out);
                near.push(ContactPoint {
                    position: g2p(p),
                    normal: g2v(inward),
                });
            }
        }
        if near.len() > out.len() {
            out = near;
        }
    }
    if out.is_empty() {
        // Contacts between samples only: keep the exact closest points.
        for (_, on_object) in windows {
            out.push(ContactPoint {
                position: g2p(on_object),
                normal: -g2v(object.outward_normal_g(on_object)),
            });
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

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
            ContactPoint {
                position: Point3::new(0.0, 0.0, 0.0),
                normal: Vector3::x(),
            },
            ContactPoint {
                position: Point3::new(0.0, 0.002, 0.0),
                normal: Vector3::y(),
            },
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
