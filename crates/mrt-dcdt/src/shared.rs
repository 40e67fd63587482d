//! What an Agora shares with its Members' endpoints, its executor and its network port: its
//! id, clock, PostOffice and route, its outlet, its Members' wakers and the shutdown flag.
//! Below the Agora itself and everything that holds a part of it.

use crate::egress::OutletSlot;
use crate::postoffice::{PostOffice, Route};
use crate::waker::Waker;
use mrt_core::{AgoraId, MemberId, SharedClock};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, RwLock};

/// What an Agora shares with its Members' endpoints and its executor.
pub(crate) struct AgoraShared {
    pub(crate) id: AgoraId,
    pub(crate) clock: SharedClock,
    pub(crate) post_office: Arc<PostOffice>,
    pub(crate) route: Route,
    pub(crate) outlet: OutletSlot,
    shutdown: AtomicBool,
    wakers: RwLock<Vec<Arc<Waker>>>,
}

impl AgoraShared {
    /// The state of a new Agora: no outlet, no Member yet, not shutting down.
    pub(crate) fn new(
        id: AgoraId,
        clock: SharedClock,
        post_office: Arc<PostOffice>,
        route: Route,
    ) -> AgoraShared {
        AgoraShared {
            id,
            clock,
            post_office,
            route,
            outlet: OutletSlot::default(),
            shutdown: AtomicBool::new(false),
            wakers: RwLock::new(Vec::new()),
        }
    }

    /// Keeps the waker of `member`, so that shutdown wakes it.
    pub(crate) fn set_waker(&self, member: MemberId, waker: Arc<Waker>) {
        let mut wakers = self.wakers.write().unwrap_or_else(|e| e.into_inner());
        if wakers.len() <= member.0 as usize {
            wakers.resize_with(member.0 as usize + 1, Default::default);
        }
        wakers[member.0 as usize] = waker;
    }

    pub(crate) fn waker(&self, member: MemberId) -> Option<Arc<Waker>> {
        self.wakers.read().unwrap_or_else(|e| e.into_inner()).get(member.0 as usize).cloned()
    }

    pub(crate) fn is_shutting_down(&self) -> bool {
        self.shutdown.load(Ordering::Acquire)
    }

    pub(crate) fn request_shutdown(&self, by: Option<MemberId>) {
        if !self.shutdown.swap(true, Ordering::AcqRel) {
            match by {
                Some(m) => tracing::info!(agora = %self.id, "shutdown requested by {m}"),
                None => tracing::info!(agora = %self.id, "shutdown requested"),
            }
        }
        for w in self.wakers.read().unwrap_or_else(|e| e.into_inner()).iter() {
            w.force_wake();
        }
        self.post_office.policy.stop_dispatcher();
    }
}
