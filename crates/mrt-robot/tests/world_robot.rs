//! A robot on a world's devices (docs/devices.md), driven here by a scripted world through an
//! in-memory port: it answers every step in order, once, with set-points its base can follow;
//! a repeated step gets the same answer; whatever a hostile or broken world sends between the
//! steps is counted and dropped without an answer, and the robot plays on; the end gets a bye.

#![allow(clippy::unwrap_used)]

use base64::Engine;
use mrt_devices::messages::{
    CameraReading, Encoding, GameReading, ImageData, Mice, OdometryReading, RefereeState,
    SonarReading,
};
use mrt_devices::{Act, Bye, End, Keys, Sense, MAX_MESSAGE};
use mrt_robot::config::RobotFile;
use mrt_robot::members::behaviors_dir;
use mrt_robot::remote::RemoteRobot;
use mrt_robot::world::{WorldMail, WorldPort, WorldRobot};
use std::sync::mpsc::{channel, sync_channel, Receiver, Sender};
use std::sync::Mutex;
use std::time::Duration;

struct Port(Mutex<Sender<(String, Vec<u8>)>>);

impl WorldPort for Port {
    fn put(&self, key: &str, bytes: Vec<u8>) -> Result<(), mrt_robot::RobotError> {
        let sent = self.0.lock().unwrap().send((key.to_string(), bytes));
        sent.map_err(|e| mrt_robot::RobotError::World(e.to_string()))
    }
}

const ROBOT: &str = r#"
[robot]
id = 1
team_size = 2
stack = "milan"
[body]
base = "differential"
[vision]
enabled = true
[devices]
kind = "world"
world = "stub"
name = "home-1"
"#;

/// The carpet, and the ball in front of the robot: a 320 × 240 image of the default camera.
fn image() -> ImageData {
    let (w, h) = (320usize, 240usize);
    let mut rgb = vec![0u8; w * h * 3];
    for (i, px) in rgb.chunks_exact_mut(3).enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let ball = (x - 160.0).hypot(y - 170.0) < 12.0;
        px.copy_from_slice(if ball { &[240, 100, 20] } else { &[30, 130, 50] });
    }
    let data = base64::engine::general_purpose::STANDARD.encode(&rgb);
    ImageData { width: 320, height: 240, encoding: Encoding::Rgb8, data }
}

fn sense(step: u64) -> Sense {
    // Driving straight at 0.3 m/s: 3 cm a step, both wheels (r = 5 cm) 0.6 rad.
    Sense {
        protocol: 1,
        world: "stub".into(),
        run: "run-1".into(),
        robot: "home-1".into(),
        step,
        time: 0.1 * step as f64,
        odometry: Some(OdometryReading {
            mice: Some(Mice { x_left: 0.0, y_left: 0.03, x_right: 0.0, y_right: 0.03 }),
            wheels: Some(vec![0.6, 0.6]),
            placed: None,
        }),
        sonars: Some(
            (0..16)
                .map(|i| SonarReading {
                    bearing: f64::from(i) * std::f64::consts::FRAC_PI_8,
                    range: Some(3.0),
                })
                .collect(),
        ),
        camera: Some(CameraReading {
            time: 0.1 * step as f64,
            pan: None,
            image: Some(image()),
            objects: None,
        }),
        game: GameReading { state: RefereeState::Playing, attack: 1.0, ..GameReading::default() },
        ..Sense::default()
    }
}

fn json<T: serde::Serialize>(t: &T) -> Vec<u8> {
    serde_json::to_vec(t).unwrap()
}

/// What a broken or hostile world puts on the robot's key between two steps (`next` is the
/// next step to come).
fn hostile(next: u64) -> Vec<Vec<u8>> {
    let mut v = vec![b"{\"protocol\": 1, \"step\": ".to_vec(), vec![0xff; 64]];
    let mut p = sense(next);
    p.protocol = 7;
    v.push(json(&p));
    let mut stranger = sense(next);
    stranger.run = "run-evil".into();
    v.push(json(&stranger));
    let mut other = sense(next);
    other.robot = "away-1".into();
    v.push(json(&other));
    v.push(json(&sense(next.saturating_sub(2))));
    let mut back = sense(next);
    back.time = 0.1 * next as f64 - 0.25;
    v.push(json(&back));
    let mut jump = sense(next);
    jump.time = 1.0e6;
    v.push(json(&jump));
    let huge = String::from_utf8(json(&sense(next))).unwrap().replace("[0.6,0.6]", "[1e999,0.6]");
    assert!(huge.contains("1e999"));
    v.push(huge.into_bytes());
    v.push(vec![b' '; MAX_MESSAGE + 1]);
    v
}

fn next_put(answers: &Receiver<(String, Vec<u8>)>) -> (String, Vec<u8>) {
    answers.recv_timeout(Duration::from_secs(20)).expect("the robot answers within 20 s")
}

#[test]
fn a_world_drives_the_robot_step_by_step_and_nothing_it_sends_stops_it() {
    let file = RobotFile::from_toml(ROBOT, "world.toml").unwrap();
    let cfg = file.config().unwrap();
    let spec = file.spec().unwrap();
    let dir = behaviors_dir(&[spec.stack], None).unwrap();
    let mut remote = RemoteRobot::new(&cfg, spec, &dir, None).unwrap();
    remote.set_presence(|_| false);
    let keys = Keys::new("stub", "home-1").unwrap();
    let robot = WorldRobot::new(remote, cfg.base, keys.clone());
    let (mail, inbox) = sync_channel(64);
    let (out, answers) = channel();
    let port = Port(Mutex::new(out));
    let runner =
        std::thread::spawn(move || robot.run(&inbox, &port, Duration::from_secs(20)).unwrap());

    let top = 24.0 + 1e-9; // IANUS3: 24 rad/s a wheel
    let mut moving = 0;
    let mut hostiles = 0;
    for step in 0..100u64 {
        if step % 10 == 5 {
            for bad in hostile(step) {
                mail.send(WorldMail::Sense(bad)).unwrap();
                hostiles += 1;
            }
        }
        mail.send(WorldMail::Sense(json(&sense(step)))).unwrap();
        let (key, bytes) = next_put(&answers);
        assert_eq!(key, keys.act());
        let act: Act = serde_json::from_slice(&bytes).unwrap();
        assert_eq!((act.step, act.run.as_str(), act.robot.as_str()), (step, "run-1", "home-1"));
        if let Some(w) = &act.wheels {
            assert_eq!(w.len(), 2);
            assert!(w.iter().all(|s| s.abs() <= top), "{w:?}");
            let t = act.twist.unwrap();
            assert!(t.vy == 0.0, "a differential base does not move sideways");
            moving += usize::from(w.iter().any(|s| *s != 0.0));
        }
        if step == 50 {
            // The world did not get it and sends the step again: the same answer, no cycle.
            mail.send(WorldMail::Sense(json(&sense(50)))).unwrap();
            assert_eq!(next_put(&answers).1, bytes);
        }
    }
    assert!(moving > 50, "the motor driver sets the wheels each cycle ({moving} of 100 steps)");
    // An end of another run is a stranger's; the world's own ends the match.
    let mut end = End { protocol: 1, world: "stub".into(), run: "run-evil".into(), steps: 100 };
    mail.send(WorldMail::End(json(&end))).unwrap();
    end.run = "run-1".into();
    mail.send(WorldMail::End(json(&end))).unwrap();
    let (key, bytes) = next_put(&answers);
    assert_eq!(key, keys.bye());
    let bye: Bye = serde_json::from_slice(&bytes).unwrap();
    let run = runner.join().unwrap();
    assert_eq!(bye, run.bye);
    assert_eq!(bye.steps, 100, "the repeat ran no cycle");
    let d = bye.dropped;
    assert_eq!(d.total(), hostiles + 1, "every bad message and the stranger's end: {d:?}");
    assert_eq!(
        (d.protocol, d.stranger, d.out_of_order, d.clock, d.too_large),
        (10, 21, 10, 20, 10)
    );
    assert_eq!(d.malformed, 30);
    assert!(bye.faults.iter().all(|f| !f.never_ran), "{:?}", bye.faults);
    assert!(answers.try_recv().is_err(), "nothing answered the bad messages");
}
