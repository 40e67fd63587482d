//! Recordings survive interruption: Ctrl-C (or SIGTERM) on `mrt sim --record` finishes the
//! file, and `mrt replay` reads a file cut short up to the cut, `--recover` writing a clean
//! copy.

#![allow(clippy::unwrap_used)]

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn mrt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mrt"))
}

/// `mrt replay FILE`: (success, stdout, stderr).
fn replay(args: &[&std::ffi::OsStr]) -> (bool, String, String) {
    let out = mrt().arg("replay").args(args).output().unwrap();
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (out.status.success(), text(&out.stdout), text(&out.stderr))
}

/// The messages `mrt replay` counts in its first line.
fn messages(listing: &str) -> u64 {
    let first = listing.lines().next().unwrap_or_default();
    let after = first.rsplit_once(": ").map_or("", |(_, m)| m);
    after.split(' ').next().unwrap_or("0").parse().unwrap_or(0)
}

#[test]
fn an_interrupted_recording_is_finished_and_a_cut_one_is_recovered() {
    let dir = std::env::temp_dir().join(format!("mrt-recording-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for signal in ["INT", "TERM"] {
        let file = dir.join(format!("{signal}.mcap"));
        let child = mrt()
            .args(["sim", "--half", "600", "--percepts", "oracle", "--record"])
            .arg(&file)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Until a few chunks are written.
        let started = Instant::now();
        while std::fs::metadata(&file).map_or(0, |m| m.len()) < 3 << 20
            && started.elapsed() < Duration::from_secs(60)
        {
            std::thread::sleep(Duration::from_millis(100));
        }
        let sent = Command::new("kill")
            .args([format!("-{signal}"), child.id().to_string()])
            .status()
            .unwrap();
        assert!(sent.success());
        let out = child.wait_with_output().unwrap();
        let said = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{signal}: {said}{}", String::from_utf8_lossy(&out.stderr));
        assert!(said.contains("interrupted after"), "{signal}: says so: {said}");
        let bytes = std::fs::read(&file).unwrap();
        assert!(bytes.ends_with(b"\x89MCAP0\r\n"), "{signal}: the file is finished");
        let (ok, listing, err) = replay(&[file.as_os_str()]);
        assert!(ok && !err.contains("damaged"), "{signal}: {listing}{err}");
        assert!(messages(&listing) > 0, "{listing}");
    }

    // Cut short, as by a killed process or a full disk: read up to the cut, recovered whole.
    let file = dir.join("INT.mcap");
    let bytes = std::fs::read(&file).unwrap();
    let (_, listing, _) = replay(&[file.as_os_str()]);
    let all = messages(&listing);
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() * 6 / 10]).unwrap();
    let (ok, listing, err) = replay(&[cut.as_os_str()]);
    assert!(ok, "{err}");
    assert!(err.contains("damaged after") && err.contains("--recover"), "{err}");
    let kept = messages(&listing);
    assert!(kept > 0 && kept < all, "{kept} of {all}");
    let clean = dir.join("clean.mcap");
    let out = mrt().arg("replay").arg(&cut).arg("--recover").arg(&clean).output().unwrap();
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && said.starts_with("recovered: "), "{said}");
    assert!(said.contains(&format!("{kept} messages")), "{said}");
    let (ok, listing, err) = replay(&[clean.as_os_str()]);
    assert!(ok && !err.contains("damaged"), "{err}");
    assert_eq!(messages(&listing), kept);
    // Not a recording at all is still an error.
    let junk = dir.join("junk.mcap");
    std::fs::write(&junk, b"not a recording").unwrap();
    assert!(!replay(&[junk.as_os_str()]).0);
    std::fs::remove_dir_all(&dir).unwrap();
}
