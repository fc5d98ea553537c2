//! An [`Inbox`]: accepts the messages of one run and counts (and logs) the rest.
//!
//! Every agent subscribes to keys of its run, yet what arrives there may not decode, or may
//! name another run (a misconfigured or hostile sender). Such a message is never acted on:
//! it is counted as a bad message and logged with the running count.

use graspopt_protocol::{Message, RunId};

use crate::Received;

/// Accepts messages of one run for one agent; counts the bad ones.
#[derive(Debug, Clone)]
pub struct Inbox {
    /// The agent, as its log lines start (`hand hand-1`).
    agent: String,
    run: RunId,
    bad: u64,
}

impl Inbox {
    /// An inbox for `agent` (the start of its log lines) on `run`.
    pub fn new(agent: impl Into<String>, run: &RunId) -> Inbox {
        Inbox {
            agent: agent.into(),
            run: run.clone(),
            bad: 0,
        }
    }

    /// The message `r` carries if it decoded and belongs to this run; otherwise it is
    /// counted and logged (`what` names it in the log: `command`, `object estimate`).
    pub fn accept<T: Message>(&mut self, r: Received<T>, what: &str) -> Option<T> {
        match r.message {
            Ok(m) if *m.run_id() == self.run => Some(m),
            Ok(m) => {
                let run = m.run_id().clone();
                self.refuse(format_args!("{what} of run {run:?} ignored"));
                None
            }
            Err(e) => {
                self.bad += 1;
                tracing::warn!(
                    "{}: bad {what} on {} ({} bad messages): {e}",
                    self.agent,
                    r.key,
                    self.bad
                );
                None
            }
        }
    }

    /// Counts and logs a message of this run refused for another reason (`why`).
    pub fn refuse(&mut self, why: impl std::fmt::Display) {
        self.bad += 1;
        tracing::warn!("{}: {why} ({} bad messages)", self.agent, self.bad);
    }

    /// Bad messages so far.
    pub fn bad(&self) -> u64 {
        self.bad
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use graspopt_protocol::{DecodeError, Encoding, ObjectEstimate, Pose};

    fn received(run: &str) -> Received<ObjectEstimate> {
        Received {
            key: "k".into(),
            encoding: Encoding::Json,
            size: 0,
            message: Ok(ObjectEstimate {
                run_id: RunId::new(run).unwrap(),
                object: "sphere".into(),
                mesh: None,
                pose: Pose::IDENTITY,
                seq: 1,
                stamp_ms: 0,
                source: "test".into(),
            }),
        }
    }

    #[test]
    fn messages_of_the_run_pass_and_the_rest_are_counted() {
        let mut inbox = Inbox::new("test", &RunId::new("r").unwrap());
        assert_eq!(
            inbox.accept(received("r"), "estimate").unwrap().object,
            "sphere"
        );
        assert!(inbox.accept(received("other"), "estimate").is_none());
        let garbage = Received::<ObjectEstimate> {
            key: "k".into(),
            encoding: Encoding::Json,
            size: 3,
            message: Err(DecodeError::Empty {
                message_type: "ObjectEstimate",
            }),
        };
        assert!(inbox.accept(garbage, "estimate").is_none());
        inbox.refuse("a command for another worker");
        assert_eq!(inbox.bad(), 3);
    }
}
