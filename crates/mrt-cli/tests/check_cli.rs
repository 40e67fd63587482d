//! `mrt check`: every shipped DCDT configuration passes, and a configuration an Agora would
//! refuse (a serial line's options included, as docs/network.md says) is refused here too,
//! naming the file and what is wrong.

#![allow(clippy::unwrap_used)]

use std::path::Path;
use std::process::Command;

fn check(files: &[&Path]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_mrt")).arg("check").args(files).output().unwrap();
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (out.status.success(), text(&out.stdout), text(&out.stderr))
}

#[test]
fn every_shipped_configuration_passes() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/dcdt");
    let files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "cfg"))
        .collect();
    assert!(!files.is_empty());
    let paths: Vec<&Path> = files.iter().map(|p| p.as_path()).collect();
    let (ok, out, err) = check(&paths);
    assert!(ok, "{err}");
    assert_eq!(out.matches(": ok").count(), files.len(), "{out}");
}

#[test]
fn serial_options_the_network_refuses_are_refused() {
    let dir = std::env::temp_dir().join(format!("mrt-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (option, why) in [
        ("baudrate=0", "baudrate `0` is not a rate of 50 to 4000000"),
        ("baudrate=99999999999999999999", "is not a rate of 50 to 4000000"),
        ("parity=even", "unknown option `parity=even`"),
    ] {
        let file = dir.join("serial.cfg");
        std::fs::write(
            &file,
            format!("127.0.0.1 239.255.0.1 2003\nser link 0 /dev/ttyS0,{option}\n"),
        )
        .unwrap();
        let (ok, _, err) = check(&[&file]);
        assert!(!ok, "{option} is refused");
        assert!(err.contains(&file.display().to_string()) && err.contains(why), "{option}: {err}");
    }
    let file = dir.join("good.cfg");
    std::fs::write(
        &file,
        "127.0.0.1 239.255.0.1 2003\nser link 0 /dev/ttyS0,baudrate=57600,connect\n",
    )
    .unwrap();
    assert!(check(&[&file]).0);
    std::fs::remove_dir_all(&dir).unwrap();
}
