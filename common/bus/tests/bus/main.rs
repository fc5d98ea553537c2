//! graspopt-bus's integration tests, one module per topic in one test binary (one link
//! instead of one per file). A new file here needs a `mod` line below.

mod config;
mod query;
mod unique;
