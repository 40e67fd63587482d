//! `mrt bb`: a served blackboard with its relay, and the client commands against it.
#![allow(clippy::unwrap_used)]

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};

struct Server(Child);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn mrt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mrt"))
}

/// Starts `mrt bb serve` on a free port with the shipped configs/bb; returns it and its address.
fn serve() -> (Server, String) {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../configs/bb");
    let mut child = mrt()
        .args(["bb", "serve", "--addr", "127.0.0.1:0", "--robot", "1", "--config-dir", dir])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
    let addr = line.trim().rsplit(' ').next().unwrap().to_string();
    assert!(line.starts_with("relay of robot 1 listening on 127.0.0.1:"), "{line}");
    (Server(child), addr)
}

fn run(args: &[&str]) -> (bool, String, String) {
    let out = mrt().args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn get_set_list_and_watch_through_the_relay() {
    let (_server, addr) = serve();
    let a = addr.as_str();
    // config-1.dat overrides config.dat for robot 1.
    let (ok, out, _) = run(&["bb", "get", "local.var.machine.config.role", "--addr", a]);
    assert!(ok && out.starts_with("String \"goalkeeper\" "), "{out}");
    let (ok, _, err) =
        run(&["bb", "set", "local.var.machine.config.def.near-ball", "Float", "0.9", "--addr", a]);
    assert!(ok, "{err}");
    let (_, out, _) = run(&["bb", "get", "local.var.machine.config.def.near-ball", "--addr", a]);
    assert!(out.starts_with("Float 0.9 "), "{out}");
    let (ok, _, err) = run(&["bb", "set", "local.var.kicker.kick", "Int", "1", "--addr", a]);
    assert!(!ok && err.contains("ERR 409") && err.contains("holds a Bool"), "{err}");
    let (ok, out, _) = run(&["bb", "list", "local.var.kicker.*", "--addr", a]);
    let lines: Vec<_> = out.lines().collect();
    assert!(ok && lines.len() == 2, "{out}");
    assert!(lines[0].starts_with("local.var.kicker.config.pulse Int 125 "), "{out}");
    assert!(lines[1].starts_with("local.var.kicker.kick Bool false "), "{out}");
    let (ok, out, _) =
        run(&["bb", "watch", "*.var.team.*", "--refresh", "20", "--count", "1", "--addr", a]);
    assert!(ok && out.starts_with("*.var.team.config.players Int 4 "), "{out}");
}

#[test]
fn no_relay_and_bad_input_give_clear_errors() {
    let (ok, _, err) = run(&["bb", "get", "local.var.x", "--addr", "127.0.0.1:1"]);
    assert!(!ok && err.contains("cannot reach the relay at 127.0.0.1:1"), "{err}");
    let (ok, _, err) = run(&["bb", "serve", "--addr", "0.0.0.0:0"]);
    assert!(!ok && err.contains("give it a shared token"), "{err}");
    let dir = std::env::temp_dir().join(format!("mrt-bb-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("config.dat"), "local.var.a Int 1\nlocal.var.b Float x\n").unwrap();
    let (ok, _, err) =
        run(&["bb", "serve", "--addr", "127.0.0.1:0", "--config-dir", dir.to_str().unwrap()]);
    assert!(!ok && err.contains("config.dat:2:19: `x` is not a Float"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
