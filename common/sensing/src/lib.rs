//! Intrinsic contact sensing: the contact point, normal, force and torsion on a fingertip
//! from the wrench its force/torque sensor measures (Bicchi, Salisbury and Brock, "Contact
//! sensing from force measurements", IJRR 12(3), 1993).
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

mod contact;
mod error;
mod noise;
mod surface;

pub use contact::{
    ContactKind, NoContact, Reading, SensedContact, SensingSettings, locate, reading_of,
};
pub use error::SensingError;
pub use noise::SensorNoise;
pub use surface::{FingertipSurface, MAX_SIZE};
