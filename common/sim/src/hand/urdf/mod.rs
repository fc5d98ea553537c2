//! Hands described by URDF (parsed with the `urdf-rs` crate), with an optional TOML file of
//! settings that URDF cannot say.
//!
//! # Conventions
//! - The root link (the one link that is no joint's child) is the palm; the palm frame is the
//!   root link's frame and the approach direction is its `+z`.
//! - Every `revolute` or `prismatic` joint without `<mimic>` *closes*: from its lower limit (open)
//!   towards its upper limit (closed). A `<mimic>` joint follows its joint as
//!   `multiplier * value + offset`, clamped to its own limits when it has a range. `fixed` joints
//!   are rigid.
//! - Closing is GraspIt!/OpenRAVE's auto-grasp, generalised to a kinematic tree: each closing
//!   joint in turn (parents before children, then file order) advances with
//!   [`advance_until_contact`] over the links it moves (its subtree and the subtrees of the joints
//!   that mimic it). When a link touches the object, that joint stops, and so does every joint
//!   between it and the palm (a later joint whose links include a touching one does not move);
//!   joints after the touching link still close.
//! - Collision geometry: `<collision>` elements with `box`, `cylinder`, `sphere` or `mesh` (OBJ or
//!   STL, with `scale`) and their `<origin>`. A link may have several; each is one collision body
//!   of the hand (named `link`, then `link#2`, ...). A mesh is used as its convex hull. `<visual>`
//!   and `<inertial>` are ignored, and so are other top-level elements (`<transmission>`,
//!   `<gazebo>`, ...).
//! - Fingers: by default, the links after the same first moving joint (on the path from the palm)
//!   form one finger, numbered in file order of those joints; links fixed to the palm are palm.
//!   Mesh paths are relative to the URDF file's folder; `package://NAME/rest` is looked up in the
//!   ancestor folder named `NAME`.
//!
//! Errors name the joint, link or file: a closing or mimic joint with no limits (URDF's default
//! `lower = upper = 0`) or of type `continuous`, `floating`, `planar` or `spherical`; a link that
//! is the child of two joints, a loop or several roots; a joint naming an unknown link; a missing
//! or unreadable mesh; capsule geometry or a mesh format other than OBJ/STL; a mimic joint whose
//! joint is missing, fixed or itself a mimic.
//!
//! # Settings (TOML)
//! A file beside the URDF with the same stem and the extension `.toml` (read by
//! [`UrdfHand::from_file`] when it exists; the URDF alone must and does work):
//! ```toml
//! name = "barrett"              # the hand's name (default: the URDF robot's name)
//! rz_degrees = 90               # the palm turned about its approach axis (default 0)
//! fingers = [["f1_medial", "f1_distal"], ["f2_medial", "f2_distal"]]  # links per finger
//!
//! [joints.spread]
//! hold = true                   # not a closing joint: stays at its open value
//! open = 0.0                    # open value (default: the limit it closes from)
//!
//! [joints.f1_distal]
//! breakaway = true              # a mimic joint that, once its joint stops on a link that is
//!                               # not one of its own, continues alone to its upper limit
//!                               # (the BH8's TorqueSwitch)
//!
//! [joints.finger_joint1]
//! close = "lower"               # closes from its upper limit towards its lower limit
//! ```
//! With `fingers`, links listed nowhere belong to the palm. Unknown keys, joints or links are
//! errors.
//!
//! `rz_degrees` turns the hand about its approach axis (the root link's `z`): the root link's
//! frame is the palm frame turned by this angle (degrees, finite, within a turn: -360 to 360),
//! so the hand sits as if the trial parameter `rz` were always that much larger. At the
//! reference pose ([`crate::pose::reference_pose`]) the root link's `-x` is world up with 0,
//! and its `+y` with 90: fingers that close along the root link's `x` then close horizontally.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Point3, Translation3, Unit, UnitQuaternion, Vector3};

use super::{
    Grasp, Hand, LinkGeometry, LinkShape, LinkSpec, advance_until_contact, clear_hand, finish_grasp,
};
use crate::convert::iso2pose;
use crate::error::{Result, SimError, ensure_finite};
use crate::mesh::{self, TriangleMesh};
use crate::object::Object;

mod hand;
mod parse;
mod summary;
pub use hand::UrdfHand;
pub use summary::{ClosingAxis, MimicJoint};

/// Per-hand settings that URDF cannot say (the TOML file beside the URDF).
#[derive(Clone, Debug, Default, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HandSettings {
    /// The hand's name (default: the URDF robot's name).
    pub name: Option<String>,
    /// The palm turned about its approach axis, degrees (default 0; see the module doc).
    pub rz_degrees: Option<f64>,
    /// Links of each finger, in finger order (default: see the module doc).
    pub fingers: Option<Vec<Vec<String>>>,
    /// Settings per joint name.
    #[serde(default)]
    pub joints: BTreeMap<String, JointSettings>,
}

/// Settings of one joint.
#[derive(Clone, Debug, Default, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSettings {
    /// Open value (default: the limit the joint closes from).
    pub open: Option<f64>,
    /// The joint does not close: it stays at its open value.
    #[serde(default)]
    pub hold: bool,
    /// Which limit the joint closes towards (default `upper`).
    pub close: Option<CloseTowards>,
    /// For a mimic joint: continue alone once its joint stops on a link that is not its own.
    #[serde(default)]
    pub breakaway: bool,
}

/// The limit a joint closes towards.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CloseTowards {
    /// From the lower limit to the upper (the default).
    Upper,
    /// From the upper limit to the lower (e.g. the Franka hand's fingers).
    Lower,
}

/// The largest `rz_degrees` either way: a full turn.
pub const MAX_RZ_DEGREES: f64 = 360.0;

impl HandSettings {
    /// Parses the TOML text of a settings file; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Self> {
        toml::from_str(text).map_err(|e| bad(file, format!("settings: {e}")))
    }

    /// The palm's turn about its approach axis in radians (`rz_degrees`, checked: finite and
    /// within a turn either way).
    fn rz(&self, file: &str) -> Result<f64> {
        let degrees = self.rz_degrees.unwrap_or(0.0);
        if !(degrees.is_finite() && degrees.abs() <= MAX_RZ_DEGREES) {
            return Err(bad(
                file,
                format!(
                    "settings: rz_degrees = {degrees} must be a finite angle within a turn (-{MAX_RZ_DEGREES} to {MAX_RZ_DEGREES} degrees)"
                ),
            ));
        }
        Ok(degrees.to_radians())
    }
}

fn bad(file: &str, reason: impl Into<String>) -> SimError {
    SimError::BadHand {
        file: file.to_string(),
        reason: reason.into(),
    }
}

/// How a joint moves.
#[derive(Clone, Copy, Debug)]
enum Motion {
    Fixed,
    Revolute(Unit<Vector3<f64>>),
    Prismatic(Unit<Vector3<f64>>),
}

/// What a joint with a value does while the hand closes.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    /// Closes: +1 towards the upper limit, -1 towards the lower.
    Closing(f64),
    /// Stays at its open value.
    Held,
    /// Follows `master` (a degree-of-freedom index) as `multiplier * value + offset`.
    Mimic {
        master: usize,
        multiplier: f64,
        offset: f64,
        breakaway: bool,
    },
}

#[derive(Clone, Debug)]
struct JointModel {
    parent: usize,
    child: usize,
    origin: Isometry3<f64>,
    motion: Motion,
    /// Index into the joint vector (`None` for fixed joints).
    dof: Option<usize>,
}

#[derive(Clone, Debug)]
struct Dof {
    name: String,
    joint: usize,
    limits: (f64, f64),
    role: Role,
    open: f64,
}

/// A collision body: one `<collision>` element of a link.
#[derive(Clone, Debug)]
struct Body {
    link: usize,
    origin: Isometry3<f64>,
}

/// Geometry of a `<collision>` element before meshes are loaded.
#[derive(Clone, Debug)]
enum RawShape {
    Ready(LinkShape),
    Mesh { filename: String, scale: [f64; 3] },
}

/// A parsed URDF hand description, meshes not yet loaded (see [`UrdfHand::new`]).
#[derive(Clone, Debug)]
pub struct HandDescription {
    file: String,
    name: String,
    link_names: Vec<String>,
    /// Joints in an order where parents come before children.
    joints: Vec<JointModel>,
    dofs: Vec<Dof>,
    bodies: Vec<(Body, String, Option<usize>, RawShape)>,
    finger_count: usize,
    /// The palm's turn about its approach axis (radians; `rz_degrees`).
    rz: f64,
}

fn pose_of(p: &urdf_rs::Pose) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(p.xyz[0], p.xyz[1], p.xyz[2]),
        UnitQuaternion::from_euler_angles(p.rpy[0], p.rpy[1], p.rpy[2]),
    )
}

/// urdf-rs's error in a user's words: its XML reader says "No elements found" for an empty
/// or non-XML file, and its serde errors start with "custom: ".
fn urdf_error(e: &urdf_rs::UrdfError) -> String {
    let text = e.to_string();
    if text.trim() == "No elements found" {
        return "the file is empty or not XML (no element found): not a URDF robot".into();
    }
    match text.strip_prefix("custom: ") {
        Some(rest) => format!("not a valid URDF robot: {rest}"),
        None => text,
    }
}

fn clamp_to(v: f64, (lo, hi): (f64, f64)) -> f64 {
    if lo < hi { v.max(lo).min(hi) } else { v }
}

/// Resolves a URDF mesh file name against the URDF's folder.
fn resolve_mesh(filename: &str, dir: &Path) -> PathBuf {
    if let Some(rest) = filename.strip_prefix("file://") {
        return PathBuf::from(rest);
    }
    if let Some(rest) = filename.strip_prefix("package://") {
        let (package, inner) = rest.split_once('/').unwrap_or((rest, ""));
        for a in dir.ancestors() {
            if a.file_name().is_some_and(|n| n == package) {
                return a.join(inner);
            }
        }
        return dir.join(inner);
    }
    dir.join(filename)
}

/// Loads a link mesh (OBJ or STL, scaled) as the triangle mesh of its convex hull. `written`
/// is its file name as the URDF gives it, `path` where it was looked for: a file that cannot
/// be read is named both ways (absolute), with the system's reason.
fn load_link_mesh(
    written: &str,
    path: &Path,
    scale: [f64; 3],
    link: &str,
    file: &str,
) -> Result<TriangleMesh> {
    let shown = path.display().to_string();
    let m = mesh::read(path).map_err(|e| match e {
        SimError::Io { source, .. } => {
            let resolved = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
            bad(
                file,
                format!(
                    "link `{link}`: cannot read the mesh `{written}` (looked for at `{}`): {source}",
                    resolved.display()
                ),
            )
        }
        e => bad(file, format!("link `{link}`: {e}")),
    })?;
    let points: Vec<Point3<f64>> = m
        .vertices
        .iter()
        .map(|v| Point3::new(v.x * scale[0], v.y * scale[1], v.z * scale[2]))
        .collect();
    mesh::convex_hull(&points)
        .map_err(|why| bad(file, format!("link `{link}`: the mesh `{shown}`: {why}")))
}
