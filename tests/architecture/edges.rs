//! The crate edges of docs/architecture.md (its `crate-edges` block) against the
//! `Cargo.toml` files, read by `cargo metadata --no-deps`.
//!
//! An edge is a normal or build dependency of one workspace crate on another. Dev-dependencies
//! are not edges: they build tests only, and may point up (a crate's tests may use a crate
//! above it). Crates are named without the `graspopt-` prefix (`graspopt` is the binary).

use std::collections::{BTreeMap, BTreeSet};
use std::process::Command;

use serde_json::Value;

use crate::root;

const MAP: &str = "docs/architecture.md";

/// One line of the map: a crate and its dependencies, in the order of the block.
#[derive(Debug, PartialEq)]
pub struct MapLine {
    pub krate: String,
    pub deps: Vec<String>,
}

/// The lines of the first ```` ```crate-edges ```` block of `doc`: `crate -> a, b` (or
/// `crate ->` for none; a crate's edges may go on over consecutive lines); `#` starts a
/// comment.
pub fn parse_map(doc: &str) -> Result<Vec<MapLine>, String> {
    let mut lines = doc.lines().skip_while(|l| l.trim() != "```crate-edges");
    if lines.next().is_none() {
        return Err(format!("{MAP} has no ```crate-edges block"));
    }
    let mut out = Vec::new();
    for line in lines.take_while(|l| l.trim() != "```") {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let (krate, deps) = line
            .split_once("->")
            .ok_or_else(|| format!("{MAP}: a crate-edges line without `->`: {line:?}"))?;
        let deps = deps
            .split(',')
            .map(str::trim)
            .filter(|d| !d.is_empty())
            .map(String::from)
            .collect();
        out.push(MapLine {
            krate: krate.trim().to_string(),
            deps,
        });
    }
    Ok(out)
}

/// Where an edge comes from: the dependent's manifest and the dependency's kind.
#[derive(Debug, Clone, PartialEq)]
pub struct Declared {
    pub manifest: String,
    pub section: &'static str,
}

/// The workspace's crates (short names, with their manifests) and edges, from the output of
/// `cargo metadata --format-version 1 --no-deps`.
pub fn cargo_edges(
    metadata: &Value,
) -> (
    BTreeMap<String, String>,
    BTreeMap<(String, String), Declared>,
) {
    let root = root().canonicalize().expect("the repository's root");
    let short = |name: &str| name.strip_prefix("graspopt-").unwrap_or(name).to_string();
    let packages = metadata["packages"].as_array().expect("metadata packages");
    let members: BTreeSet<&str> = metadata["workspace_members"]
        .as_array()
        .expect("metadata workspace_members")
        .iter()
        .filter_map(Value::as_str)
        .collect();
    let in_workspace: Vec<&Value> = packages
        .iter()
        .filter(|p| p["id"].as_str().is_some_and(|id| members.contains(id)))
        .collect();
    let names: BTreeSet<&str> = in_workspace
        .iter()
        .filter_map(|p| p["name"].as_str())
        .collect();
    let mut crates = BTreeMap::new();
    let mut edges = BTreeMap::new();
    for p in in_workspace {
        let name = short(p["name"].as_str().expect("a package name"));
        let manifest = p["manifest_path"].as_str().expect("a manifest path");
        let manifest = std::path::Path::new(manifest);
        let manifest = manifest.strip_prefix(&root).unwrap_or(manifest);
        let manifest = manifest.to_string_lossy().replace('\\', "/");
        for d in p["dependencies"].as_array().expect("package dependencies") {
            let dep = d["name"].as_str().expect("a dependency name");
            let section = match d["kind"].as_str() {
                Some("dev") => continue,
                Some("build") => "[build-dependencies]",
                _ => "[dependencies]",
            };
            if names.contains(dep) && d["path"].is_string() {
                let declared = Declared {
                    manifest: manifest.clone(),
                    section,
                };
                edges.insert((name.clone(), short(dep)), declared);
            }
        }
        crates.insert(name, manifest);
    }
    (crates, edges)
}

/// What is wrong with `map` given the crates and edges of the manifests: one line each.
pub fn mismatches(
    map: &[MapLine],
    crates: &BTreeMap<String, String>,
    edges: &BTreeMap<(String, String), Declared>,
) -> Vec<String> {
    let mut out = Vec::new();
    let mut listed: BTreeMap<&str, usize> = BTreeMap::new();
    for (i, line) in map.iter().enumerate() {
        // A crate's edges may go on over consecutive lines.
        let continued = i > 0 && map[i - 1].krate == line.krate;
        if listed.contains_key(line.krate.as_str()) && !continued {
            out.push(format!(
                "{MAP} lists crate `{}` in two places: put its lines together",
                line.krate
            ));
        }
        listed.entry(&line.krate).or_insert(i);
        if !crates.contains_key(&line.krate) {
            out.push(format!(
                "{MAP} lists crate `{}`, which is no workspace member: remove its line",
                line.krate
            ));
        }
    }
    for (krate, manifest) in crates {
        if !listed.contains_key(krate.as_str()) {
            out.push(format!(
                "crate `{krate}` ({manifest}) is not in {MAP}'s crate-edges block: add its line, \
                 and say in the map what it owns and must not know"
            ));
        }
    }
    let mapped: BTreeSet<(String, String)> = map
        .iter()
        .flat_map(|l| l.deps.iter().map(|d| (l.krate.clone(), d.clone())))
        .collect();
    for ((from, to), declared) in edges {
        if !mapped.contains(&(from.clone(), to.clone())) {
            out.push(format!(
                "edge {from} -> {to} ({} {}) is not in {MAP}: add it to the crate-edges block \
                 if {from} should know {to}, else remove the dependency",
                declared.manifest, declared.section
            ));
        }
    }
    for (from, to) in &mapped {
        if !edges.contains_key(&(from.clone(), to.clone())) {
            let manifest = crates.get(from).map_or("no manifest", String::as_str);
            out.push(format!(
                "{MAP} lists edge {from} -> {to}, but {manifest} has no such normal or build \
                 dependency: remove it from the crate-edges block"
            ));
        }
    }
    for (i, line) in map.iter().enumerate() {
        for dep in &line.deps {
            if listed.get(dep.as_str()).is_some_and(|&j| j > i) {
                out.push(format!(
                    "{MAP}: `{}` depends on `{dep}`, listed below it: the block lists each \
                     crate below the crates it uses",
                    line.krate
                ));
            }
        }
    }
    out
}

/// The crates of the workspace, but the binary, that depend on `anyhow` or `clap` (normal or
/// build dependencies): library crates return typed errors and take plain settings.
pub fn binary_only_dependencies(metadata: &Value) -> Vec<String> {
    let mut out = Vec::new();
    let members: BTreeSet<&str> = metadata["workspace_members"]
        .as_array()
        .expect("metadata workspace_members")
        .iter()
        .filter_map(Value::as_str)
        .collect();
    let packages = metadata["packages"].as_array().expect("metadata packages");
    for p in packages
        .iter()
        .filter(|p| p["id"].as_str().is_some_and(|id| members.contains(id)))
    {
        let name = p["name"].as_str().expect("a package name");
        if name == "graspopt" {
            continue;
        }
        for d in p["dependencies"].as_array().expect("package dependencies") {
            let dep = d["name"].as_str().expect("a dependency name");
            if matches!(dep, "anyhow" | "clap") && d["kind"].as_str() != Some("dev") {
                out.push(format!("{name} depends on {dep}"));
            }
        }
    }
    out
}

fn metadata() -> Value {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let manifest = root().join("Cargo.toml");
    let out = Command::new(&cargo)
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .arg("--manifest-path")
        .arg(&manifest)
        .output()
        .unwrap_or_else(|e| panic!("cannot run {cargo} metadata: {e}"));
    assert!(
        out.status.success(),
        "{cargo} metadata failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("cargo metadata prints JSON")
}

#[test]
fn the_crate_edges_of_the_map_are_the_cargo_toml_files() {
    let doc = std::fs::read_to_string(root().join(MAP)).expect("docs/architecture.md");
    let map = parse_map(&doc).unwrap_or_else(|e| panic!("{e}"));
    let (crates, edges) = cargo_edges(&metadata());
    assert!(
        crates.contains_key("graspopt"),
        "cargo metadata lists no graspopt package"
    );
    let wrong = mismatches(&map, &crates, &edges);
    assert!(
        wrong.is_empty(),
        "{MAP} does not match the Cargo.toml files:\n  {}",
        wrong.join("\n  ")
    );
}

#[test]
fn only_the_binary_uses_anyhow_and_clap() {
    let wrong = binary_only_dependencies(&metadata());
    assert!(
        wrong.is_empty(),
        "library crates return typed errors (an error.rs with a thiserror enum) and take plain \
         settings; anyhow and clap belong to agents/graspopt only:\n  {}",
        wrong.join("\n  ")
    );
}

#[test]
fn a_stale_map_is_named_edge_by_edge() {
    let map = parse_map(
        "x\n```crate-edges\n# comment\nsim ->\ntrial -> sim\ntrial -> quality # why\nquality ->\nsim ->\n```\n",
    )
    .unwrap();
    assert_eq!(map[2].deps, ["quality"]);
    let crates: BTreeMap<String, String> = ["sim", "trial", "quality", "new"]
        .iter()
        .map(|c| (c.to_string(), format!("common/{c}/Cargo.toml")))
        .collect();
    let declared = |c: &str| Declared {
        manifest: format!("common/{c}/Cargo.toml"),
        section: "[dependencies]",
    };
    let edges: BTreeMap<(String, String), Declared> = [("trial", "sim"), ("sim", "quality")]
        .iter()
        .map(|(a, b)| ((a.to_string(), b.to_string()), declared(a)))
        .collect();
    let wrong = mismatches(&map, &crates, &edges).join("\n");
    for expected in [
        "crate `new` (common/new/Cargo.toml) is not in",
        "edge sim -> quality (common/sim/Cargo.toml [dependencies]) is not in",
        "lists edge trial -> quality, but common/trial/Cargo.toml has no such",
        "`trial` depends on `quality`, listed below it",
        "lists crate `sim` in two places",
    ] {
        assert!(
            wrong.contains(expected),
            "{expected:?} missing from:\n{wrong}"
        );
    }
    assert_eq!(wrong.lines().count(), 5, "{wrong}");
    assert!(parse_map("no block").is_err());
}
