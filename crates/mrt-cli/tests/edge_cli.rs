//! `mrt edge` on a running distributed match: the robots' messages as JSON
//! on plain zenoh keys, and JSON from outside onto their bus; read and answered by plain
//! zenoh (this test, through `mrt_net::RawPort`) and by Python with PyPI's `eclipse-zenoh`
//! (`examples/python/edge_client.py`, when `$MRT_PYTHON` has the package).
#![cfg(feature = "net")]
#![allow(clippy::unwrap_used, clippy::expect_used)]

use mrt_net::{NetConfig, NetLink};
use serde_json::Value;
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

fn mrt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mrt"))
}

/// Kills the process when the test ends, however it ends.
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// Starts `mrt` with `args` and returns it with the first stderr (or stdout) line containing
/// `marker`; the rest of the output is drained so that the process never blocks.
fn start(args: &[&str], marker: &str, on_stdout: bool) -> (Running, String) {
    let mut cmd = mrt();
    cmd.args(args).stdin(Stdio::null());
    if on_stdout {
        cmd.stdout(Stdio::piped()).stderr(Stdio::inherit());
    } else {
        cmd.stdout(Stdio::null()).stderr(Stdio::piped());
    }
    let mut child = cmd.spawn().unwrap();
    let pipe: Box<dyn std::io::Read + Send> = if on_stdout {
        Box::new(child.stdout.take().unwrap())
    } else {
        Box::new(child.stderr.take().unwrap())
    };
    let running = Running(child);
    let mut out = BufReader::new(pipe);
    let mut line = String::new();
    while !line.contains(marker) {
        line.clear();
        assert!(out.read_line(&mut line).unwrap() > 0, "{args:?} ended before saying {marker:?}");
    }
    std::thread::spawn(move || std::io::copy(&mut out, &mut std::io::sink()));
    (running, line)
}

#[test]
fn programs_outside_read_the_robots_and_send_them_a_behavior_through_the_edge() {
    let (_sim, line) = start(
        &[
            "sim",
            "--distributed",
            "--half",
            "40",
            "--realtime",
            "--percepts",
            "oracle",
            "--home",
            "chaos",
            "--away",
            "chaser",
        ],
        "network of this match: ",
        false,
    );
    let net = line.split("network of this match: ").nth(1).unwrap().split_whitespace().next();
    let net = net.unwrap().to_string();
    // Home Chaos (Agoras 1-4, Lua behaviors that take pushes), away the Chaser (5-8).
    let (_edge, ready) = start(&["edge", "--net", &net, "--seconds", "60"], "edge ready", true);
    let endpoint = ready.split_whitespace().find(|w| w.starts_with("tcp/")).unwrap();
    let endpoint = endpoint.trim_end_matches([';', ',']).to_string();
    let port: u16 = endpoint.rsplit(':').next().unwrap().parse().unwrap();

    // Plain zenoh beside the edge: a session of this process linked to it.
    let agora = mrt_dcdt::Agora::builder(950).build().unwrap();
    let link = NetLink::attach(&agora, &NetConfig::loopback(free_port(), &[port])).unwrap();
    let raw = link.raw();
    let (tx, rx) = mpsc::channel::<(String, Value)>();
    let tx2 = tx.clone();
    let _snapshots = raw
        .subscribe("mrt/json/3/WorldSnapshot", move |k, b| {
            let _ = tx.send((k.to_string(), serde_json::from_slice(&b).unwrap()));
        })
        .unwrap();
    let _replies = raw
        .subscribe("mrt/json/3/BehaviorPushReply", move |k, b| {
            let _ = tx2.send((k.to_string(), serde_json::from_slice(&b).unwrap()));
        })
        .unwrap();
    let (xml_tx, xml_rx) = mpsc::channel::<String>();
    let _xml = raw
        .subscribe("mrt/xml/3/WorldSnapshot", move |_, b| {
            let _ = xml_tx.send(String::from_utf8(b).unwrap());
        })
        .unwrap();
    let (key, snapshot) = rx.recv_timeout(Duration::from_secs(30)).expect("no world snapshot");
    assert_eq!(key, "mrt/json/3/WorldSnapshot");
    let _: mrt_msgs::WorldSnapshot = serde_json::from_value(snapshot).unwrap();
    // The same snapshots in the manual's XML self-describing form (§3.2).
    let xml = xml_rx.recv_timeout(Duration::from_secs(10)).expect("no XML world snapshot");
    let described = mrt_dcdt::describe::SelfDescribing::from_xml(&xml).unwrap();
    assert_eq!(described.objects[0].name, "WorldSnapshot", "{xml}");
    assert!(described.object("my_pos.pose").and_then(|o| o.attribute("x")).is_some(), "{xml}");
    // DCDT's own keys are not for plain payloads.
    assert!(raw.put("mrt/m/1", b"x".to_vec()).is_err());

    // Garbage is dropped; a push in JSON reaches robot 3's behavior Member, which answers.
    raw.put("mrt/json-in/BehaviorPush", b"{not json".to_vec()).unwrap();
    raw.put("mrt/json-in/NoSuchType", b"{}".to_vec()).unwrap();
    let push = serde_json::json!({
        "robot": 3, "request": 4242, "file": "stand.lua",
        "source": "-- pushed through the edge\nalways(\"go\", \"STAY\")\nalways(\"turn\", \"NONE\")\nalways(\"strafe\", \"NONE\")\nneed(1, BALL)\n",
    });
    raw.put("mrt/json-in/BehaviorPush", serde_json::to_vec(&push).unwrap()).unwrap();
    let reply = loop {
        let (key, v) = rx.recv_timeout(Duration::from_secs(20)).expect("no reply to the push");
        if key.ends_with("BehaviorPushReply") && v["request"] == 4242 {
            break v;
        }
    };
    assert_eq!(reply["installed"], true, "{reply}");
    assert_eq!(reply["reloaded"], serde_json::json!(["stand"]), "{reply}");

    // The same from Python, with PyPI's zenoh, when it is installed (.ci/run installs it).
    let python = std::env::var("MRT_PYTHON").unwrap_or_else(|_| "python3".into());
    let has_zenoh = Command::new(&python)
        .args(["-c", "import zenoh"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_zenoh {
        eprintln!("skipped: the Python example (no `zenoh` module for {python}; pip install eclipse-zenoh)");
        return;
    }
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/python/edge_client.py");
    let out = Command::new(&python)
        .arg(script)
        .args(["--connect", &endpoint, "--robot", "2", "--timeout", "20"])
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{said}{}", String::from_utf8_lossy(&out.stderr));
    let result: Value = serde_json::from_str(said.trim()).unwrap();
    assert!(result["snapshots"].as_u64().unwrap() >= 3, "{result}");
    assert!(result["pose"][0].is_f64() && result["time"].as_f64().unwrap() > 0.0, "{result}");
    assert!(result["xml_objects"].as_u64().unwrap() > 5, "{result}");
    assert!(result["ball_reliability"].is_f64(), "{result}");
    assert_eq!(result["installed"], true, "{result}");
    drop(link);
}
