//! # mrt-net: DCDT links and bridges over zenoh
//!
//! The MRT manual (ch. 3) lets Agoras in other processes and on other machines find each other
//! (Finder), connect by links or bridges, and exchange exactly the message types that remote
//! Members subscribed to. This crate builds that on [zenoh] 1.x and on `mrt-dcdt`'s network
//! seam ([`mrt_dcdt::outlet`]); it writes no transport of its own.
//!
//! | manual | here |
//! |---|---|
//! | network line `<ip> <multicast> <port>` | multicast scouting on `<multicast>:<port>` (the Finder); the Agora listens on `tcp/<ip>:<ephemeral port>`, which scouting advertises (so that several Agoras of one machine share the line) |
//! | `ip link/bridge <lev> <laddr> <lport> <raddr> <rport>` | listen on `tcp/<laddr>:<lport>`, connect to `tcp/<raddr>:<rport>` |
//! | `ser link/bridge <lev> <device>` | zenoh's serial transport on `<device>`: this end waits, or opens the line when the device field ends in `,connect` (docs/network.md) |
//! | `link` | a zenoh **peer**: sends what its Members create, forwards nothing |
//! | `bridge` | a zenoh **router**: zenoh forwards data and declarations between the networks it joins, over a loop-free route |
//! | Finder | scouting (multicast, gossip) finds the Agoras; a liveliness token `mrt/agora/<id>` says which are up |
//! | remote subscriptions | a liveliness token `mrt/want/<id>/<type>` per type that some Member subscribed to as `Remote` or `All`: a message leaves only if some other Agora holds one for its type |
//! | delivery warranty | `None` → congestion control *drop*, express; `Retransmit` → *drop*, batched; `Reliable` → *block* (TCP links retransmit every frame; what differs is whether a congested queue drops it) |
//! | priority 0–255 | zenoh priorities: 0 *data* (the default), 1–63 *data-high*, 64–127 *interactive-low*, 128–191 *interactive-high*, 192–255 *real-time* |
//!
//! Frames are `mrt-dcdt`'s wire frames ([`mrt_dcdt::wire`]) in a 16-byte [`envelope`] that
//! names the send: the header travels, so the receiver's `agora_id`/`member_id` say where a
//! message came from. A malformed or oversized frame is counted and dropped; a frame of a type
//! nobody here subscribed to (a newer peer's type) is dropped with one warning; a send already
//! delivered (the same envelope, by a second route) is not delivered twice.
//!
//! ```no_run
//! use mrt_net::{NetConfig, NetLink};
//! let agora = mrt_dcdt::Agora::builder(1).build()?;
//! let link = NetLink::attach(&agora, &NetConfig::loopback(7451, &[7452]))?;
//! // ... add Members, run the Agora; messages cross to Agora 2 on port 7452.
//! println!("up: {:?}", link.agoras());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! [zenoh]: https://zenoh.io
#![deny(missing_docs)]

mod config;
mod link;
pub mod probe;

pub use config::{NetConfig, NetError};
pub use link::{
    envelope, NetLink, NetPresence, NetStats, RawPort, RawSubscription, RawToken, ENVELOPE,
};

/// Joins a NETWORK Agora (built by `Agora::from_config(file, id)`) to the network its
/// configuration file describes.
///
/// ```no_run
/// let agora = mrt_dcdt::Agora::from_config("configs/dcdt/same_machine.cfg", 1)?;
/// let link = mrt_net::connect(&agora)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn connect(agora: &mrt_dcdt::Agora) -> Result<NetLink, NetError> {
    match agora.mode() {
        mrt_dcdt::AgoraMode::Network(cfg) => {
            NetLink::attach(agora, &NetConfig::from_agora_config(cfg)?)
        }
        mrt_dcdt::AgoraMode::Standalone => Err(NetError::Standalone(agora.id().0)),
    }
}
