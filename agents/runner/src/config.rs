//! An agent's settings file: TOML, the agent's settings struct (`HandConfig`, ...), keys left
//! out keep their defaults and an unknown key is refused by name (the format:
//! docs/agent-config.md); `--set key=value` overrides go on top ([`load_with`]).

use std::path::Path;

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::error::{Boxed, RunnerError};

type Result<T> = std::result::Result<T, RunnerError>;

/// Reads a TOML settings file (defaults when none): keys left out keep their defaults, and a
/// key the settings do not have is refused, naming the keys of its table (the settings'
/// format: docs/agent-config.md).
pub fn load<T: DeserializeOwned + Serialize + Default>(path: Option<&Path>) -> Result<T> {
    let Some(p) = path else {
        return Ok(T::default());
    };
    let text = std::fs::read_to_string(p).map_err(|source| RunnerError::ReadSettings {
        path: p.to_path_buf(),
        source,
    })?;
    let in_file = |source: Boxed| RunnerError::SettingsFile {
        path: p.to_path_buf(),
        source,
    };
    let table: toml::Table = toml::from_str(&text).map_err(|e| in_file(e.into()))?;
    // Every key, with `null` for the settings that are none by default.
    let known = serde_json::to_value(T::default())?;
    if let Some(e) = unknown_key(&table, &known, "") {
        return Err(in_file(e.into()));
    }
    let settings: T = toml::from_str(&text).map_err(|e| in_file(e.into()))?;
    match p.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(folder) => relative_to(settings, &table, folder).map_err(|e| in_file(e.into())),
        None => Ok(settings),
    }
}

/// [`load`], then each of `sets` (`key=value`, `--set` on the command line; a dotted key
/// names a key of a table: `fingertips.noise.force_resolution=0`) on top. The value is read
/// as TOML (`5`, `0.5`, `true`, `"text"`), or as text when it is not TOML or the setting
/// is text; the error names the key.
pub fn load_with<T: DeserializeOwned + Serialize + Default>(
    path: Option<&Path>,
    sets: &[String],
) -> Result<T> {
    let settings: T = load(path)?;
    if sets.is_empty() {
        return Ok(settings);
    }
    let known = serde_json::to_value(T::default())?;
    let mut value = serde_json::to_value(settings)?;
    for set in sets {
        value = apply_set::<T>(value, &known, set)?;
    }
    Ok(serde_json::from_value(value)?)
}

/// The top-level keys of settings `T`, as its TOML file and `--set` name them (a table's
/// keys are `table.key`).
pub fn keys<T: Serialize + Default>() -> Vec<String> {
    match serde_json::to_value(T::default()) {
        Ok(serde_json::Value::Object(keys)) => keys.keys().cloned().collect(),
        _ => Vec::new(),
    }
}

/// `value` (the settings as JSON) with `set` (`key=value`) applied; checked against the
/// settings' type.
fn apply_set<T: DeserializeOwned>(
    mut value: serde_json::Value,
    known: &serde_json::Value,
    set: &str,
) -> Result<serde_json::Value> {
    let Some((key, text)) = set.split_once('=') else {
        return Err(RunnerError::SetWithoutValue(set.to_string()));
    };
    let refused = |why: String| RunnerError::Set {
        key: key.to_string(),
        value: text.to_string(),
        why,
    };
    let path: Vec<&str> = key.trim().split('.').collect();
    let mut table = known;
    for (i, part) in path.iter().enumerate() {
        let serde_json::Value::Object(keys) = table else {
            return Err(refused(format!("{} is not a table", path[..i].join("."))));
        };
        let Some(inner) = keys.get(*part) else {
            let unknown = RunnerError::UnknownKey {
                key: part.to_string(),
                place: place(&path[..i].join(".")),
                keys: keys
                    .keys()
                    .map(String::as_str)
                    .collect::<Vec<_>>()
                    .join(", "),
            };
            return Err(refused(unknown.to_string()));
        };
        table = inner;
    }
    let text_value = serde_json::Value::String(text.to_string());
    let typed = toml_value(text).unwrap_or_else(|| text_value.clone());
    let mut first_error = None;
    for candidate in [typed, text_value] {
        let mut slot = &mut value;
        for part in &path {
            slot = &mut slot[*part];
        }
        *slot = candidate;
        match serde_json::from_value::<T>(value.clone()) {
            Ok(_) => return Ok(value),
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    Err(refused(
        first_error.map_or_else(String::new, |e| e.to_string()),
    ))
}

/// `text` read as a TOML value (`None` when it is not one: a bare word, say).
fn toml_value(text: &str) -> Option<serde_json::Value> {
    let table: toml::Table = toml::from_str(&format!("v = {text}")).ok()?;
    serde_json::to_value(table.get("v")?).ok()
}

/// The settings that name a file: with a relative path in a settings file, the file is
/// looked up beside it (as a launch file's paths are), not in the folder the agent runs in.
/// `hand` only when it names a URDF file (a built-in hand is a name).
const FILE_KEYS: [&str; 4] = ["hand", "mesh", "replay", "journal"];

/// `settings` with the relative paths that `table` (the file) gave to [`FILE_KEYS`] made
/// relative to `folder`.
fn relative_to<T: DeserializeOwned + Serialize>(
    settings: T,
    table: &toml::Table,
    folder: &Path,
) -> std::result::Result<T, serde_json::Error> {
    let mut value = serde_json::to_value(settings)?;
    for key in FILE_KEYS {
        let Some(toml::Value::String(given)) = table.get(key) else {
            continue;
        };
        let path = Path::new(given);
        let is_file = key != "hand" || given.to_ascii_lowercase().ends_with(".urdf");
        if is_file && !given.is_empty() && path.is_relative() {
            value[key] = serde_json::Value::String(folder.join(path).display().to_string());
        }
    }
    serde_json::from_value(value)
}

/// Where a key is, in a message: at the top level, or in the table at `path` (dotted).
fn place(path: &str) -> String {
    if path.is_empty() {
        "at the top level".to_string()
    } else {
        format!("in [{path}]")
    }
}

/// The first key of `table` (at `path`, a dotted table name, empty at the top) that
/// `known` (the settings' defaults as JSON) does not have, naming the keys there; tables
/// are checked recursively where the default is a table too.
fn unknown_key(table: &toml::Table, known: &serde_json::Value, path: &str) -> Option<RunnerError> {
    let serde_json::Value::Object(keys) = known else {
        return None;
    };
    for (key, value) in table {
        let Some(default) = keys.get(key) else {
            let names: Vec<&str> = keys.keys().map(String::as_str).collect();
            return Some(RunnerError::UnknownKey {
                key: key.clone(),
                place: place(path),
                keys: names.join(", "),
            });
        };
        if let toml::Value::Table(inner) = value {
            let inner_path = if path.is_empty() {
                key.clone()
            } else {
                format!("{path}.{key}")
            };
            if let Some(e) = unknown_key(inner, default, &inner_path) {
                return Some(e);
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The TOML example under the heading `## {kind}` of docs/agent-config.md.
    fn documented(kind: &str) -> String {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/agent-config.md");
        let doc = std::fs::read_to_string(path).unwrap();
        let section = doc.split(&format!("\n## {kind}\n")).nth(1).unwrap();
        let block = section.split("```toml\n").nth(1).unwrap();
        block.split("```").next().unwrap().to_string()
    }

    fn load_text<T: DeserializeOwned + Serialize + Default>(name: &str, text: &str) -> Result<T> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        load(Some(&path))
    }

    #[test]
    fn the_documented_settings_files_are_the_defaults() {
        fn check<T>(kind: &str)
        where
            T: DeserializeOwned + Serialize + Default + PartialEq + std::fmt::Debug,
        {
            let loaded: T = load_text(&format!("{kind}.toml"), &documented(kind))
                .unwrap_or_else(|e| panic!("{kind}: {}", crate::error::chain(&e)));
            assert_eq!(loaded, T::default(), "{kind}");
        }
        check::<graspopt_perception::PerceptionConfig>("perception");
        check::<graspopt_hand::HandConfig>("hand");
        check::<graspopt_metric::MetricConfig>("metric");
        check::<graspopt_planner::PlannerConfig>("planner");
        check::<graspopt_coordinator::CoordinatorConfig>("coordinator");
    }

    #[test]
    fn an_unknown_key_is_refused_with_the_keys_of_its_table() {
        let err = load_text::<graspopt_hand::HandConfig>("h.toml", "trial_cost = 5\n").unwrap_err();
        let msg = crate::error::chain(&err);
        assert!(msg.contains("h.toml"), "{msg}");
        assert!(
            msg.contains("unknown key `trial_cost` at the top level"),
            "{msg}"
        );
        assert!(
            msg.contains("fingertips, forces, hand, id, mesh, mesh_scale, object, replay, sensing, trial_cost_ms"),
            "{msg}"
        );
        // In a table, the table's own keys.
        let text = documented("metric").replace("include_palm = true", "include_palms = true");
        let err = load_text::<graspopt_metric::MetricConfig>("m.toml", &text).unwrap_err();
        let msg = crate::error::chain(&err);
        assert!(
            msg.contains("unknown key `include_palms` in [score]"),
            "{msg}"
        );
        assert!(
            msg.contains("contacts, frame, include_palm, metric, model, torque_scale"),
            "{msg}"
        );
        let text = documented("metric").replace("resolution = ", "resolutoin = ");
        let msg = crate::error::chain(
            &load_text::<graspopt_metric::MetricConfig>("m.toml", &text).unwrap_err(),
        );
        assert!(msg.contains("`resolutoin` in [contacts.cloud]"), "{msg}");
        // Keys left out keep their defaults; flags of other kinds are not keys.
        let c: graspopt_hand::HandConfig = load_text("h.toml", "trial_cost_ms = 5\n").unwrap();
        assert_eq!((c.trial_cost_ms, c.hand.as_str()), (5, "barrett"));
    }

    /// Files named in a settings file are found beside it; absolute paths, built-in hand
    /// names and empty paths are kept.
    #[test]
    fn paths_in_a_settings_file_are_relative_to_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("h.toml");
        let text =
            "hand = \"../hands/claw.urdf\"\nmesh = \"part.stl\"\nreplay = \"/abs/rec.jsonl\"\n";
        std::fs::write(&path, text).unwrap();
        let c: graspopt_hand::HandConfig = load(Some(&path)).unwrap();
        assert_eq!(Path::new(&c.hand), dir.path().join("../hands/claw.urdf"));
        assert_eq!(
            c.mesh.as_deref(),
            Some(dir.path().join("part.stl").as_path())
        );
        assert_eq!(c.replay.as_deref(), Some(Path::new("/abs/rec.jsonl")));
        std::fs::write(&path, "hand = \"franka_hand\"\n").unwrap();
        let c: graspopt_hand::HandConfig = load(Some(&path)).unwrap();
        assert_eq!(c.hand, "franka_hand");
        let path = dir.path().join("c.toml");
        std::fs::write(&path, "journal = \"\"\n").unwrap();
        let c: graspopt_coordinator::CoordinatorConfig = load(Some(&path)).unwrap();
        assert_eq!(c.journal, Path::new(""));
    }
}
