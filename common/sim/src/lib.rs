//! # graspopt-sim: simulated grasp trials
//!
//! The geometric core of graspopt's simulator: the seven test objects of the thesis (and user
//! meshes), hands that close their fingers until contact (read from URDF: the Barrett BH8-280, a
//! parallel-jaw gripper, the Franka hand, or the user's own; one [`hand::Hand`] trait), the raw contact clouds
//! per finger and the three contact models of thesis section 4.3 (mean point, circular patch and
//! the surface model of section 2.3), trial parameter spaces, and scene meshes for export.
//!
//! This crate owns geometry only: it knows nothing of grasp-quality metrics, plotting, files on the
//! bus or networks. Collision queries use `parry3d-f64` (f64 throughout); the public API uses
//! nalgebra types, and the single conversion boundary is the private `convert` module.
//!
//! Conventions: lengths in metres, angles in radians, world `z` up. Contact normals returned by this
//! crate point INTO the object (the direction in which a finger pushes).
//!
//! Typical use:
//! ```
//! use graspopt_sim::{BarrettOracle, ContactModel, ContactModelSettings, Object, TrialSpace, run_trial};
//! let mug = Object::by_name("mug")?;
//! let space = TrialSpace::approach_vertical_2d(&mug);
//! let palm = space.palm_pose(&[0.0, 0.0])?;
//! let out = run_trial(&mug, &BarrettOracle::default(), &palm, &ContactModelSettings::default())?;
//! assert_eq!(out.fingers_in_contact(), 3);
//! let contacts = out.contacts(ContactModel::Surface, true); // positions + inward unit normals
//! assert!(!contacts.is_empty());
//! # Ok::<(), graspopt_sim::SimError>(())
//! ```
//!
//! Not modelled: the table (nothing stops a finger below the object), friction, dynamics (the
//! object never moves), self-collision between links.
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod contact;
mod convert;
pub mod error;
pub mod hand;
pub mod mesh;
pub mod noise;
pub mod object;
pub mod pose;
pub mod scene;
pub mod trial;

pub use contact::{ContactCloud, ContactModel, ContactModelSettings, ContactPoint, NoiseSettings};
pub use error::{HullError, SimError};
pub use hand::{
    BarrettOracle, BuiltinHand, CONTACT_TOLERANCE, Grasp, Hand, LinkShape, LinkSpec,
    ParallelJawOracle, UrdfHand, builtin_hand, builtin_hands, hand_by_name, hand_name, hand_names,
    same_hand,
};
pub use mesh::TriangleMesh;
pub use object::{Object, ObjectKind, RayHit, SurfacePoint};
pub use pose::{ParamKind, ParamSpec, TrialSpace, reference_pose};
pub use trial::{FingerOutcome, TrialOutcome, run_trial};
