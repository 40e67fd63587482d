//! The messages `mrt-net-node`, the multi-process tests and the network benchmark exchange:
//! small, self-describing, and of types no robot uses (`0x4E45_54xx`, "NET").

use mrt_dcdt::prelude::{Message, MsgType};

/// A numbered test message: `mrt-net-node --send N` publishes `Ping { seq: 1..=N }`.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Ping {
    /// 1 for the first message a sender created, then 2, 3, ...
    pub seq: u64,
}

impl Message for Ping {
    const TYPE: MsgType = MsgType(0x4E45_5401);
    const NAME: &'static str = "NetPing";
}

/// The benchmark's probe: a payload of the size being measured.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Probe(pub Vec<u8>);

impl Message for Probe {
    const TYPE: MsgType = MsgType(0x4E45_5402);
    const NAME: &'static str = "NetProbe";
}

/// The answer to a [`Probe`], with its payload (`mrt-net-node --echo`).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Echo(pub Vec<u8>);

impl Message for Echo {
    const TYPE: MsgType = MsgType(0x4E45_5403);
    const NAME: &'static str = "NetEcho";
}
