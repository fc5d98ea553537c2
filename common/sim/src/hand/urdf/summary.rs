//! What a URDF hand's file does not show at a glance: which joints mimic which, and along
//! which world axis the fingers close when the hand is at the reference pose (what
//! `graspopt hands FILE` prints).

use super::*;
use crate::pose::{reference_rotation, short as number};

/// A joint that follows another: `multiplier * value + offset`.
#[derive(Clone, Debug, PartialEq)]
pub struct MimicJoint {
    /// The mimic joint.
    pub joint: String,
    /// The joint it follows.
    pub follows: String,
    /// Its value per unit of the followed joint's.
    pub multiplier: f64,
    /// Its value when the followed joint is at 0 (in its own unit).
    pub offset: f64,
    /// Continues alone once its joint stops on a link that is not one of its own.
    pub breakaway: bool,
    /// Its own unit: `rad` (revolute) or `m` (prismatic).
    pub unit: &'static str,
}

/// The line along which a hand's fingers close, across its approach axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosingAxis {
    /// Unit direction in the palm frame (the root link's frame turned by `rz_degrees`), across
    /// the approach axis; its sign says nothing.
    pub palm: Vector3<f64>,
    /// The same direction at the reference pose, in the world (in the world `y`-`z` plane).
    pub world: Vector3<f64>,
    /// The share of the fingers' motion across the approach axis that is along this line
    /// (from 0.5, no line preferred, to 1, all along it).
    pub share: f64,
}

/// Below this share of their motion along one line, fingers close from several directions.
const SINGLE_AXIS_SHARE: f64 = 0.75;

/// Within this many degrees of world `y` (or `z`), a line is called horizontal (vertical).
const LEVEL_DEGREES: f64 = 5.0;

impl UrdfHand {
    /// The mimic joints, in URDF file order.
    pub fn mimic_joints(&self) -> Vec<MimicJoint> {
        self.dofs
            .iter()
            .enumerate()
            .filter_map(|(i, d)| match d.role {
                Role::Mimic {
                    master,
                    multiplier,
                    offset,
                    breakaway,
                } => Some(MimicJoint {
                    joint: d.name.clone(),
                    follows: self.dofs[master].name.clone(),
                    multiplier,
                    offset,
                    breakaway,
                    unit: match self.joints.iter().find(|j| j.dof == Some(i)) {
                        Some(JointModel {
                            motion: Motion::Prismatic(_),
                            ..
                        }) => "m",
                        _ => "rad",
                    },
                }),
                _ => None,
            })
            .collect()
    }

    /// The joint values with every closing joint at its closed limit (held joints open,
    /// mimic joints following).
    fn closed_configuration(&self) -> Vec<f64> {
        let mut q = self.open_configuration();
        for (i, d) in self.dofs.iter().enumerate() {
            if let Role::Closing(dir) = d.role {
                q[i] = if dir > 0.0 { d.limits.1 } else { d.limits.0 };
            }
        }
        for (i, d) in self.dofs.iter().enumerate() {
            if let Role::Mimic {
                master,
                multiplier,
                offset,
                ..
            } = d.role
            {
                q[i] = clamp_to(multiplier * q[master] + offset, d.limits);
            }
        }
        q
    }

    /// The line along which the fingers close: the principal direction, across the approach
    /// axis, of each finger's motion (the mean of its bodies' centres) from the open to the
    /// closed configuration. `None` when no finger moves across the approach axis.
    pub fn closing_axis(&self) -> Option<ClosingAxis> {
        let centres: Vec<Point3<f64>> = self
            .links
            .iter()
            .map(|l| {
                let m = l.shape.mesh();
                let n = m.vertices.len().max(1) as f64;
                Point3::from(m.vertices.iter().map(|v| v.coords).sum::<Vector3<f64>>() / n)
            })
            .collect();
        let mean = |poses: &[Isometry3<f64>], f: usize| -> Option<Vector3<f64>> {
            let at: Vec<Vector3<f64>> = (0..self.links.len())
                .filter(|&b| self.links[b].finger == Some(f))
                .map(|b| (poses[b] * centres[b]).coords)
                .collect();
            (!at.is_empty()).then(|| at.iter().sum::<Vector3<f64>>() / at.len() as f64)
        };
        let (open, closed) = (
            self.body_poses(&self.open_configuration()),
            self.body_poses(&self.closed_configuration()),
        );
        // The 2x2 scatter of the motions across the approach axis (palm x, y).
        let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
        for f in 0..self.finger_count {
            let (Some(a), Some(b)) = (mean(&open, f), mean(&closed, f)) else {
                continue;
            };
            let d = b - a;
            (xx, xy, yy) = (xx + d.x * d.x, xy + d.x * d.y, yy + d.y * d.y);
        }
        let spread = (xx - yy).hypot(2.0 * xy);
        let (big, small) = ((xx + yy + spread) / 2.0, (xx + yy - spread) / 2.0);
        // No motion across the approach axis (or a non-finite one).
        if big.is_nan() || big <= 1e-12 {
            return None;
        }
        let angle = 0.5 * (2.0 * xy).atan2(xx - yy);
        let palm = Vector3::new(angle.cos(), angle.sin(), 0.0);
        Some(ClosingAxis {
            palm,
            world: reference_rotation() * palm,
            share: big / (big + small.max(0.0)),
        })
    }

    /// What `graspopt hands FILE` adds to the joints and links: the mimic joints and the
    /// closing axis at the reference pose, with the `rz_degrees` that would turn it.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        let mimics = self.mimic_joints();
        if mimics.is_empty() {
            out.push_str("mimic joints: none\n");
        } else {
            out.push_str("mimic joints:\n");
        }
        for m in mimics {
            out.push_str(&format!(
                "  {:<16} follows {} as {} * {} {} {} {}{}\n",
                m.joint,
                m.follows,
                number(m.multiplier),
                m.follows,
                if m.offset < 0.0 { '-' } else { '+' },
                number(m.offset.abs()),
                m.unit,
                if m.breakaway {
                    ", breaks away (continues alone once its joint is stopped)"
                } else {
                    ""
                }
            ));
        }
        let rz = self.rz.to_degrees();
        match self.closing_axis() {
            Some(axis) => out.push_str(&format!("closing: {}\n", axis.describe(rz))),
            None => out.push_str(
                "closing: the fingers do not move across the approach axis (no closing axis)\n",
            ),
        }
        out
    }
}

impl ClosingAxis {
    /// The line's angle above world `y` at the reference pose, in degrees within (-90, 90].
    fn elevation(&self) -> f64 {
        wrap(self.world.z.atan2(self.world.y).to_degrees(), 180.0)
    }

    /// A sentence for users: along which world axis the fingers close at the reference pose
    /// (the hand turned by `rz_degrees` = `rz`), and the `rz_degrees` that would make that
    /// line horizontal or vertical.
    pub fn describe(&self, rz: f64) -> String {
        let e = self.elevation();
        let turned = if rz == 0.0 {
            String::new()
        } else {
            format!(" (turned by rz_degrees = {})", degrees(rz))
        };
        if self.share < SINGLE_AXIS_SHARE {
            return format!(
                "fingers close from several directions across the approach axis (no single axis; {}% of their motion is along the main one, at {} degrees from world y){turned}",
                (self.share * 100.0).round(),
                degrees(e)
            );
        }
        // The turn about the approach axis (world x) that brings the line to `target`.
        // Of the two turns half a turn apart, the smaller (the positive one of a tie).
        let to = |target: f64| {
            let a = wrap(rz + wrap(target - e, 180.0), 360.0);
            let b = wrap(a + 180.0, 360.0);
            degrees(if (a.abs() - b.abs()).abs() < 1e-6 {
                a.max(b)
            } else if a.abs() < b.abs() {
                a
            } else {
                b
            })
        };
        let horizontal = "world y (horizontal)";
        let vertical = "world z (vertical)";
        if e.abs() <= LEVEL_DEGREES {
            format!(
                "fingers close along {horizontal} at the reference pose{turned}; rz_degrees = {} in the hand's settings would make them close along {vertical}",
                to(90.0)
            )
        } else if e.abs() >= 90.0 - LEVEL_DEGREES {
            format!(
                "fingers close along {vertical} at the reference pose{turned}; rz_degrees = {} in the hand's settings would make them close along {horizontal}",
                to(0.0)
            )
        } else {
            format!(
                "fingers close along a line {} degrees above world y at the reference pose{turned}; rz_degrees = {} in the hand's settings would make it {horizontal}, {} {vertical}",
                degrees(e),
                to(0.0),
                to(90.0)
            )
        }
    }
}

/// `v` wrapped into `(-period / 2, period / 2]`.
fn wrap(v: f64, period: f64) -> f64 {
    let w = v - period * (v / period).round();
    if w <= -period / 2.0 { w + period } else { w }
}

/// An angle in degrees for a person: to 0.01 degree (`90`, `-60`, `12.5`).
fn degrees(v: f64) -> String {
    number((v * 100.0).round() / 100.0)
}
