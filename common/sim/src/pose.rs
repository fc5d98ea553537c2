//! Trial parameters: a grasp is a palm pose relative to a reference pose near the object.
//!
//! The reference palm frame (see [`reference_pose`]) looks horizontally at the object along world
//! `+x`: palm `z` (approach) = world `+x`, palm `y` = world `+y`, palm `x` = world `-z`. The trial
//! parameters are expressed in that frame:
//! - [`ParamKind::Approach`]: along palm `z` (positive = towards the object; the thesis's `x`);
//! - [`ParamKind::Lateral`]: along palm `y` (world `y`);
//! - [`ParamKind::Vertical`]: along palm `-x` (world up; the thesis's `y`);
//! - [`ParamKind::RotX`], [`ParamKind::RotY`], [`ParamKind::RotZ`]: the components of a rotation
//!   vector (axis times angle, radians) about the reference palm axes, applied at the offset palm
//!   origin.
//!
//! `palm = reference * translation(offsets) * rotation(rotation vector)`.

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

use crate::error::{Result, SimError, ensure_finite};
use crate::object::{Object, ObjectKind};

/// Distance from the object's near side (its bounding box face towards the hand) to the palm
/// origin in the reference pose: the object then starts just above the Barrett palm (whose top is
/// at 0.0415) within reach of the fingers' medial links.
pub const REFERENCE_STANDOFF: f64 = 0.05;

/// One trial parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ParamKind {
    /// Offset along the approach axis (palm `z`), metres.
    Approach,
    /// Offset along palm `y`, metres.
    Lateral,
    /// Offset along palm `-x` (world up in the reference pose), metres.
    Vertical,
    /// Rotation-vector component about palm `x`, radians.
    RotX,
    /// Rotation-vector component about palm `y`, radians.
    RotY,
    /// Rotation-vector component about palm `z`, radians.
    RotZ,
}

impl ParamKind {
    /// Every parameter, in the order of [`TrialSpace::full_6d`].
    pub const ALL: [ParamKind; 6] = [
        ParamKind::Approach,
        ParamKind::Lateral,
        ParamKind::Vertical,
        ParamKind::RotX,
        ParamKind::RotY,
        ParamKind::RotZ,
    ];

    /// A parameter from any of its spellings: the thesis's `x` (approach) and `y` (vertical),
    /// the names users see ([`ParamKind::name`]), the stored (serde) names of journals and
    /// CSV headers (`rot_x`), and `z`, `roll`, `pitch`, `yaw`.
    pub fn parse(name: &str) -> Result<ParamKind> {
        Ok(match name.trim() {
            "x" | "approach" => ParamKind::Approach,
            "z" | "lateral" => ParamKind::Lateral,
            "y" | "vertical" => ParamKind::Vertical,
            "rx" | "rot_x" | "roll" => ParamKind::RotX,
            "ry" | "rot_y" | "pitch" => ParamKind::RotY,
            "rz" | "rot_z" | "yaw" => ParamKind::RotZ,
            other => {
                return Err(SimError::UnknownParam {
                    name: other.to_string(),
                });
            }
        })
    }

    /// The name users type and see: `approach`, `lateral`, `vertical`, `rx`, `ry`, `rz`.
    pub fn name(self) -> &'static str {
        match self {
            ParamKind::Approach => "approach",
            ParamKind::Lateral => "lateral",
            ParamKind::Vertical => "vertical",
            ParamKind::RotX => "rx",
            ParamKind::RotY => "ry",
            ParamKind::RotZ => "rz",
        }
    }
}

impl std::fmt::Display for ParamKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A parameter and its bounds.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ParamSpec {
    /// Which parameter.
    pub kind: ParamKind,
    /// Lower bound.
    pub lower: f64,
    /// Upper bound.
    pub upper: f64,
}

/// A parameter space of trials: a reference palm pose and bounded parameters.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TrialSpace {
    /// The reference palm pose (world).
    pub reference: Isometry3<f64>,
    /// The parameters, in the order of parameter vectors.
    pub params: Vec<ParamSpec>,
}

/// Tolerance on bounds when mapping a parameter vector (round-off of grid scans).
const BOUND_SLACK: f64 = 1e-9;

impl TrialSpace {
    /// A space from its parts; bounds must be finite with `lower <= upper`, kinds distinct.
    pub fn new(reference: Isometry3<f64>, params: Vec<ParamSpec>) -> Result<Self> {
        ensure_finite(reference.to_homogeneous().as_slice(), "reference pose")?;
        for (i, p) in params.iter().enumerate() {
            ensure_finite(&[p.lower, p.upper], "parameter bounds")?;
            if p.lower > p.upper {
                return Err(SimError::InvalidInput(format!(
                    "parameter {}: lower > upper",
                    p.kind
                )));
            }
            if params[..i].iter().any(|q| q.kind == p.kind) {
                return Err(SimError::InvalidInput(format!(
                    "parameter {} given twice",
                    p.kind
                )));
            }
        }
        Ok(Self { reference, params })
    }

    /// 1D: the approach offset (the thesis's 1D scans).
    pub fn approach_1d(object: &Object) -> Self {
        let b = default_bounds(object);
        Self {
            reference: reference_pose(object),
            params: vec![b[0]],
        }
    }

    /// 2D: approach and vertical offsets (the thesis's 2D scans, figures 4.9-4.15).
    pub fn approach_vertical_2d(object: &Object) -> Self {
        let b = default_bounds(object);
        Self {
            reference: reference_pose(object),
            params: vec![b[0], b[2]],
        }
    }

    /// 6D: approach, lateral, vertical offsets and a rotation vector.
    pub fn full_6d(object: &Object) -> Self {
        Self {
            reference: reference_pose(object),
            params: default_bounds(object).to_vec(),
        }
    }

    /// The object's default space ([`TrialSpace::full_6d`]) restricted to `kinds`, in that
    /// order.
    pub fn with_params(object: &Object, kinds: &[ParamKind]) -> Result<Self> {
        let defaults = default_bounds(object);
        let params = kinds
            .iter()
            .map(|k| {
                defaults
                    .iter()
                    .find(|p| p.kind == *k)
                    .copied()
                    .ok_or_else(|| {
                        SimError::InvalidInput(format!("no default bounds for the parameter {k}"))
                    })
            })
            .collect::<Result<Vec<_>>>()?;
        Self::new(reference_pose(object), params)
    }

    /// Number of parameters.
    pub fn dim(&self) -> usize {
        self.params.len()
    }

    /// `(lower, upper)` per parameter.
    pub fn bounds(&self) -> Vec<(f64, f64)> {
        self.params.iter().map(|p| (p.lower, p.upper)).collect()
    }

    /// Maps a point of the unit cube `[0, 1]^dim` onto the bounds.
    pub fn from_unit(&self, u: &[f64]) -> Result<Vec<f64>> {
        self.check_len(u)?;
        ensure_finite(u, "unit-cube parameter vector")?;
        Ok(self
            .params
            .iter()
            .zip(u)
            .map(|(p, t)| p.lower + t * (p.upper - p.lower))
            .collect())
    }

    fn check_len(&self, x: &[f64]) -> Result<()> {
        if x.len() != self.params.len() {
            return Err(SimError::InvalidInput(format!(
                "parameter vector has {} values, the space has {}",
                x.len(),
                self.params.len()
            )));
        }
        Ok(())
    }

    /// The palm pose (world) for a parameter vector (errors if its length is wrong, a value is
    /// not finite or outside its bounds).
    pub fn palm_pose(&self, x: &[f64]) -> Result<Isometry3<f64>> {
        self.check_len(x)?;
        ensure_finite(x, "trial parameter vector")?;
        let mut t = Vector3::zeros();
        let mut r = Vector3::zeros();
        for (p, &v) in self.params.iter().zip(x) {
            if v < p.lower - BOUND_SLACK || v > p.upper + BOUND_SLACK {
                return Err(SimError::InvalidInput(format!(
                    "parameter {} = {v} outside [{}, {}]",
                    p.kind, p.lower, p.upper
                )));
            }
            match p.kind {
                ParamKind::Approach => t.z += v,
                ParamKind::Lateral => t.y += v,
                ParamKind::Vertical => t.x -= v,
                ParamKind::RotX => r.x += v,
                ParamKind::RotY => r.y += v,
                ParamKind::RotZ => r.z += v,
            }
        }
        Ok(self.reference * Translation3::from(t) * UnitQuaternion::from_scaled_axis(r))
    }
}

/// The default reference palm pose for an object: looking along world `+x` at the centre of the
/// object's world bounding box (for the wine glass, at the middle of its bowl), with the palm
/// origin [`REFERENCE_STANDOFF`] before the box's near face.
pub fn reference_pose(object: &Object) -> Isometry3<f64> {
    let (lo, hi) = object.aabb();
    let centre = nalgebra::center(&lo, &hi);
    let height = match object.kind() {
        // The bowl of the wine glass spans 0.068..0.15 above its base.
        ObjectKind::WineGlass => lo.z + 0.11,
        _ => centre.z,
    };
    let origin = Vector3::new(lo.x - REFERENCE_STANDOFF, centre.y, height);
    let rot = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
        -Vector3::z(),
        Vector3::y(),
        Vector3::x(),
    ]));
    Isometry3::from_parts(
        Translation3::from(origin),
        UnitQuaternion::from_rotation_matrix(&rot),
    )
}

/// Default bounds for an object: approach `[-0.16, 0.02]` (from beyond the fingertips' reach,
/// where nothing is touched, to the palm pressing the object), lateral and vertical over the object's half extent plus 1 cm, rotations
/// `[-pi/4, pi/4]`; order: approach, lateral, vertical, rot x, rot y, rot z.
pub fn default_bounds(object: &Object) -> [ParamSpec; 6] {
    let (lo, hi) = object.aabb();
    let half = (hi - lo) / 2.0;
    let q = std::f64::consts::FRAC_PI_4;
    let spec = |kind, lower, upper| ParamSpec { kind, lower, upper };
    [
        spec(ParamKind::Approach, -0.16, 0.02),
        spec(ParamKind::Lateral, -(half.y + 0.01), half.y + 0.01),
        spec(ParamKind::Vertical, -(half.z + 0.01), half.z + 0.01),
        spec(ParamKind::RotX, -q, q),
        spec(ParamKind::RotY, -q, q),
        spec(ParamKind::RotZ, -q, q),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    #[test]
    fn reference_frame_looks_along_world_x() {
        let o = Object::by_name("cylinder").unwrap();
        let r = reference_pose(&o);
        assert!((r * Vector3::z() - Vector3::x()).norm() < 1e-12);
        assert!((r * Vector3::x() + Vector3::z()).norm() < 1e-12);
        assert!((r.translation.vector - Vector3::new(-0.08, 0.0, 0.06)).norm() < 1e-9);
    }

    #[test]
    fn parameters_map_to_the_documented_axes() {
        let o = Object::by_name("sphere").unwrap();
        let s = TrialSpace::full_6d(&o);
        let base = s.palm_pose(&[0.0; 6]).unwrap();
        let moved = s.palm_pose(&[0.01, 0.002, 0.003, 0.0, 0.0, 0.0]).unwrap();
        let d = moved.translation.vector - base.translation.vector;
        assert!(
            (d - Vector3::new(0.01, 0.002, 0.003)).norm() < 1e-12,
            "{d:?}"
        );
        let rotated = s.palm_pose(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.3]).unwrap();
        // A rotation about the approach axis keeps the approach axis and the origin.
        assert!((rotated * Point3::origin() - base * Point3::origin()).norm() < 1e-12);
        assert!((rotated * Vector3::z() - Vector3::x()).norm() < 1e-12);
        assert!(s.palm_pose(&[f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0]).is_err());
        assert!(s.palm_pose(&[0.0; 5]).is_err());
        assert!(s.palm_pose(&[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]).is_err());
        let two = TrialSpace::approach_vertical_2d(&o);
        assert_eq!(two.dim(), 2);
        assert_eq!(
            two.from_unit(&[0.0, 1.0]).unwrap(),
            vec![two.params[0].lower, two.params[1].upper]
        );
    }

    #[test]
    fn a_parameter_parses_from_every_spelling_and_nothing_else() {
        for k in ParamKind::ALL {
            assert_eq!(ParamKind::parse(k.name()).unwrap(), k);
            // The stored (serde) name of journals and CSV headers.
            let stored = serde_json::to_value(k).unwrap();
            assert_eq!(ParamKind::parse(stored.as_str().unwrap()).unwrap(), k);
        }
        for (name, k) in [
            ("x", ParamKind::Approach),
            ("y", ParamKind::Vertical),
            ("z", ParamKind::Lateral),
            (" roll ", ParamKind::RotX),
            ("pitch", ParamKind::RotY),
            ("yaw", ParamKind::RotZ),
        ] {
            assert_eq!(ParamKind::parse(name).unwrap(), k, "{name}");
        }
        let err = ParamKind::parse("q").unwrap_err().to_string();
        assert!(err.contains("unknown trial parameter \"q\""), "{err}");
        assert!(ParamKind::parse("").is_err());
    }

    #[test]
    fn a_space_with_chosen_parameters_keeps_their_order_and_default_bounds() {
        let o = Object::by_name("mug").unwrap();
        let full = TrialSpace::full_6d(&o);
        let s = TrialSpace::with_params(&o, &[ParamKind::RotZ, ParamKind::Approach]).unwrap();
        assert_eq!(s.params, vec![full.params[5], full.params[0]]);
        assert_eq!(s.reference, full.reference);
        let twice = TrialSpace::with_params(&o, &[ParamKind::Approach, ParamKind::Approach]);
        assert!(twice.unwrap_err().to_string().contains("given twice"));
    }
}
