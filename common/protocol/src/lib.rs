//! graspopt's wire protocol: what agents say to each other, and where.
//!
//! - [`messages`]: every message as a serde type. Each carries the run id and, where it concerns
//!   a trial, the trial id and attempt, so results are idempotent by trial id.
//! - [`keys`]: the key-expression scheme, in one place: one table binds each key to the
//!   type of its messages ([`keys::TABLE`], [`Key`]). Every key starts with `graspopt/<run>/`.
//! - [`codec`]: bincode 2 (the default) and JSON (for agents written in other languages), each
//!   payload prefixed by the [`WIRE_VERSION`].
//! - [`layout`]: the fixed little-endian layout of contact clouds written straight into a
//!   shared-memory sample (hand to metric agent on one host).
//! - [`text`]: how the tools round the numbers a person reads.
//! - [`error`]: every error of the crate; [`ValidationError`] names the message, the field
//!   and the problem of a message refused by its check.
//!
//! This crate knows the shape of the conversation, not the network: it has no Zenoh, no
//! sockets, no files. `docs/protocol.md` describes the same scheme for agent writers.
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod codec;
pub mod error;
pub mod keys;
pub mod layout;
pub mod messages;
pub mod text;

pub use codec::{Encoding, Request, decode, decode_topic, encode};
pub use error::{DecodeError, ValidationError};
pub use keys::{AgentKind, Key, QueryKey, RunId, Runs, Topic};
pub use messages::*;

/// The wire version every payload carries. Bumped on any incompatible change of a message.
pub const WIRE_VERSION: u16 = 4;
