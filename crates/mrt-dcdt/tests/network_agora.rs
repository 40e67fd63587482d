//! A NETWORK Agora from a configuration file (MRT manual §3.3.1): the policy comes from the
//! file, and a broken file is refused with its file, line and column.

#![allow(clippy::unwrap_used)]

use mrt_dcdt::config::{Channel, ChannelMode};
use mrt_dcdt::{Agora, AgoraMode, DcdtError, PolicyKind};

const MANUAL_EXAMPLE: &str =
    concat!(env!("CARGO_MANIFEST_DIR"), "/../../configs/dcdt/static_link.cfg");

#[test]
fn network_agora_takes_its_policy_and_channels_from_the_file() {
    let agora = Agora::from_config(MANUAL_EXAMPLE, 7).unwrap();
    assert_eq!(agora.id().0, 7);
    assert_eq!(agora.post_office().policy(), PolicyKind::Slwb);
    let AgoraMode::Network(cfg) = agora.mode() else { panic!("expected a NETWORK Agora") };
    assert_eq!(cfg.port, 2003);
    assert!(matches!(
        cfg.channels[..],
        [Channel::Ip {
            mode: ChannelMode::Link,
            level: 0,
            local_port: 3000,
            remote_port: 3000,
            ..
        }]
    ));
    assert_eq!(*Agora::standalone().mode(), AgoraMode::Standalone);
}

#[test]
fn a_broken_file_is_refused_with_file_line_and_column() {
    let dir = std::env::temp_dir().join(format!("mrt-dcdt-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("broken.cfg");
    std::fs::write(&path, "192.168.0.1 225.0.0.1 2003\nPostOffice: FAST\n").unwrap();
    let err = Agora::from_config(&path, 1).err().unwrap();
    assert!(matches!(err, DcdtError::Config(_)));
    let text = err.to_string();
    assert!(text.contains("broken.cfg:2:13"), "{text}");
    assert!(text.contains("FAST"), "{text}");
    let missing = Agora::from_config(dir.join("missing.cfg"), 1).err().unwrap();
    assert!(missing.to_string().contains("missing.cfg"), "{missing}");
    std::fs::remove_dir_all(&dir).unwrap();
}
