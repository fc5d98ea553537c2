//! Codecs. Two encodings, told apart by the sample's declared encoding (its MIME type):
//!
//! - **bincode** (`application/x-graspopt-bincode`, the default): two bytes of wire version
//!   (little-endian `u16`), then the message in bincode 2's standard configuration (varint
//!   integers, little-endian floats, length-prefixed sequences, `Option` as a 0/1 tag).
//! - **JSON** (`application/json`): one object with the message's fields and a `"wire"` field
//!   holding the wire version.
//!
//! Decoding checks the version, refuses trailing bytes and oversized lengths, then runs the
//! message's [`Message::validate`]. Garbage in gives a [`DecodeError`], never a panic.

use serde_json::Value;

use crate::WIRE_VERSION;
pub use crate::error::{DecodeError, EncodeError};
use crate::messages::Message;

/// Largest payload accepted (64 MiB): a bound on what garbage can make a decoder allocate.
pub const MAX_PAYLOAD: usize = 64 << 20;

/// MIME type of the bincode encoding.
pub const BINCODE_MIME: &str = "application/x-graspopt-bincode";
/// MIME type of the JSON encoding.
pub const JSON_MIME: &str = "application/json";

/// A payload encoding.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Encoding {
    #[default]
    Bincode,
    Json,
}

impl Encoding {
    pub fn mime(self) -> &'static str {
        match self {
            Encoding::Bincode => BINCODE_MIME,
            Encoding::Json => JSON_MIME,
        }
    }

    /// The encoding of a declared MIME type (parameters after `;` ignored). Unknown types
    /// (including none) are taken as bincode, the default.
    pub fn from_mime(mime: &str) -> Encoding {
        let base = mime.split(';').next().unwrap_or("").trim();
        match base {
            "application/json" | "text/json" => Encoding::Json,
            _ => Encoding::Bincode,
        }
    }
}

fn bincode_config() -> impl bincode::config::Config {
    bincode::config::standard().with_limit::<MAX_PAYLOAD>()
}

/// A bincode body (after the wire version) as a `T`, and the bytes it took.
pub(crate) fn decode_bincode_body<T: serde::de::DeserializeOwned>(
    body: &[u8],
) -> Result<(T, usize), bincode::error::DecodeError> {
    bincode::serde::decode_from_slice::<T, _>(body, bincode_config())
}

/// Encodes a message.
pub fn encode<T: Message>(msg: &T, encoding: Encoding) -> Result<Vec<u8>, EncodeError> {
    match encoding {
        Encoding::Bincode => {
            let err = |e: bincode::error::EncodeError| EncodeError {
                message_type: T::TYPE,
                format: "bincode",
                detail: e.to_string(),
            };
            // Sized by a first pass, then written once: `encode_to_vec` grew its vector by
            // doubling (each growth a copy under mimalloc) and the body was copied again
            // after the wire version (`graspopt bench clouds`, encoding 10,000 points).
            let mut size = bincode::enc::write::SizeWriter::default();
            bincode::serde::encode_into_writer(msg, &mut size, bincode_config()).map_err(err)?;
            let version = WIRE_VERSION.to_le_bytes();
            let mut out = Vec::with_capacity(version.len() + size.bytes_written);
            out.extend_from_slice(&version);
            bincode::serde::encode_into_std_write(msg, &mut out, bincode_config()).map_err(err)?;
            Ok(out)
        }
        Encoding::Json => {
            let err = |detail: String| EncodeError {
                message_type: T::TYPE,
                format: "json",
                detail,
            };
            let mut value = serde_json::to_value(msg).map_err(|e| err(e.to_string()))?;
            let Value::Object(map) = &mut value else {
                return Err(err("a message must encode as a JSON object".into()));
            };
            map.insert("wire".into(), Value::from(WIRE_VERSION));
            serde_json::to_vec(&value).map_err(|e| err(e.to_string()))
        }
    }
}

/// Decodes and validates a message.
pub fn decode<T: Message>(bytes: &[u8], encoding: Encoding) -> Result<T, DecodeError> {
    let message_type = T::TYPE;
    if bytes.is_empty() {
        return Err(DecodeError::Empty { message_type });
    }
    if bytes.len() > MAX_PAYLOAD {
        return Err(DecodeError::TooLarge {
            message_type,
            size: bytes.len(),
        });
    }
    let msg: T = match encoding {
        Encoding::Bincode => {
            let malformed = |detail: String| DecodeError::Malformed {
                message_type,
                format: "bincode",
                detail,
            };
            let [a, b, body @ ..] = bytes else {
                return Err(malformed("shorter than the 2-byte wire version".into()));
            };
            let version = u16::from_le_bytes([*a, *b]);
            if version != WIRE_VERSION {
                return Err(DecodeError::WrongVersion {
                    message_type,
                    found: u64::from(version),
                    expected: WIRE_VERSION,
                });
            }
            let (msg, read) = match decode_bincode_body::<T>(body) {
                Ok(decoded) => decoded,
                Err(e) => T::decode_older(body)
                    .filter(|(_, read)| *read == body.len())
                    .ok_or_else(|| malformed(e.to_string()))?,
            };
            if read != body.len() {
                return Err(malformed(format!(
                    "{} trailing bytes after the message",
                    body.len() - read
                )));
            }
            msg
        }
        Encoding::Json => {
            let malformed = |detail: String| DecodeError::Malformed {
                message_type,
                format: "json",
                detail,
            };
            let mut value: Value =
                serde_json::from_slice(bytes).map_err(|e| malformed(e.to_string()))?;
            let Value::Object(map) = &mut value else {
                return Err(malformed("not a JSON object".into()));
            };
            let version = map
                .remove("wire")
                .ok_or_else(|| malformed("missing \"wire\" (the wire version)".into()))?;
            let version = version
                .as_u64()
                .ok_or_else(|| malformed(format!("\"wire\" is not a version number: {version}")))?;
            if version != u64::from(WIRE_VERSION) {
                return Err(DecodeError::WrongVersion {
                    message_type,
                    found: version,
                    expected: WIRE_VERSION,
                });
            }
            serde_json::from_value(value).map_err(|e| malformed(e.to_string()))?
        }
    };
    msg.validate().map_err(|detail| DecodeError::Invalid {
        message_type,
        detail,
        about: msg.attempt_ref().map(Box::new),
    })?;
    Ok(msg)
}

/// What a query carries: a message, or nothing (`()`, the coordinator's state query).
pub trait Request: Sized {
    /// The request in a query's payload (`None`: the query had none).
    fn from_payload(payload: Option<&[u8]>, encoding: Encoding) -> Result<Self, DecodeError>;
}

impl<M: Message> Request for M {
    fn from_payload(payload: Option<&[u8]>, encoding: Encoding) -> Result<Self, DecodeError> {
        match payload {
            Some(bytes) => decode(bytes, encoding),
            None => Err(DecodeError::Empty {
                message_type: M::TYPE,
            }),
        }
    }
}

impl Request for () {
    fn from_payload(_: Option<&[u8]>, _: Encoding) -> Result<Self, DecodeError> {
        Ok(())
    }
}

/// Decodes (and validates) the message a topic carries, as JSON for display: what
/// `graspopt topic echo` prints. The JSON is the message's fields, without the wire version.
pub fn decode_topic(
    topic: crate::Topic,
    bytes: &[u8],
    encoding: Encoding,
) -> Result<Value, DecodeError> {
    (topic.decode_json())(bytes, encoding)
}

/// Decodes (and validates) a `T`, as JSON: a topic's decoder for [`decode_topic`].
pub(crate) fn decode_json<T: Message>(
    bytes: &[u8],
    encoding: Encoding,
) -> Result<Value, DecodeError> {
    let msg = decode::<T>(bytes, encoding)?;
    serde_json::to_value(&msg).map_err(|e| DecodeError::Malformed {
        message_type: T::TYPE,
        format: "json",
        detail: e.to_string(),
    })
}
