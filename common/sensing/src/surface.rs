//! Fingertip surfaces in the sensor frame: their shapes, validation, outward normals, and
//! the smooth pieces ([`Piece`]) the contact solver works on.

use nalgebra::{Point3, Unit, Vector3};

use crate::error::{SensingError, check, finite};

/// The largest coordinate or size (m) a surface may have. A fingertip is centimetres
/// across; the bound keeps every square and product far from overflow.
pub const MAX_SIZE: f64 = 1.0e3;

/// The smallest radius or semi-axis (m) a surface may have (1 micrometre): far below any
/// fingertip, far above underflow.
pub const MIN_SIZE: f64 = 1.0e-6;

/// A fingertip's surface, in the sensor frame (metres).
///
/// Each shape may carry `base_z`: the fingertip is mounted below that height (sensor
/// frame z), so the part of the surface with `z < base_z` cannot be touched. A reading
/// whose only pushing contact point lies there is refused
/// ([`NoContact::OnMount`](crate::NoContact::OnMount) or
/// [`NoContact::Pulling`](crate::NoContact::Pulling)). JSON leaves it out when absent.
///
/// Serde: in human-readable formats (JSON, TOML) a surface is tagged by its shape,
/// `{"shape": "sphere", "center": [0, 0, 0.015], "radius": 0.012}`; in the others (bincode,
/// which cannot read an internally tagged enum) it is serde's default enum form with every
/// field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FingertipSurface {
    /// A sphere of `radius` about `center`.
    Sphere {
        center: [f64; 3],
        radius: f64,
        base_z: Option<f64>,
    },
    /// Semi-axes along the sensor frame's x, y, z.
    Ellipsoid {
        center: [f64; 3],
        semi_axes: [f64; 3],
        base_z: Option<f64>,
    },
    /// A cylinder of `radius` along the sensor z axis from center - half_length z to
    /// center + half_length z, capped by two hemispheres.
    Capsule {
        center: [f64; 3],
        half_length: f64,
        radius: f64,
        base_z: Option<f64>,
    },
}

/// The two serde forms of [`FingertipSurface`] (see its documentation).
mod wire {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    use super::FingertipSurface;

    /// Declares one serde mirror of the surface's variants, with conversions both ways.
    macro_rules! mirror {
        ($(#[$attr:meta])* $name:ident, $(#[$opt:meta])*) => {
            $(#[$attr])*
            pub(super) enum $name {
                Sphere {
                    center: [f64; 3],
                    radius: f64,
                    $(#[$opt])*
                    base_z: Option<f64>,
                },
                Ellipsoid {
                    center: [f64; 3],
                    semi_axes: [f64; 3],
                    $(#[$opt])*
                    base_z: Option<f64>,
                },
                Capsule {
                    center: [f64; 3],
                    half_length: f64,
                    radius: f64,
                    $(#[$opt])*
                    base_z: Option<f64>,
                },
            }

            impl From<FingertipSurface> for $name {
                fn from(s: FingertipSurface) -> Self {
                    match s {
                        FingertipSurface::Sphere { center, radius, base_z } => {
                            $name::Sphere { center, radius, base_z }
                        }
                        FingertipSurface::Ellipsoid { center, semi_axes, base_z } => {
                            $name::Ellipsoid { center, semi_axes, base_z }
                        }
                        FingertipSurface::Capsule { center, half_length, radius, base_z } => {
                            $name::Capsule { center, half_length, radius, base_z }
                        }
                    }
                }
            }

            impl From<$name> for FingertipSurface {
                fn from(s: $name) -> Self {
                    match s {
                        $name::Sphere { center, radius, base_z } => {
                            FingertipSurface::Sphere { center, radius, base_z }
                        }
                        $name::Ellipsoid { center, semi_axes, base_z } => {
                            FingertipSurface::Ellipsoid { center, semi_axes, base_z }
                        }
                        $name::Capsule { center, half_length, radius, base_z } => {
                            FingertipSurface::Capsule { center, half_length, radius, base_z }
                        }
                    }
                }
            }
        };
    }

    mirror!(
        /// Human-readable: tagged by `shape`, `base_z` left out when absent.
        #[derive(Serialize, Deserialize)]
        #[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
        Tagged,
        #[serde(default, skip_serializing_if = "Option::is_none")]
    );
    mirror!(
        /// Compact: serde's default enum form, every field.
        #[derive(Serialize, Deserialize)]
        Compact,
    );

    impl Serialize for FingertipSurface {
        fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
            if s.is_human_readable() {
                Tagged::from(*self).serialize(s)
            } else {
                Compact::from(*self).serialize(s)
            }
        }
    }

    impl<'de> Deserialize<'de> for FingertipSurface {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            if d.is_human_readable() {
                Tagged::deserialize(d).map(FingertipSurface::from)
            } else {
                Compact::deserialize(d).map(FingertipSurface::from)
            }
        }
    }
}

const CENTER: [&str; 3] = ["center[0]", "center[1]", "center[2]"];
const SEMI_AXES: [&str; 3] = ["semi_axes[0]", "semi_axes[1]", "semi_axes[2]"];
const SIZE: &str = "between 1e-6 and 1000 m";

impl FingertipSurface {
    /// Checks that every number is finite, the centre within [`MAX_SIZE`] of the origin,
    /// radii and semi-axes in [[`MIN_SIZE`], [`MAX_SIZE`]], `half_length` in
    /// [0, [`MAX_SIZE`]] and
    /// `base_z`, when given, below the top of the surface. The error names the field.
    pub fn validate(&self) -> Result<(), SensingError> {
        for (name, value) in CENTER.iter().zip(self.center_array()) {
            check(name, value, "at most 1000 m from 0", |v| {
                v.abs() <= MAX_SIZE
            })?;
        }
        let positive = |v: f64| (MIN_SIZE..=MAX_SIZE).contains(&v);
        match *self {
            Self::Sphere { radius, .. } => check("radius", radius, SIZE, positive)?,
            Self::Ellipsoid { semi_axes, .. } => {
                for (name, value) in SEMI_AXES.iter().zip(semi_axes) {
                    check(name, value, SIZE, positive)?;
                }
            }
            Self::Capsule {
                half_length,
                radius,
                ..
            } => {
                check("radius", radius, SIZE, positive)?;
                check("half_length", half_length, ">= 0 and at most 1000 m", |v| {
                    (0.0..=MAX_SIZE).contains(&v)
                })?;
            }
        }
        if let Some(base) = self.base_z() {
            finite("base_z", base)?;
            let top = self.center_array()[2] + self.half_height();
            check(
                "base_z",
                base,
                "below the top of the fingertip surface (center z + its half height)",
                |b| b < top,
            )?;
        }
        Ok(())
    }

    /// The fingertip's outward unit normal at `p`, a point on (or near) the surface: the
    /// direction from the surface into the object it touches. For a point near but off
    /// the surface it is the normal of the surface through `p` scaled about the centre
    /// (sphere, ellipsoid) or about the nearest axis point (capsule). At the centre (or
    /// on the capsule's axis), where no normal is defined, it returns +z.
    pub fn outward_normal(&self, p: &Point3<f64>) -> Unit<Vector3<f64>> {
        let c = self.center();
        let direction = match *self {
            Self::Sphere { .. } => p - c,
            Self::Ellipsoid { semi_axes, .. } => {
                let d = p - c;
                Vector3::new(
                    d.x / (semi_axes[0] * semi_axes[0]),
                    d.y / (semi_axes[1] * semi_axes[1]),
                    d.z / (semi_axes[2] * semi_axes[2]),
                )
            }
            Self::Capsule { half_length, .. } => {
                let axis_z = (p.z - c.z).clamp(-half_length, half_length);
                p - Point3::new(c.x, c.y, c.z + axis_z)
            }
        };
        Unit::try_new(direction, 0.0).unwrap_or_else(Vector3::z_axis)
    }

    /// The height below which the fingertip is mounted, if any.
    pub fn base_z(&self) -> Option<f64> {
        match *self {
            Self::Sphere { base_z, .. }
            | Self::Ellipsoid { base_z, .. }
            | Self::Capsule { base_z, .. } => base_z,
        }
    }

    /// The centre of the shape.
    pub fn center(&self) -> Point3<f64> {
        Point3::from(self.center_array())
    }

    fn center_array(&self) -> [f64; 3] {
        match *self {
            Self::Sphere { center, .. }
            | Self::Ellipsoid { center, .. }
            | Self::Capsule { center, .. } => center,
        }
    }

    /// Half the surface's extent along z.
    fn half_height(&self) -> f64 {
        match *self {
            Self::Sphere { radius, .. } => radius,
            Self::Ellipsoid { semi_axes, .. } => semi_axes[2],
            Self::Capsule {
                half_length,
                radius,
                ..
            } => half_length + radius,
        }
    }

    /// The smooth pieces of the surface, each a whole quadric with the part of it that
    /// belongs to this surface.
    pub(crate) fn pieces(&self) -> Vec<Piece> {
        let c = self.center().coords;
        match *self {
            Self::Sphere { radius, .. } => vec![Piece::Quadric {
                center: c,
                semi_axes: Vector3::repeat(radius),
                domain: Domain::All,
            }],
            Self::Ellipsoid { semi_axes, .. } => vec![Piece::Quadric {
                center: c,
                semi_axes: Vector3::from(semi_axes),
                domain: Domain::All,
            }],
            Self::Capsule {
                half_length,
                radius,
                ..
            } => {
                let top = c.z + half_length;
                let bottom = c.z - half_length;
                vec![
                    Piece::Cylinder {
                        center: c,
                        radius,
                        half_length,
                    },
                    Piece::Quadric {
                        center: Vector3::new(c.x, c.y, top),
                        semi_axes: Vector3::repeat(radius),
                        domain: Domain::Above(top),
                    },
                    Piece::Quadric {
                        center: Vector3::new(c.x, c.y, bottom),
                        semi_axes: Vector3::repeat(radius),
                        domain: Domain::Below(bottom),
                    },
                ]
            }
        }
    }

    /// `p` moved onto the surface: radially from the centre (sphere), from the nearest
    /// axis point (capsule), or radially in the coordinates that make the ellipsoid a unit
    /// sphere. For the sphere and the capsule this is the nearest surface point; for the
    /// ellipsoid it is near the nearest point when `p` is near the surface (the error is
    /// of second order in the distance). For a contact point that a simulator puts
    /// slightly off a fingertip model. At the centre (or on the axis), it returns the top
    /// of the sphere or ellipsoid, or the +x side of the capsule.
    pub fn project(&self, p: &Point3<f64>) -> Point3<f64> {
        let c = self.center();
        match *self {
            Self::Sphere { radius, .. } => {
                let d = p - c;
                match Unit::try_new(d, 0.0) {
                    Some(n) => c + n.into_inner() * radius,
                    None => c + Vector3::z() * radius,
                }
            }
            Self::Ellipsoid { semi_axes, .. } => {
                let d = p - c;
                let scaled = d.component_div(&Vector3::from(semi_axes)).norm();
                if scaled > 0.0 {
                    c + d / scaled
                } else {
                    c + Vector3::z() * semi_axes[2]
                }
            }
            Self::Capsule {
                half_length,
                radius,
                ..
            } => {
                let axis =
                    Point3::new(c.x, c.y, c.z + (p.z - c.z).clamp(-half_length, half_length));
                match Unit::try_new(p - axis, 0.0) {
                    Some(n) => axis + n.into_inner() * radius,
                    None => axis + Vector3::x() * radius,
                }
            }
        }
    }

    /// The surface point nearest the line `origin + s * direction` and its distance from
    /// the line (negative when the line passes through the inside of the shape:
    /// then the value is only a flag, the point is not meaningful).
    pub(crate) fn nearest_to_line(
        &self,
        origin: &Vector3<f64>,
        direction: &Unit<Vector3<f64>>,
    ) -> (Point3<f64>, f64) {
        let c = self.center().coords;
        let d = direction.into_inner();
        let along = |q: &Vector3<f64>| origin + d * (q - origin).dot(&d);
        match *self {
            Self::Sphere { radius, .. } => {
                let q = along(&c);
                let off = q - c;
                let dist = off.norm();
                let n = Unit::try_new(off, 0.0).unwrap_or_else(Vector3::x_axis);
                (Point3::from(c + n.into_inner() * radius), dist - radius)
            }
            Self::Capsule {
                half_length,
                radius,
                ..
            } => {
                // Closest pair between the line and the axis segment: the reduced
                // squared distance is a convex quadratic in the axis parameter, so its
                // unconstrained minimum clamped to the segment is the constrained one.
                let z = Vector3::z();
                let perp = |v: &Vector3<f64>| v - d * v.dot(&d);
                let pz = perp(&z);
                let mu = if pz.norm_squared() > 1e-24 {
                    perp(&(origin - c)).dot(&pz) / pz.norm_squared()
                } else {
                    // Line parallel to the axis: the nearest point on the cap the force
                    // points into.
                    -d.z.signum() * half_length
                };
                let axis = c + z * mu.clamp(-half_length, half_length);
                let off = along(&axis) - axis;
                let n = Unit::try_new(off, 0.0).unwrap_or_else(Vector3::x_axis);
                (
                    Point3::from(axis + n.into_inner() * radius),
                    off.norm() - radius,
                )
            }
            Self::Ellipsoid { semi_axes, .. } => {
                let a = Vector3::from(semi_axes);
                // dist(q(s), ellipsoid) is convex in s (distance to a convex set along a
                // line): golden-section search on a bracket that holds its minimum.
                let s_center = (c - origin).dot(&d);
                let center_dist = (along(&c) - c).norm();
                let a_max = a.max();
                let reach = center_dist + 2.0 * a_max;
                let dist_at = |s: f64| {
                    let y = origin + d * s - c;
                    let x = nearest_on_ellipsoid(&a, &y);
                    ((y - x).norm(), x)
                };
                let ratio = (5.0_f64.sqrt() - 1.0) / 2.0;
                let (mut lo, mut hi) = (s_center - reach, s_center + reach);
                let mut s1 = hi - ratio * (hi - lo);
                let mut s2 = lo + ratio * (hi - lo);
                let (mut f1, mut f2) = (dist_at(s1).0, dist_at(s2).0);
                for _ in 0..120 {
                    if f1 <= f2 {
                        hi = s2;
                        s2 = s1;
                        f2 = f1;
                        s1 = hi - ratio * (hi - lo);
                        f1 = dist_at(s1).0;
                    } else {
                        lo = s1;
                        s1 = s2;
                        f1 = f2;
                        s2 = lo + ratio * (hi - lo);
                        f2 = dist_at(s2).0;
                    }
                }
                let (dist, x) = dist_at(0.5 * (lo + hi));
                (Point3::from(c + x), dist)
            }
        }
    }
}

/// The point of the ellipsoid with semi-axes `a` (centred at 0) nearest `y`, a point
/// outside it. Its coordinates are x_i = a_i^2 y_i / (a_i^2 + t), where t >= 0 solves
/// sum_i (a_i y_i / (a_i^2 + t))^2 = 1; the left side decreases and is convex in t, so
/// Newton's method from t = 0 rises monotonically to the root. A point on or inside
/// the ellipsoid is returned moved radially (in scaled coordinates) onto it.
fn nearest_on_ellipsoid(a: &Vector3<f64>, y: &Vector3<f64>) -> Vector3<f64> {
    let a2 = a.component_mul(a);
    let scaled = y.component_div(a).norm();
    if scaled <= 1.0 {
        return if scaled > 0.0 {
            y / scaled
        } else {
            Vector3::z() * a.z
        };
    }
    let mut t = 0.0_f64;
    for _ in 0..200 {
        let mut h = -1.0;
        let mut dh = 0.0;
        for i in 0..3 {
            let q = a[i] * y[i] / (a2[i] + t);
            h += q * q;
            dh -= 2.0 * q * q / (a2[i] + t);
        }
        if dh >= 0.0 {
            break;
        }
        // From the left of the root every step is positive; a step that is not, or is
        // at rounding level, means converged.
        let step = -h / dh;
        if step.is_nan() || step <= 1e-15 * (a2.max() + t) {
            break;
        }
        t += step;
    }
    Vector3::new(
        a2.x * y.x / (a2.x + t),
        a2.y * y.y / (a2.y + t),
        a2.z * y.z / (a2.z + t),
    )
}

/// One smooth piece of a fingertip surface.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Piece {
    /// An axis-aligned ellipsoid (a sphere when the semi-axes are equal), of which the
    /// part in `domain` belongs to the surface.
    Quadric {
        center: Vector3<f64>,
        semi_axes: Vector3<f64>,
        domain: Domain,
    },
    /// The cylinder x^2 + y^2 = radius^2 about `center`, between heights
    /// center z -/+ half_length.
    Cylinder {
        center: Vector3<f64>,
        radius: f64,
        half_length: f64,
    },
}

/// The part of a quadric that belongs to the surface.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Domain {
    All,
    /// Points with z >= this height.
    Above(f64),
    /// Points with z <= this height.
    Below(f64),
}

impl Domain {
    /// How far (m) a point at height `z` lies outside the domain (0 inside).
    pub(crate) fn excess(&self, z: f64) -> f64 {
        match *self {
            Domain::All => 0.0,
            Domain::Above(h) => (h - z).max(0.0),
            Domain::Below(h) => (z - h).max(0.0),
        }
    }
}
