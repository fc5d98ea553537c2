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
//!
//! Each parameter has default bounds ([`default_bounds`]) and hard limits
//! ([`ParamKind::limits`]) that any bounds a user sets ([`ParamSpec::parse_range`],
//! [`TrialSpace::with_ranges`]) must stay within.

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

use crate::error::{Result, SimError, ensure_finite};
use crate::object::{Object, ObjectKind};

/// Default approach bounds (metres): from beyond the fingertips' reach, where nothing is
/// touched, to the palm pressing the object.
pub const APPROACH_DEFAULT: (f64, f64) = (-0.16, 0.02);

/// The default lateral and vertical bounds reach this far (metres) beyond the object's half
/// extent.
pub const EXTENT_MARGIN: f64 = 0.01;

/// Default bound of each rotation parameter (radians, either way): 45 degrees.
pub const ROTATION_DEFAULT: f64 = std::f64::consts::FRAC_PI_4;

/// Hard limit of the translation parameters (metres, either way): the farthest a hand placed
/// inside an object is retreated ([`crate::hand::MAX_RETREAT`]).
pub const TRANSLATION_LIMIT: f64 = crate::hand::MAX_RETREAT;

/// Hard limit of `rx` and `ry` (radians, either way): beyond a quarter turn the palm faces away
/// from the object.
pub const TILT_LIMIT: f64 = std::f64::consts::FRAC_PI_2;

/// Hard limit of `rz` (radians, either way): a full turn about the approach axis, so that
/// ranges such as `-pi:pi` or `0:2pi` fit.
pub const ROLL_LIMIT: f64 = std::f64::consts::TAU;

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

impl ParamKind {
    /// The hard limits `(lower, upper)` of the parameter: bounds outside them are refused
    /// (translations [`TRANSLATION_LIMIT`], `rx` and `ry` [`TILT_LIMIT`], `rz`
    /// [`ROLL_LIMIT`], either way).
    pub fn limits(self) -> (f64, f64) {
        let l = match self {
            ParamKind::Approach | ParamKind::Lateral | ParamKind::Vertical => TRANSLATION_LIMIT,
            ParamKind::RotX | ParamKind::RotY => TILT_LIMIT,
            ParamKind::RotZ => ROLL_LIMIT,
        };
        (-l, l)
    }

    /// The parameter's unit: `m` or `rad`.
    pub fn unit(self) -> &'static str {
        match self {
            ParamKind::RotX | ParamKind::RotY | ParamKind::RotZ => "rad",
            _ => "m",
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

impl ParamSpec {
    /// One range as a user writes it: `NAME=LOWER:UPPER` (a name [`ParamKind::parse`] reads;
    /// metres, radians for rx, ry, rz), with `LOWER < UPPER`, both within the parameter's
    /// [`ParamKind::limits`]. Errors quote the range and say what is wrong.
    pub fn parse_range(text: &str) -> Result<ParamSpec> {
        let text = text.trim();
        let bad = |reason: String| SimError::Range {
            text: text.to_string(),
            reason,
        };
        let (name, bounds) = text
            .split_once('=')
            .ok_or_else(|| bad("expected NAME=LOWER:UPPER, e.g. rz=-3.1416:3.1416".into()))?;
        let kind = ParamKind::parse(name)?;
        let (lo, hi) = bounds
            .split_once(':')
            .ok_or_else(|| bad("expected LOWER:UPPER after the name, e.g. -0.05:0.02".into()))?;
        let number = |v: &str| -> Result<f64> {
            match v.trim().parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ => Err(bad(format!("{:?} is not a finite number", v.trim()))),
            }
        };
        let spec = ParamSpec {
            kind,
            lower: number(lo)?,
            upper: number(hi)?,
        };
        spec.check().map_err(bad)?;
        Ok(spec)
    }

    /// Bounds that are finite, ordered and within the parameter's limits; the reason if not.
    fn check(&self) -> std::result::Result<(), String> {
        let (lo, hi) = self.kind.limits();
        if !(self.lower.is_finite() && self.upper.is_finite()) {
            return Err(format!("the bounds of {} are not finite", self.kind));
        }
        if self.lower >= self.upper {
            return Err(format!(
                "the lower bound of {} must be below its upper bound",
                self.kind
            ));
        }
        if self.lower < lo - BOUND_SLACK || self.upper > hi + BOUND_SLACK {
            return Err(format!(
                "{} must stay within the simulator's limits {}:{} {} ({})",
                self.kind,
                short(lo),
                short(hi),
                self.kind.unit(),
                match self.kind {
                    ParamKind::RotZ => "a full turn either way",
                    ParamKind::RotX | ParamKind::RotY => "a quarter turn either way",
                    _ => "the farthest a hand placed in the object is retreated",
                }
            ));
        }
        Ok(())
    }
}

impl std::fmt::Display for ParamSpec {
    /// `rz=-0.7854:0.7854`, as [`ParamSpec::parse_range`] reads it (4 decimals at most).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}={}:{}",
            self.kind,
            short(self.lower),
            short(self.upper)
        )
    }
}

/// A number for a message: at most 4 decimals, trailing zeros dropped (`-0.7854`, `0.02`,
/// `90`), or `1.0000e-6` when tiny or huge.
pub fn short(v: f64) -> String {
    if v == 0.0 || (1e-3..1e6).contains(&v.abs()) {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" { "0".into() } else { s.into() }
    } else {
        format!("{v:.4e}")
    }
}

/// The help of a flag of ranges (`--range`): the syntax, and the default ranges and hard
/// limits of every parameter (`approach (x) -0.16:0.02 m (limits -0.5:0.5), ...`).
pub fn ranges_help() -> String {
    let t = |lo: f64, hi: f64| format!("{}:{}", short(lo), short(hi));
    let (a, r) = (APPROACH_DEFAULT, ROTATION_DEFAULT);
    let lim = |k: ParamKind| {
        let (lo, hi) = k.limits();
        t(lo, hi)
    };
    format!(
        "Bounds of trial parameters, e.g. rz=-3.1416:3.1416,x=-0.05:0.02 (each one of the \
         trial's parameters; metres, radians). Defaults and limits: approach (x) {} m (limits \
         {}); lateral and vertical (y): the object's half extent + {} m \
         either way (limits {}); rx and ry {} rad (limits {}); rz {} rad (limits {})",
        t(a.0, a.1),
        lim(ParamKind::Approach),
        short(EXTENT_MARGIN),
        lim(ParamKind::Vertical),
        t(-r, r),
        lim(ParamKind::RotX),
        t(-r, r),
        lim(ParamKind::RotZ),
    )
}

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
            let (lo, hi) = p.kind.limits();
            if p.lower < lo - BOUND_SLACK || p.upper > hi + BOUND_SLACK {
                return Err(SimError::InvalidInput(format!(
                    "parameter {}: bounds {}:{} outside the simulator's limits {}:{} {}",
                    p.kind,
                    short(p.lower),
                    short(p.upper),
                    short(lo),
                    short(hi),
                    p.kind.unit()
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

    /// The object's default space restricted to `kinds` ([`TrialSpace::with_params`]), the
    /// bounds of the parameters named in `ranges` replaced by theirs. A range for a parameter
    /// not in `kinds`, or two for one parameter, is an error naming it.
    pub fn with_ranges(object: &Object, kinds: &[ParamKind], ranges: &[ParamSpec]) -> Result<Self> {
        let mut space = Self::with_params(object, kinds)?;
        for (i, r) in ranges.iter().enumerate() {
            let bad = |reason: String| SimError::Range {
                text: r.to_string(),
                reason,
            };
            if ranges[..i].iter().any(|o| o.kind == r.kind) {
                return Err(bad(format!("a second range for {}", r.kind)));
            }
            r.check().map_err(bad)?;
            let Some(p) = space.params.iter_mut().find(|p| p.kind == r.kind) else {
                let names: Vec<&str> = kinds.iter().map(|k| k.name()).collect();
                return Err(bad(format!(
                    "{} is not one of this command's trial parameters ({})",
                    r.kind,
                    names.join(", ")
                )));
            };
            *p = *r;
        }
        Self::new(space.reference, space.params)
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
    Isometry3::from_parts(Translation3::from(origin), reference_rotation())
}

/// The orientation of the reference palm frame in the world, the same for every object:
/// palm `z` (approach) = world `+x`, palm `y` = world `+y`, palm `x` = world `-z`.
pub fn reference_rotation() -> UnitQuaternion<f64> {
    let rot = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
        -Vector3::z(),
        Vector3::y(),
        Vector3::x(),
    ]));
    UnitQuaternion::from_rotation_matrix(&rot)
}

/// Default bounds for an object: approach [`APPROACH_DEFAULT`] (from beyond the fingertips'
/// reach, where nothing is touched, to the palm pressing the object), lateral and vertical
/// over the object's half extent plus [`EXTENT_MARGIN`], rotations [`ROTATION_DEFAULT`] either
/// way; each within its parameter's [`ParamKind::limits`]. Order: approach, lateral,
/// vertical, rot x, rot y, rot z.
pub fn default_bounds(object: &Object) -> [ParamSpec; 6] {
    let (lo, hi) = object.aabb();
    let half = (hi - lo) / 2.0;
    let q = ROTATION_DEFAULT;
    let spec = |kind: ParamKind, lower: f64, upper: f64| {
        let (min, max) = kind.limits();
        ParamSpec {
            kind,
            lower: lower.max(min),
            upper: upper.min(max),
        }
    };
    let (a, m) = (APPROACH_DEFAULT, EXTENT_MARGIN);
    [
        spec(ParamKind::Approach, a.0, a.1),
        spec(ParamKind::Lateral, -(half.y + m), half.y + m),
        spec(ParamKind::Vertical, -(half.z + m), half.z + m),
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

    #[test]
    fn a_range_parses_within_its_limits_and_bad_ones_say_why() {
        let r = ParamSpec::parse_range(" rz=-3.2:4.25 ").unwrap();
        assert_eq!((r.kind, r.lower, r.upper), (ParamKind::RotZ, -3.2, 4.25));
        assert_eq!(r.to_string(), "rz=-3.2:4.25");
        let x = ParamSpec::parse_range("x=-0.05:0.02").unwrap();
        assert_eq!(
            (x.kind, x.lower, x.upper),
            (ParamKind::Approach, -0.05, 0.02)
        );
        // A full turn either way for rz, a quarter turn for rx and ry, half a metre for
        // translations.
        ParamSpec::parse_range("rz=0:6.2831").unwrap();
        for (text, reason) in [
            (
                "rz=-7:7",
                "rz must stay within the simulator's limits -6.2832:6.2832 rad (a full turn either way)",
            ),
            (
                "ry=-2:0",
                "ry must stay within the simulator's limits -1.5708:1.5708 rad (a quarter turn either way)",
            ),
            (
                "lateral=0:0.6",
                "lateral must stay within the simulator's limits -0.5:0.5 m (the farthest a hand placed in the object is retreated)",
            ),
            (
                "x=0.02:-0.05",
                "the lower bound of approach must be below its upper bound",
            ),
            (
                "x=0:0",
                "the lower bound of approach must be below its upper bound",
            ),
            ("x=0:inf", "\"inf\" is not a finite number"),
            ("x=a:1", "\"a\" is not a finite number"),
            (
                "x=-0.05",
                "expected LOWER:UPPER after the name, e.g. -0.05:0.02",
            ),
            ("x", "expected NAME=LOWER:UPPER, e.g. rz=-3.1416:3.1416"),
        ] {
            let e = ParamSpec::parse_range(text).unwrap_err().to_string();
            assert_eq!(e, format!("range {text:?}: {reason}"));
        }
        let e = ParamSpec::parse_range("q=0:1").unwrap_err().to_string();
        assert!(e.contains("unknown trial parameter \"q\""), "{e}");
    }

    #[test]
    fn ranges_replace_the_default_bounds_of_the_parameters_they_name() {
        let o = Object::by_name("cylinder").unwrap();
        let kinds = [ParamKind::Approach, ParamKind::RotZ];
        let rz = ParamSpec::parse_range("rz=-3:3").unwrap();
        let s = TrialSpace::with_ranges(&o, &kinds, &[rz]).unwrap();
        let defaults = TrialSpace::with_params(&o, &kinds).unwrap();
        assert_eq!(s.params, vec![defaults.params[0], rz]);
        assert_eq!(s.reference, defaults.reference);
        // rz = 2.5 is a trial of this space, outside the default 45 degrees.
        s.palm_pose(&[0.0, 2.5]).unwrap();
        assert!(defaults.palm_pose(&[0.0, 2.5]).is_err());
        assert_eq!(TrialSpace::with_ranges(&o, &kinds, &[]).unwrap(), defaults);
        let lateral = ParamSpec::parse_range("lateral=-0.1:0.1").unwrap();
        let e = TrialSpace::with_ranges(&o, &kinds, &[lateral])
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "range \"lateral=-0.1:0.1\": lateral is not one of this command's trial parameters (approach, rz)"
        );
        let e = TrialSpace::with_ranges(&o, &kinds, &[rz, rz])
            .unwrap_err()
            .to_string();
        assert!(e.contains("a second range for rz"), "{e}");
        // Bounds built by hand are held to the same limits.
        let wide = ParamSpec {
            kind: ParamKind::RotZ,
            lower: -7.0,
            upper: 7.0,
        };
        assert!(TrialSpace::with_ranges(&o, &kinds, &[wide]).is_err());
        let e = TrialSpace::new(s.reference, vec![wide])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("outside the simulator's limits -6.2832:6.2832 rad"),
            "{e}"
        );
    }

    #[test]
    fn default_bounds_lie_within_the_limits_and_the_help_shows_them() {
        for name in Object::names() {
            let o = Object::by_name(name).unwrap();
            for p in default_bounds(&o) {
                let (lo, hi) = p.kind.limits();
                assert!(lo <= p.lower && p.upper <= hi, "{name}: {p:?}");
            }
        }
        let help = ranges_help();
        let cylinder = default_bounds(&Object::by_name("cylinder").unwrap());
        for part in [
            format!("approach (x) {}:{} m", cylinder[0].lower, cylinder[0].upper),
            format!(
                "rz {}:{} rad",
                short(cylinder[5].lower),
                short(cylinder[5].upper)
            ),
            "(limits -6.2832:6.2832)".to_string(),
            "(limits -1.5708:1.5708)".to_string(),
            "(limits -0.5:0.5)".to_string(),
            "half extent + 0.01 m".to_string(),
        ] {
            assert!(help.contains(&part), "{part:?} not in {help}");
        }
        // The cylinder (radius 0.03, 0.12 high): vertical over its half height plus 0.01.
        assert!((cylinder[2].upper - 0.07).abs() < 1e-12);
    }
}
