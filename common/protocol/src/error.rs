//! The errors of the protocol: a payload refused ([`DecodeError`]), a message that cannot be
//! encoded ([`EncodeError`]), a key chunk refused ([`KeyError`]) and a message whose content
//! fails its check ([`ValidationError`], which a [`DecodeError::Invalid`] carries).
//!
//! Their texts are part of the interface: tools print them, and docs/troubleshooting.md and
//! the tests quote them.

use graspopt_sensing::SensingError;

use crate::codec::MAX_PAYLOAD;

/// Why a payload was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DecodeError {
    #[error("empty {message_type} payload")]
    Empty { message_type: &'static str },
    #[error("{message_type} payload of {size} bytes is larger than the {MAX_PAYLOAD}-byte limit")]
    TooLarge {
        message_type: &'static str,
        size: usize,
    },
    #[error("{message_type} has wire version {found}, this agent speaks version {expected}")]
    WrongVersion {
        message_type: &'static str,
        found: u64,
        expected: u16,
    },
    #[error("malformed {message_type} ({format}): {detail}")]
    Malformed {
        message_type: &'static str,
        format: &'static str,
        detail: String,
    },
    #[error("invalid {message_type}: {detail}")]
    Invalid {
        message_type: &'static str,
        detail: ValidationError,
        /// The attempt the message reports on, when it names one.
        about: Option<Box<crate::messages::AttemptRef>>,
    },
}

/// Encoding failed (a message that cannot be represented, e.g. a non-finite float in JSON).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("cannot encode {message_type} as {format}: {detail}")]
pub struct EncodeError {
    pub message_type: &'static str,
    pub format: &'static str,
    pub detail: String,
}

/// A key chunk that is not valid (empty, too long or with a character outside the allowed set).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "invalid {what} {value:?}: use 1 to 64 ASCII letters, digits, '-', '_' or '.' (not starting with '.')"
)]
pub struct KeyError {
    pub what: &'static str,
    pub value: String,
}

/// A message whose content fails its check ([`crate::Message::validate`]): which message,
/// which field, what is wrong with it. It reads as the field, then the problem:
/// `fingers[1].points[2].n is not a unit normal (norm 0.5)`, `worker: invalid agent id ...`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}{}{}", .field, .problem.separator(), .problem)]
pub struct ValidationError {
    /// The type checked: the message's [`crate::Message::TYPE`] (`ContactClouds`), or the
    /// part's own name (`Pose`, `ForceAnalysis`) when a part is checked on its own.
    pub message_type: &'static str,
    /// The field, with its path in the message: `palm_pose.rotation`, `bounds[2]`,
    /// `fingertips[0].force[1]`.
    pub field: String,
    pub problem: Problem,
}

impl ValidationError {
    pub fn new(message_type: &'static str, field: impl Into<String>, problem: Problem) -> Self {
        ValidationError {
            message_type,
            field: field.into(),
            problem,
        }
    }
}

/// What is wrong with a field. The text follows the field's name.
#[derive(Debug, Clone, thiserror::Error)]
pub enum Problem {
    /// A number is NaN or infinite.
    #[error("is not finite ({0})")]
    NotFinite(f64),
    /// A text or a list that must not be empty is.
    #[error("is empty")]
    Empty,
    /// A `[lower, upper]` range with `lower >= upper`.
    #[error("is empty ({lower} >= {upper})")]
    EmptyRange { lower: f64, upper: f64 },
    /// A rotation quaternion whose norm is not 1 (within 1e-6).
    #[error("is not a unit quaternion (norm {0})")]
    NotUnitQuaternion(f64),
    /// A contact normal whose norm is not 1 (within 1e-3).
    #[error("is not a unit normal (norm {0})")]
    NotUnitNormal(f64),
    /// A number outside its range: `min_gap must be finite and >= 0, got -1`.
    #[error("must be {requirement}, got {value}")]
    OutOfRange {
        requirement: &'static str,
        value: f64,
    },
    /// A condition that does not hold: `attempt must be >= 1`.
    #[error("must be {0}")]
    Unmet(&'static str),
    /// A mesh triangle naming a vertex the mesh does not have.
    #[error("refers to a missing vertex")]
    MissingVertex,
    /// A parameter vector of the wrong dimension.
    #[error("has {len} values, not {expected}")]
    WrongLength { len: usize, expected: usize },
    /// A worker id that is not a valid key chunk.
    #[error("{0}")]
    InvalidId(KeyError),
    /// A fingertip surface the sensing crate refuses.
    #[error("{0}")]
    Surface(SensingError),
    /// A force analysis that says the least forces are unknown and gives them (`{0}`: the
    /// field that is set).
    #[error("says the least forces are unknown, yet {0} is set")]
    Contradicts(String),
}

/// Two problems are equal when they read the same, so that a refusal compares equal to itself
/// when the number it names is NaN (as it did when it was text).
impl PartialEq for Problem {
    fn eq(&self, other: &Self) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(other)
            && self.to_string() == other.to_string()
    }
}

impl Problem {
    /// What stands between the field's name and the problem's text: `": "` before another
    /// error's text (`worker: invalid agent id ...`), a space before the rest.
    fn separator(&self) -> &'static str {
        match self {
            Problem::InvalidId(_) | Problem::Surface(_) => ": ",
            _ => " ",
        }
    }
}
