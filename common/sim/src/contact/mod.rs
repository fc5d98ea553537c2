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
//! Raw clouds (contact regions) are computed in `region.rs` (and `cuboid.rs` for box links).
//!
//! The models are registered in one table, [`MODELS`] (`models.rs`): to add a contact model, see
//! there (a variant, its function, its row).

use nalgebra::{Point3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::convert::{g2p, g2v, p2g, v2g};
use crate::error::{Result, SimError, ensure_finite};
use crate::noise::gaussian;
use crate::object::Object;

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

/// The given model of a cloud (its row's [`ModelEntry::contacts`]).
pub fn model_contacts(
    model: ContactModel,
    cloud: &[ContactPoint],
    object: &Object,
    settings: &ContactModelSettings,
) -> Vec<ContactPoint> {
    (model.entry().contacts)(cloud, object, settings)
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

mod cuboid;
mod models;
mod region;

pub use models::{
    ContactModel, MODELS, ModelContacts, ModelEntry, ModelFn, noise_stream, oldest_first,
};

pub(crate) use region::link_cloud;

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
