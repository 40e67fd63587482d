//! The wire form of a DCDT message: what crosses a link when a message leaves the process.
//!
//! Inside a process messages are shared by reference (small plain ones copied into the
//! mailbox slots, see `parcel`). A link encodes a
//! message as one frame: a fixed 32-byte little-endian header, then the payload (postcard for
//! typed messages, as-is for raw ones). The receiver gets a raw message whose typed payload is
//! decoded once, on first typed access ([`Msg::get`](crate::Msg::get)).
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 4 | magic `DCDT` |
//! | 4 | 1 | frame version (1) |
//! | 5 | 1 | delivery warranty (0 none, 1 retransmit, 2 reliable) |
//! | 6 | 1 | priority |
//! | 7 | 1 | reserved, 0 |
//! | 8 | 4 | message type |
//! | 12 | 4 | Agora id |
//! | 16 | 4 | Member id |
//! | 20 | 8 | creation time, ns |
//! | 28 | 4 | payload length |
//! | 32 | n | payload |

use crate::error::DcdtError;
pub use crate::frame::{WireError, HEADER_LEN, MAGIC, MAX_PAYLOAD, VERSION};
use crate::msg::{DeliveryWarranty, Msg, MsgHeader, MsgRef, RawPayload};
use mrt_core::{AgoraId, MemberId, MsgType, Time};

/// Encodes a message as one frame.
pub fn encode(msg: &Msg) -> Result<Vec<u8>, DcdtError> {
    let mut out = Vec::with_capacity(HEADER_LEN + msg.payload().len());
    encode_into(msg, &mut out)?;
    Ok(out)
}

/// Encodes a message as one frame at the end of `out` (after a transport's own prefix, say),
/// with no intermediate buffer. On error `out` is left as it was.
pub fn encode_into(msg: &Msg, out: &mut Vec<u8>) -> Result<(), DcdtError> {
    let start = out.len();
    let h = msg.header();
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&[VERSION, h.warranty.code(), h.priority, 0]);
    out.extend_from_slice(&h.msg_type.0.to_le_bytes());
    out.extend_from_slice(&h.agora_id.0.to_le_bytes());
    out.extend_from_slice(&h.member_id.0.to_le_bytes());
    out.extend_from_slice(&h.creation_time.as_nanos().to_le_bytes());
    let len_at = out.len();
    out.extend_from_slice(&[0; 4]);
    if let Err(e) = msg.payload().encode_into(out) {
        out.truncate(start);
        return Err(e);
    }
    let len = out.len() - len_at - 4;
    if len > MAX_PAYLOAD {
        out.truncate(start);
        return Err(WireError::TooLarge(len).into());
    }
    // Cannot truncate: checked against MAX_PAYLOAD above.
    out[len_at..len_at + 4].copy_from_slice(&(len as u32).to_le_bytes());
    Ok(())
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    let mut a = [0u8; 4];
    a.copy_from_slice(&b[at..at + 4]);
    u32::from_le_bytes(a)
}

/// Decodes one frame into a shared raw message. Never panics, whatever the bytes.
pub fn decode(frame: &[u8]) -> Result<MsgRef, WireError> {
    if frame.len() < HEADER_LEN {
        return Err(WireError::Truncated { needed: HEADER_LEN, got: frame.len() });
    }
    let (head, rest) = frame.split_at(HEADER_LEN);
    if head[0..4] != MAGIC {
        return Err(WireError::BadMagic);
    }
    if head[4] != VERSION {
        return Err(WireError::Version(head[4]));
    }
    let warranty = DeliveryWarranty::from_code(head[5]).ok_or(WireError::Warranty(head[5]))?;
    if head[7] != 0 {
        return Err(WireError::Reserved(head[7]));
    }
    let mut t = [0u8; 8];
    t.copy_from_slice(&head[20..28]);
    let len = u32_at(head, 28) as usize;
    if len > MAX_PAYLOAD {
        return Err(WireError::TooLarge(len));
    }
    if rest.len() < len {
        return Err(WireError::Truncated { needed: HEADER_LEN + len, got: frame.len() });
    }
    if rest.len() > len {
        return Err(WireError::Trailing(rest.len() - len));
    }
    let header = MsgHeader {
        msg_type: MsgType(u32_at(head, 8)),
        agora_id: AgoraId(u32_at(head, 12)),
        member_id: MemberId(u32_at(head, 16)),
        priority: head[6],
        warranty,
        creation_time: Time(u64::from_le_bytes(t)),
    };
    Ok(Msg::new(header, RawPayload::new(rest.to_vec())).into_ref())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Message;
    use proptest::prelude::*;
    use serde::{Deserialize, Serialize};

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Sonar {
        ranges: Vec<f32>,
    }
    impl Message for Sonar {
        const TYPE: MsgType = MsgType(40);
        const NAME: &'static str = "Sonar";
    }

    fn header() -> MsgHeader {
        MsgHeader {
            msg_type: Sonar::TYPE,
            member_id: MemberId(3),
            agora_id: AgoraId(9),
            priority: 7,
            warranty: DeliveryWarranty::Reliable,
            creation_time: Time(123_456_789),
        }
    }

    #[test]
    fn typed_message_crosses_the_wire_and_decodes_lazily() {
        let m = Msg::new(header(), Sonar { ranges: vec![1.0, 2.5] }).into_ref();
        let frame = encode(&m).unwrap();
        // 32-byte header + postcard: 1-byte length + 2 × 4-byte floats.
        assert_eq!(frame.len(), 32 + 9);
        assert_eq!(&frame[..4], b"DCDT");
        let back = decode(&frame).unwrap();
        assert_eq!(back.header(), m.header());
        assert_eq!(back.get::<Sonar>().unwrap(), &Sonar { ranges: vec![1.0, 2.5] });
    }

    #[test]
    fn a_frame_is_written_after_a_prefix_in_one_buffer_or_not_at_all() {
        let m = Msg::new(header(), Sonar { ranges: vec![1.0, 2.5] }).into_ref();
        let mut out = b"envelope".to_vec();
        encode_into(&m, &mut out).unwrap();
        assert_eq!(&out[..8], b"envelope");
        assert_eq!(out[8..], encode(&m).unwrap()[..]);
        // Payload length field: postcard's Vec<f32> of two = 1 length byte + 2 × 4 bytes.
        assert_eq!(out[8 + 28..8 + 32], 9u32.to_le_bytes());
        let huge = Msg::new(header(), RawPayload::new(vec![0; MAX_PAYLOAD + 1])).into_ref();
        let mut out = b"envelope".to_vec();
        let e = encode_into(&huge, &mut out);
        assert!(e.is_err(), "{e:?}");
        assert_eq!(out, b"envelope", "a failed encode leaves the buffer as it was");
    }

    #[test]
    fn bad_frames_are_errors() {
        let m = Msg::new(header(), RawPayload::new(vec![1, 2, 3])).into_ref();
        let frame = encode(&m).unwrap();
        assert_eq!(decode(&frame).unwrap().bytes(), Some(&[1u8, 2, 3][..]));
        assert!(matches!(decode(&frame[..10]), Err(WireError::Truncated { needed: 32, got: 10 })));
        assert!(matches!(decode(&frame[..34]), Err(WireError::Truncated { needed: 35, got: 34 })));
        let mut bad = frame.clone();
        bad[0] = b'X';
        assert!(matches!(decode(&bad), Err(WireError::BadMagic)));
        let mut bad = frame.clone();
        bad[4] = 2;
        assert!(matches!(decode(&bad), Err(WireError::Version(2))));
        let mut bad = frame.clone();
        bad[5] = 9;
        assert!(matches!(decode(&bad), Err(WireError::Warranty(9))));
        let mut bad = frame.clone();
        bad[7] = 1;
        assert!(matches!(decode(&bad), Err(WireError::Reserved(1))));
        let mut bad = frame.clone();
        bad[28..32].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(matches!(decode(&bad), Err(WireError::TooLarge(_))));
        let mut bad = frame;
        bad.push(0);
        assert!(matches!(decode(&bad), Err(WireError::Trailing(1))));
    }

    proptest! {
        #[test]
        fn decode_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..128)) {
            let _ = decode(&bytes);
        }

        #[test]
        fn decode_never_panics_on_valid_headers_with_random_tails(tail in proptest::collection::vec(any::<u8>(), 0..64), len in 0u32..100) {
            let mut f = Vec::from(MAGIC);
            f.extend_from_slice(&[1, 0, 0, 0]);
            f.extend_from_slice(&[0; 20]);
            f.extend_from_slice(&len.to_le_bytes());
            f.extend_from_slice(&tail);
            if let Ok(m) = decode(&f) {
                prop_assert_eq!(m.payload_len(), len as usize);
                // Typed access on garbage is an error, not a panic.
                let _ = m.get::<Sonar>();
            }
        }
    }
}
