//! What the docs say of the workspace itself, checked against it: every `cargo` command they
//! show (in a code block or in running text) names packages and test targets that exist, and
//! where they count the protocol's message types, the count is the key table's.
//! (`doc_commands.rs` checks the `graspopt` commands.)

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

use graspopt_protocol::keys::TABLE;

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The docs read: README.md, deploy/README.md, docs/*.md, fuzz/README.md and every README.md
/// of benches/ and examples/.
fn docs(root: &Path) -> Vec<(String, String)> {
    let mut files = vec![
        root.join("README.md"),
        root.join("deploy/README.md"),
        root.join("fuzz/README.md"),
    ];
    for dir in ["docs", "benches", "examples"] {
        walk(&root.join(dir), &mut files);
    }
    files.sort();
    files.dedup();
    files
        .into_iter()
        .map(|p| {
            let name = p.strip_prefix(root).unwrap().display().to_string();
            (name, fs::read_to_string(&p).unwrap())
        })
        .collect()
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            walk(&path, out);
        } else if path.extension().is_some_and(|e| e == "md")
            && (dir.ends_with("docs") || path.file_name().is_some_and(|n| n == "README.md"))
        {
            out.push(path);
        }
    }
}

/// The code of a markdown text, one piece per inline code span (a line break in it read as
/// a space) or line of a fenced block, with its line number.
fn code_pieces(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fenced = false;
    let mut span: Option<(usize, String)> = None;
    for (i, line) in text.lines().enumerate() {
        if span.is_none() && line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            out.push((i + 1, line.to_string()));
            continue;
        }
        if line.trim().is_empty() {
            span = None;
        }
        for c in line.chars() {
            match (&mut span, c) {
                (None, '`') => span = Some((i + 1, String::new())),
                (Some(_), '`') => out.extend(span.take()),
                (Some((_, s)), c) => s.push(c),
                (None, _) => {}
            }
        }
        if let Some((_, s)) = &mut span {
            s.push(' ');
        }
    }
    out
}

/// The workspace's packages and the test targets of each.
fn packages(root: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let cargo = option_env!("CARGO").unwrap_or("cargo");
    let out = Command::new(cargo)
        .args([
            "metadata",
            "--no-deps",
            "--offline",
            "--format-version",
            "1",
        ])
        .current_dir(root)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    meta["packages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let tests = p["targets"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|t| t["kind"].as_array().unwrap().iter().any(|k| k == "test"))
                .map(|t| t["name"].as_str().unwrap().to_string())
                .collect();
            (p["name"].as_str().unwrap().to_string(), tests)
        })
        .collect()
}

/// What is wrong with a cargo command's `-p` and `--test` flags, if anything.
fn check_cargo(words: &[&str], packages: &BTreeMap<String, BTreeSet<String>>) -> Vec<String> {
    let mut problems = Vec::new();
    // Up to `--`: what follows goes to the program.
    let words = &words[..words.iter().position(|w| *w == "--").unwrap_or(words.len())];
    let named: Vec<&str> = words
        .windows(2)
        .filter(|w| ["-p", "--package"].contains(&w[0]))
        .map(|w| w[1])
        .collect();
    for p in &named {
        if !packages.contains_key(*p) {
            problems.push(format!("no package `{p}` in the workspace"));
        }
    }
    // The test targets of the packages that exist (one that does not is named above).
    let tests: Vec<&BTreeSet<String>> = named.iter().filter_map(|p| packages.get(*p)).collect();
    for t in words.windows(2).filter(|w| w[0] == "--test").map(|w| w[1]) {
        if !tests.is_empty() && !tests.iter().any(|tests| tests.contains(t)) {
            problems.push(format!("no test target `{t}` in {named:?}"));
        }
    }
    problems
}

/// The cargo commands of the docs that name a package or test target that does not exist.
fn wrong_cargo_commands(root: &Path) -> Vec<String> {
    let packages = packages(root);
    assert!(
        packages.get("graspopt").is_some_and(|t| t.contains("e2e")),
        "{packages:?}"
    );
    let mut wrong = Vec::new();
    for (name, text) in docs(root) {
        for (line, piece) in code_pieces(&text) {
            let words: Vec<&str> = piece.split_whitespace().collect();
            for (i, _) in words.iter().enumerate().filter(|(_, w)| **w == "cargo") {
                let end = words[i..]
                    .iter()
                    .position(|w| [";", "&&", "|", "&"].contains(w) || w.starts_with('#'))
                    .map_or(words.len(), |e| i + e);
                for problem in check_cargo(&words[i..end], &packages) {
                    wrong.push(format!(
                        "{name}:{line}: `{}`: {problem}",
                        words[i..end].join(" ")
                    ));
                }
            }
        }
    }
    wrong
}

#[test]
fn the_cargo_commands_of_the_docs_name_packages_and_tests_that_exist() {
    let wrong = wrong_cargo_commands(&repo_root());
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn a_cargo_command_with_a_package_or_test_that_is_gone_is_found() {
    let packages: BTreeMap<String, BTreeSet<String>> = [
        (
            "graspopt".to_string(),
            ["cli", "e2e"].map(String::from).into(),
        ),
        ("graspopt-sim".to_string(), BTreeSet::new()),
    ]
    .into();
    let check = |c: &str| check_cargo(&c.split_whitespace().collect::<Vec<_>>(), &packages);
    assert!(check("cargo test -p graspopt --test e2e -- --ignored fuzz::").is_empty());
    assert!(check("cargo run -p graspopt -- run --test x").is_empty());
    assert!(check("cargo test --workspace").is_empty());
    assert_eq!(
        check("cargo test -p graspopt-e2e --test faults"),
        ["no package `graspopt-e2e` in the workspace"]
    );
    assert_eq!(
        check("cargo test -p graspopt --test fuzz"),
        ["no test target `fuzz` in [\"graspopt\"]"]
    );
    let pieces = code_pieces("a `cargo test\n-p x` b\n```sh\ncargo run\n```\n`c`");
    assert_eq!(
        pieces,
        [
            (1, "cargo test -p x".to_string()),
            (4, "cargo run".to_string()),
            (6, "c".to_string())
        ]
    );
}

/// The protocol's message types: every message and request of the key table.
fn message_types() -> BTreeSet<&'static str> {
    TABLE
        .iter()
        .flat_map(|e| [Some(e.message), e.request.filter(|r| !r.is_empty())])
        .flatten()
        .collect()
}

/// Where the docs count the message types ("the seven message types"), they count the key
/// table's.
#[test]
fn the_docs_count_the_message_types_of_the_key_table() {
    let types = message_types();
    assert!(types.contains("FingertipWrenches") && types.contains("SuggestRequest"));
    let numbers = [
        "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten", "eleven",
        "twelve",
    ];
    let mut counts = Vec::new();
    for (name, text) in docs(&repo_root()) {
        let words: Vec<&str> = text.split_whitespace().collect();
        for w in words
            .windows(3)
            .filter(|w| w[1] == "message" && w[2].starts_with("types"))
        {
            let n = numbers
                .iter()
                .position(|n| w[0].eq_ignore_ascii_case(n))
                .map(|i| i + 1);
            if let Some(n) = n.or_else(|| w[0].parse().ok()) {
                counts.push((name.clone(), n));
            }
        }
    }
    assert!(
        counts.iter().any(|(name, _)| name == "docs/reliability.md"),
        "docs/reliability.md no longer counts the message types: {counts:?}"
    );
    for (name, n) in counts {
        assert_eq!(n, types.len(), "{name} counts {n} message types: {types:?}");
    }
}

/// The Python hand agents (examples/python, outside cargo's reach) stamp every payload with
/// the wire version: it must be the protocol's, or every message they send is refused (wire
/// version 4 came with the metric table, and the Python hands were left at 3).
#[test]
fn the_python_hand_agents_speak_the_protocols_wire_version() {
    let path = repo_root().join("examples/python/hand_agent.py");
    let text = fs::read_to_string(&path).unwrap();
    let line = text
        .lines()
        .find(|l| l.starts_with("WIRE_VERSION = "))
        .unwrap_or_else(|| panic!("{} sets no WIRE_VERSION", path.display()));
    let version: u16 = line["WIRE_VERSION = ".len()..]
        .split_whitespace()
        .next()
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    assert_eq!(
        version,
        graspopt_protocol::WIRE_VERSION,
        "{}",
        path.display()
    );
}
