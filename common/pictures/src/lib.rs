//! Every picture graspopt draws: SVG charts of scans, runs and experiments ([`chart`]) and
//! PNG pictures of grasps and scan maps from a small software rasteriser ([`preview`]).
//!
//! Input is numbers, meshes and contact points; this crate knows nothing of experiments,
//! journals, files other than the one it is asked to write, or the bus.

pub mod chart;
pub mod error;
pub mod preview;

pub use error::PicturesError;
