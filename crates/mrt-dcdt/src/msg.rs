//! DCDT messages (MRT manual §3.2 and §3.3.3): a [`MsgHeader`] and a payload.
//!
//! A message is created once and shared by reference ([`MsgRef`], an `Arc`): every subscriber
//! in the process reads the same allocation, and it is freed when the last one is done with it.
//! The payload is either a typed Rust value (a [`Message`]) or raw bytes (what
//! [`create_msg`](crate::Endpoint::create_msg) builds, and what arrives from another process).
//! Typed payloads are serialized when a message leaves the process ([`crate::wire`]) and, under
//! `PMQ`, when a small one of plain data travels by value in a mailbox slot (`parcel`): its
//! readers then each get an equal copy instead of the one allocation.

use crate::error::DcdtError;
use mrt_core::{AgoraId, MemberId, MsgType, Time};
pub use mrt_core::{Message, RESERVED_TYPES_START};
use serde::{Deserialize, Serialize};
use std::any::Any;
use std::fmt;
use std::sync::{Arc, OnceLock};

/// Delivery warranty of a message (§3.2): how hard the network layer must try.
///
/// Inside one process every message is delivered; the warranty matters on links.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum DeliveryWarranty {
    /// "Without any guaranty (e.g. UDP)".
    #[default]
    None,
    /// "With some retransmissions (e.g. UDP retransmitted)".
    Retransmit,
    /// "With absolute receipt guaranty (e.g. TCP)".
    Reliable,
}

impl DeliveryWarranty {
    /// The wire code: 0, 1, 2.
    pub fn code(self) -> u8 {
        match self {
            DeliveryWarranty::None => 0,
            DeliveryWarranty::Retransmit => 1,
            DeliveryWarranty::Reliable => 2,
        }
    }

    /// From a wire code.
    pub fn from_code(code: u8) -> Option<Self> {
        match code {
            0 => Some(DeliveryWarranty::None),
            1 => Some(DeliveryWarranty::Retransmit),
            2 => Some(DeliveryWarranty::Reliable),
            _ => None,
        }
    }
}

/// The header of a DCDT message (§3.3.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct MsgHeader {
    /// "A number that identifies unequivocally the type of Message".
    pub msg_type: MsgType,
    /// The Member that created the message.
    pub member_id: MemberId,
    /// The Agora where the message was created.
    pub agora_id: AgoraId,
    /// Priority, 0 (lowest) to 255. Carried end to end; links map it to transport priorities.
    pub priority: u8,
    /// Delivery warranty.
    pub warranty: DeliveryWarranty,
    /// Creation time, read from the creating Agora's [`Clock`](mrt_core::Clock).
    pub creation_time: Time,
}

/// What a payload must offer so that messages of any type share one queue.
///
/// Implemented for every [`Message`] and for [`RawPayload`]; not meant to be implemented
/// elsewhere.
pub trait Payload: Any + Send + Sync {
    /// The payload as `Any`, for typed access.
    fn as_any(&self) -> &dyn Any;
    /// Serializes the payload for the wire at the end of `out` (postcard for typed payloads,
    /// as-is for raw bytes), so that a frame is written in one buffer.
    fn encode_into(&self, out: &mut Vec<u8>) -> Result<(), DcdtError>;
    /// Size of the payload in bytes: the byte length of raw payloads, the in-memory size of
    /// typed ones (the encoded length is known only when it leaves the process).
    fn len(&self) -> usize;
    /// Whether the payload is empty (an event message, §3.2).
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The payload's type name, for errors and logs.
    fn type_name(&self) -> &'static str;
    /// The payload as raw bytes, when it is raw.
    fn as_raw(&self) -> Option<&RawPayload> {
        None
    }
}

impl<T: Message> Payload for T {
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn encode_into(&self, out: &mut Vec<u8>) -> Result<(), DcdtError> {
        /// Appends to a borrowed buffer (postcard's writer is taken by value).
        struct Append<'a>(&'a mut Vec<u8>);
        impl Extend<u8> for Append<'_> {
            fn extend<I: IntoIterator<Item = u8>>(&mut self, bytes: I) {
                self.0.extend(bytes)
            }
        }
        postcard::to_extend(self, Append(out))
            .map(|_| ())
            .map_err(|e| DcdtError::Encode { name: T::NAME, reason: e.to_string() })
    }
    fn len(&self) -> usize {
        std::mem::size_of::<T>()
    }
    fn type_name(&self) -> &'static str {
        T::NAME
    }
}

/// A payload of plain bytes, as the manual's `GetPayload()` gives (§3.3.3).
///
/// Raw payloads come from [`create_msg`](crate::Endpoint::create_msg) and from the network. When
/// a typed reader asks for a [`Message`] of the header's type, the bytes are decoded once and
/// the value is kept, so every further reader of the same message gets it for free.
pub struct RawPayload {
    bytes: Vec<u8>,
    decoded: OnceLock<Result<Box<dyn Any + Send + Sync>, String>>,
}

impl RawPayload {
    /// A raw payload holding `bytes`.
    pub fn new(bytes: Vec<u8>) -> Self {
        Self { bytes, decoded: OnceLock::new() }
    }

    /// The bytes.
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    fn decode<T: Message>(&self) -> Result<&T, DcdtError> {
        let slot = self.decoded.get_or_init(|| {
            postcard::from_bytes::<T>(&self.bytes)
                .map(|v| Box::new(v) as Box<dyn Any + Send + Sync>)
                .map_err(|e| e.to_string())
        });
        match slot {
            Ok(v) => v.downcast_ref::<T>().ok_or(DcdtError::TypeMismatch {
                msg_type: T::TYPE,
                expected: T::NAME,
                found: "a value decoded as another Rust type",
            }),
            Err(reason) => Err(DcdtError::Decode { name: T::NAME, reason: reason.clone() }),
        }
    }
}

impl fmt::Debug for RawPayload {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "RawPayload({} bytes)", self.bytes.len())
    }
}

impl Payload for RawPayload {
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn encode_into(&self, out: &mut Vec<u8>) -> Result<(), DcdtError> {
        out.extend_from_slice(&self.bytes);
        Ok(())
    }
    fn len(&self) -> usize {
        self.bytes.len()
    }
    fn type_name(&self) -> &'static str {
        "raw bytes"
    }
    fn as_raw(&self) -> Option<&RawPayload> {
        Some(self)
    }
}

/// A DCDT message: header and payload. `P` is the payload type; shared messages erase it to
/// `dyn Payload` ([`MsgRef`]).
pub struct Msg<P: ?Sized + Payload = dyn Payload> {
    header: MsgHeader,
    payload: P,
}

/// A shared, immutable message. Cloning is a reference-count increment; the message is freed
/// when the last holder drops it (the manual's "the destructor will be invoked unless other
/// Members are waiting to receive the Message").
pub type MsgRef = Arc<Msg>;

impl<P: Payload> Msg<P> {
    /// A message with this header and payload.
    pub fn new(header: MsgHeader, payload: P) -> Self {
        Self { header, payload }
    }

    /// Overwrites a message no one else holds (pool reuse).
    pub(crate) fn reset(&mut self, header: MsgHeader, payload: P) {
        self.header = header;
        self.payload = payload;
    }

    /// Puts the message behind a shared reference, ready to be shared.
    pub fn into_ref(self) -> MsgRef {
        Arc::new(self)
    }
}

impl<P: ?Sized + Payload> Msg<P> {
    /// The header.
    pub fn header(&self) -> &MsgHeader {
        &self.header
    }
    /// The message type (`ReadType`).
    pub fn msg_type(&self) -> MsgType {
        self.header.msg_type
    }
    /// The creating Agora (`ReadAgoraID()`).
    pub fn agora_id(&self) -> AgoraId {
        self.header.agora_id
    }
    /// The creating Member.
    pub fn member_id(&self) -> MemberId {
        self.header.member_id
    }
    /// The creation time (`ReadCreationTime()`).
    pub fn creation_time(&self) -> Time {
        self.header.creation_time
    }
    /// The payload length in bytes (`ReadPayloadLen()`); see [`Payload::len`].
    pub fn payload_len(&self) -> usize {
        self.payload.len()
    }
    /// The payload (`GetPayload()`), type-erased.
    pub fn payload(&self) -> &P {
        &self.payload
    }
}

impl Msg {
    /// The payload as a `T`, without a cast at the call site.
    ///
    /// Works for messages created as `T` in this process (no copy, no decoding) and for raw
    /// messages of type `T::TYPE` (decoded once, on first access). Any other message gives
    /// [`DcdtError::TypeMismatch`]; undecodable bytes give [`DcdtError::Decode`].
    pub fn get<T: Message>(&self) -> Result<&T, DcdtError> {
        if let Some(v) = self.payload.as_any().downcast_ref::<T>() {
            return Ok(v);
        }
        if self.header.msg_type != T::TYPE {
            return Err(DcdtError::TypeMismatch {
                msg_type: self.header.msg_type,
                expected: T::NAME,
                found: self.payload.type_name(),
            });
        }
        match self.payload.as_raw() {
            Some(raw) => raw.decode::<T>(),
            None => Err(DcdtError::TypeMismatch {
                msg_type: self.header.msg_type,
                expected: T::NAME,
                found: self.payload.type_name(),
            }),
        }
    }

    /// `true` when the message carries a `T` (its type id is `T::TYPE`).
    pub fn is<T: Message>(&self) -> bool {
        self.header.msg_type == T::TYPE
    }

    /// The raw bytes, when the payload is raw.
    pub fn bytes(&self) -> Option<&[u8]> {
        self.payload.as_raw().map(RawPayload::bytes)
    }
}

impl<P: ?Sized + Payload> fmt::Debug for Msg<P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Msg")
            .field("header", &self.header)
            .field("payload", &self.payload.type_name())
            .field("payload_len", &self.payload.len())
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Odometry {
        dx: f32,
        dy: f32,
    }
    impl Message for Odometry {
        const TYPE: MsgType = MsgType(7);
        const NAME: &'static str = "Odometry";
    }

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Other(u8);
    impl Message for Other {
        const TYPE: MsgType = MsgType(8);
        const NAME: &'static str = "Other";
    }

    fn header(t: MsgType) -> MsgHeader {
        MsgHeader {
            msg_type: t,
            member_id: MemberId(1),
            agora_id: AgoraId(2),
            priority: 0,
            warranty: DeliveryWarranty::None,
            creation_time: Time::from_millis(3),
        }
    }

    #[test]
    fn typed_payload_reads_back_without_copy() {
        let m = Msg::new(header(Odometry::TYPE), Odometry { dx: 1.0, dy: 2.0 }).into_ref();
        let a: *const Odometry = m.get::<Odometry>().unwrap();
        let b: *const Odometry = m.clone().get::<Odometry>().unwrap();
        assert_eq!(a, b, "both readers see the same allocation");
        assert!(m.is::<Odometry>());
        assert_eq!(m.payload_len(), 8);
        assert!(m.bytes().is_none());
        let err = m.get::<Other>().unwrap_err();
        assert!(err.to_string().contains("Other"), "{err}");
    }

    #[test]
    fn raw_payload_decodes_once_on_typed_access() {
        let bytes = postcard::to_stdvec(&Odometry { dx: 0.5, dy: -1.0 }).unwrap();
        let m = Msg::new(header(Odometry::TYPE), RawPayload::new(bytes.clone())).into_ref();
        assert_eq!(m.bytes(), Some(&bytes[..]));
        assert_eq!(m.get::<Odometry>().unwrap(), &Odometry { dx: 0.5, dy: -1.0 });
        let first: *const Odometry = m.get::<Odometry>().unwrap();
        let second: *const Odometry = m.get::<Odometry>().unwrap();
        assert_eq!(first, second, "decoded once and kept");
        assert!(matches!(m.get::<Other>(), Err(DcdtError::TypeMismatch { .. })));
    }

    #[test]
    fn garbage_bytes_give_a_decode_error() {
        let m = Msg::new(header(Odometry::TYPE), RawPayload::new(vec![1])).into_ref();
        assert!(matches!(m.get::<Odometry>(), Err(DcdtError::Decode { .. })));
    }

    #[test]
    fn warranty_codes_round_trip() {
        for w in [DeliveryWarranty::None, DeliveryWarranty::Retransmit, DeliveryWarranty::Reliable]
        {
            assert_eq!(DeliveryWarranty::from_code(w.code()), Some(w));
        }
        assert_eq!(DeliveryWarranty::from_code(3), None);
    }
}
