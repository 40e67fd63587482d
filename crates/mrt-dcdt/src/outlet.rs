//! The seam between an Agora and a network layer (the manual's links and bridges, §3.2–3.3),
//! kept free of any transport so that `mrt-dcdt` builds and tests without one.
//!
//! - Outbound: a network layer installs an [`Outlet`] with [`AgoraPort::set_outlet`]. Every
//!   message a Member of this Agora shares is offered to it after local delivery, if the
//!   outlet [`wants`](Outlet::wants) its type (some Member elsewhere subscribed to it).
//!   Producers see the outlet's interest through [`Endpoint::has_subscribers`], so a message
//!   nobody anywhere wants is still never built.
//! - Inbound: the network layer hands each message it receives to [`AgoraPort::deliver`],
//!   which shares it with this Agora (and its in-process community) keeping its header: the
//!   receiver's `agora_id`/`member_id` say where it came from, so it is `Remote` for every
//!   Member here. A delivered message is not offered to the outlet again (a bridge, which
//!   forwards what it received, does that itself).
//!
//! [`Endpoint::has_subscribers`]: crate::Endpoint::has_subscribers

pub use crate::egress::Outlet;
use crate::msg::MsgRef;
use crate::shared::AgoraShared;
use mrt_core::{AgoraId, MsgType};
use std::sync::Arc;

/// A network layer's handle on an Agora (see the module doc). Cloneable, `Send + Sync`.
#[derive(Clone)]
pub struct AgoraPort {
    pub(crate) shared: Arc<AgoraShared>,
}

impl AgoraPort {
    /// The Agora's id.
    pub fn id(&self) -> AgoraId {
        self.shared.id
    }

    /// Installs (or, with `None`, removes) the Agora's outlet.
    pub fn set_outlet(&self, outlet: Option<Box<dyn Outlet>>) {
        self.shared.outlet.set(outlet);
    }

    /// Shares a message received from the network with this Agora's Members (and its
    /// in-process community), header unchanged. Returns how many mailboxes it reached.
    pub fn deliver(&self, msg: &MsgRef) -> usize {
        self.shared.route.share(msg.agora_id(), msg.msg_type(), &mut || msg.clone())
    }

    /// The message types that Members of this Agora (or its in-process community) subscribed
    /// to from other Agoras (`Remote` or `All`), sorted: what the network should bring here.
    pub fn remote_interest(&self) -> Vec<MsgType> {
        let mut types = self.shared.route.remote_interest();
        types.sort();
        types.dedup();
        types
    }

    /// The Agora's clock (to stamp what the network layer creates).
    pub fn clock(&self) -> &mrt_core::SharedClock {
        &self.shared.clock
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prelude::*;
    use crate::{wire, SteppedExecutor};
    use mrt_core::{MemberId, SimClock};
    use std::sync::Mutex;
    use std::time::Duration;

    #[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
    struct Ping(u32);
    impl Message for Ping {
        const TYPE: MsgType = MsgType(77);
        const NAME: &'static str = "Ping";
    }

    #[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
    struct Other(u32);
    impl Message for Other {
        const TYPE: MsgType = MsgType(78);
        const NAME: &'static str = "Other";
    }

    /// A wire between two "processes": frames sent by one Agora's outlet, delivered to the
    /// other's port by the test, as a network layer would.
    #[derive(Default)]
    struct Wire {
        wanted: Mutex<Vec<MsgType>>,
        frames: Mutex<Vec<Vec<u8>>>,
    }

    struct WireOutlet(Arc<Wire>);
    impl Outlet for WireOutlet {
        fn wants(&self, ty: MsgType) -> bool {
            self.0.wanted.lock().unwrap().contains(&ty)
        }
        fn send(&self, msg: &MsgRef) {
            self.0.frames.lock().unwrap().push(wire::encode(msg).unwrap());
        }
    }

    struct Pinger(u32);
    impl Member for Pinger {
        fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            self.0 += 1;
            ctx.publish(Ping(self.0));
            ctx.publish(Other(self.0));
            Ok(())
        }
    }

    struct Listener(Arc<Mutex<Vec<(u32, AgoraId, MemberId)>>>, RequestType);
    impl Member for Listener {
        fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            ctx.subscribe_to::<Ping>(self.1);
            Ok(())
        }
        fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            while let Some(m) = ctx.receive_msg() {
                let p = m.get::<Ping>()?;
                self.0.lock().unwrap().push((p.0, m.agora_id(), m.header().member_id));
            }
            Ok(())
        }
    }

    #[test]
    fn messages_leave_through_the_outlet_and_arrive_through_the_port_as_remote() {
        let tick = Duration::from_millis(10);
        // "Process" 1: a pinger alone (nobody here listens).
        let mut one = SteppedExecutor::new(SimClock::new(), tick);
        let mut a = one.agora_builder(1).build().unwrap();
        let p = a.add_member(Pinger(0), Activation::Periodic(tick));
        a.activate_member(p).unwrap();
        let wire = Arc::new(Wire::default());
        a.port().set_outlet(Some(Box::new(WireOutlet(wire.clone()))));
        one.add_agora(a).unwrap();
        // "Process" 2: one Remote listener, one Local listener.
        let mut two = SteppedExecutor::new(SimClock::new(), tick);
        let mut b = two.agora_builder(2).build().unwrap();
        let remote = Arc::new(Mutex::new(Vec::new()));
        let local = Arc::new(Mutex::new(Vec::new()));
        let r = b.add_member(Listener(remote.clone(), RequestType::Remote), Activation::OnMessage);
        let l = b.add_member(Listener(local.clone(), RequestType::Local), Activation::OnMessage);
        b.activate_member(r).unwrap();
        b.activate_member(l).unwrap();
        let port = b.port();
        two.add_agora(b).unwrap();
        two.run_for(tick); // the listeners subscribe
                           // The network layer learns what process 2 wants: Ping, not Other.
        assert_eq!(port.remote_interest(), vec![Ping::TYPE]);
        *wire.wanted.lock().unwrap() = port.remote_interest();
        one.run_for(Duration::from_millis(30));
        let frames = std::mem::take(&mut *wire.frames.lock().unwrap());
        assert_eq!(frames.len(), 3, "three Pings, no Other (nobody wants it)");
        for f in &frames {
            assert_eq!(port.deliver(&wire::decode(f).unwrap()), 1, "the Remote listener only");
        }
        two.run_for(tick);
        let got = remote.lock().unwrap().clone();
        assert_eq!(
            got,
            vec![
                (1, AgoraId(1), MemberId(0)),
                (2, AgoraId(1), MemberId(0)),
                (3, AgoraId(1), MemberId(0))
            ]
        );
        assert!(local.lock().unwrap().is_empty(), "created elsewhere: not Local");
        // Without the outlet nothing leaves.
        one.agoras().for_each(|a| a.port().set_outlet(None));
        one.run_for(Duration::from_millis(20));
        assert!(wire.frames.lock().unwrap().is_empty());
    }
}
