//! Reading the journal's rows into its types.

use rusqlite::Row;
use rusqlite::types::Type;

use crate::types::{RunRow, StoredRunPhase, StoredTrialPhase, TrialRow};

pub(crate) fn conversion_error(
    idx: usize,
    ty: Type,
    err: impl Into<Box<dyn std::error::Error + Send + Sync>>,
) -> rusqlite::Error {
    rusqlite::Error::FromSqlConversionFailure(idx, ty, err.into())
}

pub(crate) fn u64_col(r: &Row<'_>, idx: usize) -> rusqlite::Result<u64> {
    let v: i64 = r.get(idx)?;
    u64::try_from(v).map_err(|e| conversion_error(idx, Type::Integer, e))
}

pub(crate) fn run_from_row(r: &Row<'_>) -> rusqlite::Result<RunRow> {
    let names: String = r.get(3)?;
    let param_names: Vec<String> =
        serde_json::from_str(&names).map_err(|e| conversion_error(3, Type::Text, e))?;
    let status: String = r.get(4)?;
    let status = StoredRunPhase::parse(&status)
        .ok_or_else(|| conversion_error(4, Type::Text, format!("unknown run status {status:?}")))?;
    Ok(RunRow {
        run_id: r.get(0)?,
        created_ms: r.get(1)?,
        config_json: r.get(2)?,
        param_names,
        status,
    })
}

/// The index of the column `name` of `r` (for an error's message).
pub(crate) fn index(r: &Row<'_>, name: &str) -> usize {
    r.as_ref().column_index(name).unwrap_or(0)
}

/// Reads a trial row (`SELECT * FROM trials`) by column name.
pub(crate) fn trial_from_row(r: &Row<'_>) -> rusqlite::Result<TrialRow> {
    let at = |name| index(r, name);
    let state: String = r.get("state")?;
    let state = StoredTrialPhase::parse(&state).ok_or_else(|| {
        conversion_error(
            at("state"),
            Type::Text,
            format!("unknown trial state {state:?}"),
        )
    })?;
    let params: String = r.get("params")?;
    let params: Vec<f64> =
        serde_json::from_str(&params).map_err(|e| conversion_error(at("params"), Type::Text, e))?;
    let forces = match r.get::<_, Option<String>>("forces_json")? {
        None => None,
        Some(json) => {
            let e = |e| conversion_error(at("forces_json"), Type::Text, e);
            Some(serde_json::from_str(&json).map_err(e)?)
        }
    };
    let count =
        |name: &str| Ok::<u32, rusqlite::Error>(r.get::<_, Option<u32>>(name)?.unwrap_or(0));
    let trial_id: i64 = r.get("trial_id")?;
    Ok(TrialRow {
        run_id: r.get("run_id")?,
        trial_id: u64::try_from(trial_id)
            .map_err(|e| conversion_error(at("trial_id"), Type::Integer, e))?,
        state,
        attempts: r.get("attempts")?,
        params,
        worker: r.get("worker")?,
        issued_ms: r.get("issued_ms")?,
        lease_until_ms: r.get("lease_until_ms")?,
        completed_ms: r.get("completed_ms")?,
        result_attempt: r.get("result_attempt")?,
        score: r.get("score")?,
        metrics: crate::metrics::read(r)?,
        contacts: count("contacts")?,
        fingers_in_contact: count("fingers_in_contact")?,
        cloud_points: count("cloud_points")?,
        details_json: r.get("details_json")?,
        error: r.get("error")?,
        forces,
    })
}
