//! `mrt hfsm dot --svg` on a large machine: the drawing's layout is linear in the machine's
//! size (a general graph layout took 91 s on these 200 states; the benchmark
//! `cargo bench -p mrt-script --bench drawing` times it).

#![allow(clippy::unwrap_used)]

use std::process::Command;

#[test]
fn a_200_state_machine_is_drawn() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../mrt-script/tests/data/chain200.hfsm.lua");
    let svg = std::env::temp_dir().join(format!("mrt-hfsm-200-{}.svg", std::process::id()));
    let out = Command::new(env!("CARGO_BIN_EXE_mrt"))
        .args(["hfsm", "dot", file, "--dot", "/dev/null", "--svg"])
        .arg(&svg)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.contains(">S198<"));
    assert_eq!(text.matches(r#"<g class="state">"#).count(), 202);
    std::fs::remove_file(&svg).unwrap();
}
