//! The database layout, its version, and the check made at open.

use rusqlite::{Connection, TransactionBehavior};

use crate::error::{JournalError, Result};

/// The schema version stored in `PRAGMA user_version`.
pub const SCHEMA_VERSION: i64 = 3;

/// The current layout: version 1 ([`DDL_V1`]) and what each later version added
/// ([`DDL_V2_ADDITIONS`], [`DDL_V3_ADDITIONS`]).
pub(crate) fn ddl() -> String {
    format!("{DDL_V1}{DDL_V2_ADDITIONS}{DDL_V3_ADDITIONS}")
}

/// Version 3 adds each trial's contact-force analysis (`TrialResult::forces`, JSON). An
/// older journal is upgraded in place when opened; its trials have none.
pub(crate) const DDL_V3_ADDITIONS: &str = "
ALTER TABLE trials ADD COLUMN forces_json TEXT;
";

/// What upgrades a journal of version `from` to the next version.
fn additions_after(from: i64) -> Option<&'static str> {
    match from {
        1 => Some(DDL_V2_ADDITIONS),
        2 => Some(DDL_V3_ADDITIONS),
        _ => None,
    }
}

/// Version 2 adds the planner's engine state per run (opaque bytes the planner replies
/// with; the coordinator sends them back so that a new planner continues exactly). A
/// version-1 journal is upgraded in place when opened.
pub(crate) const DDL_V2_ADDITIONS: &str = "
CREATE TABLE planner_state (
    run_id     TEXT    NOT NULL PRIMARY KEY REFERENCES runs (run_id),
    state      BLOB    NOT NULL,
    updated_ms INTEGER NOT NULL
) STRICT;
";

/// Version 1 of the layout. Tables are STRICT, so a value of the wrong type
/// is refused by SQLite itself rather than stored silently.
pub(crate) const DDL_V1: &str = "
CREATE TABLE runs (
    run_id      TEXT    NOT NULL PRIMARY KEY,
    created_ms  INTEGER NOT NULL,
    config_json TEXT    NOT NULL,
    param_names TEXT    NOT NULL,
    status      TEXT    NOT NULL CHECK (status IN ('running', 'finished', 'stopped')),
    status_ms   INTEGER NOT NULL
) STRICT;

CREATE TABLE trials (
    run_id             TEXT    NOT NULL REFERENCES runs (run_id),
    trial_id           INTEGER NOT NULL CHECK (trial_id >= 0),
    state              TEXT    NOT NULL CHECK (state IN ('running', 'completed', 'failed')),
    attempts           INTEGER NOT NULL CHECK (attempts >= 1),
    params             TEXT    NOT NULL,
    worker             TEXT    NOT NULL,
    issued_ms          INTEGER NOT NULL,
    lease_until_ms     INTEGER NOT NULL,
    completed_ms       INTEGER,
    result_attempt     INTEGER,
    score              REAL,
    rank               INTEGER,
    force_closure      INTEGER CHECK (force_closure IN (0, 1)),
    epsilon            REAL,
    volume             REAL,
    distance           REAL,
    bw                 REAL,
    contacts           INTEGER,
    fingers_in_contact INTEGER,
    cloud_points       INTEGER,
    details_json       TEXT,
    error              TEXT,
    PRIMARY KEY (run_id, trial_id),
    CHECK ((state = 'completed') = (score IS NOT NULL AND completed_ms IS NOT NULL)),
    CHECK ((state = 'failed') = (error IS NOT NULL))
) STRICT;

CREATE INDEX trials_by_score ON trials (run_id, state, score);

CREATE TABLE events (
    seq      INTEGER PRIMARY KEY AUTOINCREMENT,
    run_id   TEXT    NOT NULL,
    trial_id INTEGER NOT NULL,
    attempt  INTEGER NOT NULL,
    kind     TEXT    NOT NULL
             CHECK (kind IN ('issued', 'reissued', 'result', 'duplicate', 'failed')),
    worker   TEXT    NOT NULL,
    at_ms    INTEGER NOT NULL,
    note     TEXT,
    FOREIGN KEY (run_id, trial_id) REFERENCES trials (run_id, trial_id)
) STRICT;

CREATE INDEX events_by_run ON events (run_id, seq);
";

/// The columns each table must have, in order. `trials` may have more: the columns of
/// metrics of the metric table that version 1 did not have (see `metrics.rs`).
const LAYOUT: &[(&str, &[&str])] = &[
    (
        "runs",
        &[
            "run_id",
            "created_ms",
            "config_json",
            "param_names",
            "status",
            "status_ms",
        ],
    ),
    (
        "trials",
        &[
            "run_id",
            "trial_id",
            "state",
            "attempts",
            "params",
            "worker",
            "issued_ms",
            "lease_until_ms",
            "completed_ms",
            "result_attempt",
            "score",
            "rank",
            "force_closure",
            "epsilon",
            "volume",
            "distance",
            "bw",
            "contacts",
            "fingers_in_contact",
            "cloud_points",
            "details_json",
            "error",
            "forces_json",
        ],
    ),
    (
        "events",
        &[
            "seq", "run_id", "trial_id", "attempt", "kind", "worker", "at_ms", "note",
        ],
    ),
    ("planner_state", &["run_id", "state", "updated_ms"]),
];

fn user_version(conn: &Connection) -> Result<i64> {
    Ok(conn.query_row("PRAGMA user_version", [], |r| r.get(0))?)
}

/// Creates the schema in an empty database, upgrades a version-1 one, or checks an
/// existing one.
pub(crate) fn ensure(conn: &mut Connection) -> Result<()> {
    match user_version(conn)? {
        0 => create(conn),
        SCHEMA_VERSION => check_layout(conn),
        found if additions_after(found).is_some() => upgrade(conn, found),
        found => Err(JournalError::SchemaVersion {
            found,
            expected: SCHEMA_VERSION,
        }),
    }
}

/// Upgrades a journal of version `from` by one version (what that version added, nothing
/// else changed), under the write lock: another process may be upgrading the same journal
/// right now. Then looks again, up to the current version.
fn upgrade(conn: &mut Connection, from: i64) -> Result<()> {
    let tx = conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
    match additions_after(from) {
        Some(ddl) if user_version(&tx)? == from => {
            tx.execute_batch(ddl)?;
            tx.pragma_update(None, "user_version", from + 1)?;
            tx.commit()?;
        }
        _ => drop(tx),
    }
    // Upgraded here or by the other process: checked (or upgraded further) as any other.
    ensure(conn)
}

fn create(conn: &mut Connection) -> Result<()> {
    // Take the write lock first and look again: another process may be
    // creating the same journal right now.
    let tx = conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
    match user_version(&tx)? {
        0 => {}
        SCHEMA_VERSION => {
            drop(tx);
            return check_layout(conn);
        }
        found => {
            return Err(JournalError::SchemaVersion {
                found,
                expected: SCHEMA_VERSION,
            });
        }
    }
    let objects: i64 = tx.query_row("SELECT count(*) FROM sqlite_schema", [], |r| r.get(0))?;
    if objects != 0 {
        return Err(JournalError::Schema(format!(
            "the database holds {objects} schema objects but no journal schema version"
        )));
    }
    tx.execute_batch(&ddl())?;
    tx.pragma_update(None, "user_version", SCHEMA_VERSION)?;
    tx.commit()?;
    Ok(())
}

fn check_layout(conn: &Connection) -> Result<()> {
    for (table, expected) in LAYOUT {
        let found = crate::metrics::columns(conn, table)?;
        if found.is_empty() {
            return Err(JournalError::Schema(format!("table {table} is missing")));
        }
        // Besides the layout's, trials may have metric columns (anywhere: an upgrade appends
        // the columns of its version after them).
        let added_metric = |c: &&String| {
            *table == "trials"
                && !expected.contains(&c.as_str())
                && graspopt_quality::metrics::Metric::from_key(c).is_some()
        };
        let known = found
            .iter()
            .filter(|c| !added_metric(c))
            .map(String::as_str);
        if !known.eq(expected.iter().copied()) {
            return Err(JournalError::Schema(format!(
                "table {table} has columns {found:?}, expected {expected:?}"
            )));
        }
    }
    Ok(())
}
