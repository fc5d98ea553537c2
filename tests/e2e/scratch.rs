//! Scratch folders of the CLI and end-to-end tests, deleted when dropped. The CLI tests
//! include this file too (`#[path]` in agents/graspopt/tests/cli/main.rs): one copy.

use std::ffi::OsStr;
use std::ops::Deref;
use std::path::Path;

/// A fresh, empty folder named after `name`, removed with everything in it when dropped.
/// It reads as its path (`dir.join(..)`, `&dir` where a `&Path` is wanted).
pub struct Scratch(tempfile::TempDir);

/// A fresh scratch folder for the test `name`.
pub fn tempdir(name: &str) -> Scratch {
    let dir = tempfile::Builder::new()
        .prefix(&format!("graspopt-test-{name}-"))
        .tempdir()
        .expect("a scratch folder");
    Scratch(dir)
}

impl Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        self.0.path()
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        self.0.path()
    }
}

impl AsRef<OsStr> for Scratch {
    fn as_ref(&self) -> &OsStr {
        self.0.path().as_os_str()
    }
}
