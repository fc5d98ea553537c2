//! Readings, settings, sensed contacts and the solver: [`locate`] (a reading to a contact)
//! and [`wrench_of`] (a contact to a reading).

use nalgebra::{Point3, Unit, Vector3};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::error::{SensingError, check};
use crate::surface::{Domain, FingertipSurface, Piece};

/// What the sensor measures: the wrench the object applies to the fingertip, in the sensor
/// frame, the torque taken about the sensor frame's origin (N, N m).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FingertipWrench {
    pub force: Vector3<f64>,
    pub torque: Vector3<f64>,
}

/// The largest force (N) or torque (N m) component a reading may have: far beyond any
/// fingertip sensor's range, far below overflow.
pub const MAX_WRENCH: f64 = 1.0e6;

/// The smallest force (N) taken as a contact whatever the threshold: below it the
/// force's direction is noise.
pub const MIN_FORCE: f64 = 1.0e-9;

const FORCE: [&str; 3] = ["force[0]", "force[1]", "force[2]"];
const TORQUE: [&str; 3] = ["torque[0]", "torque[1]", "torque[2]"];

impl FingertipWrench {
    /// Checks that every component is finite and at most [`MAX_WRENCH`] in absolute
    /// value; the error names it.
    pub fn validate(&self) -> Result<(), SensingError> {
        let names = FORCE.iter().chain(TORQUE.iter());
        let values = self.force.iter().chain(self.torque.iter());
        for (name, value) in names.zip(values) {
            check(name, *value, "at most 1e6 in absolute value", |v| {
                v.abs() <= MAX_WRENCH
            })?;
        }
        Ok(())
    }
}

/// The contact model a reading is interpreted with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactKind {
    /// A point contact: a force only (torque = p x F).
    Point,
    /// A soft finger: a force and a moment about the contact normal
    /// (torque = p x F - t n).
    SoftFinger,
}

/// How readings are turned into contacts.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensingSettings {
    /// The contact model.
    pub kind: ContactKind,
    /// Readings with a force below this (N) are no contact (and below [`MIN_FORCE`]
    /// whatever this is). Default 0.05 N.
    pub force_threshold: f64,
    /// How far (m) the solution may lie off the surface and still be taken, snapped onto
    /// it: a point-contact force line that grazes the surface within this distance gives
    /// the surface point nearest the line; a point this far beyond a capsule's seam or
    /// below the base height still counts. Default 1e-4 m.
    pub surface_tolerance: f64,
    /// Point contact only: the largest pitch (m) of the measured wrench, |torque . F| /
    /// |F|^2, that is taken as noise. A point contact's wrench has pitch 0; a larger pitch
    /// is a torsional moment the point model cannot explain, and the reading is refused
    /// ([`NoContact::Torsion`]). Default 2e-4 m.
    pub pitch_tolerance: f64,
    /// Soft finger only: the largest ratio (m) of the torsion to the normal force,
    /// |t| / (f . n), accepted. A soft contact's torsion is bounded by its torsional
    /// friction, a length of the order of its contact patch times the normal force; a
    /// larger ratio is refused ([`NoContact::TorsionBeyondLimit`]). Every reading of a
    /// convex fingertip has a soft-finger solution, so this bound is what refuses
    /// readings no real soft contact gives (a torsion far too large, or a force almost
    /// tangent to the surface). Default 0.01 m.
    pub torsion_ratio_limit: f64,
}

impl Default for SensingSettings {
    fn default() -> Self {
        Self {
            kind: ContactKind::Point,
            force_threshold: 0.05,
            surface_tolerance: 1e-4,
            pitch_tolerance: 2e-4,
            torsion_ratio_limit: 0.01,
        }
    }
}

impl SensingSettings {
    /// Checks that the threshold and tolerances are finite and >= 0.
    pub fn validate(&self) -> Result<(), SensingError> {
        let non_negative = |v: f64| v >= 0.0;
        check(
            "force_threshold",
            self.force_threshold,
            ">= 0",
            non_negative,
        )?;
        check(
            "surface_tolerance",
            self.surface_tolerance,
            ">= 0",
            non_negative,
        )?;
        check(
            "pitch_tolerance",
            self.pitch_tolerance,
            ">= 0",
            non_negative,
        )?;
        check(
            "torsion_ratio_limit",
            self.torsion_ratio_limit,
            ">= 0",
            non_negative,
        )
    }
}

/// A contact recovered from one reading, in the sensor frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SensedContact {
    pub point: Point3<f64>,
    /// The fingertip's outward normal at `point` (it points into the object).
    pub normal: Unit<Vector3<f64>>,
    /// The force the fingertip applies to the object (= -reading.force).
    pub force: Vector3<f64>,
    /// The moment about `normal` the fingertip applies to the object (0 for
    /// [`ContactKind::Point`]).
    pub torsion: f64,
}

/// Why a reading gives no contact.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum NoContact {
    /// The force `force` (N) is below `threshold` (N): the settings' threshold, or
    /// [`MIN_FORCE`] if that is larger. Nothing touches the fingertip.
    #[error("the force is {force:.4} N, below the contact threshold of {threshold:.4} N")]
    BelowThreshold { force: f64, threshold: f64 },
    /// Point contact only: the torque has a component `torsion` (N m) along the force,
    /// a wrench of pitch `pitch` = torsion / |F| (m) beyond `tolerance` (m). A point
    /// contact cannot apply it: the reading needs the soft-finger model (or is corrupt).
    #[error(
        "the torque has a component of {torsion:.3e} N m along the force (pitch {:.4} mm), beyond the {:.4} mm a point contact allows: a torsional moment the point-contact model cannot explain (use the soft-finger model)",
        pitch * 1e3,
        tolerance * 1e3
    )]
    Torsion {
        torsion: f64,
        pitch: f64,
        tolerance: f64,
    },
    /// Soft finger only: the contact that explains the reading needs a torsion `torsion`
    /// (N m) more than `limit` (m) times its normal force `normal_force` (N): more than a
    /// soft contact can apply.
    #[error(
        "the soft-finger contact that explains the reading needs a torsion of {torsion:.3e} N m with a normal force of {normal_force:.4} N, more than {:.4} mm times the normal force a soft contact can apply",
        limit * 1e3
    )]
    TorsionBeyondLimit {
        torsion: f64,
        normal_force: f64,
        limit: f64,
    },
    /// No point of the surface explains the reading: for a point contact the force's line
    /// of action passes `distance` (m) from the surface, beyond the surface tolerance; for
    /// a soft finger (capsule only) the nearest solution lies `distance` beyond the
    /// surface's pieces.
    #[error(
        "no point of the fingertip surface explains the reading: the solution lies {:.4} mm off the surface, beyond the surface tolerance",
        distance * 1e3
    )]
    MissesSurface { distance: f64 },
    /// The only points of the usable surface (above the base) that explain the reading
    /// are ones where the fingertip would pull the object: its normal force there,
    /// `normal_force` (N), is negative. The pushing solution lies on the mount.
    #[error(
        "the only point of the fingertip's usable surface that explains the reading is one where the fingertip would pull the object (normal force {normal_force:.4} N); the pushing solution lies below the base, where the fingertip is mounted"
    )]
    Pulling { normal_force: f64 },
    /// The only point where the contact pushes lies at height `z`, below `base_z` (m,
    /// sensor frame) where the fingertip is mounted, and no usable point explains the
    /// reading.
    #[error(
        "the contact point that explains the reading is at z = {:.4} mm, below the base at z = {:.4} mm where the fingertip is mounted",
        z * 1e3,
        base_z * 1e3
    )]
    OnMount { z: f64, base_z: f64 },
    /// Two distinct points of the surface, `separation` (m) apart, both explain the
    /// reading; none is chosen.
    #[error(
        "two points of the fingertip surface {:.4} mm apart both explain the reading",
        separation * 1e3
    )]
    Ambiguous { separation: f64 },
    /// The surface, the settings or the reading is invalid. (Its text is in the message,
    /// so it is not a `source()`: a chain printed with `{:#}` would say it twice.)
    #[error("invalid input: {0}")]
    Invalid(SensingError),
}

impl From<SensingError> for NoContact {
    fn from(e: SensingError) -> Self {
        NoContact::Invalid(e)
    }
}

/// Candidates closer than this (m) are one solution (a capsule seam gives the same
/// point from two pieces).
const SAME_POINT: f64 = 1e-8;

/// One solution of the reading on one piece's whole quadric.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    point: Vector3<f64>,
    normal: Unit<Vector3<f64>>,
    torsion: f64,
    /// How far (m) the point lies outside the part of the quadric that is surface.
    excess: f64,
    /// Whether the fingertip pushes the object there (f . n > 0).
    pushing: bool,
}

/// The reading produced by the fingertip applying `force` and the moment `torsion` about
/// the outward normal at surface point `point` (the forward model: the sensor measures the
/// opposite wrench, force -`force` and torque `point` x (-`force`) - `torsion` n).
pub fn wrench_of(
    surface: &FingertipSurface,
    point: &Point3<f64>,
    force: &Vector3<f64>,
    torsion: f64,
) -> FingertipWrench {
    let n = surface.outward_normal(point);
    let on_tip = -force;
    FingertipWrench {
        force: on_tip,
        torque: point.coords.cross(&on_tip) - n.into_inner() * torsion,
    }
}

/// The contact that explains `reading` on `surface`, or why there is none. See the crate
/// documentation for the method.
pub fn locate(
    surface: &FingertipSurface,
    reading: &FingertipWrench,
    settings: &SensingSettings,
) -> Result<SensedContact, NoContact> {
    let contact = solve(surface, reading, settings)?;
    let normal_force = contact.force.dot(&contact.normal);
    if settings.kind == ContactKind::SoftFinger
        && contact.torsion.abs() > settings.torsion_ratio_limit * normal_force
    {
        return Err(NoContact::TorsionBeyondLimit {
            torsion: contact.torsion,
            normal_force,
            limit: settings.torsion_ratio_limit,
        });
    }
    Ok(contact)
}

/// [`locate`] but for the torsion limit.
fn solve(
    surface: &FingertipSurface,
    reading: &FingertipWrench,
    settings: &SensingSettings,
) -> Result<SensedContact, NoContact> {
    surface.validate()?;
    settings.validate()?;
    reading.validate()?;
    let (f, torque) = applied_wrench(reading, settings)?;
    let soft = settings.kind == ContactKind::SoftFinger;
    let candidates: Vec<Candidate> = surface
        .pieces()
        .iter()
        .flat_map(|piece| piece_candidates(piece, &f, &torque, soft))
        .collect();
    if let Some(found) = from_candidates(surface, &candidates, &f, settings) {
        return found;
    }
    // Point contact whose line of action misses the surface: within the tolerance, the
    // surface point nearest the line.
    let f_norm = f.norm();
    let tol = settings.surface_tolerance;
    let line_point = f.cross(&torque) / (f_norm * f_norm);
    let direction = Unit::new_unchecked(f / f_norm);
    let (point, distance) = surface.nearest_to_line(&line_point, &direction);
    if distance > tol {
        return Err(NoContact::MissesSurface { distance });
    }
    match surface.base_z() {
        Some(base_z) if !usable(Some(base_z), tol, &point.coords) => {
            Err(NoContact::OnMount { z: point.z, base_z })
        }
        _ => Ok(SensedContact {
            point,
            normal: surface.outward_normal(&point),
            force: -f,
            torsion: 0.0,
        }),
    }
}

/// Whether `p` is on the fingertip's usable surface: above its mount's base (`base`, if any)
/// less the tolerance.
fn usable(base: Option<f64>, tol: f64, p: &Vector3<f64>) -> bool {
    base.is_none_or(|b| p.z >= b - tol)
}

/// The reading's force and the torque to explain: above the force threshold; for a point
/// contact, with no more torsion than the pitch tolerance allows, and that torsion removed.
fn applied_wrench(
    reading: &FingertipWrench,
    settings: &SensingSettings,
) -> Result<(Vector3<f64>, Vector3<f64>), NoContact> {
    let f = reading.force;
    let f_norm = f.norm();
    let threshold = settings.force_threshold.max(MIN_FORCE);
    if f_norm < threshold {
        return Err(NoContact::BelowThreshold {
            force: f_norm,
            threshold,
        });
    }
    let mut torque = reading.torque;
    if settings.kind != ContactKind::SoftFinger {
        let torsion = torque.dot(&f) / f_norm;
        let pitch = torsion / f_norm;
        if pitch.abs() > settings.pitch_tolerance {
            return Err(NoContact::Torsion {
                torsion,
                pitch,
                tolerance: settings.pitch_tolerance,
            });
        }
        torque -= f * (torque.dot(&f) / (f_norm * f_norm));
    }
    Ok((f, torque))
}

/// The contact among the pieces' `candidates` for the force `f`, or why there is none;
/// `None` for a point contact whose line of action misses every piece (see [`solve`]).
fn from_candidates(
    surface: &FingertipSurface,
    candidates: &[Candidate],
    f: &Vector3<f64>,
    settings: &SensingSettings,
) -> Option<Result<SensedContact, NoContact>> {
    let tol = settings.surface_tolerance;
    let base = surface.base_z();
    let usable_at = |p: &Vector3<f64>| usable(base, tol, p);
    let contact = |c: &Candidate| SensedContact {
        point: Point3::from(c.point),
        normal: c.normal,
        force: -f,
        torsion: c.torsion,
    };
    // A pushing solution on its piece and on the usable surface: the contact, unless
    // there are two distinct ones.
    let exact: Vec<&Candidate> = candidates
        .iter()
        .filter(|c| c.pushing && c.excess == 0.0 && usable_at(&c.point))
        .collect();
    if !exact.is_empty() {
        return Some(one_point(&exact).map(|c| contact(&c)));
    }
    // Just beyond a capsule seam (noise): the least outside, snapped onto the surface.
    let near = candidates
        .iter()
        .filter(|c| c.pushing && c.excess <= tol)
        .map(|c| {
            let point = surface.project(&Point3::from(c.point));
            Candidate {
                point: point.coords,
                normal: surface.outward_normal(&point),
                ..*c
            }
        })
        .filter(|c| usable_at(&c.point))
        .min_by(|a, b| a.excess.total_cmp(&b.excess));
    if let Some(c) = near {
        return Some(Ok(contact(&c)));
    }
    // A pushing solution exists but only on the mount.
    if let (Some(base_z), Some(mounted)) = (
        base,
        candidates.iter().find(|c| c.pushing && c.excess <= tol),
    ) {
        let pulling = candidates
            .iter()
            .find(|c| !c.pushing && c.excess <= tol && usable_at(&c.point));
        return Some(Err(match pulling {
            Some(c) => NoContact::Pulling {
                normal_force: -f.dot(&c.normal),
            },
            None => NoContact::OnMount {
                z: mounted.point.z,
                base_z,
            },
        }));
    }
    if settings.kind == ContactKind::SoftFinger {
        let distance = candidates
            .iter()
            .filter(|c| c.pushing)
            .map(|c| c.excess)
            .fold(f64::INFINITY, f64::min);
        return Some(Err(NoContact::MissesSurface { distance }));
    }
    None
}

/// The one point of `candidates` (not empty), or [`NoContact::Ambiguous`] when two lie
/// more than [`SAME_POINT`] apart.
fn one_point(candidates: &[&Candidate]) -> Result<Candidate, NoContact> {
    let first = candidates[0];
    let separation = candidates
        .iter()
        .map(|c| (c.point - first.point).norm())
        .fold(0.0, f64::max);
    if separation > SAME_POINT {
        Err(NoContact::Ambiguous { separation })
    } else {
        Ok(*first)
    }
}

/// The pushing and pulling solutions of a reading (force `f` on the fingertip, torque
/// about the origin) on one piece's whole quadric.
fn piece_candidates(
    piece: &Piece,
    f: &Vector3<f64>,
    torque: &Vector3<f64>,
    soft: bool,
) -> Vec<Candidate> {
    match *piece {
        Piece::Quadric {
            center,
            semi_axes,
            domain,
        } => quadric_candidates(&center, &semi_axes, domain, f, torque, soft),
        Piece::Cylinder {
            center,
            radius,
            half_length,
        } => cylinder_candidates(&center, radius, half_length, f, torque, soft),
    }
}

/// Solutions on the ellipsoid with semi-axes `a` about `center` (crate doc, "Ellipsoid
/// and sphere"): in the coordinates v = D^-1 (p - center), D = diag(a), the ellipsoid is
/// the unit sphere and the reading equation becomes v x G - k v = b.
fn quadric_candidates(
    center: &Vector3<f64>,
    a: &Vector3<f64>,
    domain: Domain,
    f: &Vector3<f64>,
    torque: &Vector3<f64>,
    soft: bool,
) -> Vec<Candidate> {
    let torque_c = torque - center.cross(f);
    let g_vec = Vector3::new(a.y * a.z * f.x, a.x * a.z * f.y, a.x * a.y * f.z);
    let g = g_vec.norm();
    if g <= 0.0 || !g.is_finite() {
        return Vec::new();
    }
    let g_hat = g_vec / g;
    let b = a.component_mul(&torque_c);
    let beta = if soft { b.dot(&g_hat) } else { 0.0 };
    let b_perp = b - g_hat * b.dot(&g_hat);
    let g2 = g * g;
    let diff = g2 - b_perp.norm_squared() - beta * beta;
    let root = (diff * diff + 4.0 * beta * beta * g2).sqrt();
    // x = k^2 solves x^2 + (g^2 - |b|^2) x - beta^2 g^2 = 0 (its root >= 0), and
    // |alpha| = |beta| / sqrt(x); both written without cancellation.
    let (x, alpha_mag) = if diff > 0.0 {
        (
            2.0 * beta * beta * g2 / (diff + root),
            ((diff + root) / 2.0).sqrt() / g,
        )
    } else {
        let x = (root - diff) / 2.0;
        let alpha = if x > 0.0 { beta.abs() / x.sqrt() } else { 0.0 };
        (x, alpha)
    };
    // alpha = 0: the line of a point contact misses or grazes; a soft finger's solution
    // is tangent. Neither pushes nor pulls.
    if alpha_mag <= 0.0 {
        return Vec::new();
    }
    let cross = b_perp.cross(&g_hat);
    [true, false]
        .into_iter()
        .map(|pushing| {
            // Pushing: alpha < 0 (G . v < 0, i.e. F . n < 0); k alpha = -beta.
            let alpha = if pushing { -alpha_mag } else { alpha_mag };
            let k = if beta == 0.0 { 0.0 } else { -beta / alpha };
            let w = -(cross * g + b_perp * k) / (g2 + x);
            let v = g_hat * alpha + w;
            let u = a.component_mul(&v);
            let grad = v.component_div(a);
            let grad_norm = grad.norm();
            let point = center + u;
            Candidate {
                point,
                normal: Unit::new_unchecked(grad / grad_norm),
                torsion: k * grad_norm,
                excess: domain.excess(point.z),
                pushing,
            }
        })
        .collect()
}

/// Solutions on the cylinder of `radius` about the vertical line through `center`
/// (crate doc, "Capsule"): the torque about the axis fixes the normal's angle, then the
/// height and the torsion follow linearly.
fn cylinder_candidates(
    center: &Vector3<f64>,
    radius: f64,
    half_length: f64,
    f: &Vector3<f64>,
    torque: &Vector3<f64>,
    soft: bool,
) -> Vec<Candidate> {
    let torque_c = torque - center.cross(f);
    let f_xy = f.x.hypot(f.y);
    if f_xy <= 1e-12 * f.norm() {
        return Vec::new();
    }
    let e = Vector3::new(f.x / f_xy, f.y / f_xy, 0.0);
    let e_perp = Vector3::new(-e.y, e.x, 0.0);
    let s = torque_c.z / (radius * f_xy);
    if s.abs() >= 1.0 {
        return Vec::new();
    }
    let c = (1.0 - s * s).sqrt();
    let z_cross_f = Vector3::new(-f.y, f.x, 0.0);
    [true, false]
        .into_iter()
        .map(|pushing| {
            let n = if pushing {
                -e * c - e_perp * s
            } else {
                e * c - e_perp * s
            };
            let torsion = if soft {
                -torque_c.dot(f) / n.dot(f)
            } else {
                0.0
            };
            let z = (torque_c - n.cross(f) * radius + n * torsion).dot(&z_cross_f) / (f_xy * f_xy);
            let point = center + n * radius + Vector3::z() * z;
            Candidate {
                point,
                normal: Unit::new_unchecked(n),
                torsion,
                excess: (z.abs() - half_length).max(0.0),
                pushing,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn candidate(x: f64) -> Candidate {
        Candidate {
            point: Vector3::new(x, 0.0, 0.01),
            normal: Vector3::x_axis(),
            torsion: 0.0,
            excess: 0.0,
            pushing: true,
        }
    }

    #[test]
    fn two_distinct_points_are_ambiguous_a_seam_duplicate_is_one() {
        let (a, b, c) = (candidate(0.008), candidate(0.008 + 1e-12), candidate(0.007));
        let one = one_point(&[&a, &b]).expect("one point");
        assert_eq!(one.point, a.point);
        match one_point(&[&a, &b, &c]) {
            Err(NoContact::Ambiguous { separation }) => {
                assert!((separation - 1e-3).abs() < 1e-15, "{separation}")
            }
            other => panic!("expected Ambiguous, got {other:?}"),
        }
    }
}
