//! graspopt-trial's integration tests, one module per topic in one test binary (one link
//! instead of one per file). A new file here needs a `mod` line below.

mod contacts;
mod fingertips;
mod grid;
mod qualitative;
mod scoring;
mod settings;
mod urdf_hand;
