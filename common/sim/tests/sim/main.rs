//! graspopt-sim's integration tests, one module per topic in one test binary (one link
//! instead of one per file). A new file here needs a `mod` line below. `tests/urdf.rs` is
//! still its own binary: its `include_str!` paths are relative to its place.

mod meshes;
mod trials;
