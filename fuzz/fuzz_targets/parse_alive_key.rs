//! Key expressions from the network, as UTF-8 text (other inputs are skipped: Zenoh keys are
//! strings): liveliness tokens (`parse_alive_key`), topic keys (`Topic::classify`), and
//! `sanitize_chunk` / `Encoding::from_mime` on the same text.
//!
//! Checks: never panics; a parsed liveliness token or topic key is rebuilt, by the key
//! builders of the run it names, into exactly the input; `sanitize_chunk` always gives a
//! valid key chunk.
#![no_main]

use graspopt_protocol::keys::{
    CLOUDS, COMMAND, OBJECT, RESULT, Runs, STATUS, WRENCHES, alive_token,
};
use graspopt_protocol::keys::{check_agent_id, parse_alive_key, sanitize_chunk};
use graspopt_protocol::{Encoding, RunId, Topic};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(key) = std::str::from_utf8(data) else {
        return;
    };
    if let Some(alive) = parse_alive_key(key) {
        let mut rebuilt = alive_token(&alive.run, alive.kind, &alive.host, &alive.id, None);
        if alive.encoding == Encoding::Json {
            rebuilt.push_str("/json");
        }
        if let Some(topic) = alive.publishes {
            rebuilt = format!("{rebuilt}/{}", topic.entry().name);
        }
        assert_eq!(rebuilt, key, "{alive:?}");
    }
    if let Some((run, topic)) = Topic::classify(key) {
        let rebuilt = match topic {
            Topic::Object => OBJECT.key(Runs::One(&run)).to_string(),
            Topic::Command => COMMAND
                .worker_key(Runs::One(&run), key.split('/').nth(3).unwrap_or_default())
                .to_string(),
            Topic::Clouds => CLOUDS.key(Runs::One(&run)).to_string(),
            Topic::Result => RESULT.key(Runs::One(&run)).to_string(),
            Topic::Status => STATUS.key(Runs::One(&run)).to_string(),
            Topic::Wrenches => WRENCHES.key(Runs::One(&run)).to_string(),
        };
        assert_eq!(rebuilt, key, "{topic:?}");
    }
    let chunk = sanitize_chunk(key);
    assert!(
        check_agent_id(&chunk).is_ok(),
        "{key:?} sanitized to {chunk:?}"
    );
    assert!(RunId::new(&chunk).is_ok(), "{key:?} sanitized to {chunk:?}");
    let _ = Encoding::from_mime(key);
});
