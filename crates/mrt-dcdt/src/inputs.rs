//! A Member's inputs declared once: each message type it reads, from where, and what to do with
//! one. [`Inputs::subscribe`] (in `init`) subscribes to them all; [`Inputs::drain`] (in
//! `do_your_job`) hands every waiting message to the handler of its type. The subscriptions
//! and the dispatch cannot disagree, and no Member sorts its mail by type by hand.
//!
//! ```
//! use mrt_dcdt::{Context, Inputs, Member, MemberError, RequestType};
//! # use serde::{Deserialize, Serialize};
//! # #[derive(Clone, Debug, Serialize, Deserialize)] struct Ping(u32);
//! # #[derive(Clone, Debug, Serialize, Deserialize)] struct Pong(u32);
//! # impl mrt_dcdt::Message for Ping { const TYPE: mrt_dcdt::MsgType = mrt_dcdt::MsgType(0x8000_0001); const NAME: &'static str = "Ping"; }
//! # impl mrt_dcdt::Message for Pong { const TYPE: mrt_dcdt::MsgType = mrt_dcdt::MsgType(0x8000_0002); const NAME: &'static str = "Pong"; }
//!
//! /// Counts pings and keeps the latest pong.
//! struct Listener {
//!     inputs: Inputs<Listener>,
//!     pings: u32,
//!     pong: Option<u32>,
//! }
//!
//! impl Listener {
//!     fn new() -> Self {
//!         let inputs = Inputs::<Listener>::new()
//!             .on::<Ping>(RequestType::Local, |l, _| l.pings += 1)
//!             .on::<Pong>(RequestType::All, |l, p| l.pong = Some(p.0));
//!         Listener { inputs, pings: 0, pong: None }
//!     }
//! }
//!
//! impl Member for Listener {
//!     fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
//!         self.inputs.subscribe(ctx);
//!         Ok(())
//!     }
//!
//!     fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
//!         self.inputs.clone().drain(self, ctx)?;
//!         Ok(())
//!     }
//! }
//! ```

use crate::endpoint::Context;
use crate::error::DcdtError;
use crate::msg::{Message, MsgRef};
use crate::policy::RequestType;
use mrt_core::MsgType;
use std::sync::Arc;

/// What a Member does with one message of a type it declared.
type Handler<M> = Arc<dyn Fn(&mut M, &MsgRef) -> Result<(), DcdtError> + Send + Sync>;

/// One declared input.
struct Input<M> {
    ty: MsgType,
    from: RequestType,
    handle: Handler<M>,
}

impl<M> Clone for Input<M> {
    fn clone(&self) -> Self {
        Input { ty: self.ty, from: self.from, handle: Arc::clone(&self.handle) }
    }
}

/// The message types a Member of type `M` reads, each with where it comes from and its
/// handler (module doc). Cloning is cheap (the declarations are shared), which is how a Member
/// drains its own inputs: `self.inputs.clone().drain(self, ctx)`.
pub struct Inputs<M> {
    inputs: Arc<Vec<Input<M>>>,
}

impl<M> Clone for Inputs<M> {
    fn clone(&self) -> Self {
        Inputs { inputs: Arc::clone(&self.inputs) }
    }
}

impl<M> Default for Inputs<M> {
    fn default() -> Self {
        Inputs { inputs: Arc::new(Vec::new()) }
    }
}

impl<M: 'static> Inputs<M> {
    /// No inputs yet.
    pub fn new() -> Self {
        Inputs::default()
    }

    /// Reads messages of type `T` from `from` with `handle`. A second declaration of the same
    /// type replaces the first.
    pub fn on<T: Message>(self, from: RequestType, handle: fn(&mut M, &T)) -> Self {
        self.declare(
            T::TYPE,
            from,
            Arc::new(move |m, msg| {
                handle(m, msg.get::<T>()?);
                Ok(())
            }),
        )
    }

    /// Reads messages of type `T` from `from` as they came (a [`MsgRef`], no copy of the
    /// payload): for a Member that keeps a large message to read later.
    pub fn on_msg<T: Message>(self, from: RequestType, handle: fn(&mut M, &MsgRef)) -> Self {
        self.declare(
            T::TYPE,
            from,
            Arc::new(move |m, msg| {
                handle(m, msg);
                Ok(())
            }),
        )
    }

    fn declare(mut self, ty: MsgType, from: RequestType, handle: Handler<M>) -> Self {
        let inputs = Arc::make_mut(&mut self.inputs);
        inputs.retain(|i| i.ty != ty);
        inputs.push(Input { ty, from, handle });
        self
    }

    /// Subscribes to every declared type (call it in `init`).
    pub fn subscribe(&self, ctx: &Context<'_>) {
        for i in self.inputs.iter() {
            ctx.subscribe(i.ty, i.from);
        }
    }

    /// The declared types, in declaration order.
    pub fn types(&self) -> impl Iterator<Item = MsgType> + '_ {
        self.inputs.iter().map(|i| i.ty)
    }

    /// Hands every waiting message to the handler of its type (call it in `do_your_job`);
    /// returns how many were handled. A message of a type not declared (subscribed by other
    /// means) is left unhandled and not counted. A payload that is not its type's (a raw
    /// payload that does not decode) is an error, after the messages before it were handled.
    pub fn drain(&self, member: &mut M, ctx: &mut Context<'_>) -> Result<usize, DcdtError> {
        let mut handled = 0;
        while let Some(msg) = ctx.receive_msg() {
            if let Some(i) = self.inputs.iter().find(|i| i.ty == msg.msg_type()) {
                (i.handle)(member, &msg)?;
                handled += 1;
            }
        }
        Ok(handled)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Activation, Member, MemberError, SteppedExecutor};
    use mrt_core::SimClock;
    use serde::{Deserialize, Serialize};
    use std::sync::Mutex;
    use std::time::Duration;

    #[derive(Clone, Debug, Serialize, Deserialize)]
    struct Ping(u32);
    impl Message for Ping {
        const TYPE: MsgType = MsgType(0x8000_0101);
        const NAME: &'static str = "Ping";
    }

    #[derive(Clone, Debug, Serialize, Deserialize)]
    struct Pong(u32);
    impl Message for Pong {
        const TYPE: MsgType = MsgType(0x8000_0102);
        const NAME: &'static str = "Pong";
    }

    /// Sends two pings and a pong each job.
    struct Sender;
    impl Member for Sender {
        fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            ctx.publish(Ping(1));
            ctx.publish(Pong(7));
            ctx.publish(Ping(2));
            Ok(())
        }
    }

    /// What the listener saw: the sum of the pings, the pongs in order, messages handled.
    type Seen = Arc<Mutex<(u32, Vec<u32>, usize)>>;

    struct Listener {
        inputs: Inputs<Listener>,
        pings: u32,
        pongs: Vec<u32>,
        seen: Seen,
    }

    impl Member for Listener {
        fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            self.inputs.subscribe(ctx);
            Ok(())
        }
        fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            let handled = self.inputs.clone().drain(self, ctx)?;
            if let Ok(mut s) = self.seen.lock() {
                *s = (self.pings, self.pongs.clone(), s.2 + handled);
            }
            Ok(())
        }
    }

    #[test]
    fn each_declared_type_is_subscribed_and_handed_to_its_handler() {
        let seen: Seen = Arc::default();
        let inputs = Inputs::new()
            .on::<Ping>(RequestType::Local, |l: &mut Listener, p| l.pings += p.0)
            .on::<Pong>(RequestType::Local, |l, p| l.pongs.push(p.0));
        assert_eq!(inputs.types().collect::<Vec<_>>(), [Ping::TYPE, Pong::TYPE]);
        let listener = Listener { inputs, pings: 0, pongs: Vec::new(), seen: seen.clone() };
        let mut exec = SteppedExecutor::new(SimClock::new(), Duration::from_millis(10));
        let mut agora = exec.agora_builder(1).build().unwrap();
        let s = agora.add_member(Sender, Activation::Periodic(Duration::from_millis(10)));
        let l = agora.add_member(listener, Activation::OnMessage);
        agora.activate_member(s).unwrap();
        agora.activate_member(l).unwrap();
        exec.add_agora(agora).unwrap();
        exec.run_for(Duration::from_millis(50));
        exec.finish();
        let (pings, pongs, handled) = seen.lock().unwrap().clone();
        assert!(pongs.len() >= 2 && pongs.iter().all(|p| *p == 7), "{pongs:?}");
        assert_eq!(pings, 3 * pongs.len() as u32, "two pings (1 + 2) a pong");
        assert_eq!(handled, 3 * pongs.len());
    }

    #[test]
    fn a_second_declaration_of_a_type_replaces_the_first() {
        let inputs = Inputs::<u32>::new()
            .on::<Ping>(RequestType::Local, |n, _| *n += 1)
            .on::<Pong>(RequestType::All, |n, _| *n += 10)
            .on::<Ping>(RequestType::Remote, |n, _| *n += 100);
        assert_eq!(inputs.types().collect::<Vec<_>>(), [Pong::TYPE, Ping::TYPE]);
        // A clone shares the declarations; declaring on it leaves the original as it was.
        let more = inputs.clone().on::<Pong>(RequestType::Local, |n, _| *n += 1000);
        assert_eq!(more.types().count(), 2);
        assert_eq!(inputs.inputs[0].from, RequestType::All);
        assert_eq!(more.inputs[1].from, RequestType::Local);
    }
}
