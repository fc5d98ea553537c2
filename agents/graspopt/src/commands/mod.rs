//! The subcommands of `graspopt`.

pub mod experiment;
pub mod optimize_function;
pub mod quality;
pub mod scan;
pub mod setup;
pub mod svg;
pub mod trial;
