//! The Proxy (ISocRob-2000 report §3.2.5): the Member of a robot's Agora that carries the shared
//! (`*` and `n`) blackboard changes between robots. It publishes each local change as a
//! [`BbUpdate`] and applies every [`BbUpdate`] it receives from another Agora (a `Remote`
//! subscription: a robot never hears itself). On the bus the changes travel wherever DCDT
//! links carry them: between the Agoras of one process today, over the network where links
//! connect Agoras in other processes.
//!
//! A malformed update (not a symbol, a `local` symbol, a type that contradicts the stored
//! one) is counted and dropped: it never disturbs the blackboard. So is an update past the
//! blackboard's limits ([`crate::board::BbLimits`]: a string too long, a new symbol when
//! guests may create no more, the byte budget), counted also in [`Proxy::over_limit`].

use crate::board::{BbError, Blackboard, Update};
use crossbeam_channel::Receiver;
use mrt_dcdt::{Context, Member, MemberError, Message, MsgType, RequestType};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// A shared blackboard change on the bus.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BbUpdate(pub Update);

impl Message for BbUpdate {
    const TYPE: MsgType = mrt_msgs::ids::BB_UPDATE;
    const NAME: &'static str = "BbUpdate";
}

/// The Proxy Member of one robot.
pub struct Proxy {
    bb: Blackboard,
    outbox: Receiver<Update>,
    rejected: Arc<AtomicU64>,
    over_limit: Arc<AtomicU64>,
}

impl Proxy {
    /// The proxy of `bb` (it takes the blackboard's outbox).
    pub fn new(bb: Blackboard) -> Proxy {
        let outbox = bb.outbox();
        Proxy { bb, outbox, rejected: Arc::default(), over_limit: Arc::default() }
    }

    /// A counter of the updates received and dropped as malformed, readable after the Member
    /// is handed to its Agora.
    pub fn rejected(&self) -> Arc<AtomicU64> {
        self.rejected.clone()
    }

    /// A counter of the received updates dropped because they broke the blackboard's limits
    /// (also counted in [`Proxy::rejected`]).
    pub fn over_limit(&self) -> Arc<AtomicU64> {
        self.over_limit.clone()
    }
}

impl Member for Proxy {
    fn name(&self) -> String {
        format!("bb-proxy-{}", self.bb.robot())
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<BbUpdate>(RequestType::Remote);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            let applied = m.get::<BbUpdate>().map(|u| self.bb.apply(&u.0));
            if let Ok(Err(BbError::Full { .. } | BbError::TooLong { .. })) = &applied {
                self.over_limit.fetch_add(1, Ordering::Relaxed);
            }
            if !matches!(applied, Ok(Ok(()))) {
                let n = self.rejected.fetch_add(1, Ordering::Relaxed);
                if n == 0 {
                    tracing::warn!(
                        robot = self.bb.robot(),
                        "dropped a malformed blackboard update: {applied:?}"
                    );
                }
            }
        }
        for update in self.outbox.try_iter() {
            ctx.publish(BbUpdate(update));
        }
        Ok(())
    }
}
