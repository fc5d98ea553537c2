//! The subcommands of `graspopt`.

pub mod quality;
