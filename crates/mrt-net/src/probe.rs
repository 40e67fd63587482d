//! The messages `mrt-net-node`, the multi-process tests and the network benchmark exchange:
//! small, self-describing, and of types no robot uses (`0x4E45_54xx`, "NET").
//!
//! Byte payloads are marked `#[serde(with = "serde_bytes")]`: without it serde writes a
//! `Vec<u8>` as a sequence of separate numbers, byte by byte (1 KiB then costs microseconds
//! to encode and decode); with it, one length and one copy. Do the same in your own messages
//! that carry bytes (images, scans).

use mrt_dcdt::prelude::{Message, MsgType};

/// A numbered test message: `mrt-net-node --send N` publishes `Ping { seq: 1..=N }`.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Ping {
    /// 1 for the first message a sender created, then 2, 3, ...
    pub seq: u64,
}

impl Message for Ping {
    const TYPE: MsgType = mrt_msgs::ids::NET_PING;
    const NAME: &'static str = "NetPing";
}

/// The benchmark's probe: a payload of the size being measured.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Probe(#[serde(with = "serde_bytes")] pub Vec<u8>);

impl Message for Probe {
    const TYPE: MsgType = mrt_msgs::ids::NET_PROBE;
    const NAME: &'static str = "NetProbe";
}

/// The answer to a [`Probe`], with its payload (`mrt-net-node --echo`).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Echo(#[serde(with = "serde_bytes")] pub Vec<u8>);

impl Message for Echo {
    const TYPE: MsgType = mrt_msgs::ids::NET_ECHO;
    const NAME: &'static str = "NetEcho";
}

/// The one-way throughput probe: `mrt-net-node --echo` counts them and answers one [`Echo`]
/// per batch. The payload's first four bytes (little-endian) say how many make a batch
/// ([`flood_payload`]), so that the raw zenoh comparison carries the very same bytes.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Flood(#[serde(with = "serde_bytes")] pub Vec<u8>);

impl Message for Flood {
    const TYPE: MsgType = mrt_msgs::ids::NET_FLOOD;
    const NAME: &'static str = "NetFlood";
}

/// A payload of `size` bytes (at least 4) announcing batches of `batch` messages.
pub fn flood_payload(batch: u32, size: usize) -> Vec<u8> {
    let mut p = vec![7u8; size.max(4)];
    p[..4].copy_from_slice(&batch.to_le_bytes());
    p
}

/// Counts [`Flood`] payloads; says when a batch is complete (and starts the next).
#[derive(Debug, Default)]
pub struct FloodCounter(std::sync::atomic::AtomicU32);

impl FloodCounter {
    /// Counts one payload; true when it completes its batch. A payload shorter than four
    /// bytes counts as a batch of one.
    pub fn count(&self, payload: &[u8]) -> bool {
        use std::sync::atomic::Ordering;
        let batch = payload.get(..4).and_then(|b| b.try_into().ok()).map_or(1, u32::from_le_bytes);
        let n = self.0.fetch_add(1, Ordering::AcqRel) + 1;
        if n >= batch.max(1) {
            self.0.store(0, Ordering::Release);
            true
        } else {
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flood_counter_completes_a_batch_every_n_payloads() {
        let c = FloodCounter::default();
        let p = flood_payload(3, 64);
        assert_eq!(p.len(), 64);
        let done: Vec<bool> = (0..7).map(|_| c.count(&p)).collect();
        assert_eq!(done, [false, false, true, false, false, true, false]);
        assert!(FloodCounter::default().count(&[1]), "too short: a batch of one");
        assert!(FloodCounter::default().count(&flood_payload(0, 4)), "0 counts as 1");
    }
}
