//! The workspace's Rust files, and which of them hold production code.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use crate::scan::{Scan, scan};

/// One `.rs` file of the repository.
pub struct SourceFile {
    /// Relative to the repository's root, with `/` separators.
    pub path: String,
    pub lines: usize,
    pub scan: Scan,
    /// In a `src/` folder and not test code (a `tests.rs` file, or a module a
    /// `#[cfg(test)] mod name;` declares, with its submodules).
    pub production: bool,
}

/// Every `.rs` file under `root`, except in `target` folders (`target/`, `fuzz/target/`) and
/// hidden ones (`.git/`), sorted by path.
pub fn source_files(root: &Path) -> Vec<SourceFile> {
    let mut paths = Vec::new();
    walk(root, &mut paths);
    paths.sort();
    let mut files: Vec<SourceFile> = paths
        .iter()
        .map(|p| {
            let text = std::fs::read_to_string(p)
                .unwrap_or_else(|e| panic!("cannot read {}: {e}", p.display()));
            let rel = p.strip_prefix(root).unwrap_or(p);
            let path = rel.to_string_lossy().replace('\\', "/");
            let production = path.split('/').any(|c| c == "src") && !path.ends_with("/tests.rs");
            SourceFile {
                path,
                lines: text.lines().count(),
                scan: scan(&text),
                production,
            }
        })
        .collect();
    let test_modules = test_module_paths(&files);
    for f in &mut files {
        let under =
            |m: &String| f.path == format!("{m}.rs") || f.path.starts_with(&format!("{m}/"));
        if test_modules.iter().any(under) {
            f.production = false;
        }
    }
    files
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let entries =
        std::fs::read_dir(dir).unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()));
    for entry in entries {
        let path = entry.expect("a folder entry").path();
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        if path.is_dir() {
            if name != "target" && !name.starts_with('.') {
                walk(&path, out);
            }
        } else if name.ends_with(".rs") {
            out.push(path);
        }
    }
}

/// The module paths (`common/x/src/a/tests`, without `.rs`) of every `#[cfg(test)] mod name;`:
/// `name.rs` or `name/mod.rs` beside a `lib.rs`, `main.rs` or `mod.rs`, else in the folder
/// named after the declaring file.
pub fn test_module_paths(files: &[SourceFile]) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for f in files {
        let (dir, file) = f.path.rsplit_once('/').unwrap_or(("", &f.path));
        let stem = file.trim_end_matches(".rs");
        let base = if matches!(stem, "lib" | "main" | "mod") {
            dir.to_string()
        } else {
            format!("{dir}/{stem}")
        };
        for m in &f.scan.test_mods {
            out.insert(format!("{base}/{m}"));
        }
    }
    out
}
