//! The frame format's constants (magic, version, header and payload sizes) and what can be
//! wrong with a frame ([`WireError`]). Public through `mrt_dcdt::wire`; kept here, below
//! both the codec (`wire`) and the crate's error type (`error`, which wraps [`WireError`]).

/// Frame magic.
pub const MAGIC: [u8; 4] = *b"DCDT";
/// Frame version written and accepted.
pub const VERSION: u8 = 1;
/// Size of the frame header.
pub const HEADER_LEN: usize = 32;
/// Largest payload accepted (16 MiB): a bigger announced length is an error, not an
/// allocation.
pub const MAX_PAYLOAD: usize = 16 << 20;

/// Why a frame could not be decoded. A receiver counts and drops such frames.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum WireError {
    /// Fewer bytes than the header or the announced payload.
    #[error("truncated frame: {needed} bytes needed, {got} received")]
    Truncated {
        /// Bytes the frame should have.
        needed: usize,
        /// Bytes received.
        got: usize,
    },
    /// The frame does not start with `DCDT`.
    #[error("not a DCDT frame (bad magic)")]
    BadMagic,
    /// A frame version this build does not know.
    #[error("unsupported frame version {0} (this build speaks version 1)")]
    Version(u8),
    /// An unknown delivery warranty code.
    #[error("unknown delivery warranty code {0}")]
    Warranty(u8),
    /// The announced payload is larger than [`MAX_PAYLOAD`].
    #[error("payload of {0} bytes is larger than the {MAX_PAYLOAD}-byte limit")]
    TooLarge(usize),
    /// The reserved header byte is not 0 (a frame of a newer, incompatible layout).
    #[error("reserved header byte is {0}, expected 0")]
    Reserved(u8),
    /// Bytes after the payload.
    #[error("{0} unexpected bytes after the payload")]
    Trailing(usize),
}
