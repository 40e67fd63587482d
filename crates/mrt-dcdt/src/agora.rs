//! The Agora (MRT manual §3.1, §3.3): the process-level object that hosts Members and their
//! PostOffice.

use crate::config::{AgoraConfig, PolicyKind};
use crate::endpoint::Endpoint;
use crate::error::DcdtError;
use crate::member::{Activation, Member, MemberState, Runner, SharedState};
use crate::outlet::AgoraPort;
use crate::policy::MailboxBounds;
use crate::postoffice::{InnerLinkManager, PostOffice, Route};
use crate::shared::AgoraShared;
use crate::waker::Waker;
use mrt_core::{AgoraId, MemberId, SharedClock, WallClock};
use std::path::Path;
use std::sync::Arc;

/// How the Agora was instantiated (§3.3).
#[derive(Clone, Debug, PartialEq)]
pub enum AgoraMode {
    /// No configuration file: Members talk inside this process only.
    Standalone,
    /// From a configuration file: the network half (links, bridges, Finder) uses it.
    Network(Box<AgoraConfig>),
}

/// Builds an [`Agora`]: id, clock, PostOffice policy, in-process community.
pub struct AgoraBuilder {
    id: AgoraId,
    clock: Option<SharedClock>,
    policy: Option<PolicyKind>,
    inner_link: Option<InnerLinkManager>,
    config: Option<AgoraConfig>,
    bounds: MailboxBounds,
}

impl AgoraBuilder {
    /// The clock all of this Agora reads time from (default: a new [`WallClock`]).
    pub fn clock(mut self, clock: SharedClock) -> Self {
        self.clock = Some(clock);
        self
    }

    /// The PostOffice policy (default: the configuration file's, else [`PolicyKind::Pmq`]).
    pub fn policy(mut self, policy: PolicyKind) -> Self {
        self.policy = Some(policy);
        self
    }

    /// The bounds of every subscription's buffer in this Agora, unless the subscription gives
    /// its own (default: [`MailboxBounds::default`], 2048 messages, 32 768 when `Reliable`).
    /// Checked by [`build`](Self::build).
    pub fn mailbox_bounds(mut self, bounds: MailboxBounds) -> Self {
        self.bounds = bounds;
        self
    }

    /// Joins the in-process community of `ilm` (several Agoras in one process).
    pub fn inner_link(mut self, ilm: &InnerLinkManager) -> Self {
        self.inner_link = Some(ilm.clone());
        self
    }

    /// A NETWORK Agora described by this configuration.
    pub fn config(mut self, config: AgoraConfig) -> Self {
        self.config = Some(config);
        self
    }

    /// Builds the Agora. Fails when the community already has an Agora with this id, or the
    /// mailbox bounds are not `1 <= capacity <= reliable_limit`.
    pub fn build(self) -> Result<Agora, DcdtError> {
        let policy =
            self.policy.or_else(|| self.config.as_ref().and_then(|c| c.policy)).unwrap_or_default();
        let bounds = self.bounds.check(self.id)?;
        let post_office = Arc::new(PostOffice::new(self.id, policy, bounds));
        let route = match &self.inner_link {
            Some(ilm) => {
                ilm.join(post_office.clone())?;
                Route::Community(ilm.clone())
            }
            None => Route::Alone(post_office.clone()),
        };
        Ok(self.assemble(post_office, route))
    }

    fn assemble(self, post_office: Arc<PostOffice>, route: Route) -> Agora {
        let clock = self.clock.unwrap_or_else(|| Arc::new(WallClock::new()));
        let shared = Arc::new(AgoraShared::new(self.id, clock, post_office, route));
        let mode = match self.config {
            Some(c) => AgoraMode::Network(Box::new(c)),
            None => AgoraMode::Standalone,
        };
        Agora { shared, mode, inner_link: self.inner_link, slots: Vec::new(), next_member: 0 }
    }
}

struct Slot {
    id: MemberId,
    name: String,
    runner: Option<Runner>,
    state: SharedState,
}

/// "The main object instantiated in every application that makes use of DCDT" (§3.3): hosts
/// Members and their PostOffice.
///
/// ```
/// use mrt_dcdt::prelude::*;
/// use std::time::Duration;
///
/// struct Hello;
/// impl Member for Hello {
///     fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
///         ctx.terminate(); // one cycle is enough
///         Ok(())
///     }
/// }
///
/// let mut agora = Agora::standalone();
/// let hello = agora.add_member(Hello, Activation::Periodic(Duration::from_millis(10)));
/// agora.activate_member(hello)?;
/// let report = agora.lets_work()?; // returns when every Member terminated
/// assert_eq!(report.members[0].cycles, 1);
/// # Ok::<(), mrt_dcdt::DcdtError>(())
/// ```
pub struct Agora {
    pub(crate) shared: Arc<AgoraShared>,
    mode: AgoraMode,
    inner_link: Option<InnerLinkManager>,
    slots: Vec<Slot>,
    next_member: u32,
}

impl Agora {
    /// Starts building an Agora with this id.
    pub fn builder(id: impl Into<AgoraId>) -> AgoraBuilder {
        AgoraBuilder {
            id: id.into(),
            clock: None,
            policy: None,
            inner_link: None,
            config: None,
            bounds: MailboxBounds::default(),
        }
    }

    /// A STANDALONE Agora with id 0, a wall clock and the default policy.
    pub fn standalone() -> Agora {
        let post_office =
            Arc::new(PostOffice::new(AgoraId(0), PolicyKind::default(), MailboxBounds::default()));
        let route = Route::Alone(post_office.clone());
        Agora::builder(0).assemble(post_office, route)
    }

    /// A NETWORK Agora from a configuration file (`new DCDT_Agora("dcdt.cfg")`).
    pub fn from_config(path: impl AsRef<Path>, id: impl Into<AgoraId>) -> Result<Agora, DcdtError> {
        let config = AgoraConfig::from_file(path)?;
        Agora::builder(id).config(config).build()
    }

    /// This Agora's id.
    pub fn id(&self) -> AgoraId {
        self.shared.id
    }

    /// STANDALONE or NETWORK.
    pub fn mode(&self) -> &AgoraMode {
        &self.mode
    }

    /// The clock.
    pub fn clock(&self) -> &SharedClock {
        &self.shared.clock
    }

    /// The PostOffice.
    pub fn post_office(&self) -> &PostOffice {
        &self.shared.post_office
    }

    /// The handle a network layer uses to send this Agora's messages out and deliver the ones
    /// it receives ([`crate::outlet`]).
    pub fn port(&self) -> AgoraPort {
        AgoraPort { shared: self.shared.clone() }
    }

    fn new_member_id(&mut self) -> MemberId {
        let id = MemberId(self.next_member);
        self.next_member += 1;
        let waker = Arc::new(Waker::default());
        self.shared.post_office.register(id, waker.clone());
        self.shared.set_waker(id, waker);
        id
    }

    /// Adds a Member (`AddMember`): creates its mailbox and state; it does not run until
    /// [`activate_member`](Self::activate_member).
    pub fn add_member(&mut self, member: impl Member, activation: Activation) -> MemberId {
        self.add_boxed_member(Box::new(member), activation)
    }

    /// [`add_member`](Self::add_member) for an already boxed Member.
    pub fn add_boxed_member(
        &mut self,
        member: Box<dyn Member>,
        activation: Activation,
    ) -> MemberId {
        let id = self.new_member_id();
        let state = SharedState::default();
        let endpoint = Endpoint::new(self.shared.clone(), id);
        let runner = Runner::new(member, endpoint, activation, state.clone());
        self.slots.push(Slot { id, name: runner.name.clone(), runner: Some(runner), state });
        id
    }

    /// Activates a Member (`ActivateMember`): it runs when an executor runs the Agora — on its
    /// own thread under [`lets_work`](Self::lets_work), in turn under the [`SteppedExecutor`](crate::SteppedExecutor).
    pub fn activate_member(&mut self, id: MemberId) -> Result<(), DcdtError> {
        let slot = self.slot(id)?;
        if slot.state.get() == MemberState::Added {
            slot.state.set(MemberState::Activated);
        }
        Ok(())
    }

    fn slot(&self, id: MemberId) -> Result<&Slot, DcdtError> {
        self.slots
            .iter()
            .find(|s| s.id == id)
            .ok_or(DcdtError::UnknownMember { agora: self.shared.id, member: id })
    }

    /// A Member's state.
    pub fn member_state(&self, id: MemberId) -> Result<MemberState, DcdtError> {
        Ok(self.slot(id)?.state.get())
    }

    /// A Member's name.
    pub fn member_name(&self, id: MemberId) -> Result<&str, DcdtError> {
        Ok(&self.slot(id)?.name)
    }

    /// An endpoint on this Agora's PostOffice for code that is not a Member (a driver thread,
    /// a test, the simulator). It gets its own Member id and mailbox.
    pub fn endpoint(&mut self) -> Endpoint {
        let id = self.new_member_id();
        Endpoint::new(self.shared.clone(), id)
    }

    /// A handle that shuts the Agora down from any thread (like a Member calling `shutdown`).
    pub fn shutdown_handle(&self) -> ShutdownHandle {
        ShutdownHandle(self.shared.clone())
    }

    /// Takes the activated Members' runners out, for an executor.
    pub(crate) fn take_runners(&mut self) -> Vec<Runner> {
        self.slots
            .iter_mut()
            .filter(|s| s.state.get() == MemberState::Activated)
            .filter_map(|s| s.runner.take())
            .collect()
    }
}

impl Drop for Agora {
    fn drop(&mut self) {
        if let Some(ilm) = &self.inner_link {
            ilm.leave(self.shared.id);
        }
    }
}

/// Shuts an Agora down from any thread; see [`Agora::shutdown_handle`].
#[derive(Clone)]
pub struct ShutdownHandle(Arc<AgoraShared>);

impl ShutdownHandle {
    /// Every Member ends within its current cycle.
    pub fn shutdown(&self) {
        self.0.request_shutdown(None)
    }

    /// Whether shutdown was requested.
    pub fn is_shutting_down(&self) -> bool {
        self.0.is_shutting_down()
    }
}
