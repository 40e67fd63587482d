//! Every Member of the robot cycle declares its inputs once, as `mrt_dcdt::Inputs`: the
//! subscriptions and the handling of each message type come from one declaration, so no
//! Member subscribes by hand or sorts its mail by type in a chain of `if`s.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

#[test]
fn the_robot_cycle_members_read_their_mail_through_declared_inputs() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files: Vec<_> = std::fs::read_dir(src.join("members"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "rs"))
        .collect();
    files.extend(["planner.rs", "brain.rs", "mission.rs"].map(|f| src.join(f)));
    assert!(files.len() >= 10, "the robot cycle's sources were not found: {files:?}");
    let by_hand = ["subscribe_to::<", "receive_msg("];
    let mut found = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or_default();
            if by_hand.iter().any(|p| code.contains(p)) {
                found.push(format!("{}:{}: {}", file.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "declare the inputs with mrt_dcdt::Inputs instead:\n{}",
        found.join("\n")
    );
}
