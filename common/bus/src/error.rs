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
    #[error("shared memory: {0}")]
    Shm(#[from] graspopt_shm::ShmError),
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
}

impl BusError {
    pub(crate) fn zenoh(what: impl Into<String>, e: impl std::fmt::Display) -> Self {
        BusError::Zenoh {
            what: what.into(),
            detail: e.to_string(),
        }
    }
}
