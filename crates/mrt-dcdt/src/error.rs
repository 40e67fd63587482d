//! The error type of `mrt-dcdt`.

use mrt_core::{AgoraId, MemberId, MsgType};

/// Everything that can go wrong in DCDT.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DcdtError {
    /// A typed read asked for a Rust type the message does not carry.
    #[error("message of {msg_type} is not a `{expected}` (it carries {found})")]
    TypeMismatch {
        /// The message's type id.
        msg_type: MsgType,
        /// The Rust message type that was asked for.
        expected: &'static str,
        /// What the message carries.
        found: &'static str,
    },
    /// Raw bytes could not be decoded as the requested message type.
    #[error("cannot decode a `{name}` from the payload: {reason}")]
    Decode {
        /// The Rust message type.
        name: &'static str,
        /// The codec's explanation.
        reason: String,
    },
    /// A typed payload could not be encoded for the wire.
    #[error("cannot encode a `{name}`: {reason}")]
    Encode {
        /// The Rust message type.
        name: &'static str,
        /// The codec's explanation.
        reason: String,
    },
    /// No Member with this id in this Agora.
    #[error("{agora} has no {member}")]
    UnknownMember {
        /// The Agora asked.
        agora: AgoraId,
        /// The missing Member.
        member: MemberId,
    },
    /// An executor was given an Agora whose clock does not suit it.
    #[error("{agora}: {reason}")]
    ClockMismatch {
        /// The Agora.
        agora: AgoraId,
        /// Why the clock does not suit the executor.
        reason: &'static str,
    },
    /// Mailbox bounds that cannot work: a capacity of 0, or a `Reliable` limit below it.
    #[error(
        "{agora}: mailbox bounds need 1 <= capacity <= reliable_limit, got capacity {capacity} \
         and reliable_limit {reliable_limit}"
    )]
    MailboxBounds {
        /// The Agora.
        agora: AgoraId,
        /// The capacity asked for.
        capacity: usize,
        /// The limit for `Reliable` messages asked for.
        reliable_limit: usize,
    },
    /// Two Agoras of one community have the same id.
    #[error("an Agora with id {0} is already part of this community")]
    DuplicateAgora(AgoraId),
    /// The Agora configuration file is wrong.
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
    /// A network frame is malformed.
    #[error(transparent)]
    Wire(#[from] crate::frame::WireError),
    /// A thread could not be started.
    #[error("cannot start the thread of {what}: {source}")]
    Spawn {
        /// What the thread was for.
        what: String,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
}
