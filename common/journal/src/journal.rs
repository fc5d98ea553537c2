//! The [`Journal`]: one SQLite connection and the operations on it.

use std::path::{Path, PathBuf};
use std::time::Duration;

use rusqlite::{Connection, OptionalExtension, Transaction, TransactionBehavior, params};

use crate::error::{JournalError, Result};
use crate::rows::{run_from_row, trial_from_row, u64_col};
use crate::schema;
use crate::types::{
    EventRow, ResultOutcome, ResultRow, RunExport, RunRow, StateCounts, StoredRunPhase,
    StoredTrialPhase, TrialIssue, TrialRow,
};
use crate::writes::{db_id, failure_in, issue_in, parse_state, planner_state_in, result_in};

/// How long a statement waits for another connection's lock before failing.
const BUSY_TIMEOUT: Duration = Duration::from_secs(5);
/// Prepared statements kept by the connection: more than the journal has, so that none is
/// ever prepared twice.
const STATEMENT_CACHE: usize = 64;

/// Pages of write-ahead log after which a commit copies the log into the database (a
/// checkpoint, SQLite's default is 1,000). A checkpoint syncs the disk twice: every 1,000
/// pages it took most of a coordinator's time (`graspopt bench coordinator`,
/// docs/benchmarks.md). A commit is in the log before the checkpoint either way, so this
/// changes nothing of what survives a killed process; the log grows to about 40 MB.
const WAL_CHECKPOINT_PAGES: u32 = 10_000;

/// Columns read into a [`TrialRow`]: all of them, read by name ([`trial_from_row`]), so a
/// journal without a metric's column still reads (the metric is missing).
const TRIAL_COLUMNS: &str = "*";

/// The durable trial journal: runs, trials and their event log in one SQLite
/// database file (write-ahead log, so a killed process loses at most the
/// transaction it was in, and readers in other connections never block the writer).
///
/// Every write method is one transaction; [`Journal::record`] writes several
/// in one (see [`crate::batch`]). The journal is `Send` but not `Sync`: one
/// thread (or a mutex) owns it.
pub struct Journal {
    conn: Connection,
    path: Option<PathBuf>,
}

impl std::fmt::Debug for Journal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Journal").field("path", &self.path).finish()
    }
}

impl Journal {
    /// Opens (creating if needed) the journal at `path`: WAL mode,
    /// `synchronous=NORMAL` (survives a kill -9 of the process at any point;
    /// a power loss may lose the last transactions but never corrupts),
    /// foreign keys on, busy timeout 5 s, schema created or checked.
    ///
    /// A file SQLite cannot open or write (its only word for it is "unable to open
    /// database file") is [`JournalError::Open`], saying why: a missing folder, a
    /// permission, a folder where the file should be.
    pub fn open(path: &Path) -> Result<Journal> {
        let opened = Connection::open(path).and_then(|conn| {
            conn.busy_timeout(BUSY_TIMEOUT)?;
            let mode: String = conn.query_row("PRAGMA journal_mode = WAL", [], |r| r.get(0))?;
            Ok((conn, mode))
        });
        let (conn, mode) = opened.map_err(|e| match e.sqlite_error_code() {
            Some(rusqlite::ErrorCode::CannotOpen | rusqlite::ErrorCode::ReadOnly) => {
                JournalError::Open {
                    path: path.to_path_buf(),
                    reason: why_unopenable(path, &e),
                }
            }
            _ => JournalError::Sqlite(e),
        })?;
        if !mode.eq_ignore_ascii_case("wal") {
            return Err(JournalError::JournalMode(mode));
        }
        Self::init(conn, Some(path.to_path_buf()))
    }

    /// Opens the journal at `path` to read it (an export, say): a file that does not exist
    /// or is empty is an error, where [`Journal::open`] would make it a new journal.
    pub fn open_existing(path: &Path) -> Result<Journal> {
        match std::fs::metadata(path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(JournalError::Open {
                path: path.to_path_buf(),
                reason: "there is no such file".into(),
            }),
            Ok(m) if m.is_file() && m.len() == 0 => Err(JournalError::Schema(
                "the file is empty (a journal holds at least its tables)".into(),
            )),
            _ => Self::open(path),
        }
    }

    /// A journal that lives only as long as this value (for tests and dry runs).
    pub fn open_in_memory() -> Result<Journal> {
        let conn = Connection::open_in_memory()?;
        conn.busy_timeout(BUSY_TIMEOUT)?;
        Self::init(conn, None)
    }

    fn init(mut conn: Connection, path: Option<PathBuf>) -> Result<Journal> {
        // Every statement of the write path is prepared once and kept (`prepare_cached`):
        // preparing them per call was a tenth of a run's CPU in `graspopt bench
        // coordinator`.
        conn.set_prepared_statement_cache_capacity(STATEMENT_CACHE);
        conn.execute_batch(&format!(
            "PRAGMA synchronous = NORMAL; PRAGMA foreign_keys = ON; \
             PRAGMA wal_autocheckpoint = {WAL_CHECKPOINT_PAGES};"
        ))?;
        let fk: i64 = conn.query_row("PRAGMA foreign_keys", [], |r| r.get(0))?;
        if fk != 1 {
            return Err(JournalError::Schema(
                "this SQLite build cannot enforce foreign keys".to_string(),
            ));
        }
        schema::ensure(&mut conn)?;
        crate::metrics::add_missing_columns(&mut conn)?;
        Ok(Journal { conn, path })
    }

    /// The file this journal was opened from (`None` in memory).
    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    pub(crate) fn write_tx(&mut self) -> Result<Transaction<'_>> {
        Ok(self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)?)
    }

    /// A read transaction, so that multi-statement reads see one snapshot even
    /// while another process writes.
    pub(crate) fn read_tx(&self) -> Result<Transaction<'_>> {
        Ok(self.conn.unchecked_transaction()?)
    }

    // ----------------------------------------------------------------- runs

    /// Records a new run. Idempotent when the same run id exists with the same
    /// config (equal text, or equal JSON values) and parameter names; otherwise
    /// [`JournalError::ConfigMismatch`] naming the run, and nothing changes.
    pub fn create_run(&mut self, run: &RunRow) -> Result<()> {
        let names_json = serde_json::to_string(&run.param_names)?;
        let tx = self.write_tx()?;
        let existing: Option<(String, String)> = tx
            .query_row(
                "SELECT config_json, param_names FROM runs WHERE run_id = ?1",
                [&run.run_id],
                |r| Ok((r.get(0)?, r.get(1)?)),
            )
            .optional()?;
        match existing {
            Some((config, names)) => {
                let names: Vec<String> = serde_json::from_str(&names)?;
                if same_json(&config, &run.config_json) && names == run.param_names {
                    Ok(())
                } else {
                    Err(JournalError::ConfigMismatch {
                        run_id: run.run_id.clone(),
                    })
                }
            }
            None => {
                tx.execute(
                    "INSERT INTO runs (run_id, created_ms, config_json, param_names, status, status_ms)
                     VALUES (?1, ?2, ?3, ?4, ?5, ?2)",
                    params![
                        run.run_id,
                        run.created_ms,
                        run.config_json,
                        names_json,
                        run.status.as_str()
                    ],
                )?;
                tx.commit()?;
                Ok(())
            }
        }
    }

    /// The run, if the journal has it.
    pub fn run(&self, run_id: &str) -> Result<Option<RunRow>> {
        let mut stmt = self.conn.prepare_cached(
            "SELECT run_id, created_ms, config_json, param_names, status FROM runs WHERE run_id = ?1",
        )?;
        Ok(stmt.query_row([run_id], run_from_row).optional()?)
    }

    /// All runs, oldest first (ties in insertion order).
    pub fn runs(&self) -> Result<Vec<RunRow>> {
        let mut stmt = self.conn.prepare_cached(
            "SELECT run_id, created_ms, config_json, param_names, status FROM runs
             ORDER BY created_ms, rowid",
        )?;
        let rows = stmt
            .query_map([], run_from_row)?
            .collect::<rusqlite::Result<Vec<_>>>()?;
        Ok(rows)
    }

    /// Sets a run's status; [`JournalError::UnknownRun`] if there is no such run.
    pub fn set_run_phase(
        &mut self,
        run_id: &str,
        status: StoredRunPhase,
        at_ms: i64,
    ) -> Result<()> {
        let tx = self.write_tx()?;
        let n = tx.execute(
            "UPDATE runs SET status = ?2, status_ms = ?3 WHERE run_id = ?1",
            params![run_id, status.as_str(), at_ms],
        )?;
        if n == 0 {
            return Err(JournalError::UnknownRun(run_id.to_string()));
        }
        tx.commit()?;
        Ok(())
    }

    /// Replaces a run's recorded config (a resumed run whose budget was raised, say);
    /// [`JournalError::UnknownRun`] if there is no such run. The parameter names stay.
    pub fn set_run_config(&mut self, run_id: &str, config_json: &str) -> Result<()> {
        let tx = self.write_tx()?;
        let n = tx.execute(
            "UPDATE runs SET config_json = ?2 WHERE run_id = ?1",
            params![run_id, config_json],
        )?;
        if n == 0 {
            return Err(JournalError::UnknownRun(run_id.to_string()));
        }
        tx.commit()?;
        Ok(())
    }

    /// Removes a run that issued no trial (a start that stopped before its first trial),
    /// with its planner state, so that the run can be created afresh. Returns whether it
    /// was removed: `false`, with nothing changed, when the run is not in the journal or
    /// has a trial.
    pub fn remove_unstarted_run(&mut self, run_id: &str) -> Result<bool> {
        let tx = self.write_tx()?;
        let trials: Option<i64> = tx
            .query_row(
                "SELECT (SELECT count(*) FROM trials WHERE run_id = ?1) FROM runs
                 WHERE run_id = ?1",
                [run_id],
                |r| r.get(0),
            )
            .optional()?;
        if trials != Some(0) {
            return Ok(false);
        }
        tx.execute("DELETE FROM planner_state WHERE run_id = ?1", [run_id])?;
        tx.execute("DELETE FROM runs WHERE run_id = ?1", [run_id])?;
        tx.commit()?;
        Ok(true)
    }

    /// Keeps `state`, the planner's engine after its last reply for the run (opaque
    /// bytes), replacing the previous one.
    pub fn set_planner_state(&mut self, run_id: &str, state: &[u8], at_ms: i64) -> Result<()> {
        let tx = self.write_tx()?;
        planner_state_in(&tx, run_id, state, at_ms)?;
        tx.commit()?;
        Ok(())
    }

    /// The planner's engine state kept for the run, if any (see [`Self::set_planner_state`]).
    pub fn planner_state(&self, run_id: &str) -> Result<Option<Vec<u8>>> {
        Ok(self
            .conn
            .query_row(
                "SELECT state FROM planner_state WHERE run_id = ?1",
                params![run_id],
                |r| r.get(0),
            )
            .optional()?)
    }

    // --------------------------------------------------------------- trials

    /// A trial issued to a worker (attempt 1: inserts the trial row, event
    /// `issued`) or re-issued (attempt n+1: updates attempts, worker and lease,
    /// event `reissued` whose note is `reason`). The state is Running.
    ///
    /// Refused, with nothing written: an unknown run; a parameter count that
    /// differs from the run's parameter names; a non-finite parameter; an
    /// attempt that is not the next one; re-issuing a completed or failed
    /// trial; re-issuing with different parameters.
    pub fn write_issue(&mut self, issue: &TrialIssue) -> Result<()> {
        let tx = self.write_tx()?;
        issue_in(&tx, issue)?;
        tx.commit()?;
        Ok(())
    }

    /// A trial's result, accepted exactly once per (run, trial).
    ///
    /// - Running trial: completed with this result → `Accepted` (event
    ///   `result`; if the result's attempt is older than the latest issue the
    ///   note says so, and `result_attempt` records which attempt did the work).
    /// - Trial already completed or failed: → `Duplicate`; the trial row is
    ///   unchanged and a `duplicate` event is written.
    /// - Unknown run or trial: → `UnknownTrial`, nothing written.
    ///
    /// A NaN or infinite score or metric is an error naming the field, and
    /// nothing is written.
    pub fn write_result(&mut self, result: &ResultRow) -> Result<ResultOutcome> {
        let tx = self.write_tx()?;
        let outcome = result_in(&tx, result)?;
        tx.commit()?;
        Ok(outcome)
    }

    /// A trial that failed permanently: state Failed with `message` (event
    /// `failed`, note = message, worker = the trial's latest worker).
    /// Returns false, writing nothing, when the trial is already completed or
    /// failed, or when the run or trial is unknown.
    pub fn write_failure(
        &mut self,
        run_id: &str,
        trial_id: u64,
        attempt: u32,
        message: &str,
        at_ms: i64,
    ) -> Result<bool> {
        let tx = self.write_tx()?;
        let written = failure_in(&tx, run_id, trial_id, attempt, message, at_ms)?;
        tx.commit()?;
        Ok(written)
    }

    // ---------------------------------------------------------------- reads

    /// A run's trials by trial id; [`JournalError::UnknownRun`] for an unknown run.
    pub fn trials(&self, run_id: &str) -> Result<Vec<TrialRow>> {
        let tx = self.read_tx()?;
        require_run(&tx, run_id)?;
        query_trials(&tx, run_id)
    }

    /// One trial, if the run has it; [`JournalError::UnknownRun`] for an unknown run.
    pub fn trial(&self, run_id: &str, trial_id: u64) -> Result<Option<TrialRow>> {
        let tx = self.read_tx()?;
        require_run(&tx, run_id)?;
        let Ok(id) = db_id(trial_id) else {
            return Ok(None);
        };
        let mut stmt = tx.prepare_cached(&format!(
            "SELECT {TRIAL_COLUMNS} FROM trials WHERE run_id = ?1 AND trial_id = ?2"
        ))?;
        Ok(stmt
            .query_row(params![run_id, id], trial_from_row)
            .optional()?)
    }

    /// A run's events in insertion order; [`JournalError::UnknownRun`] for an unknown run.
    pub fn events(&self, run_id: &str) -> Result<Vec<EventRow>> {
        let tx = self.read_tx()?;
        require_run(&tx, run_id)?;
        let mut stmt = tx.prepare_cached(
            "SELECT seq, run_id, trial_id, attempt, kind, worker, at_ms, note FROM events
             WHERE run_id = ?1 ORDER BY seq",
        )?;
        let rows = stmt
            .query_map([run_id], |r| {
                Ok(EventRow {
                    seq: r.get(0)?,
                    run_id: r.get(1)?,
                    trial_id: u64_col(r, 2)?,
                    attempt: r.get(3)?,
                    kind: r.get(4)?,
                    worker: r.get(5)?,
                    at_ms: r.get(6)?,
                    note: r.get(7)?,
                })
            })?
            .collect::<rusqlite::Result<Vec<_>>>()?;
        Ok(rows)
    }

    /// The completed trial with the highest score (ties: lowest trial id).
    pub fn best(&self, run_id: &str) -> Result<Option<TrialRow>> {
        let tx = self.read_tx()?;
        require_run(&tx, run_id)?;
        let mut stmt = tx.prepare_cached(&format!(
            "SELECT {TRIAL_COLUMNS} FROM trials WHERE run_id = ?1 AND state = 'completed'
             ORDER BY score DESC, trial_id ASC LIMIT 1"
        ))?;
        Ok(stmt.query_row([run_id], trial_from_row).optional()?)
    }

    /// How many of the run's trials are running, completed and failed.
    pub fn counts(&self, run_id: &str) -> Result<StateCounts> {
        let tx = self.read_tx()?;
        require_run(&tx, run_id)?;
        let mut stmt = tx.prepare_cached(
            "SELECT state, count(*) FROM trials WHERE run_id = ?1 GROUP BY state",
        )?;
        let mut counts = StateCounts::default();
        let rows = stmt
            .query_map([run_id], |r| {
                Ok((r.get::<_, String>(0)?, r.get::<_, i64>(1)?))
            })?
            .collect::<rusqlite::Result<Vec<_>>>()?;
        for (state, n) in rows {
            let n = usize::try_from(n).unwrap_or(0);
            match parse_state(&state)? {
                StoredTrialPhase::Running => counts.running = n,
                StoredTrialPhase::Completed => counts.completed = n,
                StoredTrialPhase::Failed => counts.failed = n,
            }
        }
        Ok(counts)
    }

    /// The highest trial id the run has issued (`None` before the first issue):
    /// a restarted coordinator continues from here.
    pub fn max_trial_id(&self, run_id: &str) -> Result<Option<u64>> {
        let tx = self.read_tx()?;
        require_run(&tx, run_id)?;
        let max: Option<i64> = tx.query_row(
            "SELECT max(trial_id) FROM trials WHERE run_id = ?1",
            [run_id],
            |r| r.get(0),
        )?;
        Ok(max.and_then(|m| u64::try_from(m).ok()))
    }

    /// Running trials whose lease ended before `now_ms`, by trial id: what a
    /// restarted coordinator should re-issue.
    pub fn expired_leases(&self, run_id: &str, now_ms: i64) -> Result<Vec<TrialRow>> {
        let tx = self.read_tx()?;
        require_run(&tx, run_id)?;
        let mut stmt = tx.prepare_cached(&format!(
            "SELECT {TRIAL_COLUMNS} FROM trials
             WHERE run_id = ?1 AND state = 'running' AND lease_until_ms < ?2 ORDER BY trial_id"
        ))?;
        let rows = stmt
            .query_map(params![run_id, now_ms], trial_from_row)?
            .collect::<rusqlite::Result<Vec<_>>>()?;
        Ok(rows)
    }

    /// The run and all its trials, read in one snapshot (what the exports write).
    pub fn export(&self, run_id: &str) -> Result<RunExport> {
        let tx = self.read_tx()?;
        let run = tx
            .query_row(
                "SELECT run_id, created_ms, config_json, param_names, status FROM runs
                 WHERE run_id = ?1",
                [run_id],
                run_from_row,
            )
            .optional()?
            .ok_or_else(|| JournalError::UnknownRun(run_id.to_string()))?;
        let trials = query_trials(&tx, run_id)?;
        Ok(RunExport { run, trials })
    }

    /// `PRAGMA integrity_check` reports "ok".
    pub fn integrity_check(&self) -> Result<bool> {
        let mut stmt = self.conn.prepare("PRAGMA integrity_check")?;
        let lines = stmt
            .query_map([], |r| r.get::<_, String>(0))?
            .collect::<rusqlite::Result<Vec<_>>>()?;
        Ok(lines.len() == 1 && lines[0] == "ok")
    }
}

/// Equal text, or both valid JSON with equal values (key order and spacing ignored).
fn same_json(a: &str, b: &str) -> bool {
    if a == b {
        return true;
    }
    match (
        serde_json::from_str::<serde_json::Value>(a),
        serde_json::from_str::<serde_json::Value>(b),
    ) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

pub(crate) fn require_run(conn: &Connection, run_id: &str) -> Result<()> {
    let mut stmt = conn.prepare_cached("SELECT 1 FROM runs WHERE run_id = ?1")?;
    if stmt.exists([run_id])? {
        Ok(())
    } else {
        Err(JournalError::UnknownRun(run_id.to_string()))
    }
}

fn query_trials(conn: &Connection, run_id: &str) -> Result<Vec<TrialRow>> {
    let mut stmt = conn.prepare_cached(&format!(
        "SELECT {TRIAL_COLUMNS} FROM trials WHERE run_id = ?1 ORDER BY trial_id"
    ))?;
    let rows = stmt
        .query_map([run_id], trial_from_row)?
        .collect::<rusqlite::Result<Vec<_>>>()?;
    Ok(rows)
}

/// Why SQLite could not open or write the journal at `path` (it says only "unable to open
/// database file"): the file system's own answer for the folder and the file, else
/// SQLite's words (`e`).
fn why_unopenable(path: &Path, e: &rusqlite::Error) -> String {
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if path.is_dir() {
        return format!("{} is a folder, not a journal file", path.display());
    }
    match std::fs::metadata(folder) {
        Err(err) if err.kind() == std::io::ErrorKind::NotFound => {
            return format!("its folder {} does not exist", folder.display());
        }
        Err(err) => return format!("its folder {}: {err}", folder.display()),
        Ok(m) if !m.is_dir() => return format!("{} is not a folder", folder.display()),
        Ok(_) => {}
    }
    if path.exists()
        && let Err(err) = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
    {
        return format!("cannot write it: {err}");
    }
    // The journal keeps its write-ahead log and index (`-wal`, `-shm`) beside the file.
    if let Err(err) = tempfile::tempfile_in(folder) {
        return format!(
            "cannot create files in its folder {} ({err}); the journal keeps its \
             write-ahead log beside it",
            folder.display()
        );
    }
    format!("SQLite: {e}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_journal_checkpoints_its_log_every_ten_thousand_pages() {
        let dir = tempfile::tempdir().unwrap();
        let journal = Journal::open(&dir.path().join("j.sqlite")).unwrap();
        let pages: u32 = journal
            .conn
            .query_row("PRAGMA wal_autocheckpoint", [], |r| r.get(0))
            .unwrap();
        assert_eq!(pages, WAL_CHECKPOINT_PAGES);
        assert_eq!(pages, 10_000);
    }

    /// The message of `Journal::open(path)`'s error.
    fn refusal(path: &Path) -> String {
        match Journal::open(path) {
            Ok(_) => panic!("{} opened", path.display()),
            Err(e @ JournalError::Open { .. }) => e.to_string(),
            Err(e) => panic!("{}: not an Open error: {e:?}", path.display()),
        }
    }

    #[test]
    fn a_journal_that_cannot_be_opened_says_why() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("no-such-folder");
        assert_eq!(
            refusal(&missing.join("j.sqlite")),
            format!("its folder {} does not exist", missing.display())
        );
        assert_eq!(
            refusal(dir.path()),
            format!("{} is a folder, not a journal file", dir.path().display())
        );
        let file = dir.path().join("plain-file");
        std::fs::write(&file, b"x").unwrap();
        assert_eq!(
            refusal(&file.join("j.sqlite")),
            format!("{} is not a folder", file.display())
        );
    }

    #[test]
    fn an_export_does_not_make_a_journal_of_an_empty_or_missing_file() {
        let dir = tempfile::tempdir().unwrap();
        let empty = dir.path().join("empty.sqlite");
        std::fs::write(&empty, b"").unwrap();
        let e = Journal::open_existing(&empty).unwrap_err().to_string();
        assert_eq!(
            e,
            "not a graspopt journal: the file is empty (a journal holds at least its tables)"
        );
        assert_eq!(std::fs::metadata(&empty).unwrap().len(), 0);
        let missing = dir.path().join("missing.sqlite");
        let e = Journal::open_existing(&missing).unwrap_err().to_string();
        assert_eq!(e, "there is no such file");
        assert!(!missing.exists());
        let made = dir.path().join("made.sqlite");
        drop(Journal::open(&made).unwrap());
        assert!(Journal::open_existing(&made).is_ok());
    }

    #[test]
    fn a_wrapped_error_is_said_once() {
        // In the message and not a `source()` too: `{:#}` would print it twice.
        let e = JournalError::from(rusqlite::Error::QueryReturnedNoRows);
        assert!(e.to_string().contains("no rows"), "{e}");
        assert!(std::error::Error::source(&e).is_none());
        let e = JournalError::from(std::io::Error::other("disk on fire"));
        assert_eq!(e.to_string(), "journal I/O error: disk on fire");
        assert!(std::error::Error::source(&e).is_none());
    }
}
