//! A two-finger parallel-jaw gripper: a box palm and two box jaws translating towards each other
//! along the palm `y` axis. Each jaw stops independently at its first contact (GraspIt!-style
//! auto-grasp); a real gripper's jaws are usually mechanically coupled, which this ignores.
//!
//! Palm frame: `z` the approach direction, the palm's top face at `z = 0`, jaw 0 on `-y` (the same
//! side as the Barrett hand's F1/F2), jaw 1 on `+y`.

use nalgebra::{Isometry3, Vector3};

use super::{
    Grasp, Hand, LinkGeometry, LinkShape, LinkSpec, advance_until_contact, clear_hand, finish_grasp,
};
use crate::convert::iso2pose;
use crate::error::{Result, SimError, ensure_finite};
use crate::object::Object;

/// Palm box half extents (x, y, z); its top face is at `z = 0`.
pub const PALM_HALF: [f64; 3] = [0.02, 0.08, 0.015];
/// Jaw box half extents (x: width, y: thickness, z: length).
pub const JAW_HALF: [f64; 3] = [0.01, 0.005, 0.03];
/// Distance of each open jaw's inner face from the centre line (maximum opening 0.12 m).
pub const OPEN_HALF_WIDTH: f64 = 0.06;
/// Travel of each jaw from open to closed: `[0, MAX_TRAVEL]`.
pub const MAX_TRAVEL: f64 = OPEN_HALF_WIDTH;

/// A parallel-jaw gripper.
#[derive(Debug)]
pub struct ParallelJawOracle {
    links: Vec<LinkSpec>,
    geometry: LinkGeometry,
}

impl Default for ParallelJawOracle {
    fn default() -> Self {
        let links = vec![
            LinkSpec {
                name: "palm".to_string(),
                finger: None,
                shape: LinkShape::Box {
                    half_extents: Vector3::from(PALM_HALF),
                },
            },
            LinkSpec {
                name: "jaw0".to_string(),
                finger: Some(0),
                shape: LinkShape::Box {
                    half_extents: Vector3::from(JAW_HALF),
                },
            },
            LinkSpec {
                name: "jaw1".to_string(),
                finger: Some(1),
                shape: LinkShape::Box {
                    half_extents: Vector3::from(JAW_HALF),
                },
            },
        ];
        let geometry = LinkGeometry::new(&links);
        Self { links, geometry }
    }
}

impl ParallelJawOracle {
    fn jaw(side: usize, travel: f64) -> Isometry3<f64> {
        let sign = if side == 0 { -1.0 } else { 1.0 };
        Isometry3::translation(
            0.0,
            sign * (OPEN_HALF_WIDTH + JAW_HALF[1] - travel),
            JAW_HALF[2],
        )
    }
}

impl Hand for ParallelJawOracle {
    fn name(&self) -> &str {
        "parallel_jaw"
    }

    fn links(&self) -> &[LinkSpec] {
        &self.links
    }

    fn finger_count(&self) -> usize {
        2
    }

    fn joint_names(&self) -> Vec<String> {
        vec!["jaw0".to_string(), "jaw1".to_string()]
    }

    fn joint_limits(&self) -> Vec<(f64, f64)> {
        vec![(0.0, MAX_TRAVEL); 2]
    }

    fn open_configuration(&self) -> Vec<f64> {
        vec![0.0, 0.0]
    }

    fn link_poses(&self, joints: &[f64]) -> Result<Vec<Isometry3<f64>>> {
        if joints.len() != 2 {
            return Err(SimError::InvalidInput(format!(
                "parallel-jaw gripper needs 2 joint values, got {}",
                joints.len()
            )));
        }
        ensure_finite(joints, "gripper joint values")?;
        Ok(vec![
            Isometry3::translation(0.0, 0.0, -PALM_HALF[2]),
            Self::jaw(0, joints[0]),
            Self::jaw(1, joints[1]),
        ])
    }

    fn close(&self, object: &Object, palm_pose: &Isometry3<f64>) -> Result<Grasp> {
        let (palm, retreat) = clear_hand(self, &self.geometry, object, palm_pose)?;
        let mut joints = self.open_configuration();
        for (side, joint) in joints.iter_mut().enumerate() {
            let adv = advance_until_contact(
                |t| {
                    Ok(vec![self.geometry.distance_g(
                        object,
                        1 + side,
                        &iso2pose(&(palm * Self::jaw(side, t))),
                        0.05,
                    )?])
                },
                0.0,
                MAX_TRAVEL,
                &[1.0],
            )?;
            *joint = adv.t;
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
