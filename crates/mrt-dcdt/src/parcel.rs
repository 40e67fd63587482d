//! How a message travels from a producer to one mailbox: shared by reference, or by value.
//!
//! A DCDT message is shared (MRT manual §3.3.3): every subscriber reads the same allocation
//! ([`MsgRef`]). Between two threads that costs cache-line traffic on every message: the
//! producer writes the block, each consumer takes and releases references to it (atomic
//! read-modify-writes on the block's counter, contended when several consumers read it), and
//! the block goes back to the producer's pool. For a large message (an image) that is still
//! far cheaper than a copy; for a small one it is not. So under `PMQ` a small payload of
//! plain data travels *inside* each subscriber's mailbox slot, by value, like a value sent
//! through a channel, and becomes a [`MsgRef`] on the consumer's thread, in the consumer's own
//! pool (its block, counter and reuse never leave that thread's cache). Readers see no
//! difference: `receive_msg` returns a [`MsgRef`] either way, with the publisher's header and an
//! equal value; only the value's address tells a copy from a shared message.
//!
//! The value is encoded in the slot as on the wire (postcard), so a [`Message`] must decode to
//! what it encoded, as it must anyway to cross a process boundary.
//!
//! Measured in `docs/performance.md` (PostOffice throughput 1→1).

use crate::msg::{DeliveryWarranty, Message, Msg, MsgHeader, MsgRef, RawPayload};
use crate::pool::MsgPool;
use mrt_core::{AgoraId, MemberId, MsgType, Time};
use std::mem::{needs_drop, size_of};

/// Encoded payload bytes a message may have to travel by value.
pub(crate) const INLINE_BYTES: usize = 32;

/// A message by value: its header, its payload encoded (postcard, as on the wire) inside the
/// slot, and the function that knows the payload's type and decodes it. Copied into the slot
/// of each subscriber. (The header's fields are laid out by hand so that the small ones share
/// a word with the payload's length: a mailbox slot is 64 bytes instead of 72.)
#[derive(Clone, Copy)]
pub(crate) struct InlineMsg {
    creation_time: Time,
    msg_type: MsgType,
    member_id: MemberId,
    agora_id: AgoraId,
    priority: u8,
    warranty: DeliveryWarranty,
    len: u8,
    bytes: [u8; INLINE_BYTES],
    open: fn(MsgHeader, &[u8], &MsgPool) -> MsgRef,
}

impl InlineMsg {
    /// Whether a payload of type `T` may travel by value: plain data (no drop glue: no heap
    /// memory, no `Drop` with side effects, so a copy cannot be told from the original but by
    /// its address) whose in-memory size is close to the slot's (its encoding then likely fits;
    /// [`new`](Self::new) checks).
    #[inline]
    pub(crate) const fn fits<T: Message>() -> bool {
        !needs_drop::<T>() && size_of::<T>() <= INLINE_BYTES + 8
    }

    /// `value` by value, if it [`fits`](Self::fits) and its encoding does; else gives it back.
    #[inline]
    pub(crate) fn new<T: Message>(header: MsgHeader, value: T) -> Result<Self, T> {
        if !Self::fits::<T>() {
            return Err(value);
        }
        let mut bytes = [0u8; INLINE_BYTES];
        let len = match postcard::to_slice(&value, &mut bytes) {
            Ok(used) => used.len(),
            Err(_) => return Err(value),
        };
        // `len` ≤ INLINE_BYTES = 32.
        let MsgHeader { msg_type, member_id, agora_id, priority, warranty, creation_time } = header;
        Ok(Self {
            creation_time,
            msg_type,
            member_id,
            agora_id,
            priority,
            warranty,
            len: len as u8,
            bytes,
            open: open::<T>,
        })
    }

    fn header(&self) -> MsgHeader {
        MsgHeader {
            msg_type: self.msg_type,
            member_id: self.member_id,
            agora_id: self.agora_id,
            priority: self.priority,
            warranty: self.warranty,
            creation_time: self.creation_time,
        }
    }
}

/// Decodes a `T` from `bytes` into a shared message from `pool`. Bytes that do not decode
/// (a type whose serde form does not round-trip) become a raw message, whose typed read
/// reports the decoding error.
fn open<T: Message>(header: MsgHeader, bytes: &[u8], pool: &MsgPool) -> MsgRef {
    match postcard::from_bytes::<T>(bytes) {
        Ok(value) => pool.make(header, value),
        Err(_) => Msg::new(header, RawPayload::new(bytes.to_vec())).into_ref(),
    }
}

/// A message on its way to one mailbox.
pub(crate) enum Parcel {
    /// Shared with the other subscribers.
    Shared(MsgRef),
    /// By value: a copy of its own.
    Inline(InlineMsg),
}

impl Parcel {
    /// The message's delivery warranty.
    #[inline]
    pub(crate) fn warranty(&self) -> DeliveryWarranty {
        match self {
            Parcel::Shared(m) => m.header().warranty,
            Parcel::Inline(i) => i.warranty,
        }
    }

    /// The message as its reader gets it: a value is put into a block of `pool` (the
    /// receiving endpoint's).
    #[inline]
    pub(crate) fn open(self, pool: &MsgPool) -> MsgRef {
        match self {
            Parcel::Shared(m) => m,
            Parcel::Inline(i) => {
                let bytes = i.bytes.get(..usize::from(i.len)).unwrap_or_default();
                (i.open)(i.header(), bytes, pool)
            }
        }
    }
}

/// Builds the message a delivery needs, once, and only if somebody subscribed.
pub(crate) trait Make {
    /// The message, shared.
    fn shared(&mut self) -> MsgRef;
    /// The message by value, copied to each subscriber; `None` when it cannot travel so
    /// (then [`shared`](Self::shared) is asked).
    fn inline(&mut self) -> Option<InlineMsg> {
        None
    }
}

impl<F: FnMut() -> MsgRef> Make for F {
    #[inline]
    fn shared(&mut self) -> MsgRef {
        self()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::{Deserialize, Serialize};

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Pose {
        x: f64,
        y: f64,
        theta: f64,
    }
    impl Message for Pose {
        const TYPE: MsgType = MsgType(7);
        const NAME: &'static str = "Pose";
    }

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Big([u64; 6]);
    impl Message for Big {
        const TYPE: MsgType = MsgType(8);
        const NAME: &'static str = "Big";
    }

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Owns(String);
    impl Message for Owns {
        const TYPE: MsgType = MsgType(9);
        const NAME: &'static str = "Owns";
    }

    fn header(ty: MsgType) -> MsgHeader {
        MsgHeader {
            msg_type: ty,
            member_id: MemberId(3),
            agora_id: AgoraId(2),
            priority: 9,
            warranty: DeliveryWarranty::Reliable,
            creation_time: Time(42),
        }
    }

    #[test]
    fn a_small_plain_message_travels_by_value_and_opens_unchanged() {
        let pose = Pose { x: 1.5, y: -2.0, theta: 0.25 };
        let Ok(inline) = InlineMsg::new(header(Pose::TYPE), pose) else {
            panic!("a 24-byte struct fits");
        };
        let parcel = Parcel::Inline(inline);
        assert_eq!(parcel.warranty(), DeliveryWarranty::Reliable);
        let msg = parcel.open(&MsgPool::default());
        assert_eq!(msg.get::<Pose>().unwrap(), &Pose { x: 1.5, y: -2.0, theta: 0.25 });
        assert_eq!(msg.header(), &header(Pose::TYPE));
    }

    #[test]
    fn a_payload_larger_than_the_slot_is_given_back_to_be_shared() {
        assert!(InlineMsg::new(header(Big::TYPE), Big([1; 6])).is_err_and(|b| b == Big([1; 6])));
        assert!(InlineMsg::fits::<Pose>() && !InlineMsg::fits::<Big>());
    }

    #[test]
    fn an_owning_payload_is_shared() {
        // Its copy would be a second allocation and a second `Drop`: readers could tell.
        let owns = Owns("text".into());
        assert!(InlineMsg::new(header(Owns::TYPE), owns).is_err_and(|o| o.0 == "text"));
    }

    #[test]
    fn a_plain_payload_whose_encoding_is_too_long_is_shared() {
        // 40 bytes in memory, 5 varints of up to 10 bytes each on the wire.
        #[derive(Debug, PartialEq, Serialize, Deserialize)]
        struct Counters([u64; 5]);
        impl Message for Counters {
            const TYPE: MsgType = MsgType(10);
            const NAME: &'static str = "Counters";
        }
        assert!(InlineMsg::fits::<Counters>());
        let small = Counters([1, 2, 3, 4, 5]);
        let msg = Parcel::Inline(InlineMsg::new(header(Counters::TYPE), small).ok().unwrap());
        assert_eq!(msg.open(&MsgPool::default()).get::<Counters>().unwrap().0, [1, 2, 3, 4, 5]);
        let large = Counters([u64::MAX; 5]);
        assert!(InlineMsg::new(header(Counters::TYPE), large).is_err_and(|c| c.0[4] == u64::MAX));
    }

    #[test]
    fn a_parcel_fits_a_cache_line() {
        // A lane preallocates this per slot, plus its arrival number and the ring's stamp (8
        // bytes each): 80 bytes, 160 KiB for the default 2048 messages.
        assert_eq!(size_of::<Parcel>(), 64);
    }
}
