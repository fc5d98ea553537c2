//! The size limits of issue #30. Each test lists every offender, longest first.

use crate::files::{SourceFile, source_files};
use crate::{MAX_BINARY_LINES, MAX_FILE_LINES, MAX_FN_LINES, root};

fn files() -> Vec<SourceFile> {
    let files = source_files(&root());
    assert!(
        files
            .iter()
            .any(|f| f.path == "agents/graspopt/src/main.rs"),
        "the walk from {} found no agents/graspopt/src/main.rs",
        root().display()
    );
    files
}

#[test]
fn every_rust_file_is_at_most_800_lines() {
    let mut long: Vec<(usize, String)> = files()
        .into_iter()
        .filter(|f| f.lines > MAX_FILE_LINES)
        .map(|f| (f.lines, f.path))
        .collect();
    long.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    let list: Vec<String> = long
        .iter()
        .map(|(n, p)| format!("  {p}: {n} lines"))
        .collect();
    assert!(
        long.is_empty(),
        "{} .rs files are over the limit of {MAX_FILE_LINES} lines (tests too): split them \
         into modules that each read alone:\n{}",
        long.len(),
        list.join("\n")
    );
}

#[test]
fn every_production_function_is_at_most_80_lines() {
    let mut long: Vec<(usize, String)> = Vec::new();
    for f in files().iter().filter(|f| f.production) {
        for func in f
            .scan
            .fns
            .iter()
            .filter(|s| !s.test && s.lines > MAX_FN_LINES)
        {
            let at = format!("{}:{}  {}", f.path, func.line, func.name);
            long.push((func.lines, at));
        }
    }
    long.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    let list: Vec<String> = long
        .iter()
        .map(|(n, at)| format!("  {at}: {n} lines"))
        .collect();
    assert!(
        long.is_empty(),
        "{} production functions are over the limit of {MAX_FN_LINES} lines (from `fn` to its \
         closing brace; src/ only, #[cfg(test)] items and tests.rs files not counted): split \
         them into named steps:\n{}",
        long.len(),
        list.join("\n")
    );
}

#[test]
fn the_binary_is_at_most_2500_lines() {
    let binary: Vec<SourceFile> = files()
        .into_iter()
        .filter(|f| f.path.starts_with("agents/graspopt/src/"))
        .collect();
    let total: usize = binary.iter().map(|f| f.lines).sum();
    let mut biggest: Vec<(usize, &str)> = binary.iter().map(|f| (f.lines, &*f.path)).collect();
    biggest.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(b.1)));
    let list: Vec<String> = biggest
        .iter()
        .take(10)
        .map(|(n, p)| format!("  {p}: {n} lines"))
        .collect();
    assert!(
        total <= MAX_BINARY_LINES,
        "agents/graspopt/src is {total} lines, over the limit of {MAX_BINARY_LINES}: the binary \
         wires libraries to flags, files and the terminal; move logic into the library crates \
         (docs/architecture.md). Its largest files:\n{}",
        list.join("\n")
    );
}
