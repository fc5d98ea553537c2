//! The subcommands of `graspopt`.

pub mod agent;
pub mod bench;
pub mod bus;
pub mod experiment;
pub mod export;
pub mod hands;
pub mod launch;
pub mod monitor;
pub mod optimize_function;
pub mod quality;
pub mod record;
pub mod router;
pub mod run;
pub mod scan;
pub mod setup;
pub mod topic;
pub mod trial;
