//! Errors of the sensing crate's inputs. Each names the field that is wrong.

use thiserror::Error;

/// What is wrong with a fingertip surface, the sensing settings, the sensor noise or a
/// reading.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SensingError {
    /// A number is NaN or infinite.
    #[error("{field} is not finite ({value})")]
    NotFinite { field: &'static str, value: f64 },
    /// A number is finite but outside its range.
    #[error("{field} is {value}: it must be {requirement}")]
    OutOfRange {
        field: &'static str,
        value: f64,
        requirement: &'static str,
    },
}

/// `Ok` when `value` is finite, else [`SensingError::NotFinite`] naming `field`.
pub(crate) fn finite(field: &'static str, value: f64) -> Result<f64, SensingError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(SensingError::NotFinite { field, value })
    }
}

/// `Ok` when `value` is finite and `ok(value)` holds, else the error naming `field` and
/// `requirement`.
pub(crate) fn check(
    field: &'static str,
    value: f64,
    requirement: &'static str,
    ok: impl Fn(f64) -> bool,
) -> Result<(), SensingError> {
    finite(field, value)?;
    if ok(value) {
        Ok(())
    } else {
        Err(SensingError::OutOfRange {
            field,
            value,
            requirement,
        })
    }
}
