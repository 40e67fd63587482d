//! The web monitor: `mrt replay FILE --serve` answers over HTTP, and the page,
//! loaded in a real headless Chromium driven through ChromeDriver (Debian's `chromium` and
//! `chromium-driver`, installed by `.ci/run`), draws the field and follows the replay. Without
//! ChromeDriver the browser test says that it was skipped.

#![allow(clippy::unwrap_used)]

use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn mrt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mrt"))
}

/// Kills its process when dropped, so that a failing test leaves nothing running.
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        self.0.kill().ok();
        self.0.wait().ok();
    }
}

/// A recorded match, Chaser v Chaos with the object sensor, two halves of 40 s, and what its
/// report says: the final score and when each goal fell. The tests read what they expect from
/// the report, so that any match will do (a better team changes the match, not the tests).
struct Recorded {
    path: PathBuf,
    /// (home, away).
    score: (u64, u64),
    /// Each goal: scored by the home team, and when (s of play).
    goals: Vec<(bool, f64)>,
}

impl Recorded {
    /// The score after `t` s of play.
    fn score_at(&self, t: f64) -> (u64, u64) {
        let count = |home: bool| self.goals.iter().filter(|g| g.0 == home && g.1 <= t).count();
        (count(true) as u64, count(false) as u64)
    }

    /// Whether a goal falls within a second of `t` (the report rounds its times to the second).
    fn near_a_goal(&self, t: f64) -> bool {
        self.goals.iter().any(|g| (g.1 - t).abs() < 1.5)
    }
}

fn recording(name: &str) -> Recorded {
    let args = ["--half", "40", "--seed", "61", "--percepts", "oracle"];
    let (path, stdout) =
        record(name, &[&args[..], &["--home", "chaser", "--away", "chaos"]].concat());
    // The report's first line is "chaser (home) H : A chaos (away)   seed S", and each goal
    // has a line "goal TEAM at M:SS".
    let head: Vec<&str> = stdout.lines().next().unwrap_or_default().split_whitespace().collect();
    assert!(head.len() > 4 && head[..2] == ["chaser", "(home)"] && head[3] == ":", "{stdout}");
    let score = (head[2].parse().unwrap(), head[4].parse().unwrap());
    let goals: Vec<(bool, f64)> = stdout
        .lines()
        .filter_map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            let (m, s) = (w.len() == 4 && w[0] == "goal" && w[2] == "at")
                .then_some(w[3])?
                .split_once(':')?;
            Some((w[1] == "chaser", m.parse::<f64>().ok()? * 60.0 + s.parse::<f64>().ok()?))
        })
        .collect();
    let recorded = Recorded { path, score, goals };
    assert_eq!(recorded.score_at(f64::INFINITY), score, "every goal is listed: {stdout}");
    recorded
}

/// `mrt sim ARGS --record` into a file of the temporary directory named after `name`; the
/// file and the match's report.
fn record(name: &str, args: &[&str]) -> (PathBuf, String) {
    let path = std::env::temp_dir().join(format!("mrt-monitor-{name}-{}.mcap", std::process::id()));
    let out = mrt().arg("sim").args(args).arg("--record").arg(&path).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    (path, stdout)
}

/// Starts `mrt replay FILE --serve 127.0.0.1:0`; returns it and the page's address.
fn serve(file: &Path) -> (Running, String) {
    let mut child = mrt()
        .arg("replay")
        .arg(file)
        .args(["--serve", "127.0.0.1:0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
    let url = line.split_whitespace().nth(1).unwrap_or_default().to_string();
    assert!(url.starts_with("http://127.0.0.1:") && line.contains("frames"), "{line}");
    (Running(child), url)
}

/// One HTTP/1.1 request to `addr` (`host:port`), `Connection: close`; the status and body.
fn http(method: &str, addr: &str, path: &str, body: Option<&Value>) -> (u16, String) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    let body = body.map(Value::to_string).unwrap_or_default();
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\
         Content-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    )
    .unwrap();
    // Read the head, then as much body as it announces: ChromeDriver keeps the connection
    // open whatever the request asked.
    let mut raw = Vec::new();
    let mut buf = [0u8; 65536];
    let head_end = loop {
        if let Some(k) = raw.windows(4).position(|w| w == b"\r\n\r\n") {
            break k + 4;
        }
        let n = s.read(&mut buf).unwrap();
        assert!(n > 0, "{addr}{path}: closed before the response's head");
        raw.extend_from_slice(&buf[..n]);
    };
    let head = String::from_utf8_lossy(&raw[..head_end]).to_ascii_lowercase();
    let status = head.split_whitespace().nth(1).unwrap().parse().unwrap();
    let length = head
        .lines()
        .find_map(|l| l.strip_prefix("content-length:"))
        .map(|v| v.trim().parse::<usize>().unwrap());
    let chunked = head.contains("transfer-encoding: chunked");
    loop {
        let body = &raw[head_end..];
        let done = match length {
            Some(n) => body.len() >= n,
            None => chunked && body.windows(5).any(|w| w == b"0\r\n\r\n"),
        };
        if done {
            break;
        }
        let n = s.read(&mut buf).unwrap();
        if n == 0 {
            break;
        }
        raw.extend_from_slice(&buf[..n]);
    }
    let rest = String::from_utf8_lossy(&raw[head_end..]).into_owned();
    (status, if chunked { dechunk(&rest) } else { rest })
}

fn dechunk(mut rest: &str) -> String {
    let mut body = String::new();
    while let Some((size, tail)) = rest.split_once("\r\n") {
        let n = usize::from_str_radix(size.trim(), 16).unwrap_or(0);
        if n == 0 {
            break;
        }
        body.push_str(&tail[..n]);
        rest = &tail[n + 2..];
    }
    body
}

fn host(url: &str) -> &str {
    url.trim_start_matches("http://").trim_end_matches('/')
}

/// The server answers the page, the field, frames by index (clamped into the recording) and
/// the last one, whose truth holds the match's final score; a bad index is an error, not a
/// crash.
#[test]
fn replay_serve_answers_the_page_the_field_and_frames() {
    let rec = recording("http");
    let file = rec.path.clone();
    let (_server, url) = serve(&file);
    let addr = host(&url);
    let (status, page) = http("GET", addr, "/", None);
    assert_eq!(status, 200);
    assert!(page.contains("<canvas id=\"field\""), "{page}");
    let (_, meta) = http("GET", addr, "/meta", None);
    let meta: Value = serde_json::from_str(&meta).unwrap();
    assert_eq!(meta["finished"], true);
    assert_eq!(meta["field"]["half_length"], 9.0, "the default world's 18 x 12 m field");
    assert_eq!(meta["end"], 800, "80 s at 10 Hz: {meta}");
    let (_, last) = http("GET", addr, "/frame/latest", None);
    let last: Value = serde_json::from_str(&last).unwrap();
    assert_eq!(last["index"], 799);
    assert_eq!(last["frame"]["truth"]["score"], json!([rec.score.0, rec.score.1]));
    assert_eq!(last["frame"]["robots"].as_array().unwrap().len(), 8, "{last}");
    let (_, clamped) = http("GET", addr, "/frame/99999", None);
    assert!(clamped.contains("\"index\":799"), "{clamped}");
    // Each frame's truth holds the score at its time, away from the instants goals fall.
    for index in (0..800).step_by(50) {
        let (_, frame) = http("GET", addr, &format!("/frame/{index}"), None);
        let frame: Value = serde_json::from_str(&frame).unwrap();
        let t = frame["frame"]["t"].as_f64().unwrap();
        assert!((t - f64::from(index) / 10.0).abs() < 1e-6, "{frame}");
        if !rec.near_a_goal(t) {
            let (home, away) = rec.score_at(t);
            assert_eq!(frame["frame"]["truth"]["score"], json!([home, away]), "at {t} s");
        }
    }
    let (_, bad) = http("GET", addr, "/frame/x", None);
    assert!(bad.contains("not a frame index"), "{bad}");
    std::fs::remove_file(&file).ok();
}

/// `mrt sim --serve` serves the match while it plays (frames come in, not finished), then
/// keeps it to replay (finished, every frame there).
#[test]
fn sim_serve_shows_the_match_live_then_keeps_it() {
    let mut child = mrt()
        .args([
            "sim",
            "--half",
            "3",
            "--percepts",
            "oracle",
            "--realtime",
            "--serve",
            "127.0.0.1:0",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let _running = Running(child);
    let mut line = String::new();
    out.read_line(&mut line).unwrap();
    let url = line.trim().strip_prefix("monitor: ").unwrap_or_default().to_string();
    assert!(url.starts_with("http://127.0.0.1:"), "{line}");
    let addr = host(&url);
    let meta = |addr: &str| -> Value {
        serde_json::from_str(&http("GET", addr, "/meta", None).1).unwrap()
    };
    let start = Instant::now();
    let mut live = None;
    while start.elapsed() < Duration::from_secs(5) {
        let m = meta(addr);
        if m["end"].as_u64().unwrap() > 5 {
            live = Some(m);
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let live = live.expect("frames while the match plays");
    assert_eq!(live["finished"], false, "{live}");
    let (_, latest) = http("GET", addr, "/frame/latest", None);
    assert!(latest.contains("\"truth\":{"), "{latest}");
    // The report, then the line that says the match stays served.
    let mut report = String::new();
    while !report.contains("stays at") {
        let mut l = String::new();
        assert!(out.read_line(&mut l).unwrap() > 0, "{report}");
        report.push_str(&l);
    }
    assert!(report.starts_with("milan (home) "), "{report}");
    let done = meta(addr);
    assert_eq!(done["finished"], true, "{done}");
    assert_eq!(done["end"], 60, "two halves of 3 s at 10 Hz: {done}");
}

fn replay(args: &[&std::ffi::OsStr]) -> (bool, String, String) {
    let out = mrt().arg("replay").args(args).output().unwrap();
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (out.status.success(), text(&out.stdout), text(&out.stderr))
}

/// `mrt replay --accuracy` measures the recorded beliefs against the recorded truth as the
/// simulator's own report does: the same figures for the whole match, one row per robot.
#[test]
fn replay_accuracy_gives_the_match_reports_figures() {
    let (file, report) = record("accuracy", &["--half", "10"]);
    let (ok, out, err) = replay(&[file.as_os_str(), "--accuracy".as_ref(), "--json".as_ref()]);
    std::fs::remove_file(&file).ok();
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let rows = v.as_array().unwrap();
    let names: Vec<&str> = rows.iter().filter_map(|r| r["robot"].as_str()).collect();
    assert_eq!(names.len(), 9, "{names:?}");
    assert_eq!(names.last(), Some(&"all"));
    let all = &rows[8];
    // The report's line, e.g. "position 0.01 m median, 0.07 m p95; heading 0.3° median, 1.7° p95".
    let numbers = |line: &str| -> Vec<f64> {
        line.replace("p95", "")
            .split(|c: char| !(c.is_ascii_digit() || c == '.'))
            .filter_map(|w| w.parse().ok())
            .collect()
    };
    let line = report.lines().find(|l| l.contains("localization error")).unwrap();
    let n = numbers(line.split_once("position").unwrap().1);
    let deg = 180.0 / std::f64::consts::PI;
    let close = |got: f64, printed: f64, half: f64| (got - printed).abs() <= half + 1e-9;
    assert!(close(all["position"]["median"].as_f64().unwrap(), n[0], 0.005), "{line}\n{all}");
    assert!(close(all["position"]["p95"].as_f64().unwrap(), n[1], 0.005), "{line}\n{all}");
    assert!(close(all["heading"]["median"].as_f64().unwrap() * deg, n[2], 0.05), "{line}\n{all}");
    assert!(close(all["heading"]["p95"].as_f64().unwrap() * deg, n[3], 0.05), "{line}\n{all}");
    let line = report.lines().find(|l| l.contains("ball error while seen")).unwrap();
    let n = numbers(line.split_once("seen:").unwrap().1);
    assert!(close(all["ball"]["mean"].as_f64().unwrap(), n[0], 0.005), "{line}\n{all}");
    assert!(close(all["ball"]["p95"].as_f64().unwrap(), n[1], 0.005), "{line}\n{all}");
    assert!(close(all["ball_velocity"]["mean"].as_f64().unwrap(), n[2], 0.005), "{line}\n{all}");
    // The simulator tells each robot where it was put down: every one knows from its first
    // estimate.
    assert_eq!(all["found_after"].as_f64(), Some(0.0), "{all}");
}

/// A robot's behaviors re-run on the world snapshots it had give back
/// exactly the recorded commands (Milan's Mr. BRIAN, Chaos' HFSM player and HBM keeper); an
/// edited behavior shows where its commands differ; a behavior that does not load is reported
/// with its file and line.
#[test]
fn replay_robot_reruns_its_behaviors_on_the_recorded_snapshots() {
    let (file, _) = record("rerun", &["--half", "10", "--percepts", "oracle"]);
    let f = file.as_os_str();
    for robot in ["home/0", "home/2", "away/0", "away/3"] {
        let (ok, out, err) = replay(&[f, "--robot".as_ref(), robot.as_ref()]);
        assert!(ok, "{err}");
        assert!(out.contains("200 world snapshots re-run"), "{out}");
        assert!(out.contains("differ from the recording in 0 cycles"), "{robot}: {out}");
    }
    let (_, json_out, _) = replay(&[f, "--robot".as_ref(), "home/1".as_ref(), "--json".as_ref()]);
    let v: Value = serde_json::from_str(&json_out).unwrap();
    assert_eq!(
        (v["stack"].as_str(), v["cycles"].as_u64(), v["differing"].as_u64()),
        (Some("milan"), Some(200), Some(0))
    );

    // Team Milan's fastest speed turned down from 1200 to 900 mm/s.
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let edited = std::env::temp_dir().join(format!("mrt-monitor-milan-{}", std::process::id()));
    copy_dir(&root.join("configs/brian/milan"), &edited);
    let shapes = edited.join("s_shape.txt");
    let text = std::fs::read_to_string(&shapes).unwrap();
    std::fs::write(&shapes, text.replace("(SNG (FAST 1200))", "(SNG (FAST 900))")).unwrap();
    let (ok, out, err) = replay(&[
        f,
        "--robot".as_ref(),
        "home/2".as_ref(),
        "--behaviors".as_ref(),
        edited.as_os_str(),
    ]);
    assert!(ok, "{err}");
    let n: u64 = out
        .split("differ from the recording in ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(n > 0, "{out}");
    assert!(
        out.contains("vx -1.2000 → -0.9000 m/s") || out.contains("vx 1.2000 → 0.9000 m/s"),
        "{out}"
    );

    // A TeamChaos file that does not parse: no commands, the file and line reported.
    let broken = std::env::temp_dir().join(format!("mrt-monitor-chaos-{}", std::process::id()));
    copy_dir(&root.join("behaviors/teamchaos"), &broken);
    let go2ball = broken.join("go2ball.lua");
    let mut text = std::fs::read_to_string(&go2ball).unwrap();
    text.push_str("\nthis is not Lua (\n");
    std::fs::write(&go2ball, text).unwrap();
    let (ok, out, err) = replay(&[
        f,
        "--robot".as_ref(),
        "away/2".as_ref(),
        "--behaviors".as_ref(),
        broken.as_os_str(),
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("in 200 cycles") && out.contains("no command re-run"), "{out}");
    assert!(out.contains("faulted") && out.contains("go2ball.lua:"), "{out}");

    let (ok, _, err) = replay(&[f, "--robot".as_ref(), "away/7".as_ref()]);
    assert!(!ok && err.contains("robots 0 to 3"), "{err}");
    let (ok, _, err) = replay(&[f, "--robot".as_ref(), "east/1".as_ref()]);
    assert!(!ok && err.contains("no such team"), "{err}");
    for p in [&edited, &broken] {
        std::fs::remove_dir_all(p).ok();
    }
    std::fs::remove_file(&file).ok();
}

/// `--compact`: the same match in a smaller file that keeps every topic (the world snapshots
/// at 2 Hz, 4 decimals), that the monitor still shows with each robot's beliefs, that
/// Python's `mcap` reads and validates against the schemas (when `$MRT_PYTHON` has the
/// packages), and on which `mrt replay --robot` says it cannot re-run behaviors exactly
/// instead of listing differences. Both files hold Foxglove's views: `/field`, `/scene`
/// (`foxglove.SceneUpdate`) and `/<robot>/pose` (`foxglove.FrameTransform`).
#[test]
fn a_compact_recording_is_smaller_and_still_shows_the_match() {
    let args = ["--half", "5", "--percepts", "oracle"];
    let (full, _) = record("full", &args);
    let (compact, said) = record("compact", &[&args[..], &["--compact"]].concat());
    assert!(said.contains("left out by --compact"), "{said}");
    let size = |p: &Path| std::fs::metadata(p).unwrap().len();
    assert!(size(&compact) * 2 < size(&full), "{} against {}", size(&compact), size(&full));
    let topics = |file: &Path| -> Vec<(String, String, u64)> {
        let (ok, listing, err) = replay(&[file.as_os_str(), "--json".as_ref()]);
        assert!(ok, "{err}");
        let list: Vec<Value> = serde_json::from_str(&listing).unwrap();
        list.iter()
            .map(|t| {
                let s = |k: &str| t[k].as_str().unwrap_or_default().to_string();
                (s("topic"), s("schema"), t["messages"].as_u64().unwrap_or(0))
            })
            .collect()
    };
    let (full_topics, compact_topics) = (topics(&full), topics(&compact));
    let names = |t: &[(String, String, u64)]| t.iter().map(|t| t.0.clone()).collect::<Vec<_>>();
    assert_eq!(names(&full_topics), names(&compact_topics), "every topic kept");
    let count = |t: &[(String, String, u64)], topic: &str| {
        t.iter().find(|t| t.0 == topic).map(|t| (t.1.clone(), t.2)).unwrap_or_default()
    };
    // Two halves of 5 s: 100 cycles; the snapshots at 2 Hz, the commands and the truth at 10.
    assert_eq!(count(&full_topics, "/home/2/WorldSnapshot").1, 100);
    assert_eq!(count(&compact_topics, "/home/2/WorldSnapshot").1, 20);
    assert_eq!(count(&compact_topics, "/home/2/RobotCommand").1, 100);
    assert_eq!(count(&compact_topics, "/truth").1, 100);
    assert_eq!(count(&full_topics, "/scene"), ("foxglove.SceneUpdate".into(), 100));
    assert_eq!(count(&compact_topics, "/scene").1, 50, "5 Hz");
    assert_eq!(count(&compact_topics, "/field"), ("foxglove.SceneUpdate".into(), 1));
    assert_eq!(count(&full_topics, "/away/1/pose"), ("foxglove.FrameTransform".into(), 100));
    assert_eq!(count(&compact_topics, "/away/1/pose").1, 20);

    // The monitor shows it: a frame at every cycle, each robot with a believed pose.
    let (server, url) = serve(&compact);
    let (_, meta) = http("GET", host(&url), "/meta", None);
    let meta: Value = serde_json::from_str(&meta).unwrap();
    assert_eq!(meta["end"], 100, "{meta}");
    let (_, frame) = http("GET", host(&url), "/frame/60", None);
    let frame: Value = serde_json::from_str(&frame).unwrap();
    let robots = frame["frame"]["robots"].as_array().unwrap();
    assert_eq!(robots.len(), 8, "{frame}");
    assert!(robots.iter().all(|r| r["pose"].is_array() || r["pose"].is_object()), "{frame}");
    drop(server);

    // No misleading differences from a compact recording.
    let (ok, out, err) = replay(&[compact.as_os_str(), "--robot".as_ref(), "home/2".as_ref()]);
    assert!(!ok && out.is_empty(), "{out}");
    assert!(err.contains("compact recording") && err.contains("without --compact"), "{err}");
    let (ok, out, err) = replay(&[full.as_os_str(), "--robot".as_ref(), "home/2".as_ref()]);
    assert!(ok && out.contains("in 0 cycles"), "{out}{err}");

    let python = std::env::var("MRT_PYTHON").unwrap_or_else(|_| "python3".into());
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/python/check_recording.py");
    for file in [&compact, &full] {
        match Command::new(&python).arg(script).arg(file).output() {
            Ok(out) if out.status.code() == Some(3) => {
                eprintln!(
                    "skipped: the Python check ({python}): {}",
                    String::from_utf8_lossy(&out.stderr)
                );
            }
            Ok(out) => {
                let stdout = String::from_utf8_lossy(&out.stdout);
                assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
                let counts: Value = serde_json::from_str(stdout.trim()).unwrap();
                assert_eq!(
                    (counts["invalid"].as_u64(), counts["truth"].as_u64()),
                    (Some(0), Some(100))
                );
            }
            Err(e) => eprintln!("skipped: the Python check, no {python}: {e}"),
        }
    }
    std::fs::remove_file(&full).ok();
    std::fs::remove_file(&compact).ok();
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &to.join(e.file_name()));
        } else {
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    }
}

/// `--images N`: N camera images a second of each robot, JPEG on `/<robot>/camera` with
/// Foxglove's `foxglove.CompressedImage` schema; the monitor serves the selected robot's.
#[test]
fn camera_images_are_recorded_and_served() {
    let (file, _) = record("images", &["--half", "2", "--images", "5"]);
    let (ok, listing, err) = replay(&[file.as_os_str()]);
    assert!(ok, "{err}");
    let camera =
        listing.lines().find(|l| l.trim_start().starts_with("/home/1/camera ")).unwrap_or_default();
    // Two halves of 2 s, a camera frame every 0.1 s, every second one kept.
    assert!(
        camera.contains("foxglove.CompressedImage") && camera.contains(" 20 messages"),
        "{listing}"
    );
    let (_server, url) = serve(&file);
    let addr = host(&url);
    let (_, frame) = http("GET", addr, "/frame/21", None);
    let frame: Value = serde_json::from_str(&frame).unwrap();
    let robot = frame["frame"]["robots"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "home/1")
        .unwrap();
    assert_eq!(robot["image"], 20, "the image of frame 20, the last at or before 21: {robot}");
    let mut s = TcpStream::connect(addr).unwrap();
    write!(s, "GET /image/home/1/21 HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n")
        .unwrap();
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let head_end = raw.windows(4).position(|w| w == b"\r\n\r\n").unwrap() + 4;
    let head = String::from_utf8_lossy(&raw[..head_end]).to_ascii_lowercase();
    assert!(
        head.starts_with("http/1.1 200") && head.contains("content-type: image/jpeg"),
        "{head}"
    );
    assert_eq!(&raw[head_end..head_end + 2], &[0xff, 0xd8], "a JPEG");
    let (status, _) = http("GET", addr, "/image/home/9/21", None);
    assert_eq!(status, 404);
    // What the vision found in that same image, where in it (`Percepts::detections`).
    let (status, seen) = http("GET", addr, "/seen/home/1/21", None);
    assert_eq!(status, 200, "{seen}");
    let seen: Value = serde_json::from_str(&seen).unwrap();
    assert!((seen["time"].as_f64().unwrap() - frame["frame"]["t"].as_f64().unwrap()).abs() < 0.15);
    let (w, h) = (
        seen["detections"]["width"].as_f64().unwrap(),
        seen["detections"]["height"].as_f64().unwrap(),
    );
    assert!(w >= 160.0 && h >= 120.0, "{seen}");
    for item in seen["detections"]["items"].as_array().unwrap() {
        let (x, y) = (item["x"].as_f64().unwrap(), item["y"].as_f64().unwrap());
        assert!((0.0..=w).contains(&x) && (0.0..=h).contains(&y), "{item}");
    }
    // The away team's TeamChaos robots run an HFSM: its shape, once, named by each frame.
    let away = frame["frame"]["robots"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "away/1")
        .unwrap();
    let told = away["hfsm_structure"].as_u64().unwrap();
    let (status, shape) = http("GET", addr, &format!("/hfsm/away/1/{told}"), None);
    assert_eq!(status, 200, "{shape}");
    let shape: Value = serde_json::from_str(&shape).unwrap();
    let root = shape["root"].as_str().unwrap();
    assert!(away["hfsm"].as_str().unwrap().starts_with(root), "{away}\n{shape}");
    assert!(!shape["machines"][0]["states"].as_array().unwrap().is_empty(), "{shape}");
    assert_eq!(http("GET", addr, "/hfsm/home/1/21", None).0, 404, "Mr. BRIAN has no HFSM");
    let out = mrt().args(["sim", "--images", "2"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--images"), "{err}");
    std::fs::remove_file(&file).ok();
}

/// `--serve` takes one in-process match; a recording the monitor cannot show is an error.
#[test]
fn serve_refuses_what_it_cannot_show() {
    let out = mrt().args(["sim", "--serve", "127.0.0.1:0", "--matches", "2"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--serve takes one in-process match"), "{err}");
    let missing = std::env::temp_dir().join("mrt-monitor-no-such-file.mcap");
    let out = mrt().arg("replay").arg(&missing).args(["--serve", "127.0.0.1:0"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("no-such-file"), "{err}");
}

/// ChromeDriver's address, started on a free port; `None` (the test is skipped) without
/// ChromeDriver and Chromium.
fn chromedriver() -> Option<(Running, String)> {
    let driver = std::env::var("MRT_CHROMEDRIVER").unwrap_or_else(|_| "chromedriver".into());
    let port = std::net::TcpListener::bind("127.0.0.1:0").ok()?.local_addr().ok()?.port();
    let child = Command::new(&driver)
        .arg(format!("--port={port}"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .ok()?;
    let running = Running(child);
    let addr = format!("127.0.0.1:{port}");
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(20) {
        if TcpStream::connect(&addr).is_ok() {
            return Some((running, addr));
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    None
}

/// A WebDriver session in headless Chromium.
struct Browser {
    driver: String,
    session: String,
}

impl Browser {
    fn open(driver: &str, profile: &Path) -> Browser {
        let binary = std::env::var("MRT_CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".into());
        // The flags this machine's closed network needs (no background connections).
        let args = [
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--window-size=1400,900",
        ];
        let mut args: Vec<String> = args.iter().map(ToString::to_string).collect();
        args.push(format!("--user-data-dir={}", profile.display()));
        let caps = json!({"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:chromeOptions": {"binary": binary, "args": args},
        }}});
        let (status, body) = http("POST", driver, "/session", Some(&caps));
        let v: Value = serde_json::from_str(&body).unwrap();
        assert_eq!(status, 200, "ChromeDriver did not start Chromium: {body}");
        let session = v["value"]["sessionId"].as_str().unwrap().to_string();
        Browser { driver: driver.to_string(), session }
    }

    fn command(&self, method: &str, what: &str, body: Option<&Value>) -> Value {
        let path = format!("/session/{}/{what}", self.session);
        let (status, body) = http(method, &self.driver, &path, body);
        assert_eq!(status, 200, "{what}: {body}");
        serde_json::from_str::<Value>(&body).unwrap()["value"].clone()
    }

    fn go(&self, url: &str) {
        self.command("POST", "url", Some(&json!({ "url": url })));
    }

    /// Runs `script` (a function body) in the page and returns its value.
    fn eval(&self, script: &str) -> Value {
        self.command("POST", "execute/sync", Some(&json!({"script": script, "args": []})))
    }

    /// Waits up to 20 s for `script` to return true.
    fn wait(&self, script: &str, what: &str) {
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(20) {
            if self.eval(script) == json!(true) {
                return;
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        panic!("timed out waiting for {what}: {}", self.eval("return document.body.innerText"));
    }

    fn text(&self, id: &str) -> String {
        self.eval(&format!("return document.getElementById('{id}').innerText"))
            .as_str()
            .unwrap_or_default()
            .to_string()
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let path = format!("/session/{}", self.session);
        let _ = std::panic::catch_unwind(|| http("DELETE", &self.driver, &path, None));
    }
}

/// How many pixels of the field's canvas are of each colour the page draws: the field's
/// green, the lines' white, the home team's blue and the away team's red discs, the ball's
/// orange.
const COUNT_COLOURS: &str = "
    const c = document.getElementById('field');
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    const near = (i, r, g, b) => Math.abs(d[i] - r) + Math.abs(d[i + 1] - g) + Math.abs(d[i + 2] - b) < 30;
    const n = { green: 0, white: 0, home: 0, away: 0, ball: 0 };
    for (let i = 0; i < d.length; i += 4) {
      if (near(i, 0x2e, 0x7d, 0x32)) n.green++;
      else if (near(i, 255, 255, 255)) n.white++;
      else if (near(i, 0x42, 0xa5, 0xf5)) n.home++;
      else if (near(i, 0xef, 0x53, 0x50)) n.away++;
      else if (near(i, 0xff, 0xa7, 0x26)) n.ball++;
    }
    return n;";

/// The page loads in a real headless Chromium, its canvas draws the field,
/// the robots and the ball, and as the replay advances (played, then scrubbed to the end) the
/// clock, the score and the selected robot's state follow the recording; a screenshot is kept
/// in the test's target directory.
#[test]
fn the_page_draws_the_field_and_follows_the_replay_in_headless_chromium() {
    let Some((_driver, driver)) = chromedriver() else {
        eprintln!(
            "skipped: no chromedriver (Debian's chromium and chromium-driver packages; \
             .ci/run installs them, MRT_CHROMEDRIVER and MRT_CHROMIUM point elsewhere)"
        );
        return;
    };
    let rec = recording("browser");
    let file = rec.path.clone();
    let (_server, url) = serve(&file);
    let profile = std::env::temp_dir().join(format!("mrt-monitor-chromium-{}", std::process::id()));
    let browser = Browser::open(&driver, &profile);
    browser.go(&format!("{url}?frame=0&paused=1&robot=home/2"));
    browser.wait("return document.body.dataset.frame === '0'", "the first frame");
    assert_eq!(browser.text("time"), "0.0 s");
    assert_eq!(browser.eval("return document.getElementById('robot').value"), "home/2");
    // The field, its lines, four robots a team and the ball are drawn.
    let colours = browser.eval(COUNT_COLOURS);
    assert!(colours["green"].as_u64().unwrap() > 200_000, "{colours}");
    assert!(colours["white"].as_u64().unwrap() > 3_000, "{colours}");
    assert!(colours["home"].as_u64().unwrap() > 4 * 200, "{colours}");
    assert!(colours["away"].as_u64().unwrap() > 4 * 200, "{colours}");
    assert!(colours["ball"].as_u64().unwrap() > 30, "{colours}");
    let state_at_start = browser.text("robot-state");
    assert!(state_at_start.contains("role") && state_at_start.contains("pose"), "{state_at_start}");

    // Played: the clock and the robot's beliefs move on.
    browser.eval("window.monitor.play()");
    browser.wait("return Number(document.body.dataset.frame) >= 30", "the replay to play on");
    browser.eval("window.monitor.pause()");
    let t: f64 = browser.text("time").trim_end_matches(" s").parse().unwrap();
    assert!(t >= 3.0, "{t}");
    assert_ne!(browser.text("robot-state"), state_at_start, "the selected robot's state follows");
    let shown = |(home, away): (u64, u64)| format!("{home} : {away}");
    if !rec.near_a_goal(t) {
        assert_eq!(browser.text("score"), shown(rec.score_at(t)));
    }

    // Scrubbed: the score follows the truth, after each goal and at the end.
    let mut seeks: Vec<u64> = rec.goals.iter().map(|g| (g.1 as u64 + 2).min(79) * 10).collect();
    seeks.push(500);
    seeks.push(799);
    for frame in seeks {
        browser.eval(&format!("window.monitor.seek({frame})"));
        browser.wait(&format!("return document.body.dataset.frame === '{frame}'"), "the frame");
        let t = frame as f64 / 10.0;
        assert_eq!(browser.text("time"), format!("{t:.1} s"));
        if !rec.near_a_goal(t) {
            assert_eq!(browser.text("score"), shown(rec.score_at(t)), "at {t} s");
        }
    }
    browser.eval("window.monitor.select('away/1')");
    assert!(browser.text("robot-state").contains("HFSM"), "{}", browser.text("robot-state"));

    let png = browser.command("GET", "screenshot", None);
    let png = base64_decode(png.as_str().unwrap());
    assert_eq!(&png[1..4], b"PNG");
    let shot = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("monitor.png");
    std::fs::write(&shot, png).unwrap();
    eprintln!("screenshot: {}", shot.display());
    drop(browser);
    std::fs::remove_file(&file).ok();
    std::fs::remove_dir_all(&profile).ok();
}

/// Counts the pixels drawn on canvas `id` (not transparent), and those of the HFSM's amber.
const COUNT_DRAWN: &str = "
    const c = document.getElementById(arguments[0]);
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let drawn = 0, amber = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (d[i + 3] > 0) drawn++;
      if (d[i + 3] > 0 && d[i] > 200 && d[i + 1] > 140 && d[i + 1] < 220 && d[i + 2] < 90) amber++;
    }
    return { drawn, amber, width: c.width, height: c.height };";

/// Over the selected robot's camera image the page draws where its vision
/// found things (a canvas over the picture, fed by `/seen` for that same image), and below the
/// field its HFSM as a graph with the active path highlighted (fed by `/hfsm`), following the
/// replay; a screenshot is kept in the test's target directory.
#[test]
fn the_page_draws_the_camera_detections_and_the_hfsm_in_headless_chromium() {
    let Some((_driver, driver)) = chromedriver() else {
        eprintln!("skipped: no chromedriver (see the test above)");
        return;
    };
    let (file, _) = record("overlay", &["--half", "3", "--images", "5", "--percepts", "vision"]);
    let (_server, url) = serve(&file);
    let addr = host(&url).to_string();
    // A frame whose image of away/1 shows something to its vision.
    let frame = (1..60)
        .find(|i| {
            let (status, seen) = http("GET", &addr, &format!("/seen/away/1/{i}"), None);
            status == 200
                && serde_json::from_str::<Value>(&seen).unwrap()["detections"]["items"]
                    .as_array()
                    .is_some_and(|a| !a.is_empty())
        })
        .expect("away/1's vision finds something in 6 s");
    let profile =
        std::env::temp_dir().join(format!("mrt-monitor-chromium-overlay-{}", std::process::id()));
    let browser = Browser::open(&driver, &profile);
    browser.go(&format!("{url}?frame={frame}&paused=1&robot=away/1"));
    browser.wait(&format!("return document.body.dataset.frame === '{frame}'"), "the frame");
    browser.wait(
        "return Number(document.getElementById('camera-overlay').dataset.drawn) > 0",
        "the camera overlay",
    );
    let count = |id: &str| {
        browser.command("POST", "execute/sync", Some(&json!({"script": COUNT_DRAWN, "args": [id]})))
    };
    let overlay = count("camera-overlay");
    assert!(overlay["drawn"].as_u64().unwrap() > 10, "{overlay}");
    browser.wait(
        "const h = document.getElementById('hfsm').dataset; return Number(h.states) > 2 && Number(h.active) >= 2",
        "the HFSM graph with its active path",
    );
    let graph = count("hfsm");
    assert!(graph["drawn"].as_u64().unwrap() > 5_000, "{graph}");
    assert!(graph["amber"].as_u64().unwrap() > 50, "the active path: {graph}");
    assert!(browser.text("hfsm-file").contains(".hfsm.lua"), "{}", browser.text("hfsm-file"));
    // The graph follows the replay: the active path is the frame's.
    browser.eval("window.monitor.seek(55)");
    browser.wait("return document.body.dataset.frame === '55'", "frame 55");
    let path = browser
        .eval("return window.monitor.state().frame.robots.find((r) => r.name === 'away/1').hfsm");
    assert!(browser.text("hfsm-file").ends_with(path.as_str().unwrap()), "{path}");
    // Home's Mr. BRIAN robots have no HFSM: no graph.
    browser.eval("window.monitor.select('home/1')");
    assert_eq!(browser.eval("return document.getElementById('hfsm-view').hidden"), json!(true));
    browser.eval("window.monitor.select('away/1')");
    browser.eval(&format!("window.monitor.seek({frame})"));
    browser.wait(
        "return Number(document.getElementById('camera-overlay').dataset.drawn) > 0",
        "the camera overlay again",
    );

    let png = browser.command("GET", "screenshot", None);
    let png = base64_decode(png.as_str().unwrap());
    assert_eq!(&png[1..4], b"PNG");
    let shot = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("monitor-overlay.png");
    std::fs::write(&shot, png).unwrap();
    eprintln!("screenshot: {}", shot.display());
    // And the HFSM graph, below the field.
    browser.eval("document.getElementById('hfsm-view').scrollIntoView()");
    let png = browser.command("GET", "screenshot", None);
    let shot = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("monitor-hfsm.png");
    std::fs::write(&shot, base64_decode(png.as_str().unwrap())).unwrap();
    eprintln!("screenshot: {}", shot.display());
    drop(browser);
    std::fs::remove_file(&file).ok();
    std::fs::remove_dir_all(&profile).ok();
}

/// Standard base64 (WebDriver's screenshots).
fn base64_decode(s: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        _ => 63,
    };
    let bytes: Vec<u8> = s.bytes().filter(|&c| c != b'=' && !c.is_ascii_whitespace()).collect();
    let mut out = Vec::with_capacity(bytes.len() * 3 / 4);
    for chunk in bytes.chunks(4) {
        let v: Vec<u32> = chunk.iter().map(|&c| u32::from(value(c))).collect();
        let n = v.iter().fold(0u32, |acc, x| acc << 6 | x) << (6 * (4 - v.len()));
        let k = v.len() * 6 / 8;
        out.extend(n.to_be_bytes()[1..=k].iter());
    }
    out
}

/// `mrt topic` joins a running `mrt sim --distributed` through the network
/// file the match prints: `list` names the types and the Agoras publishing them, `echo`
/// prints robot 2's world snapshots (Agora 3) as JSON Lines, `hz` measures the 10 Hz cycle.
#[test]
fn topic_lists_echoes_and_measures_a_distributed_match() {
    let mut child = mrt()
        .args(["sim", "--distributed", "--half", "30", "--realtime", "--percepts", "oracle"])
        .args(["--home", "chaser", "--away", "chaser"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let _sim = Running(child);
    let mut line = String::new();
    while !line.contains("network of this match: ") {
        line.clear();
        assert!(err.read_line(&mut line).unwrap() > 0, "the match ended before its network line");
    }
    // Keep reading what the match writes, so that it never blocks on a full pipe.
    std::thread::spawn(move || std::io::copy(&mut err, &mut std::io::sink()));
    let file = line
        .split("network of this match: ")
        .nth(1)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .to_string();
    let topic = |args: &[&str]| {
        let out = mrt().arg("topic").args(args).args(["--net", &file]).output().unwrap();
        let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
        assert!(out.status.success(), "{}", text(&out.stderr));
        text(&out.stdout)
    };
    let echo = topic(&["echo", "WorldSnapshot", "--agora", "3", "--count", "3", "--seconds", "60"]);
    let lines: Vec<Value> = echo.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 3, "{echo}");
    for l in &lines {
        assert_eq!(l["agora"], 3);
        let _: mrt_msgs::WorldSnapshot = serde_json::from_value(l["message"].clone()).unwrap();
    }
    let list = topic(&["list", "--seconds", "2"]);
    let snapshots = list.lines().find(|l| l.starts_with("WorldSnapshot")).unwrap_or_default();
    assert!(snapshots.contains("from Agoras 1, 2, 3, 4, 5, 6, 7, 8"), "{list}");
    let hz = topic(&["hz", "RobotCommand", "--seconds", "3"]);
    let one = hz.lines().find(|l| l.starts_with("RobotCommand from Agora 1: ")).unwrap_or_default();
    let rate: f64 =
        one.split(": ").nth(1).unwrap_or("0").split(' ').next().unwrap().parse().unwrap();
    assert!((7.0..13.0).contains(&rate), "a 10 Hz cycle: {hz}");
    assert!(one.contains("delay beyond the quickest message") || one.contains("real time"), "{hz}");
    // `mrt record --net`: every robot's messages into a file that `mrt replay` reads; Ctrl-C
    // (SIGINT) ends it long before its --seconds with the file complete.
    let recorded =
        std::env::temp_dir().join(format!("mrt-monitor-net-{}.mcap", std::process::id()));
    let child = mrt()
        .args(["record", "--net", &file, "--seconds", "600", "-o"])
        .arg(&recorded)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_secs(3));
    let interrupted = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(interrupted.success());
    let out = child.wait_with_output().unwrap();
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && said.starts_with("recorded "),
        "{said}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // A finished MCAP file ends with its footer (opcode 0x02, 20 bytes: where the summary
    // with the index starts, 0 when there is none) and the magic.
    let bytes = std::fs::read(&recorded).unwrap();
    let (footer, magic) = bytes.split_at(bytes.len() - 8);
    assert_eq!(magic, b"\x89MCAP0\r\n", "the file is finished");
    let footer = &footer[footer.len() - 29..];
    assert_eq!(footer[0], 0x02, "a footer record");
    let summary_start = u64::from_le_bytes(footer[9..17].try_into().unwrap());
    assert!(summary_start > 0, "the file has its summary and index");
    let (ok, listing, err) = replay(&[recorded.as_os_str()]);
    assert!(ok, "{err}");
    assert!(
        listing.contains("/agora/3/WorldSnapshot") && listing.contains("/agora/8/RobotCommand"),
        "{listing}"
    );
    std::fs::remove_file(&recorded).ok();
    // `mrt monitor --net --serve`: the page's frames fill from the network.
    let mut child = mrt()
        .args(["monitor", "--net", &file, "--serve", "127.0.0.1:0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap()).read_line(&mut first).unwrap();
    let _monitor = Running(child);
    let url = first.split_whitespace().nth(1).unwrap_or_default().trim_end_matches(';').to_string();
    let addr = host(&url).to_string();
    let start = Instant::now();
    let mut frames = 0;
    while frames < 5 && start.elapsed() < Duration::from_secs(20) {
        std::thread::sleep(Duration::from_millis(200));
        let meta: Value = serde_json::from_str(&http("GET", &addr, "/meta", None).1).unwrap();
        frames = meta["end"].as_u64().unwrap();
    }
    assert!(frames >= 5, "{first}");
    let (_, latest) = http("GET", &addr, "/frame/latest", None);
    assert!(latest.contains("\"name\":\"agora/3\""), "{latest}");
    let out = mrt().args(["topic", "echo", "Nonsense", "--net", &file]).output().unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && e.contains("WorldSnapshot"), "the types are listed: {e}");
}
