//! The journal's writes inside a transaction: issues, results, failures and planner state.
//! [`crate::Journal`]'s methods and [`crate::batch`] call them with their transaction.

use rusqlite::types::Value as Sql;
use rusqlite::{Connection, OptionalExtension, params};

use crate::error::{JournalError, Result};
use crate::types::{ResultOutcome, ResultRow, StoredTrialPhase, TrialIssue, event_kind};

/// Completes a trial with its result: the fixed columns, then every metric's column
/// ([`crate::metrics::assignments`]) from parameter 12 on.
static COMPLETE_TRIAL: std::sync::LazyLock<String> = std::sync::LazyLock::new(|| {
    format!(
        "UPDATE trials SET state = 'completed', worker = ?3, completed_ms = ?4,
             result_attempt = ?5, score = ?6, contacts = ?7, fingers_in_contact = ?8,
             cloud_points = ?9, details_json = ?10, forces_json = ?11, {}
         WHERE run_id = ?1 AND trial_id = ?2",
        crate::metrics::assignments(12)
    )
});

pub(crate) fn planner_state_in(
    tx: &Connection,
    run_id: &str,
    state: &[u8],
    at_ms: i64,
) -> Result<()> {
    let known: bool = tx
        .prepare_cached("SELECT EXISTS (SELECT 1 FROM runs WHERE run_id = ?1)")?
        .query_row(params![run_id], |r| r.get(0))?;
    if !known {
        return Err(JournalError::UnknownRun(run_id.to_string()));
    }
    tx.prepare_cached(
        "INSERT INTO planner_state (run_id, state, updated_ms) VALUES (?1, ?2, ?3)
         ON CONFLICT (run_id) DO UPDATE SET state = excluded.state,
                                            updated_ms = excluded.updated_ms",
    )?
    .execute(params![run_id, state, at_ms])?;
    Ok(())
}

pub(crate) fn issue_in(tx: &Connection, issue: &TrialIssue) -> Result<()> {
    for (i, p) in issue.params.iter().enumerate() {
        check_finite(|| format!("params[{i}]"), *p)?;
    }
    let id = db_id(issue.trial_id)?;
    check_param_count(tx, issue)?;
    let existing: Option<(String, u32, String)> = tx
        .prepare_cached(
            "SELECT state, attempts, params FROM trials WHERE run_id = ?1 AND trial_id = ?2",
        )?
        .query_row(params![issue.run_id, id], |r| {
            Ok((r.get(0)?, r.get(1)?, r.get(2)?))
        })
        .optional()?;
    match existing {
        None => first_issue(tx, issue, id),
        Some((state, attempts, stored)) => reissue(tx, issue, id, &state, attempts, &stored),
    }
}

/// The run is known and has as many parameter names as the issue has parameters.
fn check_param_count(tx: &Connection, issue: &TrialIssue) -> Result<()> {
    let names: Option<String> = tx
        .prepare_cached("SELECT param_names FROM runs WHERE run_id = ?1")?
        .query_row([&issue.run_id], |r| r.get(0))
        .optional()?;
    let Some(names) = names else {
        return Err(JournalError::UnknownRun(issue.run_id.clone()));
    };
    let names: Vec<String> = serde_json::from_str(&names)?;
    if names.len() != issue.params.len() {
        return Err(JournalError::ParamCount {
            run_id: issue.run_id.clone(),
            trial_id: issue.trial_id,
            expected: names.len(),
            found: issue.params.len(),
        });
    }
    Ok(())
}

/// Attempt 1 of a new trial: its row and its `issued` event.
fn first_issue(tx: &Connection, issue: &TrialIssue, id: i64) -> Result<()> {
    if issue.attempt != 1 {
        return Err(JournalError::AttemptMismatch {
            run_id: issue.run_id.clone(),
            trial_id: issue.trial_id,
            expected: 1,
            found: issue.attempt,
        });
    }
    tx.prepare_cached(
        "INSERT INTO trials (run_id, trial_id, state, attempts, params, worker,
                             issued_ms, lease_until_ms)
         VALUES (?1, ?2, 'running', 1, ?3, ?4, ?5, ?6)",
    )?
    .execute(params![
        issue.run_id,
        id,
        serde_json::to_string(&issue.params)?,
        issue.worker,
        issue.at_ms,
        issue.lease_until_ms
    ])?;
    issue_event(tx, issue, id, event_kind::ISSUED)
}

/// The next attempt of a running trial, with the same parameters: its new worker and lease,
/// and its `reissued` event.
fn reissue(
    tx: &Connection,
    issue: &TrialIssue,
    id: i64,
    state: &str,
    attempts: u32,
    stored_params: &str,
) -> Result<()> {
    let state = parse_state(state)?;
    if state != StoredTrialPhase::Running {
        return Err(JournalError::TrialClosed {
            run_id: issue.run_id.clone(),
            trial_id: issue.trial_id,
            state,
        });
    }
    let expected = attempts.saturating_add(1);
    if issue.attempt != expected {
        return Err(JournalError::AttemptMismatch {
            run_id: issue.run_id.clone(),
            trial_id: issue.trial_id,
            expected,
            found: issue.attempt,
        });
    }
    let stored: Vec<f64> = serde_json::from_str(stored_params)?;
    if !same_bits(&stored, &issue.params) {
        return Err(JournalError::ParamsMismatch {
            run_id: issue.run_id.clone(),
            trial_id: issue.trial_id,
        });
    }
    tx.prepare_cached(
        "UPDATE trials SET attempts = ?3, worker = ?4, lease_until_ms = ?5
         WHERE run_id = ?1 AND trial_id = ?2",
    )?
    .execute(params![
        issue.run_id,
        id,
        issue.attempt,
        issue.worker,
        issue.lease_until_ms
    ])?;
    issue_event(tx, issue, id, event_kind::REISSUED)
}

/// The `issued` or `reissued` event of `issue`, its reason as the note.
fn issue_event(tx: &Connection, issue: &TrialIssue, id: i64, kind: &str) -> Result<()> {
    insert_event(
        tx,
        &issue.run_id,
        id,
        issue.attempt,
        kind,
        &issue.worker,
        issue.at_ms,
        issue.reason.as_deref(),
    )
}

pub(crate) fn result_in(tx: &Connection, result: &ResultRow) -> Result<ResultOutcome> {
    check_finite(|| "score".to_string(), result.score)?;
    if let Some(m) = &result.metrics {
        crate::metrics::check_finite(m)?;
    }
    if let Some(f) = &result.forces {
        f.validate("forces")
            .map_err(|e| JournalError::Invalid(e.to_string()))?;
    }
    let Ok(id) = db_id(result.trial_id) else {
        return Ok(ResultOutcome::UnknownTrial);
    };
    let existing: Option<(String, u32, Option<u32>)> = tx
        .prepare_cached(
            "SELECT state, attempts, result_attempt FROM trials
             WHERE run_id = ?1 AND trial_id = ?2",
        )?
        .query_row(params![result.run_id, id], |r| {
            Ok((r.get(0)?, r.get(1)?, r.get(2)?))
        })
        .optional()?;
    let Some((state, attempts, result_attempt)) = existing else {
        return Ok(ResultOutcome::UnknownTrial);
    };
    match parse_state(&state)? {
        StoredTrialPhase::Completed | StoredTrialPhase::Failed => {
            let note = match result_attempt {
                Some(a) => format!("trial already completed by attempt {a}"),
                None => "trial already failed".to_string(),
            };
            result_event(tx, result, id, event_kind::DUPLICATE, Some(&note))?;
            Ok(ResultOutcome::Duplicate)
        }
        StoredTrialPhase::Running => {
            complete(tx, result, id, attempts)?;
            Ok(ResultOutcome::Accepted)
        }
    }
}

/// Completes a running trial with `result` (its latest attempt is `attempts`): the result's
/// columns and the `result` event, whose note says when the attempt is not the latest.
fn complete(tx: &Connection, result: &ResultRow, id: i64, attempts: u32) -> Result<()> {
    let note = if result.attempt < attempts {
        Some(format!(
            "late result from attempt {} (latest attempt {attempts})",
            result.attempt
        ))
    } else if result.attempt > attempts {
        Some(format!(
            "result from attempt {} which was never issued (latest attempt {attempts})",
            result.attempt
        ))
    } else {
        None
    };
    let forces_json = match &result.forces {
        Some(f) => Some(serde_json::to_string(f)?),
        None => None,
    };
    let mut values: Vec<Sql> = vec![
        result.run_id.clone().into(),
        id.into(),
        result.worker.clone().into(),
        result.at_ms.into(),
        result.attempt.into(),
        result.score.into(),
        result.contacts.into(),
        result.fingers_in_contact.into(),
        result.cloud_points.into(),
        result.details_json.clone().into(),
        forces_json.into(),
    ];
    values.extend(crate::metrics::sql_values(result.metrics.as_ref())?);
    tx.prepare_cached(&COMPLETE_TRIAL)?
        .execute(rusqlite::params_from_iter(values))?;
    result_event(tx, result, id, event_kind::RESULT, note.as_deref())
}

/// The `result` or `duplicate` event of `result`.
fn result_event(
    tx: &Connection,
    result: &ResultRow,
    id: i64,
    kind: &str,
    note: Option<&str>,
) -> Result<()> {
    insert_event(
        tx,
        &result.run_id,
        id,
        result.attempt,
        kind,
        &result.worker,
        result.at_ms,
        note,
    )
}

pub(crate) fn failure_in(
    tx: &Connection,
    run_id: &str,
    trial_id: u64,
    attempt: u32,
    message: &str,
    at_ms: i64,
) -> Result<bool> {
    let Ok(id) = db_id(trial_id) else {
        return Ok(false);
    };
    let existing: Option<(String, String)> = tx
        .prepare_cached("SELECT state, worker FROM trials WHERE run_id = ?1 AND trial_id = ?2")?
        .query_row(params![run_id, id], |r| Ok((r.get(0)?, r.get(1)?)))
        .optional()?;
    let Some((state, worker)) = existing else {
        return Ok(false);
    };
    if parse_state(&state)? != StoredTrialPhase::Running {
        return Ok(false);
    }
    tx.prepare_cached(
        "UPDATE trials SET state = 'failed', error = ?3 WHERE run_id = ?1 AND trial_id = ?2",
    )?
    .execute(params![run_id, id, message])?;
    insert_event(
        tx,
        run_id,
        id,
        attempt,
        event_kind::FAILED,
        &worker,
        at_ms,
        Some(message),
    )?;
    Ok(true)
}

pub(crate) fn db_id(trial_id: u64) -> Result<i64> {
    i64::try_from(trial_id).map_err(|_| JournalError::TrialIdRange(trial_id))
}

fn check_finite(field: impl FnOnce() -> String, v: f64) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(JournalError::NonFinite { field: field() })
    }
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

pub(crate) fn parse_state(s: &str) -> Result<StoredTrialPhase> {
    StoredTrialPhase::parse(s)
        .ok_or_else(|| JournalError::Schema(format!("unknown trial state {s:?} in the database")))
}

#[allow(clippy::too_many_arguments)]
fn insert_event(
    conn: &Connection,
    run_id: &str,
    trial_id: i64,
    attempt: u32,
    kind: &str,
    worker: &str,
    at_ms: i64,
    note: Option<&str>,
) -> Result<()> {
    let mut stmt = conn.prepare_cached(
        "INSERT INTO events (run_id, trial_id, attempt, kind, worker, at_ms, note)
         VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)",
    )?;
    stmt.execute(params![
        run_id, trial_id, attempt, kind, worker, at_ms, note
    ])?;
    Ok(())
}
