//! A run's trials as CSV (one row per trial) or JSON (`{"run": .., "trials": [..]}`).

use std::borrow::Cow;
use std::io::Write;

use crate::error::Result;
use crate::journal::Journal;
use crate::types::{MetricValue, TrialRow};
use graspopt_quality::metrics::TABLE;

/// The columns after the metric columns.
const RESULT_COLUMNS: [&str; 10] = [
    "contacts",
    "fingers_in_contact",
    "cloud_points",
    "can_resist",
    "resisting_force",
    "resisting_max",
    "net_force",
    "min_slip_margin",
    "forces_unavailable",
    "error",
];

/// Writes the run's trials as CSV, one row per trial by trial id.
///
/// Header: `trial,state,attempts,worker,issued_ms,completed_ms,<param
/// names...>,score,<metric keys...>,contacts,
/// fingers_in_contact,cloud_points,can_resist,resisting_force,resisting_max,net_force,
/// min_slip_margin,forces_unavailable,error`. The metric columns are the metric table's keys
/// in its order (`rank,force_closure,epsilon,volume,distance,bw,...`), without an optional
/// metric's when no trial has it (`volume`: only runs scored by the volume compute it). The force columns come from the result's force
/// analysis ([`crate::ForceAnalysis`]): whether forces in the friction cones can resist the
/// object's weight, the 2-norm of the least such forces over all contacts and the largest at
/// one contact (N), and for hands that measure forces the net measured force (N) and the
/// smallest slip margin (N); when the least forces are unavailable (the solver found no
/// answer) the first three are empty and `forces_unavailable` says why. A missing value (`None`)
/// is an empty field, and so are the result columns of a trial without a
/// result. Numbers are written
/// so that they parse back to the same f64. Fields containing a comma, a
/// double quote, CR or LF are quoted per RFC 4180; lines end with `\n`.
/// An unknown run is [`crate::JournalError::UnknownRun`].
pub fn write_csv(journal: &Journal, run_id: &str, out: &mut dyn Write) -> Result<()> {
    let export = journal.export(run_id)?;
    let mut header: Vec<&str> = vec![
        "trial",
        "state",
        "attempts",
        "worker",
        "issued_ms",
        "completed_ms",
    ];
    header.extend(export.run.param_names.iter().map(String::as_str));
    header.push("score");
    let metrics = metric_columns(&export.trials);
    header.extend(metrics.iter().copied());
    header.extend(RESULT_COLUMNS);
    let mut line = String::new();
    push_record(&mut line, header.iter().map(|h| Cow::Borrowed(*h)));
    out.write_all(line.as_bytes())?;
    for trial in &export.trials {
        line.clear();
        push_record(&mut line, trial_fields(trial, &metrics));
        out.write_all(line.as_bytes())?;
    }
    out.flush()?;
    Ok(())
}

/// Writes `{"run": RunRow, "trials": [TrialRow, ...]}` as pretty JSON
/// (a [`crate::RunExport`]); an unknown run is [`crate::JournalError::UnknownRun`].
pub fn write_json(journal: &Journal, run_id: &str, out: &mut dyn Write) -> Result<()> {
    let export = journal.export(run_id)?;
    serde_json::to_writer_pretty(&mut *out, &export)?;
    out.write_all(b"\n")?;
    out.flush()?;
    Ok(())
}

fn num<T: std::fmt::Debug>(v: T) -> Cow<'static, str> {
    // Debug of f64 is the shortest text that parses back to the same value
    // (with an exponent for very large or small magnitudes); for integers it
    // is the plain number.
    Cow::Owned(format!("{v:?}"))
}

fn opt<T: std::fmt::Debug>(v: Option<T>) -> Cow<'static, str> {
    v.map_or(Cow::Borrowed(""), num)
}

/// The metric columns of the CSV: every metric of the table, an optional one only if a
/// trial has it.
fn metric_columns(trials: &[TrialRow]) -> Vec<&'static str> {
    let has = |key: &str| {
        trials
            .iter()
            .any(|t| t.metrics.as_ref().is_some_and(|m| m.get(key).is_some()))
    };
    TABLE
        .iter()
        .filter(|d| !d.optional || has(d.key))
        .map(|d| d.key)
        .collect()
}

fn metric_field(v: Option<MetricValue>) -> Cow<'static, str> {
    match v {
        None => Cow::Borrowed(""),
        Some(MetricValue::Count(n)) => num(n),
        Some(MetricValue::Flag(b)) => num(b),
        Some(MetricValue::Real(x)) => num(x),
    }
}

/// The CSV fields of `t`, with the metric fields of `metrics`.
fn trial_fields<'a>(t: &'a TrialRow, metrics: &[&str]) -> Vec<Cow<'a, str>> {
    let mut f: Vec<Cow<'_, str>> = vec![
        num(t.trial_id),
        Cow::Borrowed(t.state.as_str()),
        num(t.attempts),
        Cow::Borrowed(t.worker.as_str()),
        num(t.issued_ms),
        opt(t.completed_ms),
    ];
    f.extend(t.params.iter().map(|p| num(*p)));
    let m = t.metrics.as_ref();
    let has_result = t.score.is_some();
    f.push(opt(t.score));
    f.extend(
        metrics
            .iter()
            .map(|key| metric_field(m.and_then(|m| m.get(key)))),
    );
    f.push(opt(has_result.then_some(t.contacts)));
    f.push(opt(has_result.then_some(t.fingers_in_contact)));
    f.push(opt(has_result.then_some(t.cloud_points)));
    let forces = t.forces.as_ref();
    f.push(opt(forces.and_then(|a| a.can_resist())));
    f.push(opt(forces.and_then(|a| a.resisting_norm)));
    f.push(opt(forces.and_then(|a| a.resisting_max)));
    f.push(opt(forces.and_then(|a| a.net_force())));
    f.push(opt(forces.and_then(|a| a.min_slip_margin())));
    f.push(
        forces
            .and_then(|a| a.unavailable.as_deref())
            .map_or(Cow::Borrowed(""), Cow::Borrowed),
    );
    f.push(t.error.as_deref().map_or(Cow::Borrowed(""), Cow::Borrowed));
    f
}

/// Appends one CSV record (with its line end) to `line`.
fn push_record<'a>(line: &mut String, fields: impl IntoIterator<Item = Cow<'a, str>>) {
    for (i, field) in fields.into_iter().enumerate() {
        if i > 0 {
            line.push(',');
        }
        push_field(line, &field);
    }
    line.push('\n');
}

fn push_field(line: &mut String, field: &str) {
    if field.contains([',', '"', '\r', '\n']) {
        line.push('"');
        for c in field.chars() {
            if c == '"' {
                line.push('"');
            }
            line.push(c);
        }
        line.push('"');
    } else {
        line.push_str(field);
    }
}
