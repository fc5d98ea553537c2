//! What a graspopt command leaves in its output folder: the CSV and images of a scan, the
//! files of a run (trials.csv/json from the journal, best.png, trials.svg, best.svg), a
//! trial's preview and scene, and the experiment reports (CSV, markdown, figures).
//!
//! This crate lays out what others compute: the trial crate (scans, evaluations), the
//! experiment crate (the thesis studies as data) and the journal (a run's trials). Figures are
//! drawn by `graspopt-pictures`, scenes written by `graspopt-scene`. It computes nothing of its
//! own and knows nothing of the bus.
//!
//! - [`scan`]: `graspopt scan`'s CSV, SVG and PNG.
//! - [`trial`]: `graspopt trial --preview/--scene`, and the preview picture of a trial.
//! - [`run`]: the results folder of `graspopt run`.
//! - [`experiment`]: the folders of `graspopt experiment metrics` and `experiment bo`.
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod error;
pub mod experiment;
pub mod run;
pub mod scan;
pub mod trial;

pub use error::{ReportError, Result};

use std::path::Path;

/// Writes `text` to `dir/name`; returns `name` (for a report's list of files).
pub(crate) fn write(dir: &Path, name: &str, text: &str) -> Result<String> {
    let path = dir.join(name);
    std::fs::write(&path, text).map_err(|source| ReportError::Write {
        path: path.clone(),
        source,
    })?;
    Ok(name.to_string())
}

/// `word` as one word of a POSIX shell command line: as it is when it holds only characters
/// no shell treats specially, else in single quotes (a quote inside written `'\''`).
pub(crate) fn shell_word(word: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "-_./,:=+@%".contains(c);
    if !word.is_empty() && word.chars().all(plain) {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', r"'\''"))
    }
}

/// Creates `dir` and its parents.
pub(crate) fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| ReportError::CreateDir {
        dir: dir.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::shell_word;

    #[test]
    fn shell_words_are_quoted_only_when_a_shell_would_split_or_expand_them() {
        assert_eq!(shell_word("hands/my_gripper.urdf"), "hands/my_gripper.urdf");
        assert_eq!(shell_word("my hands/g.urdf"), "'my hands/g.urdf'");
        assert_eq!(shell_word("it's.urdf"), r"'it'\''s.urdf'");
        assert_eq!(shell_word("$HOME/g.urdf"), "'$HOME/g.urdf'");
        assert_eq!(shell_word(""), "''");
    }
}
