//! `decode_topic` (what `graspopt topic echo` shows) from untrusted bytes. The selector byte
//! picks the encoding (bit 0: bincode or JSON) and the topic (the other bits, modulo 6).
//!
//! Checks: never panics; it agrees with the typed decoder of the topic's message (same
//! error, or the message's JSON); what it shows is a JSON object without the wire version.
#![no_main]

use graspopt_protocol::{
    ContactClouds, DecodeError, Encoding, FingertipWrenches, Message, ObjectEstimate, RunStatus,
    Topic, TrialCommand, TrialResult, decode, decode_topic,
};
use libfuzzer_sys::fuzz_target;
use serde_json::Value;

fn typed<T: Message>(
    topic: Topic,
    payload: &[u8],
    encoding: Encoding,
) -> Result<Value, DecodeError> {
    assert_eq!(topic.message_type(), T::TYPE, "{topic:?}");
    decode::<T>(payload, encoding)
        .map(|msg| serde_json::to_value(&msg).expect("a decoded message converts to JSON"))
}

fuzz_target!(|data: &[u8]| {
    let Some((&selector, payload)) = data.split_first() else {
        return;
    };
    let encoding = if selector & 1 == 0 {
        Encoding::Bincode
    } else {
        Encoding::Json
    };
    let topic = Topic::ALL[usize::from(selector >> 1) % Topic::ALL.len()];
    let shown = decode_topic(topic, payload, encoding);
    let expected = match topic {
        Topic::Object => typed::<ObjectEstimate>(topic, payload, encoding),
        Topic::Command => typed::<TrialCommand>(topic, payload, encoding),
        Topic::Clouds => typed::<ContactClouds>(topic, payload, encoding),
        Topic::Result => typed::<TrialResult>(topic, payload, encoding),
        Topic::Status => typed::<RunStatus>(topic, payload, encoding),
        Topic::Wrenches => typed::<FingertipWrenches>(topic, payload, encoding),
    };
    assert_eq!(shown, expected, "{topic:?} {encoding:?}");
    if let Ok(value) = shown {
        let object = value.as_object().expect("a message shows as a JSON object");
        assert!(
            !object.contains_key("wire"),
            "{topic:?} shows the wire version"
        );
    }
});
