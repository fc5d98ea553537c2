//! A Barrett BH8-280 hand: a palm disc and three fingers (F1, F2 spreading about the palm
//! normal in opposite senses, F3 fixed), two links each, sizes and limits from the BH8-280
//! kinematic description (`shared/spec/barrett-hand.md`) and OpenRAVE's model of the hand (the
//! one the thesis used), see the constants.
//!
//! Palm frame: `z` out of the palm (the approach direction), F1/F2 bases on the `x` axis, F3 on
//! `+y`. With spread 0, F1 and F2 stand side by side at `y = -0.05` facing F3 at `y = +0.05`.
//!
//! Facts taken from OpenRAVE's `src/robots/barretthand.kinbody.xml` (rdiankov/openrave):
//! - spread bases 0.025 m either side of the palm centre, the flexion joint 0.05 m out along the
//!   finger from the spread axis, all three flexion joints in one plane (here 0.0754 m above
//!   the palm's underside, as the spec says);
//! - medial link 0.07 m from the flexion joint to the distal joint (`Translation 0.07 0 0`);
//! - flexion joints `JF1..JF3` over `[0, 140]` degrees;
//! - distal joints `JF1mimic..JF3mimic`: `mimic="JFk 0.33333 0.8727"`, i.e.
//!   `distal = medial / 3 + 0.8727` rad, with limits `[0, 90]` degrees; the distal angle is
//!   measured from the medial link's line, in the closing sense, so at rest (medial 0) the
//!   distal link is bent 50 degrees inwards and the fingertips point towards the object.
//!
//! The distal length (0.059 m, joint to fingertip) is the spec's: OpenRAVE gives that link as a
//! mesh only.
//!
//! Closing: the medial (proximal) joint advances from 0 with the distal joint coupled at
//! `medial / 3 + 0.8727`, held at its 90 degree limit once the coupling reaches it. If the
//! medial link touches, it stops and the distal joint continues alone (the TorqueSwitch
//! breakaway) until the distal link touches or reaches its limit. If the distal link touches
//! first, the whole finger stops. Simplifications: the knuckle housings between the palm and
//! the flexion joints and the 0.003 m lateral offset of the distal joint are not modelled;
//! links are boxes.

use nalgebra::{Isometry3, Point3, Translation3, Unit, UnitQuaternion, Vector3};
use parry3d_f64::math::Pose;

use super::{
    CONTACT_TOLERANCE, Grasp, Hand, LinkGeometry, LinkShape, LinkSpec, advance_until_contact,
    clear_hand, finish_grasp,
};
use crate::convert::iso2pose;
use crate::error::{Result, SimError, ensure_finite};
use crate::object::Object;

/// Palm disc radius.
pub const PALM_RADIUS: f64 = 0.045;
/// Palm disc thickness (below the finger bases).
pub const PALM_THICKNESS: f64 = 0.02;
/// Height of the palm disc's centre: its top face (the finger bases' plane) is at 0.0415.
pub const PALM_CENTRE: f64 = 0.0315;
/// F1 spread-joint base on the palm (F2 mirrored in `x`).
pub const F1_BASE: [f64; 3] = [-0.025, 0.0, 0.0415];
/// F3 base (its flexion joint; F3 has no spread).
pub const F3_BASE: [f64; 3] = [0.0, 0.05, 0.0754];
/// From the spread-joint frame to the flexion joint: along the finger.
pub const KNUCKLE_OUT: f64 = 0.05;
/// From the spread-joint frame to the flexion joint: up (palm `z`).
pub const KNUCKLE_UP: f64 = 0.0339;
/// Medial link, joint to joint (OpenRAVE's 0.07; the spec's measured 0.06994 differs by 0.06 mm).
pub const MEDIAL_LENGTH: f64 = 0.07;
/// Distal link, joint to fingertip.
pub const DISTAL_LENGTH: f64 = 0.059;
/// Finger width (along the flexion axis).
pub const FINGER_WIDTH: f64 = 0.025;
/// Finger thickness (in the closing direction).
pub const FINGER_THICKNESS: f64 = 0.02;
/// Flexion range of the medial joint: `[0, FLEX_MAX]` (140 degrees).
pub const FLEX_MAX: f64 = 2.44346;
/// Distal joint upper limit (90 degrees, OpenRAVE's `limitsdeg 0 90`); the lower limit is 0.
pub const DISTAL_MAX: f64 = std::f64::consts::FRAC_PI_2;
/// The distal joint's coupling ratio to the medial joint (OpenRAVE: 0.33333).
pub const DISTAL_RATIO: f64 = 1.0 / 3.0;
/// The fixed distal bend: the coupled distal angle at medial 0 (OpenRAVE's mimic offset, 50
/// degrees).
pub const DISTAL_OFFSET: f64 = 0.8727;
/// Spread range `[0, pi]`.
pub const SPREAD_MAX: f64 = std::f64::consts::PI;

/// A Barrett BH8-style hand with a fixed spread angle.
#[derive(Debug)]
pub struct BarrettOracle {
    spread: f64,
    links: Vec<LinkSpec>,
    geometry: LinkGeometry,
}

impl Default for BarrettOracle {
    /// Spread 0: F1 and F2 side by side facing F3.
    fn default() -> Self {
        Self::build(0.0)
    }
}

impl BarrettOracle {
    /// A hand whose F1/F2 spread joint is at `spread` (radians, `[0, pi]`) during the grasp.
    pub fn new(spread: f64) -> Result<Self> {
        ensure_finite(&[spread], "Barrett spread angle")?;
        if !(0.0..=SPREAD_MAX).contains(&spread) {
            return Err(SimError::InvalidInput(format!(
                "Barrett spread {spread} outside [0, pi]"
            )));
        }
        Ok(Self::build(spread))
    }

    fn build(spread: f64) -> Self {
        let palm = LinkSpec {
            name: "palm".to_string(),
            finger: None,
            shape: LinkShape::Cylinder {
                radius: PALM_RADIUS,
                half_height: PALM_THICKNESS / 2.0,
            },
        };
        let mut links = vec![palm];
        for f in 0..3 {
            for (part, len) in [("medial", MEDIAL_LENGTH), ("distal", DISTAL_LENGTH)] {
                links.push(LinkSpec {
                    name: format!("f{}_{part}", f + 1),
                    finger: Some(f),
                    shape: LinkShape::Box {
                        half_extents: Vector3::new(
                            FINGER_WIDTH / 2.0,
                            FINGER_THICKNESS / 2.0,
                            len / 2.0,
                        ),
                    },
                });
            }
        }
        let geometry = LinkGeometry::new(&links);
        Self {
            spread,
            links,
            geometry,
        }
    }

    /// The spread angle used.
    pub fn spread(&self) -> f64 {
        self.spread
    }

    /// Frame of finger `f`'s flexion joint in the palm frame: `x` the flexion axis, `y` pointing
    /// away from the palm centre (closing moves the finger towards `-y`), `z` the palm normal.
    pub fn finger_frame(&self, f: usize) -> Isometry3<f64> {
        Self::frame_at(f, self.spread)
    }

    /// The flexion joint frame of finger `f` at `spread`. The frames are composed joint by
    /// joint (a fixed offset, then the joint's motion), in the order and with the operations a
    /// URDF chain uses, so that the URDF description of this hand gives the same poses to the
    /// last bit.
    fn frame_at(f: usize, spread: f64) -> Isometry3<f64> {
        match f {
            0 | 1 => {
                // F1 spreads about -z, F2 (mirrored in x) about +z; both knuckle frames are
                // turned half a turn so that their y points out along the finger.
                let sign = if f == 0 { -1.0 } else { 1.0 };
                let knuckle = offset(
                    [sign * -F1_BASE[0], F1_BASE[1], F1_BASE[2]],
                    std::f64::consts::PI,
                ) * turn(Vector3::new(0.0, 0.0, sign), spread);
                knuckle * offset([0.0, KNUCKLE_OUT, KNUCKLE_UP], 0.0)
            }
            _ => offset(F3_BASE, 0.0),
        }
    }

    /// Medial and distal link frames (box centres) in the palm frame, for the flexion joint
    /// frame `flex`.
    fn finger_links(
        flex: &Isometry3<f64>,
        medial: f64,
        distal: f64,
    ) -> (Isometry3<f64>, Isometry3<f64>) {
        let m = flex * turn(Vector3::x(), medial);
        let d = (m * offset([0.0, 0.0, MEDIAL_LENGTH], 0.0)) * turn(Vector3::x(), distal);
        (
            m * offset([0.0, 0.0, MEDIAL_LENGTH / 2.0], 0.0),
            d * offset([0.0, 0.0, DISTAL_LENGTH / 2.0], 0.0),
        )
    }

    /// Fingertip (centre of the distal link's end face) in the palm frame.
    pub fn fingertip(&self, f: usize, medial: f64, distal: f64) -> Point3<f64> {
        let (_, d) = Self::finger_links(&self.finger_frame(f), medial, distal);
        d * Point3::new(0.0, 0.0, DISTAL_LENGTH / 2.0)
    }
}

/// A fixed offset: a translation and a turn about `z` (URDF's `<origin xyz rpy="0 0 yaw">`).
fn offset(xyz: [f64; 3], yaw: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(0.0, 0.0, yaw),
    )
}

/// A revolute joint's motion: `angle` about the unit `axis`.
fn turn(axis: Vector3<f64>, angle: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_axis_angle(&Unit::new_normalize(axis), angle),
    )
}

impl Hand for BarrettOracle {
    fn name(&self) -> &str {
        "barrett"
    }

    fn links(&self) -> &[LinkSpec] {
        &self.links
    }

    fn finger_count(&self) -> usize {
        3
    }

    /// `spread, f1_medial, f1_distal, f2_medial, f2_distal, f3_medial, f3_distal`.
    fn joint_names(&self) -> Vec<String> {
        let mut v = vec!["spread".to_string()];
        for f in 1..=3 {
            v.push(format!("f{f}_medial"));
            v.push(format!("f{f}_distal"));
        }
        v
    }

    fn joint_limits(&self) -> Vec<(f64, f64)> {
        let mut v = vec![(0.0, SPREAD_MAX)];
        for _ in 0..3 {
            v.push((0.0, FLEX_MAX));
            v.push((0.0, DISTAL_MAX));
        }
        v
    }

    fn open_configuration(&self) -> Vec<f64> {
        let d = coupled_distal(0.0);
        vec![self.spread, 0.0, d, 0.0, d, 0.0, d]
    }

    fn link_poses(&self, joints: &[f64]) -> Result<Vec<Isometry3<f64>>> {
        if joints.len() != 7 {
            return Err(SimError::InvalidInput(format!(
                "Barrett hand needs 7 joint values, got {}",
                joints.len()
            )));
        }
        ensure_finite(joints, "Barrett joint values")?;
        let mut out = vec![offset([0.0, 0.0, PALM_CENTRE], 0.0)];
        // The spread value of the joint vector is used for F1/F2 (it may differ from self.spread).
        for f in 0..3 {
            let frame = Self::frame_at(f, joints[0]);
            let (m, d) = Self::finger_links(&frame, joints[1 + 2 * f], joints[2 + 2 * f]);
            out.push(m);
            out.push(d);
        }
        Ok(out)
    }

    fn close(&self, object: &Object, palm_pose: &Isometry3<f64>) -> Result<Grasp> {
        let (palm, retreat) = clear_hand(self, &self.geometry, object, palm_pose)?;
        let mut joints = self.open_configuration();
        let half = Vector3::new(FINGER_WIDTH / 2.0, FINGER_THICKNESS / 2.0, 0.0);
        let r_medial = (half + Vector3::z() * MEDIAL_LENGTH).norm();
        let r_distal = (half + Vector3::z() * DISTAL_LENGTH).norm();
        for f in 0..3 {
            let frame = self.finger_frame(f);
            let (im, id) = (1 + 2 * f, 2 + 2 * f);
            let poses = |m: f64, d: f64| -> (Pose, Pose) {
                let (lm, ld) = Self::finger_links(&frame, m, d);
                (iso2pose(&(palm * lm)), iso2pose(&(palm * ld)))
            };
            // Phase 1: medial and distal coupled (distal = medial / 3 + 0.8727, at most 90 deg).
            let adv = advance_until_contact(
                |t| {
                    let (pm, pd) = poses(t, coupled_distal(t));
                    Ok(vec![
                        self.geometry.distance_g(object, im, &pm, 0.05)?,
                        self.geometry.distance_g(object, id, &pd, 0.05)?,
                    ])
                },
                0.0,
                FLEX_MAX,
                &[r_medial, MEDIAL_LENGTH + r_distal + r_distal * DISTAL_RATIO],
            )?;
            let medial = adv.t;
            let mut distal = coupled_distal(adv.t);
            if adv.touched == Some(0) {
                // Phase 2: medial blocked, distal continues alone (unless already touching).
                let (_, pm) = poses(medial, distal);
                let d_now = self.geometry.distance_g(object, id, &pm, 0.05)?;
                if d_now > CONTACT_TOLERANCE {
                    let adv2 = advance_until_contact(
                        |t| {
                            let (_, pd) = poses(medial, t);
                            Ok(vec![self.geometry.distance_g(object, id, &pd, 0.05)?])
                        },
                        distal,
                        DISTAL_MAX.max(distal),
                        &[r_distal],
                    )?;
                    distal = adv2.t;
                }
            }
            joints[im] = medial;
            joints[id] = distal;
        }
        finish_grasp(
            self,
            &self.geometry,
            object,
            palm_pose,
            palm,
            retreat,
            joints,
        )
    }
}

/// The distal angle coupled to the medial one before the breakaway: `medial / 3 + 0.8727`,
/// held at the distal limit once it reaches it.
pub fn coupled_distal(medial: f64) -> f64 {
    (DISTAL_RATIO * medial + DISTAL_OFFSET).min(DISTAL_MAX)
}
