//! `mrt behave push` over two processes: this test's
//! process is the robot (an Agora with the TeamChaos field player's HFSM Member, joined to the
//! network on loopback), `mrt behave push` in a process of its own is the editor.
#![cfg(feature = "net")]
#![allow(clippy::unwrap_used, clippy::expect_used)]

use mrt_dcdt::{Activation, Context, Member, MemberError, RequestType};
use mrt_msgs::robot::RobotCommand;
use mrt_net::{NetConfig, NetLink};
use mrt_script::member::BehaviorMember;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::mpsc;
use std::time::{Duration, Instant};

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// Hands every command the behavior Member publishes to the test.
struct Commands(mpsc::Sender<RobotCommand>);

impl Member for Commands {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<RobotCommand>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            let _ = self.0.send(m.get::<RobotCommand>()?.clone());
        }
        Ok(())
    }
}

fn scratch(name: &str) -> PathBuf {
    let d =
        PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The newest command within `wait`, after dropping those already queued.
fn fresh_command(rx: &mpsc::Receiver<RobotCommand>, wait: Duration) -> RobotCommand {
    while rx.try_recv().is_ok() {}
    rx.recv_timeout(wait).expect("the robot stopped publishing commands")
}

fn push(net: &Path, file: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mrt"))
        .args(["behave", "push"])
        .arg(file)
        .args(["--robot", "5", "--net"])
        .arg(net)
        .args(extra)
        .output()
        .unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn a_running_robot_takes_a_pushed_behavior_or_keeps_its_own_with_the_error_and_line() {
    // The robot: the shipped behaviors in a directory of its own.
    let shipped = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../behaviors/teamchaos");
    let robot_dir = scratch("push-robot");
    for e in std::fs::read_dir(&shipped).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "lua") {
            std::fs::copy(&p, robot_dir.join(p.file_name().unwrap())).unwrap();
        }
    }
    let mut agora = mrt_dcdt::Agora::builder(5).build().unwrap();
    let player = BehaviorMember::hfsm(&robot_dir, robot_dir.join("player.hfsm.lua"));
    let m = agora.add_member(player, Activation::Periodic(Duration::from_millis(20)));
    agora.activate_member(m).unwrap();
    let (tx, commands) = mpsc::channel();
    let c = agora.add_member(Commands(tx), Activation::OnMessage);
    agora.activate_member(c).unwrap();
    let (robot_port, editor_port, discovery) = (free_port(), free_port(), free_port());
    let link = NetLink::attach(&agora, &NetConfig::loopback(robot_port, &[])).unwrap();
    let stop = agora.shutdown_handle();
    let robot = std::thread::spawn(move || agora.lets_work().unwrap());
    // Before the kickoff the player stands: no speed.
    assert_eq!(fresh_command(&commands, Duration::from_secs(10)).twist.vx, 0.0);

    // The editor's side: the network file, and edited copies of two files.
    let editor = scratch("push-editor");
    let net = editor.join("robot.cfg");
    std::fs::write(
        &net,
        format!(
            "127.0.0.1 224.0.0.224 {discovery}\nip link 0 127.0.0.1 {editor_port} 127.0.0.1 {robot_port}\n"
        ),
    )
    .unwrap();

    // 1. A syntax error is found before sending, with the edited file's line.
    let broken = editor.join("stand.lua");
    std::fs::write(
        &broken,
        "-- stand, edited\nalways(\"go\", \"FAST\"\nalways(\"turn\", \"NONE\")\n",
    )
    .unwrap();
    let out = push(&net, &broken, &[]);
    let err = text(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("stand.lua:3:") && err.contains("not sent"), "{err}");

    // 2. A machine that compiles but names a state it does not have: the robot refuses it,
    // with the line, and keeps running its own.
    let machine = std::fs::read_to_string(robot_dir.join("player.hfsm.lua")).unwrap();
    let bad_machine = machine.replacen("initial = \"Wait\"", "initial = \"Nowhere\"", 1);
    assert_ne!(bad_machine, machine, "the shipped player's initial state moved");
    let bad_file = editor.join("player.hfsm.lua");
    std::fs::write(&bad_file, &bad_machine).unwrap();
    let out = push(&net, &bad_file, &["--json"]);
    let err = text(&out.stderr);
    assert!(!out.status.success(), "{}", text(&out.stdout));
    assert!(err.contains("robot 5 kept its running version") && err.contains("Nowhere"), "{err}");
    let reply: serde_json::Value = serde_json::from_str(text(&out.stdout).trim()).unwrap();
    assert_eq!(reply["installed"], false);
    assert!(reply["line"].as_u64().is_some_and(|l| l > 0), "{reply}");
    assert_eq!(fresh_command(&commands, Duration::from_secs(2)).twist.vx, 0.0, "the robot stopped");
    // It compiled, so it was written; refused, it was taken back: the disk holds what runs.
    assert_eq!(std::fs::read_to_string(robot_dir.join("player.hfsm.lua")).unwrap(), machine);

    // 3. A good edit runs from the next cycle on and is kept on the robot's disk.
    let fast = editor.join("stand.lua");
    std::fs::write(
        &fast,
        "-- stand, edited: run\nalways(\"go\", \"FAST\")\nalways(\"turn\", \"NONE\")\n",
    )
    .unwrap();
    let t = Instant::now();
    let out = push(&net, &fast, &[]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("robot 5: stand.lua installed"), "{}", text(&out.stdout));
    let vx = fresh_command(&commands, Duration::from_secs(2)).twist.vx;
    assert!(vx > 0.5, "the pushed stand.lua does not run: {vx} m/s forward");
    eprintln!(
        "push to a running robot: {:.2} s, process start included",
        t.elapsed().as_secs_f64()
    );
    assert!(std::fs::read_to_string(robot_dir.join("stand.lua")).unwrap().contains("edited: run"));
    // No stray temporary files are left.
    let leftovers: Vec<_> = std::fs::read_dir(&robot_dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".push"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");

    // 4. A robot that is not there is an error, not a wait without end.
    let out = Command::new(env!("CARGO_BIN_EXE_mrt"))
        .args(["behave", "push"])
        .arg(&fast)
        .args(["--robot", "77", "--timeout", "1", "--net"])
        .arg(&net)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("robot 77"), "{}", text(&out.stderr));

    stop.shutdown();
    robot.join().unwrap();
    drop(link);
    let _ = std::fs::remove_dir_all(&robot_dir);
    let _ = std::fs::remove_dir_all(&editor);
}
