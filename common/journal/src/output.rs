//! Where an export is written: never over the journal it reads (nor its SQLite side files),
//! and an existing file replaced only once the new content is complete (a temporary file
//! beside it, renamed over it by `tempfile`'s `persist`).

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{JournalError, Result};

fn refused(path: &Path, reason: impl Into<String>) -> JournalError {
    JournalError::Output {
        path: path.display().to_string(),
        reason: reason.into(),
    }
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

/// Whether the file at `path` is an SQLite database (a journal, or another program's): it
/// starts with SQLite's 16-byte header. A file that cannot be read is not one.
pub fn holds_database(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 16];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && head == *b"SQLite format 3\0"
}

/// Refuses an `output` that is the journal or one of its SQLite side files (`-wal`,
/// `-shm`, `-journal`), compared after resolving `./`, `..`, symlinks and hard links.
pub fn refuse_journal(journal: &Path, output: &Path) -> Result<()> {
    let journal_real =
        resolved(journal).ok_or_else(|| refused(journal, "cannot resolve the journal's path"))?;
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
    match clash {
        Some(f) => Err(refused(
            output,
            format!(
                "it is the journal{} ({}): the export would overwrite the data it reads; write to another file",
                if *f == journal_real {
                    ""
                } else {
                    "'s SQLite side file"
                },
                f.display()
            ),
        )),
        None => Ok(()),
    }
}

/// Writes `bytes` to `path` without ever leaving it truncated: a regular (or new) file is
/// written to a temporary file in the same folder, synced, given the replaced file's
/// permissions and renamed over it; anything else (a device, a pipe) is written directly.
/// A symlink is followed: the file it points to is replaced and the link stays.
pub fn write_replacing(path: &Path, bytes: &[u8]) -> Result<()> {
    let target = match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => std::fs::canonicalize(path)
            .map_err(|e| refused(path, format!("cannot resolve the link: {e}")))?,
        _ => path.to_path_buf(),
    };
    let existing = std::fs::metadata(&target).ok();
    match &existing {
        Some(m) if m.is_dir() => return Err(refused(path, "it is a folder, not a file")),
        Some(m) if !m.is_file() => {
            let mut f = std::fs::OpenOptions::new()
                .write(true)
                .open(&target)
                .map_err(|e| refused(path, format!("cannot open it: {e}")))?;
            return f
                .write_all(bytes)
                .map_err(|e| refused(path, format!("cannot write it: {e}")));
        }
        _ => {}
    }
    if target.file_name().is_none() {
        return Err(refused(path, "it has no file name"));
    }
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let write = || -> std::io::Result<()> {
        let mut tmp = tempfile::Builder::new()
            .prefix(".graspopt-export-")
            .tempfile_in(&dir)?;
        tmp.write_all(bytes)?;
        tmp.as_file().sync_all()?;
        if let Some(m) = &existing {
            std::fs::set_permissions(tmp.path(), m.permissions())?;
        }
        tmp.persist(&target).map_err(|e| e.error)?;
        Ok(())
    };
    write().map_err(|e| refused(path, format!("cannot write it: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_journal_and_its_side_files_are_refused_as_output() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("sub")).unwrap();
        let journal = dir.path().join("journal.sqlite");
        std::fs::write(&journal, b"data").unwrap();
        let link = dir.path().join("link.csv");
        std::os::unix::fs::symlink(&journal, &link).unwrap();
        for out in [
            journal.clone(),
            dir.path().join("sub/../journal.sqlite"),
            dir.path().join("./journal.sqlite"),
            dir.path().join("journal.sqlite-wal"),
            link,
        ] {
            let e = refuse_journal(&journal, &out).unwrap_err().to_string();
            assert!(e.contains("it is the journal"), "{}: {e}", out.display());
        }
        refuse_journal(&journal, &dir.path().join("trials.csv")).unwrap();
    }

    #[test]
    fn a_replaced_file_keeps_its_permissions_and_no_temporary_file_is_left() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.csv");
        std::fs::write(&out, b"old").unwrap();
        std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_replacing(&out, b"new").unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), b"new");
        let mode = std::fs::metadata(&out).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o640);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        let e = write_replacing(dir.path(), b"x").unwrap_err().to_string();
        assert!(e.contains("is a folder"), "{e}");
    }
}
