//! Where an Agora's messages leave the process: the [`Outlet`] trait a network layer
//! implements (public through `mrt_dcdt::outlet`) and the slot an Agora keeps its outlet in.
//! Below the Agora's shared state, which holds the slot, and the outlet module's port, which
//! fills it.

use crate::msg::MsgRef;
use arc_swap::ArcSwapOption;
use mrt_core::MsgType;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Where messages leave the process: a link or bridge of a network layer.
pub trait Outlet: Send + Sync + 'static {
    /// Whether messages of `ty` should leave (some remote Member subscribed to them). Called on
    /// every share of this Agora: keep it cheap.
    fn wants(&self, ty: MsgType) -> bool;
    /// Sends a message created here (after it was delivered locally). Must not block for
    /// long: a Member is waiting.
    fn send(&self, msg: &MsgRef);
}

/// The installed outlet of an Agora (none by default): one relaxed load on the share path
/// when there is none.
#[derive(Default)]
pub(crate) struct OutletSlot {
    present: AtomicBool,
    outlet: ArcSwapOption<Box<dyn Outlet>>,
}

impl OutletSlot {
    #[inline]
    pub(crate) fn wants(&self, ty: MsgType) -> bool {
        self.present.load(Ordering::Relaxed)
            && self.outlet.load().as_ref().is_some_and(|o| o.wants(ty))
    }

    /// The outlet, if one is installed and wants `ty`.
    #[inline]
    pub(crate) fn for_type(&self, ty: MsgType) -> Option<Arc<Box<dyn Outlet>>> {
        if !self.present.load(Ordering::Relaxed) {
            return None;
        }
        self.outlet.load_full().filter(|o| o.wants(ty))
    }

    /// Installs `outlet`, or removes the installed one with `None`.
    pub(crate) fn set(&self, outlet: Option<Box<dyn Outlet>>) {
        self.present.store(outlet.is_some(), Ordering::Relaxed);
        self.outlet.store(outlet.map(Arc::new));
    }
}
