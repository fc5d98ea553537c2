//! Shared by the message targets. An input is one selector byte, then the payload: an even
//! selector decodes the payload as bincode, an odd one as JSON.
//!
//! Checked for every input: decoding never panics. For every payload that decodes:
//! - re-encoding in the same encoding and decoding again gives an equal message;
//! - a message decoded from JSON re-encodes as bincode and decodes back equal;
//! - a message decoded from bincode re-encodes as JSON and decodes back equal, unless it holds
//!   a non-finite float that its type's validation allows (JSON has no NaN or infinity: such a
//!   message must then be refused cleanly, which "never panics" covers).
#![allow(dead_code)]

use std::fmt::Debug;

use graspopt_protocol::{Encoding, Message, decode, encode};

/// The encoding the selector byte picks, and the payload.
pub fn split(data: &[u8]) -> Option<(Encoding, &[u8])> {
    let (&selector, payload) = data.split_first()?;
    let encoding = if selector & 1 == 0 {
        Encoding::Bincode
    } else {
        Encoding::Json
    };
    Some((encoding, payload))
}

/// Equal messages. bincode writes floats bit for bit, so equal bincode bytes also make two
/// messages holding NaN (never `==` to itself) the same.
fn same<T: Message + PartialEq>(a: &T, b: &T) -> bool {
    a == b
        || matches!(
            (encode(a, Encoding::Bincode), encode(b, Encoding::Bincode)),
            (Ok(x), Ok(y)) if x == y
        )
}

/// `msg` (decoded from `from`) encoded as `to` decodes back to an equal message.
fn round_trip<T: Message + PartialEq + Debug>(msg: &T, from: Encoding, to: Encoding) {
    let ty = T::TYPE;
    let bytes = encode(msg, to).unwrap_or_else(|e| {
        panic!("{ty} decoded from {from:?} does not encode as {to:?}: {e}\n{msg:?}")
    });
    let again = decode::<T>(&bytes, to).unwrap_or_else(|e| {
        panic!("{ty} decoded from {from:?} and encoded as {to:?} does not decode: {e}\n{msg:?}")
    });
    assert!(
        same(msg, &again),
        "{ty} decoded from {from:?} changed through {to:?}:\n{msg:?}\n{again:?}"
    );
}

/// The checks above; `json_safe` tells whether a decoded message can be carried by JSON.
pub fn check<T: Message + PartialEq + Debug>(data: &[u8], json_safe: impl Fn(&T) -> bool) {
    let Some((encoding, payload)) = split(data) else {
        return;
    };
    let Ok(msg) = decode::<T>(payload, encoding) else {
        return;
    };
    round_trip(&msg, encoding, encoding);
    match encoding {
        Encoding::Json => round_trip(&msg, encoding, Encoding::Bincode),
        Encoding::Bincode if json_safe(&msg) => round_trip(&msg, encoding, Encoding::Json),
        Encoding::Bincode => {
            if let Ok(json) = encode(&msg, Encoding::Json) {
                let _ = decode::<T>(&json, Encoding::Json);
            }
        }
    }
}

/// All finite.
pub fn finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}
