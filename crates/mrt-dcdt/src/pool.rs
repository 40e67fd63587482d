//! Recycling of message allocations, per producer.
//!
//! At 1→1 the cost of a message is dominated by its allocation on the producer's thread and its
//! free on the consumer's (see `docs/performance.md`). An [`Endpoint`](crate::Endpoint) keeps
//! the last few messages it published of each type; when it publishes again and the oldest one
//! has no other holder left (every subscriber is done with it), its block is reused in place.
//!
//! Only payload types without drop glue are recycled (`!needs_drop::<T>()`: plain numbers,
//! arrays, small structs): for them "freed when the last subscriber is done" and "returned to
//! the pool" are the same thing. Messages owning resources (a `Vec`, a `String`) are allocated
//! and freed as usual, so their resources go as soon as the last reader lets go.

use crate::msg::{Message, Msg, MsgHeader, MsgRef};
use rustc_hash::FxHashMap;
use std::any::{Any, TypeId};
use std::cell::RefCell;
use std::collections::VecDeque;
use std::sync::Arc;

/// Messages kept per type before the oldest is checked for reuse.
const RING: usize = 32;

#[derive(Default)]
pub(crate) struct MsgPool {
    rings: RefCell<FxHashMap<TypeId, Box<dyn Any + Send>>>,
}

impl MsgPool {
    /// A shared message holding `value`: a recycled block when one is free, else a new one.
    #[inline]
    pub(crate) fn make<T: Message>(&self, header: MsgHeader, value: T) -> MsgRef {
        if std::mem::needs_drop::<T>() {
            return Msg::new(header, value).into_ref();
        }
        // Never re-entered (no user code runs in here: `T` has no drop glue), but stay safe.
        let Ok(mut rings) = self.rings.try_borrow_mut() else {
            return Msg::new(header, value).into_ref();
        };
        let ring = rings
            .entry(TypeId::of::<T>())
            .or_insert_with(|| Box::new(VecDeque::<Arc<Msg<T>>>::with_capacity(RING + 1)));
        let Some(ring) = ring.downcast_mut::<VecDeque<Arc<Msg<T>>>>() else {
            return Msg::new(header, value).into_ref();
        };
        if ring.len() >= RING {
            if let Some(mut oldest) = ring.pop_front() {
                if let Some(slot) = Arc::get_mut(&mut oldest) {
                    slot.reset(header, value);
                    ring.push_back(oldest.clone());
                    return oldest;
                }
                // Still held by a slow reader: let it go, that reader frees it.
            }
        }
        let fresh = Arc::new(Msg::new(header, value));
        ring.push_back(fresh.clone());
        fresh
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::DeliveryWarranty;
    use mrt_core::{AgoraId, MemberId, MsgType, Time};
    use serde::{Deserialize, Serialize};

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Pod(u64);
    impl Message for Pod {
        const TYPE: MsgType = MsgType(1);
        const NAME: &'static str = "Pod";
    }

    fn header(t: u64) -> MsgHeader {
        MsgHeader {
            msg_type: Pod::TYPE,
            member_id: MemberId(0),
            agora_id: AgoraId(0),
            priority: 0,
            warranty: DeliveryWarranty::None,
            creation_time: Time(t),
        }
    }

    #[test]
    fn a_block_is_reused_only_when_nobody_else_holds_it() {
        let pool = MsgPool::default();
        let first: Vec<MsgRef> = (0..RING as u64).map(|i| pool.make(header(i), Pod(i))).collect();
        let ptr = |m: &MsgRef| Arc::as_ptr(m) as *const u8;
        let (ptr0, ptr1) = (ptr(&first[0]), ptr(&first[1]));
        // Everybody still holds the oldest message: the next one gets a new block.
        let a = pool.make(header(100), Pod(100));
        assert_ne!(ptr(&a), ptr0);
        drop(first);
        // Now the oldest kept one (the second message) is free: its block is reused, with the
        // new contents.
        let b = pool.make(header(101), Pod(101));
        assert_eq!(ptr(&b), ptr1);
        assert_eq!(b.get::<Pod>().unwrap(), &Pod(101));
        assert_eq!(b.creation_time(), Time(101));
        // A value read by a holder never changes under it.
        assert_eq!(a.get::<Pod>().unwrap(), &Pod(100));
    }

    #[test]
    fn types_with_drop_glue_are_not_pooled() {
        #[derive(Serialize, Deserialize)]
        struct Owns(Vec<u8>);
        impl Message for Owns {
            const TYPE: MsgType = MsgType(2);
            const NAME: &'static str = "Owns";
        }
        let pool = MsgPool::default();
        let _m = pool.make(header(0), Owns(vec![1]));
        assert!(pool.rings.borrow().is_empty());
    }
}
