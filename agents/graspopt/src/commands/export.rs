//! `graspopt export RUN`: a run's trials from its journal, as CSV or JSON.
//!
//! The journal is read completely before the output is touched, an output that is the journal
//! itself (or one of its SQLite side files) is refused, and an existing output file is only
//! replaced, atomically, once the export succeeded (written to a temporary file beside it,
//! then renamed over it).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    Csv,
    Json,
}

#[derive(Args, Debug)]
pub struct ExportArgs {
    /// The run id.
    pub run: String,
    /// The journal (default: results/<run>/journal.sqlite).
    #[arg(long)]
    pub journal: Option<PathBuf>,
    /// csv (one row per trial; a missing value is an empty cell) or json.
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    pub format: Format,
    /// Output file (default: standard output). Must not be the journal; an existing file is
    /// replaced only once the export succeeded.
    #[arg(long, short, visible_alias = "out")]
    pub output: Option<PathBuf>,
}

pub fn run(args: &ExportArgs) -> Result<ExitCode> {
    let path = args.journal.clone().unwrap_or_else(|| {
        PathBuf::from("results")
            .join(&args.run)
            .join("journal.sqlite")
    });
    anyhow::ensure!(path.exists(), "no journal at {}", path.display());
    // Refuse an output that is the journal before opening anything.
    if let Some(out) = &args.output {
        refuse_journal_as_output(&path, out)?;
    }
    let journal = graspopt_journal::Journal::open(&path)
        .with_context(|| format!("cannot open the journal {}", path.display()))?;
    // The whole export, in memory: the journal is read before any output exists.
    let mut bytes = Vec::new();
    match args.format {
        Format::Csv => graspopt_journal::export::write_csv(&journal, &args.run, &mut bytes)?,
        Format::Json => graspopt_journal::export::write_json(&journal, &args.run, &mut bytes)?,
    }
    drop(journal);
    match &args.output {
        Some(p) => write_replacing(p, &bytes)?,
        None => {
            let mut out = crate::out::stdout();
            out.write_all(&bytes)?;
            out.flush()?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The absolute, symlink-free form of `path`: canonical if it exists, else its canonical
/// parent joined with its file name (`None` if neither can be resolved).
fn resolved(path: &Path) -> Option<PathBuf> {
    if let Ok(p) = std::fs::canonicalize(path) {
        return Some(p);
    }
    let name = path.file_name()?;
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    std::fs::canonicalize(parent).ok().map(|p| p.join(name))
}

/// Whether `a` and `b` are the same file (same device and inode: also through hard links).
#[cfg(unix)]
fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_: &Path, _: &Path) -> bool {
    false
}

/// Errors when `output` is the journal or one of its SQLite side files (`-wal`, `-shm`,
/// `-journal`), compared after resolving `./`, `..` and symlinks.
fn refuse_journal_as_output(journal: &Path, output: &Path) -> Result<()> {
    let journal_real = resolved(journal)
        .with_context(|| format!("cannot resolve the journal path {}", journal.display()))?;
    let output_real = resolved(output);
    let mut forbidden = vec![journal_real.clone()];
    for suffix in ["-wal", "-shm", "-journal"] {
        let mut side = journal_real.clone().into_os_string();
        side.push(suffix);
        forbidden.push(PathBuf::from(side));
    }
    let clash = forbidden
        .iter()
        .find(|f| output_real.as_deref() == Some(f.as_path()) || same_file(f, output));
    if let Some(f) = clash {
        bail!(
            "--output {} is the journal{} ({}): the export would overwrite the data it reads; \
             write to another file",
            output.display(),
            if *f == journal_real {
                ""
            } else {
                "'s SQLite side file"
            },
            f.display()
        );
    }
    Ok(())
}

/// Writes `bytes` to `path` without ever leaving it truncated: a regular (or new) file is
/// written to a temporary file in the same folder and renamed over it; anything else (a
/// device, a pipe) is written directly.
fn write_replacing(path: &Path, bytes: &[u8]) -> Result<()> {
    // Follow a symlink, so the file it points to is replaced and the link stays.
    let target = match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => std::fs::canonicalize(path)
            .with_context(|| format!("cannot resolve --output {}", path.display()))?,
        _ => path.to_path_buf(),
    };
    let existing = std::fs::metadata(&target).ok();
    if existing.as_ref().is_some_and(|m| !m.is_file()) {
        if existing.as_ref().is_some_and(std::fs::Metadata::is_dir) {
            bail!("--output {} is a folder, not a file", path.display());
        }
        let mut f = std::fs::OpenOptions::new()
            .write(true)
            .open(&target)
            .with_context(|| format!("cannot open --output {}", path.display()))?;
        f.write_all(bytes)
            .with_context(|| format!("cannot write --output {}", path.display()))?;
        return Ok(());
    }
    let name = target
        .file_name()
        .with_context(|| format!("--output {} has no file name", path.display()))?;
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp-{}", std::process::id()));
    let tmp = dir.join(tmp_name);
    let result = (|| -> Result<()> {
        let mut f = std::fs::File::create(&tmp)
            .with_context(|| format!("cannot create {}", tmp.display()))?;
        f.write_all(bytes)
            .with_context(|| format!("cannot write {}", tmp.display()))?;
        f.sync_all()
            .with_context(|| format!("cannot write {}", tmp.display()))?;
        if let Some(m) = &existing {
            // Keep the replaced file's permissions.
            std::fs::set_permissions(&tmp, m.permissions())
                .with_context(|| format!("cannot set the permissions of {}", tmp.display()))?;
        }
        std::fs::rename(&tmp, &target)
            .with_context(|| format!("cannot move {} to {}", tmp.display(), target.display()))?;
        Ok(())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.with_context(|| format!("cannot write --output {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_journal_and_its_side_files_are_refused_as_output() {
        let dir = std::env::temp_dir().join(format!("graspopt-export-cmd-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let journal = dir.join("journal.sqlite");
        std::fs::write(&journal, b"data").unwrap();
        for out in [
            journal.clone(),
            dir.join("sub/../journal.sqlite"),
            dir.join("./journal.sqlite"),
            dir.join("journal.sqlite-wal"),
        ] {
            let e = refuse_journal_as_output(&journal, &out).unwrap_err();
            assert!(format!("{e:#}").contains("--output"), "{e:#}");
        }
        refuse_journal_as_output(&journal, &dir.join("trials.csv")).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn write_replacing_leaves_no_temporary_file() {
        let dir = std::env::temp_dir().join(format!("graspopt-export-tmp-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("out.csv");
        std::fs::write(&out, b"old").unwrap();
        write_replacing(&out, b"new").unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), b"new");
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(names.len(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
