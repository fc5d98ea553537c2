//! Architecture checks of the whole workspace, run by `cargo test --workspace` (and so by
//! `.ci/run`), or alone with `cargo test -p graspopt --test architecture`:
//!
//! - the size limits of issue #30: every `.rs` file at most [`MAX_FILE_LINES`] lines, every
//!   production function at most [`MAX_FN_LINES`] lines, `agents/graspopt/src` at most
//!   [`MAX_BINARY_LINES`] lines in all ([`sizes`]);
//! - the crate edges listed in docs/architecture.md against the `Cargo.toml` files, as
//!   `cargo metadata` reads them ([`edges`]): the map fails the build when it goes stale.
//!
//! Each failure lists every offender with what to do. The functions are found by a small
//! scanner of Rust source ([`scan`], tested on its own in `scan_tests`).

mod edges;
mod files;
mod scan;
mod scan_tests;
mod sizes;

/// Most lines in one `.rs` file, tests included.
pub const MAX_FILE_LINES: usize = 800;
/// Most lines in one production function (in `src/`, outside `#[cfg(test)]` items and
/// `tests.rs` files), from its `fn` keyword to its closing brace.
pub const MAX_FN_LINES: usize = 80;
/// Most lines in `agents/graspopt/src`, all its files together: the binary only wires
/// libraries to flags, files and the terminal.
pub const MAX_BINARY_LINES: usize = 2_500;

/// The repository's root (this package is agents/graspopt).
pub fn root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}
