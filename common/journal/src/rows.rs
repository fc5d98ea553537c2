//! Reading the journal's rows into its types.

use rusqlite::Row;
use rusqlite::types::Type;

use crate::types::{MetricValues, RunLifecycle, RunRecord, TrialRow, TrialState};

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

pub(crate) fn run_from_row(r: &Row<'_>) -> rusqlite::Result<RunRecord> {
    let names: String = r.get(3)?;
    let param_names: Vec<String> =
        serde_json::from_str(&names).map_err(|e| conversion_error(3, Type::Text, e))?;
    let status: String = r.get(4)?;
    let status = RunLifecycle::parse(&status)
        .ok_or_else(|| conversion_error(4, Type::Text, format!("unknown run status {status:?}")))?;
    Ok(RunRecord {
        run_id: r.get(0)?,
        created_ms: r.get(1)?,
        config_json: r.get(2)?,
        param_names,
        status,
    })
}

/// Reads a row selected with [`TRIAL_COLUMNS`].
pub(crate) fn trial_from_row(r: &Row<'_>) -> rusqlite::Result<TrialRow> {
    let state: String = r.get(2)?;
    let state = TrialState::parse(&state)
        .ok_or_else(|| conversion_error(2, Type::Text, format!("unknown trial state {state:?}")))?;
    let params: String = r.get(4)?;
    let params: Vec<f64> =
        serde_json::from_str(&params).map_err(|e| conversion_error(4, Type::Text, e))?;
    let metrics = match r.get::<_, Option<u32>>(11)? {
        None => None,
        Some(rank) => Some(MetricValues {
            rank,
            force_closure: r.get(12)?,
            epsilon: r.get(13)?,
            volume: r.get(14)?,
            distance: r.get(15)?,
            bw: r.get(16)?,
        }),
    };
    let forces = match r.get::<_, Option<String>>(22)? {
        None => None,
        Some(json) => {
            Some(serde_json::from_str(&json).map_err(|e| conversion_error(22, Type::Text, e))?)
        }
    };
    Ok(TrialRow {
        run_id: r.get(0)?,
        trial_id: u64_col(r, 1)?,
        state,
        attempts: r.get(3)?,
        params,
        worker: r.get(5)?,
        issued_ms: r.get(6)?,
        lease_until_ms: r.get(7)?,
        completed_ms: r.get(8)?,
        result_attempt: r.get(9)?,
        score: r.get(10)?,
        metrics,
        contacts: r.get::<_, Option<u32>>(17)?.unwrap_or(0),
        fingers_in_contact: r.get::<_, Option<u32>>(18)?.unwrap_or(0),
        cloud_points: r.get::<_, Option<u32>>(19)?.unwrap_or(0),
        details_json: r.get(20)?,
        error: r.get(21)?,
        forces,
    })
}
