//! The trials' metric columns, one per entry of the metric table
//! (`graspopt_quality::metrics::TABLE`), named by its key.
//!
//! The table drives them: a journal gains the column of a metric it lacks when opened
//! (appended, so an older journal keeps its rows and reads the new metric as missing), the
//! result write sets every metric's column by name, and rows are read by column name, a
//! column the file does not have being `None`. Nothing here names a metric.

use graspopt_quality::metrics::{Kind, MetricDef, TABLE};
use rusqlite::types::{Type, Value as Sql};
use rusqlite::{Connection, Row, TransactionBehavior};

use crate::error::{JournalError, Result};
use crate::rows::{conversion_error, index};
use crate::types::{MetricValue, MetricValues};

/// The SQL type of a metric's column.
fn column_type(def: &MetricDef) -> String {
    match def.kind {
        Kind::Count => "INTEGER".to_string(),
        Kind::Flag => format!("INTEGER CHECK ({} IN (0, 1))", def.key),
        Kind::Real => "REAL".to_string(),
    }
}

/// The names of the columns of `table`.
pub(crate) fn columns(conn: &Connection, table: &str) -> Result<Vec<String>> {
    let mut stmt = conn.prepare("SELECT name FROM pragma_table_info(?1) ORDER BY cid")?;
    let names = stmt
        .query_map([table], |r| r.get::<_, String>(0))?
        .collect::<rusqlite::Result<Vec<String>>>()?;
    Ok(names)
}

/// Adds the column of every metric of the table that `trials` lacks, under the write lock
/// (another process may be adding it right now).
pub(crate) fn add_missing_columns(conn: &mut Connection) -> Result<()> {
    let missing = |conn: &Connection| -> Result<Vec<&'static MetricDef>> {
        let have = columns(conn, "trials")?;
        Ok(TABLE
            .iter()
            .filter(|d| !have.iter().any(|c| c == d.key))
            .collect())
    };
    if missing(conn)?.is_empty() {
        return Ok(());
    }
    let tx = conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
    for def in missing(&tx)? {
        tx.execute_batch(&format!(
            "ALTER TABLE trials ADD COLUMN {} {};",
            def.key,
            column_type(def)
        ))?;
    }
    tx.commit()?;
    Ok(())
}

/// `col = ?first, col = ?first+1, ...` for every metric column, in table order.
pub(crate) fn assignments(first: usize) -> String {
    TABLE
        .iter()
        .enumerate()
        .map(|(i, d)| format!("{} = ?{}", d.key, first + i))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Every real metric of `m` is finite; an error names it (`metrics.bw`).
pub(crate) fn check_finite(m: &MetricValues) -> Result<()> {
    for (key, value) in m.iter() {
        if let Some(MetricValue::Real(x)) = value
            && !x.is_finite()
        {
            return Err(JournalError::NonFinite {
                field: format!("metrics.{key}"),
            });
        }
    }
    Ok(())
}

/// The value of every metric column, in table order (all NULL without metrics). A value
/// of another kind than its metric's is refused, naming it.
pub(crate) fn sql_values(m: Option<&MetricValues>) -> Result<Vec<Sql>> {
    TABLE
        .iter()
        .map(|def| {
            let Some(v) = m.and_then(|m| m.get(def.key)) else {
                return Ok(Sql::Null);
            };
            match (def.kind, v) {
                (Kind::Count, MetricValue::Count(n)) => Ok(Sql::Integer(i64::from(n))),
                (Kind::Flag, MetricValue::Flag(b)) => Ok(Sql::Integer(i64::from(b))),
                (Kind::Real, v @ (MetricValue::Real(_) | MetricValue::Count(_))) => {
                    Ok(Sql::Real(v.as_f64()))
                }
                (kind, v) => Err(JournalError::Invalid(format!(
                    "metrics.{}: {v:?} is not a {} value",
                    def.key,
                    format!("{kind:?}").to_lowercase()
                ))),
            }
        })
        .collect()
}

/// The column `name` of `r`, `None` when NULL or when the journal has no such column.
pub(crate) fn optional<T: rusqlite::types::FromSql>(
    r: &Row<'_>,
    name: &str,
) -> rusqlite::Result<Option<T>> {
    match r.get::<_, Option<T>>(name) {
        Err(rusqlite::Error::InvalidColumnName(_)) => Ok(None),
        other => other,
    }
}

/// The metrics of a trial row, by column name: `None` when every metric column is NULL
/// (a trial without a result, or one that touched nothing).
pub(crate) fn read(r: &Row<'_>) -> rusqlite::Result<Option<MetricValues>> {
    let mut values = Vec::with_capacity(TABLE.len());
    for def in &TABLE {
        let value = match def.kind {
            Kind::Count => optional::<i64>(r, def.key)?
                .map(|n| {
                    u32::try_from(n)
                        .map_err(|e| conversion_error(index(r, def.key), Type::Integer, e))
                })
                .transpose()?
                .map(MetricValue::Count),
            Kind::Flag => optional::<bool>(r, def.key)?.map(MetricValue::Flag),
            Kind::Real => optional::<f64>(r, def.key)?.map(MetricValue::Real),
        };
        values.push((def.key.to_string(), value));
    }
    Ok(values
        .iter()
        .any(|(_, v)| v.is_some())
        .then(|| MetricValues::new(values)))
}
