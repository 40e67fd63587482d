//! Files that are not what they seem: every command that reads a file a user names refuses a
//! link to `/dev/zero`, which never ends, and a file larger than its kind may be, at once and
//! with the reason, instead of reading until the memory runs out.

#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

fn mrt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mrt"))
}

/// A directory of this test's own, removed when dropped.
struct Dir(PathBuf);

impl Dir {
    fn new(name: &str) -> Dir {
        let p = std::env::temp_dir().join(format!("mrt-bounded-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).unwrap();
        Dir(p)
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs `mrt args`: it must fail within 20 s, its error naming `file` and containing `why`.
fn refused(args: &[&str], file: &Path, why: &str) {
    let started = Instant::now();
    let out = mrt().args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert!(started.elapsed() < Duration::from_secs(20), "{args:?} took {:?}", started.elapsed());
    let name = file.file_name().unwrap().to_str().unwrap();
    assert!(stderr.contains(name) && stderr.contains(why), "{args:?}: {stderr}");
}

#[cfg(unix)]
#[test]
fn a_link_to_dev_zero_is_refused_by_every_command_that_reads_a_file() {
    if !Path::new("/dev/zero").exists() {
        return;
    }
    let dir = Dir::new("zero");
    let link = |name: &str| {
        let p = dir.0.join(name);
        std::os::unix::fs::symlink("/dev/zero", &p).unwrap();
        p
    };
    let (toml, lua, hfsm, csv) =
        (link("world.toml"), link("b.lua"), link("m.hfsm.lua"), link("log.csv"));
    let s = |p: &Path| p.to_str().unwrap().to_owned();
    let why = "not a regular file";
    refused(&["sim", "--config", &s(&toml), "--half", "1"], &toml, why);
    refused(&["plan", "path", "--from", "0,0", "--to", "1,1", "--map", &s(&toml)], &toml, why);
    refused(&["check", &s(&toml)], &toml, why);
    refused(&["mice", "calibrate", &s(&csv)], &csv, why);
    refused(&["behave", &s(&lua)], &lua, why);
    refused(&["hfsm", "dot", &s(&hfsm)], &hfsm, why);
}

#[test]
fn a_configuration_larger_than_a_megabyte_is_refused_with_its_size() {
    let dir = Dir::new("large");
    let big = dir.0.join("big.toml");
    // A valid TOML array, 2 MB long.
    let text = format!("x = [{}]\n", "1,".repeat(1 << 20));
    std::fs::write(&big, text).unwrap();
    let s = big.to_str().unwrap();
    let why = "more than the 1048576 bytes such a file may have";
    refused(&["sim", "--config", s, "--half", "1"], &big, why);
    refused(&["check", s], &big, why);
}
