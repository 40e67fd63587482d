//! Binary and XML messages: DCDT wire frames and the self-describing XML message.

use super::{Harness, Seed, Target};
use crate::FuzzError;
use mrt_core::{AgoraId, MemberId, MsgType, Time};
use mrt_dcdt::describe::{Attribute, Object, SelfDescribing};
use mrt_dcdt::wire::{decode, encode, HEADER_LEN};
use mrt_dcdt::{DeliveryWarranty, Message, Msg, MsgHeader, RawPayload};
use mrt_msgs::robot::{RobotCommand, WorldSnapshot};
use std::path::Path;

/// DCDT wire frames.
pub(super) const WIRE: Target = Target {
    name: "wire",
    about: "DCDT wire frames: wire::decode, the payload read as every standard message type, a decoded frame re-encoded to the same bytes",
    keywords: &["DCDT"],
    structured: None,
    seeds: wire_seeds,
    harness: |_| Ok(Box::new(Frames)),
};

/// Calls `$f!(Type)` for every standard message type of MRT.
macro_rules! message_types {
    ($f:ident) => {
        $f!(WorldSnapshot);
        $f!(RobotCommand);
        $f!(SelfDescribing);
        $f!(mrt_blackboard::BbUpdate);
        $f!(mrt_fuzzy::member::BrianInputs);
        $f!(mrt_fuzzy::member::BrianCommands);
        $f!(mrt_script::member::BehaviorStatus);
        $f!(mrt_script::member::ReloadRequest);
        $f!(mrt_msgs::MateReport);
        $f!(mrt_msgs::Odometry);
        $f!(mrt_msgs::CameraFrame);
        $f!(mrt_msgs::SonarScan);
        $f!(mrt_msgs::MotorCommand);
        $f!(mrt_msgs::GameInfo);
        $f!(mrt_msgs::Localization);
        $f!(mrt_msgs::Percepts);
        $f!(mrt_msgs::PlanRequest);
        $f!(mrt_msgs::PlannedPath);
        $f!(mrt_msgs::BehaviorPush);
        $f!(mrt_msgs::BehaviorPushReply);
        $f!(mrt_msgs::HfsmStructure);
    };
}

fn header(msg_type: MsgType) -> MsgHeader {
    MsgHeader {
        msg_type,
        agora_id: AgoraId(3),
        member_id: MemberId(7),
        priority: 5,
        warranty: DeliveryWarranty::Reliable,
        creation_time: Time(1_234_567_890),
    }
}

fn sample_describing() -> SelfDescribing {
    SelfDescribing::new(Time(12_500_000_000)).with_object(
        Object::new("ball", "Ball")
            .with(Attribute::number("distance", 2.4, 0.1, 0.9))
            .with(Attribute::symbol("colour", "orange", 0.0, 1.0)),
    )
}

/// A frame of every standard message (a sample of the richer ones), and a raw one.
fn wire_seeds(_root: &Path) -> Result<Vec<Seed>, FuzzError> {
    let mut seeds = Vec::new();
    let mut push = |name: &str, msg: mrt_dcdt::MsgRef| -> Result<(), FuzzError> {
        let frame = encode(&msg).map_err(|e| FuzzError::Harness {
            target: "wire".to_string(),
            message: format!("cannot encode a {name}: {e}"),
        })?;
        seeds.push(Seed::new(name, frame));
        Ok(())
    };
    macro_rules! default_frame {
        ($t:ty) => {
            push(<$t as Message>::NAME, Msg::new(header(<$t>::TYPE), <$t>::default()).into_ref())?;
        };
    }
    default_frame!(WorldSnapshot);
    default_frame!(RobotCommand);
    default_frame!(mrt_fuzzy::member::BrianInputs);
    default_frame!(mrt_fuzzy::member::BrianCommands);
    default_frame!(mrt_script::member::BehaviorStatus);
    default_frame!(mrt_msgs::Odometry);
    default_frame!(mrt_msgs::CameraFrame);
    default_frame!(mrt_msgs::SonarScan);
    default_frame!(mrt_msgs::BehaviorPushReply);
    default_frame!(mrt_msgs::HfsmStructure);
    let pushed = mrt_msgs::BehaviorPush {
        robot: 3,
        request: 17,
        file: "attacker.lua".to_string(),
        source: "-- an edited behavior\nfunction go() end\n".to_string(),
    };
    push("BehaviorPush", Msg::new(header(mrt_msgs::BehaviorPush::TYPE), pushed).into_ref())?;
    push("SelfDescribing", Msg::new(header(SelfDescribing::TYPE), sample_describing()).into_ref())?;
    let update = mrt_blackboard::BbUpdate(mrt_blackboard::Update {
        from: 2,
        symbol: "*.var.team.config.players".to_string(),
        value: mrt_blackboard::Value::Int(4),
    });
    push("BbUpdate", Msg::new(header(mrt_blackboard::BbUpdate::TYPE), update).into_ref())?;
    push("raw", Msg::new(header(MsgType(42)), RawPayload::new(b"hello".to_vec())).into_ref())?;
    Ok(seeds)
}

struct Frames;

impl Harness for Frames {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        // The input as it came, then with its header made consistent (magic, version,
        // warranty, reserved byte, payload length), so that mutated payloads reach the
        // message decoders.
        frame(input) || (input.len() >= HEADER_LEN && frame(&repair(input)))
    }
}

/// A frame whose header says what its bytes are.
fn repair(input: &[u8]) -> Vec<u8> {
    let mut f = input.to_vec();
    f[..4].copy_from_slice(&mrt_dcdt::wire::MAGIC);
    f[4] = mrt_dcdt::wire::VERSION;
    f[5] %= 3;
    f[7] = 0;
    let len = u32::try_from(f.len() - HEADER_LEN).unwrap_or(u32::MAX);
    f[28..32].copy_from_slice(&len.to_le_bytes());
    f
}

/// Decodes a frame and reads its payload every way; `true` if it decoded.
fn frame(input: &[u8]) -> bool {
    let Ok(msg) = decode(input) else { return false };
    // Documented: a raw payload is written as is, so the frame comes back byte for byte.
    match encode(&msg) {
        Ok(again) => assert!(again == input, "a decoded frame re-encodes differently"),
        Err(e) => panic!("a decoded frame does not encode: {e}"),
    }
    let payload = input.get(HEADER_LEN..).unwrap_or_default().to_vec();
    // The payload as the message its header names, and as every other standard type.
    macro_rules! try_as {
        ($t:ty) => {
            let _ = msg.get::<$t>();
            let as_t = Msg::new(header(<$t>::TYPE), RawPayload::new(payload.clone())).into_ref();
            let _ = as_t.get::<$t>();
        };
    }
    message_types!(try_as);
    true
}

/// The self-describing XML message.
pub(super) const XML: Target = Target {
    name: "xml",
    about: "self-describing XML messages: SelfDescribing::from_xml, and a parsed message's to_xml read back the same",
    keywords: &["<message", "</message>", "<object", "</object>", "<attribute", "/>", "timestamp=", "name=", "class=", "value=", "symbol=", "variability=", "reliability=", "&amp;", "&lt;", "&#0;", "&#x1F600;", "<!DOCTYPE message>", "<?xml version=\"1.0\"?>", "<!--", "-->", "<![CDATA[", "]]>"],
    structured: None,
    seeds: |_| {
        Ok(vec![
            Seed::new("sample", sample_describing().to_xml()),
            Seed::new("empty", SelfDescribing::new(Time(0)).to_xml()),
            Seed::new(
                "declared",
                format!(
                    "<?xml version=\"1.0\"?>\n<!DOCTYPE message>\n<!-- a comment -->\n{}",
                    SelfDescribing::new(Time(1))
                        .with_object(Object::new("a&b", "<C>").with(Attribute::number(
                            "x",
                            f64::NAN,
                            0.0,
                            0.5
                        )))
                        .to_xml()
                ),
            ),
        ])
    },
    harness: |_| Ok(Box::new(Xml)),
};

struct Xml;

impl Harness for Xml {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        let Ok(text) = std::str::from_utf8(input) else { return false };
        let Ok(msg) = SelfDescribing::from_xml(text) else { return false };
        // Documented: from_xml reads to_xml's text back exactly.
        let xml = msg.to_xml();
        match SelfDescribing::from_xml(&xml) {
            Ok(again) => assert_eq!(again.to_xml(), xml, "to_xml's text reads back differently"),
            Err(e) => panic!("to_xml's text does not read back: {e}\n{xml}"),
        }
        true
    }
}
