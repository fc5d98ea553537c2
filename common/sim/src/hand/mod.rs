//! Hands: the [`Hand`] trait (links as collision shapes, their poses as a function of the joint
//! values, an open configuration and an auto-grasp `close`), the shared closing machinery, and
//! [`UrdfHand`], a hand read from URDF (see [`urdf`] for the conventions). The built-in hands
//! ([`builtin_hands`]: the Barrett BH8-280, a parallel-jaw gripper, the Franka hand) are URDF
//! files in `common/sim/hands/`, embedded in the binary.
//!
//! [`BarrettOracle`] and [`ParallelJawOracle`] are the same hands written in Rust; they stay as
//! test oracles that the URDF versions must match. A hand can also be a new implementation of
//! [`Hand`]; the public helpers here ([`LinkGeometry`], [`clear_hand`], [`advance_until_contact`],
//! [`finish_grasp`]) do the collision work (see the `Pusher` hand in this crate's tests).
//!
//! Placing: if the open hand intersects the object at the requested palm pose, it is retreated
//! along its approach axis (palm `-z`) until clear and advanced back until a link is within
//! [`CONTACT_TOLERANCE`] (as a real approach would stop); [`Grasp::retreat`] reports the distance.
//!
//! Closing (as GraspIt!/OpenRAVE auto-grasp): from the open configuration each finger's joints
//! advance; a link that touches the object stops, the links after it keep closing until they touch
//! or reach their limit. Each step is at least the *conservative-advancement* step (no point of a
//! moving link moves farther than the link's distance to the object minus half the tolerance,
//! using a bound on point speed per unit joint motion) and at most a secant extrapolation of the
//! measured approach; a step that ends intersecting the object is undone by bisection. A link is
//! in contact, and stops, when its distance is at most [`CONTACT_TOLERANCE`] (0.2 mm) and greater
//! than zero: links never penetrate the object (penetration tolerance zero, up to round-off).

mod barrett;
mod gripper;
pub mod urdf;

pub use barrett::BarrettOracle;
pub use gripper::ParallelJawOracle;
pub use urdf::UrdfHand;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::math::Pose;
use parry3d_f64::shape::{Ball, ConvexPolyhedron, Cuboid, Cylinder, Shape};

use crate::convert::{iso2pose, p2g, v2g};
use crate::error::{Result, SimError, ensure_finite};
use crate::mesh::{self, TriangleMesh};
use crate::object::Object;

/// A link stops when its distance to the object is at most this (metres, 0.2 mm). Links never
/// penetrate: their final gap lies in `(0, CONTACT_TOLERANCE]`.
pub const CONTACT_TOLERANCE: f64 = 2e-4;

/// Upper bound on conservative-advancement iterations for one motion (a safety net for grazing
/// approaches; the motion then stops where it is and the link is reported as touching).
pub const MAX_ADVANCE_ITERATIONS: usize = 400;

/// The accelerated (secant) closing step moves no link point farther than its current distance
/// plus this (metres): object features thinner than 1 mm could be stepped over, thicker ones not.
pub const MAX_OVERSHOOT: f64 = 1e-3;

/// How far back (metres) a hand placed in collision is retreated along its approach axis at most.
pub const MAX_RETREAT: f64 = 0.5;

/// Collision shape of a link, centred in the link frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum LinkShape {
    /// A box with these half extents along the link frame's axes.
    Box {
        /// Half extents (x, y, z).
        half_extents: Vector3<f64>,
    },
    /// A cylinder (disc) whose axis is the link frame's `z`.
    Cylinder {
        /// Radius.
        radius: f64,
        /// Half of the height along `z`.
        half_height: f64,
    },
    /// A ball centred on the link frame's origin.
    Sphere {
        /// Radius.
        radius: f64,
    },
    /// A convex mesh in the link frame (a URDF mesh link is stored as its convex hull).
    Mesh {
        /// The closed convex mesh, triangles counter-clockwise seen from outside.
        mesh: TriangleMesh,
    },
}

impl LinkShape {
    /// The shape's kind: `box`, `cylinder`, `sphere` or `mesh`.
    pub fn kind(&self) -> &'static str {
        match self {
            LinkShape::Box { .. } => "box",
            LinkShape::Cylinder { .. } => "cylinder",
            LinkShape::Sphere { .. } => "sphere",
            LinkShape::Mesh { .. } => "mesh",
        }
    }
}

impl LinkShape {
    /// A triangle mesh of the shape in the link frame.
    pub fn mesh(&self) -> TriangleMesh {
        match self {
            LinkShape::Box { half_extents } => mesh::box_mesh(half_extents),
            LinkShape::Cylinder {
                radius,
                half_height,
            } => mesh::revolve(
                &[
                    (0.0, -half_height),
                    (*radius, -half_height),
                    (*radius, *half_height),
                    (0.0, *half_height),
                ],
                48,
            ),
            LinkShape::Sphere { radius } => {
                let profile: Vec<(f64, f64)> = (0..=24)
                    .map(|i| {
                        let a = std::f64::consts::PI * (i as f64 / 24.0 - 0.5);
                        (radius * a.cos(), radius * a.sin())
                    })
                    .collect();
                mesh::revolve(&profile, 48)
            }
            LinkShape::Mesh { mesh } => mesh.clone(),
        }
    }

    /// Largest distance from the link frame origin to a point of the shape.
    pub fn bounding_radius(&self) -> f64 {
        match self {
            LinkShape::Box { half_extents } => half_extents.norm(),
            LinkShape::Cylinder {
                radius,
                half_height,
            } => radius.hypot(*half_height),
            LinkShape::Sphere { radius } => *radius,
            LinkShape::Mesh { mesh } => mesh
                .vertices
                .iter()
                .map(|v| v.coords.norm())
                .fold(0.0, f64::max),
        }
    }

    /// Largest distance from the point `p` (link frame) to a point of the shape.
    pub fn farthest_from(&self, p: &nalgebra::Point3<f64>) -> f64 {
        match self {
            LinkShape::Box { half_extents } => (p.coords.abs() + half_extents).norm(),
            LinkShape::Cylinder {
                radius,
                half_height,
            } => (p.x.hypot(p.y) + radius).hypot(p.z.abs() + half_height),
            LinkShape::Sphere { radius } => p.coords.norm() + radius,
            LinkShape::Mesh { mesh } => mesh
                .vertices
                .iter()
                .map(|v| (v - p).norm())
                .fold(0.0, f64::max),
        }
    }
}

/// Static description of one link.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LinkSpec {
    /// Link name, e.g. `f1_medial`.
    pub name: String,
    /// Finger index, `None` for the palm.
    pub finger: Option<usize>,
    /// Collision shape in the link frame.
    pub shape: LinkShape,
}

/// The result of closing a hand on an object.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Grasp {
    /// The hand's name.
    pub hand: String,
    /// The palm pose asked for (world).
    pub requested_palm_pose: Isometry3<f64>,
    /// The palm pose used (world): the requested one, retreated along `-z` (approach axis) by
    /// `retreat` if the open hand intersected the object there.
    pub palm_pose: Isometry3<f64>,
    /// Distance retreated along the approach axis (0 if the open hand was clear of the object).
    pub retreat: f64,
    /// Final joint values (the hand's own order, see [`Hand::joint_names`]).
    pub joints: Vec<f64>,
    /// Final link frames in the world, in [`Hand::links`] order.
    pub link_poses: Vec<Isometry3<f64>>,
    /// Per link: stopped by (or resting within [`CONTACT_TOLERANCE`] of) the object.
    pub link_touching: Vec<bool>,
    /// Per link: final distance to the object (0 would mean intersecting; never below 0).
    pub link_distances: Vec<f64>,
}

impl Grasp {
    /// Whether any link (palm included) touches the object.
    pub fn touches(&self) -> bool {
        self.link_touching.iter().any(|t| *t)
    }
}

/// A robot hand. Link frames are given relative to the palm frame, whose `z` axis is the approach
/// direction (out of the palm).
pub trait Hand: Send + Sync + std::fmt::Debug {
    /// Short name (`barrett`, `parallel_jaw`).
    fn name(&self) -> &str;
    /// The links, palm first.
    fn links(&self) -> &[LinkSpec];
    /// Number of fingers (links carry their finger index).
    fn finger_count(&self) -> usize;
    /// Joint names, in the order of joint vectors.
    fn joint_names(&self) -> Vec<String>;
    /// Joint limits `(min, max)`.
    fn joint_limits(&self) -> Vec<(f64, f64)>;
    /// The open configuration from which `close` starts.
    fn open_configuration(&self) -> Vec<f64>;
    /// Link frames in the palm frame for the given joint values.
    fn link_poses(&self, joints: &[f64]) -> Result<Vec<Isometry3<f64>>>;
    /// Places the open hand at `palm_pose` (retreating along the approach axis if it intersects
    /// the object) and closes it until contact.
    fn close(&self, object: &Object, palm_pose: &Isometry3<f64>) -> Result<Grasp>;
}

/// A hand shipped with graspopt: a URDF file (and its settings) in `common/sim/hands/`, embedded
/// in the binary.
#[derive(Clone, Copy, Debug)]
pub struct BuiltinHand {
    /// The name `--hand` takes.
    pub name: &'static str,
    /// Other names accepted for it.
    pub aliases: &'static [&'static str],
    /// The URDF file in the repository.
    pub source: &'static str,
    /// The settings file beside it, if any.
    pub settings_source: Option<&'static str>,
    urdf: &'static str,
    settings: Option<&'static str>,
}

impl BuiltinHand {
    /// Builds the hand from its embedded description.
    pub fn build(&self) -> Result<UrdfHand> {
        UrdfHand::from_strs(self.source, self.urdf, self.settings, None)
    }
}

const BUILTIN_HANDS: [BuiltinHand; 4] = [
    BuiltinHand {
        name: "barrett",
        aliases: &["bh8", "bh8_280"],
        source: "common/sim/hands/bh8_280.urdf",
        settings_source: Some("common/sim/hands/bh8_280.toml"),
        urdf: include_str!("../../hands/bh8_280.urdf"),
        settings: Some(include_str!("../../hands/bh8_280.toml")),
    },
    BuiltinHand {
        name: "barrett_ft",
        aliases: &["bh8_ft", "bh8_280_ft"],
        source: "common/sim/hands/bh8_280_ft.urdf",
        settings_source: Some("common/sim/hands/bh8_280_ft.toml"),
        urdf: include_str!("../../hands/bh8_280_ft.urdf"),
        settings: Some(include_str!("../../hands/bh8_280_ft.toml")),
    },
    BuiltinHand {
        name: "parallel_jaw",
        aliases: &["gripper"],
        source: "common/sim/hands/parallel_jaw.urdf",
        settings_source: None,
        urdf: include_str!("../../hands/parallel_jaw.urdf"),
        settings: None,
    },
    BuiltinHand {
        name: "franka_hand",
        aliases: &["franka", "panda_hand"],
        source: "common/sim/hands/franka_hand.urdf",
        settings_source: Some("common/sim/hands/franka_hand.toml"),
        urdf: include_str!("../../hands/franka_hand.urdf"),
        settings: Some(include_str!("../../hands/franka_hand.toml")),
    },
];

/// The hands shipped with graspopt.
pub fn builtin_hands() -> &'static [BuiltinHand] {
    &BUILTIN_HANDS
}

/// The built-in hand names.
pub fn hand_names() -> Vec<&'static str> {
    BUILTIN_HANDS.iter().map(|h| h.name).collect()
}

/// Whether `hand` names a URDF file (it ends in `.urdf`, any case) rather than a hand.
fn is_urdf_file(hand: &str) -> bool {
    hand.to_ascii_lowercase().ends_with(".urdf")
}

/// The built-in hand called `name` or one of its aliases (`-` and `_` alike, any case).
pub fn builtin_hand(name: &str) -> Option<&'static BuiltinHand> {
    let key = name.trim().to_ascii_lowercase().replace('-', "_");
    BUILTIN_HANDS
        .iter()
        .find(|h| h.name == key || h.aliases.contains(&key.as_str()))
}

/// A built-in hand by name (see [`builtin_hand`]), or a hand read from a URDF file (a name
/// ending in `.urdf`, see [`urdf`]).
pub fn hand_by_name(name: &str) -> Result<Box<dyn Hand>> {
    Ok(Box::new(UrdfHand::by_name(name)?))
}

impl UrdfHand {
    /// The hand [`hand_by_name`] gives, as the [`UrdfHand`] it is.
    pub fn by_name(name: &str) -> Result<UrdfHand> {
        let trimmed = name.trim();
        if is_urdf_file(trimmed) {
            return UrdfHand::from_file(std::path::Path::new(trimmed));
        }
        match builtin_hand(trimmed) {
            Some(h) => h.build(),
            None => Err(SimError::UnknownHand {
                name: name.to_string(),
                valid: format!("{}, or a FILE.urdf", hand_names().join(", ")),
            }),
        }
    }
}

/// The name a run knows the hand `hand` by, in its trial commands, its journal and its
/// workers' answers: a built-in hand's own name for its name or any alias; for a URDF file,
/// the name of the hand it describes (its settings' `name`, else the robot's), so that a
/// worker given the file and a coordinator given the same file, or the hand's name, agree;
/// any other text is the name of a hand that only its own agent knows (a real hand),
/// unchanged.
pub fn hand_name(hand: &str) -> Result<String> {
    let trimmed = hand.trim();
    if is_urdf_file(trimmed) {
        return Ok(UrdfHand::from_file(std::path::Path::new(trimmed))?
            .name()
            .to_string());
    }
    Ok(builtin_hand(trimmed).map_or_else(|| trimmed.to_string(), |h| h.name.to_string()))
}

/// Whether two hand names are the same hand (a built-in hand's aliases are its name).
pub fn same_hand(a: &str, b: &str) -> bool {
    let own = |n: &str| builtin_hand(n).map_or_else(|| n.trim().to_string(), |h| h.name.into());
    own(a) == own(b)
}

/// parry shapes of a hand's links, built once.
pub struct LinkGeometry {
    shapes: Vec<(Box<dyn Shape>, Pose, f64)>,
}

impl std::fmt::Debug for LinkGeometry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "LinkGeometry({} links)", self.shapes.len())
    }
}

impl LinkGeometry {
    /// Builds the parry shapes for `links`.
    pub fn new(links: &[LinkSpec]) -> Self {
        let shapes = links
            .iter()
            .map(|l| {
                let r = l.shape.bounding_radius();
                match &l.shape {
                    LinkShape::Box { half_extents } => (
                        Box::new(Cuboid::new(v2g(half_extents))) as Box<dyn Shape>,
                        Pose::IDENTITY,
                        r,
                    ),
                    LinkShape::Cylinder {
                        radius,
                        half_height,
                    } => (
                        Box::new(Cylinder::new(*half_height, *radius)) as Box<dyn Shape>,
                        // parry cylinders are along y; the link's axis is z.
                        iso2pose(&Isometry3::from_parts(
                            Translation3::identity(),
                            UnitQuaternion::from_axis_angle(
                                &Vector3::x_axis(),
                                std::f64::consts::FRAC_PI_2,
                            ),
                        )),
                        r,
                    ),
                    LinkShape::Sphere { radius } => (
                        Box::new(Ball::new(*radius)) as Box<dyn Shape>,
                        Pose::IDENTITY,
                        r,
                    ),
                    LinkShape::Mesh { mesh } => {
                        let points: Vec<_> = mesh.vertices.iter().map(p2g).collect();
                        // A mesh that is no convex solid falls back to a ball of its radius
                        // (meshes built by this crate are convex hulls, see mesh::convex_hull).
                        let shape: Box<dyn Shape> =
                            match ConvexPolyhedron::from_convex_hull(&points) {
                                Some(c) => Box::new(c),
                                None => Box::new(Ball::new(r)),
                            };
                        (shape, Pose::IDENTITY, r)
                    }
                }
            })
            .collect();
        Self { shapes }
    }

    /// The parry shape and its pose for link `i` whose frame is at `link_world`.
    pub(crate) fn shape_at(&self, i: usize, link_world: &Pose) -> Option<(&dyn Shape, Pose)> {
        self.shapes
            .get(i)
            .map(|(s, off, _)| (s.as_ref(), *link_world * *off))
    }

    /// Distance (0 if intersecting) from link `i` whose frame is at `link_world` to the object.
    pub fn distance(&self, object: &Object, i: usize, link_world: &Isometry3<f64>) -> Result<f64> {
        self.distance_g(object, i, &iso2pose(link_world), 0.0)
    }

    /// [`LinkGeometry::distance`] in parry types; returns the cheap bounding-sphere lower bound
    /// instead when it already exceeds `far` (conservative for advancement).
    pub(crate) fn distance_g(
        &self,
        object: &Object,
        i: usize,
        link_world: &Pose,
        far: f64,
    ) -> Result<f64> {
        let Some((shape, pose)) = self.shape_at(i, link_world) else {
            return Err(SimError::InvalidInput(format!("no link {i}")));
        };
        let bound = object.distance_lower_bound(link_world.translation, self.shapes[i].2);
        if bound > far {
            return Ok(bound);
        }
        object.distance_to_shape(&pose, shape)
    }
}

/// Outcome of [`advance_until_contact`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Advance {
    /// Where the motion parameter stopped.
    pub t: f64,
    /// Index (into the `links` argument) of the first link found in contact, if any.
    pub touched: Option<usize>,
}

/// Conservative advancement of a one-parameter motion from `t0` to `t1` (`t1 >= t0`).
///
/// `distances(t)` returns, for each moving link, its distance to the object at parameter `t`
/// (0 when intersecting); `rates[k]` bounds how far any point of link `k` moves per unit of `t`.
/// Stops at the first `t` where some link is within [`CONTACT_TOLERANCE`] (and not
/// intersecting), or at `t1`.
///
/// Each step is the larger of the safe step (no point moves farther than the link's distance
/// minus half the tolerance) and a secant extrapolation of the measured approach speed; a step
/// that ends intersecting the object is undone by bisection between the last clear `t` and it,
/// so the result never intersects.
pub fn advance_until_contact(
    mut distances: impl FnMut(f64) -> Result<Vec<f64>>,
    t0: f64,
    t1: f64,
    rates: &[f64],
) -> Result<Advance> {
    let mut t = t0;
    let mut d = distances(t)?;
    if let Some(k) = touching(&d).or_else(|| d.iter().position(|&di| di <= 0.0)) {
        // Already touching (or, if the caller allowed it, intersecting) at the start.
        return Ok(Advance {
            t,
            touched: Some(k),
        });
    }
    let mut prev: Option<(f64, Vec<f64>)> = None;
    for _ in 0..MAX_ADVANCE_ITERATIONS {
        if t >= t1 {
            return Ok(Advance {
                t: t1,
                touched: None,
            });
        }
        let step = next_step(&d, prev.as_ref(), t, rates);
        let t_new = (t + step).min(t1);
        let d_new = distances(t_new)?;
        if intersecting(&d_new) {
            // Overshot into the object: bisect between the clear t and t_new.
            return bisect_overshoot(&mut distances, t, t_new, d, rates);
        }
        prev = Some((t, std::mem::replace(&mut d, d_new)));
        t = t_new;
        if let Some(k) = touching(&d) {
            return Ok(Advance {
                t,
                touched: Some(k),
            });
        }
    }
    // Grazing approach: stop here and report the nearest link.
    Ok(Advance {
        t,
        touched: nearest_link(&d),
    })
}

/// Whether some link touches (within the tolerance, not intersecting): the first such link.
fn touching(d: &[f64]) -> Option<usize> {
    d.iter().position(|&di| di > 0.0 && di <= CONTACT_TOLERANCE)
}

/// Whether some link intersects the object.
fn intersecting(d: &[f64]) -> bool {
    d.iter().any(|&di| di <= 0.0)
}

/// The link nearest the object.
fn nearest_link(d: &[f64]) -> Option<usize> {
    d.iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map(|(k, _)| k)
}

/// The next step of [`advance_until_contact`] from `t` (distances `d`; `prev`: the previous
/// parameter and its distances): the safe step, or the secant extrapolation when larger.
fn next_step(d: &[f64], prev: Option<&(f64, Vec<f64>)>, t: f64, rates: &[f64]) -> f64 {
    let tol = CONTACT_TOLERANCE;
    let safe = d
        .iter()
        .zip(rates)
        .map(|(&di, &r)| (di - 0.5 * tol) / r.max(1e-12))
        .fold(f64::INFINITY, f64::min);
    let mut step = safe;
    if let Some((tp, dp)) = prev {
        let dt = t - tp;
        let secant = d
            .iter()
            .zip(dp)
            .filter_map(|(&di, &dpi)| {
                let slope = (dpi - di) / dt;
                (slope > 0.0).then(|| 0.9 * (di - 0.6 * tol) / slope)
            })
            .fold(f64::INFINITY, f64::min);
        // Never let a link move more than MAX_OVERSHOOT beyond its current distance, so an
        // optimistic extrapolation cannot jump through a feature thicker than that.
        let cap = d
            .iter()
            .zip(rates)
            .map(|(&di, &r)| (di + MAX_OVERSHOOT) / r.max(1e-12))
            .fold(f64::INFINITY, f64::min);
        if secant.is_finite() {
            step = step.max(secant.min(cap));
        }
    }
    step
}

/// A step of [`advance_until_contact`] that ended intersecting the object: bisects between
/// the clear `lo` (distances `d`) and `hi` until a link touches; at the round-off limit, stops
/// at the last clear parameter, reporting the nearest link.
fn bisect_overshoot(
    distances: &mut impl FnMut(f64) -> Result<Vec<f64>>,
    mut lo: f64,
    mut hi: f64,
    mut d: Vec<f64>,
    rates: &[f64],
) -> Result<Advance> {
    let max_rate = rates.iter().fold(0.0_f64, |a, &r| a.max(r));
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        let dm = distances(mid)?;
        if intersecting(&dm) {
            hi = mid;
        } else if let Some(k) = touching(&dm) {
            return Ok(Advance {
                t: mid,
                touched: Some(k),
            });
        } else {
            lo = mid;
            d = dm;
        }
        if (hi - lo) * max_rate < 1e-9 {
            break;
        }
    }
    Ok(Advance {
        t: lo,
        touched: nearest_link(&d),
    })
}

/// Builds the [`Grasp`] of a closed hand: world link poses, final distances and touching flags.
pub fn finish_grasp(
    hand: &dyn Hand,
    geometry: &LinkGeometry,
    object: &Object,
    requested_palm_pose: &Isometry3<f64>,
    palm_pose: Isometry3<f64>,
    retreat: f64,
    joints: Vec<f64>,
) -> Result<Grasp> {
    let link_poses: Vec<Isometry3<f64>> = hand
        .link_poses(&joints)?
        .iter()
        .map(|l| palm_pose * l)
        .collect();
    let link_distances = link_poses
        .iter()
        .enumerate()
        .map(|(i, p)| geometry.distance_g(object, i, &iso2pose(p), 0.01))
        .collect::<Result<Vec<f64>>>()?;
    let link_touching = link_distances
        .iter()
        .map(|&x| x <= CONTACT_TOLERANCE)
        .collect();
    Ok(Grasp {
        hand: hand.name().to_string(),
        requested_palm_pose: *requested_palm_pose,
        palm_pose,
        retreat,
        joints,
        link_poses,
        link_touching,
        link_distances,
    })
}

/// Checks the palm pose, then retreats the open hand along `-z` until it is clear of the object
/// and advances it back until some link is within [`CONTACT_TOLERANCE`]. Returns the palm pose
/// to use and the retreat distance (0 when the requested pose is already clear).
pub fn clear_hand(
    hand: &dyn Hand,
    geometry: &LinkGeometry,
    object: &Object,
    palm_pose: &Isometry3<f64>,
) -> Result<(Isometry3<f64>, f64)> {
    ensure_finite(palm_pose.to_homogeneous().as_slice(), "palm pose")?;
    let open = hand.open_configuration();
    let rel = hand.link_poses(&open)?;
    let n = rel.len();
    let at = |s: f64| -> Isometry3<f64> { palm_pose * Translation3::new(0.0, 0.0, -s) };
    let dists = |s: f64| -> Result<Vec<f64>> {
        let palm = at(s);
        (0..n)
            .map(|i| geometry.distance_g(object, i, &iso2pose(&(palm * rel[i])), 0.05))
            .collect()
    };
    let d0 = dists(0.0)?;
    if d0.iter().all(|&d| d > 0.0) {
        return Ok((*palm_pose, 0.0));
    }
    // Retreat in 5 mm steps until clear by more than the tolerance.
    let step = 0.005;
    let mut s = step;
    loop {
        if s > MAX_RETREAT {
            return Err(SimError::CannotClear(MAX_RETREAT));
        }
        if dists(s)?.iter().all(|&d| d > CONTACT_TOLERANCE) {
            break;
        }
        s += step;
    }
    // Advance back (translation: every point moves 1 m per m).
    let rates = vec![1.0; n];
    let adv = advance_until_contact(|u| dists(s - u), 0.0, s, &rates)?;
    let retreat = s - adv.t;
    Ok((at(retreat), retreat))
}
