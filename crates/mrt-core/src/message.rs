//! The [`Message`] trait: what makes a Rust type a DCDT message (MRT manual §3.2).
//!
//! It lives here, below both the bus (`mrt-dcdt`) and the catalogue of standard messages
//! (`mrt-msgs`), so that the catalogue needs no bus and the bus knows no robot type.

use crate::MsgType;
use serde::{de::DeserializeOwned, Serialize};

/// A Rust type that travels on the bus as a DCDT message.
///
/// The type declares its stable [`MsgType`] once; Members then publish and receive values of
/// the type without casts. All Agoras of a community must agree on the ids (§3.2). Ids from
/// [`RESERVED_TYPES_START`] up are reserved for MRT's own standard messages, listed in one
/// table (`mrt_msgs::ids`).
///
/// A message must decode to what it encoded (postcard): it is encoded when it leaves the
/// process, and a small one of plain data is also copied encoded into each subscriber's
/// mailbox slot inside the process (`mrt-dcdt`'s `PMQ`). A field skipped by serde is lost on
/// both ways.
///
/// ```
/// use mrt_core::{Message, MsgType};
/// use serde::{Deserialize, Serialize};
///
/// #[derive(Debug, Serialize, Deserialize)]
/// struct BallSeen { distance: f32, bearing: f32 }
///
/// impl Message for BallSeen {
///     const TYPE: MsgType = MsgType(100);
///     const NAME: &'static str = "BallSeen";
/// }
/// ```
pub trait Message: Serialize + DeserializeOwned + Send + Sync + 'static {
    /// The stable, community-wide type id.
    const TYPE: MsgType;
    /// A short human-readable name, used in logs and error messages.
    const NAME: &'static str;
}

/// The first message type id reserved for MRT's own standard messages.
pub const RESERVED_TYPES_START: u32 = 0xFFFF_0000;
