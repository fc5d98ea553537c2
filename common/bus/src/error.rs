use graspopt_protocol::DecodeError;
use graspopt_protocol::codec::EncodeError;

/// What can go wrong on the bus.
#[derive(Debug, thiserror::Error)]
pub enum BusError {
    #[error("zenoh: {what}: {detail}")]
    Zenoh { what: String, detail: String },
    #[error("invalid bus configuration: {0}")]
    Config(String),
    #[error(transparent)]
    Encode(#[from] EncodeError),
    #[error(transparent)]
    Decode(#[from] DecodeError),
    /// Its text is in the message, so it is not a `source()` (a chain printed with `{:#}`
    /// would say it twice).
    #[error("shared memory: {0}")]
    Shm(graspopt_shm::ShmError),
    #[error("no reply from {key} within {timeout_ms} ms")]
    NoReply { key: String, timeout_ms: u64 },
    /// Another agent already holds this agent's place in the run (its id, or the run's one
    /// coordinator).
    #[error("{0}")]
    Taken(String),
    /// The query ended at once, without a reply: nothing on the bus answers on `key`.
    #[error("nothing answers on {key}")]
    NoResponder { key: String },
    #[error("{key} replied with an error: {detail}")]
    ReplyError { key: String, detail: String },
    /// None of the endpoints the session connects to was reached: why (nothing answers, a
    /// host name that does not resolve, a router that refused the login).
    #[error("{0}")]
    Unreached(String),
}

impl From<graspopt_shm::ShmError> for BusError {
    fn from(e: graspopt_shm::ShmError) -> Self {
        BusError::Shm(e)
    }
}

impl BusError {
    pub(crate) fn zenoh(what: impl Into<String>, e: impl std::fmt::Display) -> Self {
        BusError::Zenoh {
            what: what.into(),
            detail: without_source_locations(&e.to_string()),
        }
    }
}

/// `text` without the ` at /path/to/file.rs:123` locations Zenoh appends to its errors
/// (paths of the build machine's crate registry, of no use to a user).
pub(crate) fn without_source_locations(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find(" at /") {
        let tail = &rest[i + 4..];
        let end = tail.find(char::is_whitespace).unwrap_or(tail.len());
        // The location may be followed by a full stop and the brackets it closed: "...rs:61.]".
        let location = tail[..end].trim_end_matches(['.', ']', ')']);
        let is_source = location
            .rsplit_once(".rs:")
            .is_some_and(|(_, line)| !line.is_empty() && line.bytes().all(|b| b.is_ascii_digit()));
        if is_source {
            out.push_str(&rest[..i]);
            let suffix = &tail[location.len()..end];
            // A sentence's full stop after the location stays, unless it ends the text or
            // comes before a closing bracket ("(os error 98)]", not "(os error 98).]").
            let after = if end == tail.len() && suffix == "." {
                end
            } else if suffix.len() > 1 && suffix.starts_with('.') {
                location.len() + 1
            } else {
                location.len()
            };
            rest = &tail[after..];
        } else {
            out.push_str(&rest[..i + 4]);
            rest = tail;
        }
    }
    out.push_str(rest);
    out.trim_end().to_string()
}

#[cfg(test)]
mod tests {
    use super::without_source_locations;

    #[test]
    fn source_locations_are_dropped_and_other_paths_kept() {
        assert_eq!(
            without_source_locations(
                "Unable to connect to any of [tcp/127.0.0.1:1]! at /root/.cargo/registry/src/zenoh-1.10.0/src/net/runtime/orchestrator.rs:393."
            ),
            "Unable to connect to any of [tcp/127.0.0.1:1]!"
        );
        assert_eq!(
            without_source_locations("a at /x/y.rs:1. b at /u/v.rs:22"),
            "a. b"
        );
        assert_eq!(
            without_source_locations(
                "Can not create a new TCP listener bound to tcp/127.0.0.1:7447: [127.0.0.1:7447: Address already in use (os error 98) at /root/.cargo/registry/src/x/zenoh-link-commons-1.10.2/src/tcp.rs:61.]"
            ),
            "Can not create a new TCP listener bound to tcp/127.0.0.1:7447: [127.0.0.1:7447: Address already in use (os error 98)]"
        );
        assert_eq!(
            without_source_locations("cannot read at /etc/graspopt/agent.json5"),
            "cannot read at /etc/graspopt/agent.json5"
        );
    }
}
