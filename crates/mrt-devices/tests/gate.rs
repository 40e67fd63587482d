//! The robot's rules for what its world sends (docs/devices.md, "What the robot refuses"):
//! every bad message is counted and dropped, a repeated step gets the same answer, one run is
//! followed, and no input panics.

#![allow(clippy::unwrap_used)]

use base64::Engine;
use mrt_devices::messages::{
    CameraReading, Encoding, GameReading, ImageData, Mice, OdometryReading, RefereeState,
    SonarReading,
};
use mrt_devices::{Admitted, Dropped, Gate, Readings, Refusal, Sense, MAX_MESSAGE};
use proptest::prelude::*;
use std::time::{Duration, Instant};

fn sense(step: u64, time: f64) -> Sense {
    Sense {
        protocol: 1,
        world: "stub".into(),
        run: "run-a".into(),
        robot: "home-1".into(),
        step,
        time,
        odometry: Some(OdometryReading {
            mice: Some(Mice { x_left: 0.0, y_left: 0.01, x_right: 0.0, y_right: 0.01 }),
            wheels: Some(vec![0.2, 0.2]),
            placed: None,
        }),
        sonars: Some(vec![
            SonarReading { bearing: 0.0, range: Some(1.5) },
            SonarReading { bearing: 1.0, range: None },
        ]),
        game: GameReading { state: RefereeState::Playing, attack: 1.0, ..GameReading::default() },
        ..Sense::default()
    }
}

fn bytes(s: &Sense) -> Vec<u8> {
    serde_json::to_vec(s).unwrap()
}

fn step(gate: &mut Gate, s: &Sense, now: Instant) -> Result<Readings, Refusal> {
    match gate.admit(&bytes(s), now)? {
        Admitted::Step(r) => {
            gate.answered(r.step, r.time, format!("answer {}", r.step).into_bytes());
            Ok(*r)
        }
        Admitted::Repeat(a) => panic!("a repeat: {}", String::from_utf8_lossy(&a)),
    }
}

#[test]
fn a_good_step_gives_the_robot_its_readings_in_its_own_types() {
    let mut gate = Gate::new("stub", "home-1", 2);
    let r = step(&mut gate, &sense(0, 0.0), Instant::now()).unwrap();
    assert!(r.odometry);
    assert_eq!(r.mice.y_left, 0.01);
    assert_eq!(r.wheel_turns, Some(vec![0.2, 0.2]));
    let sonars = r.sonars.unwrap();
    assert_eq!(sonars[0].range, 1.5);
    assert!(sonars[1].range.is_infinite(), "no echo is an infinite range");
    assert_eq!(r.game.state, mrt_msgs::GameState::Playing);
    assert_eq!(gate.run(), Some("run-a"));
    assert_eq!(gate.steps(), 1);
    assert_eq!(gate.dropped(), Dropped::default());
}

#[test]
fn without_mice_the_readings_say_so_and_the_encoders_count() {
    let mut gate = Gate::new("stub", "home-1", 2);
    let mut s = sense(0, 0.0);
    s.odometry = Some(OdometryReading { wheels: Some(vec![1.0, 1.0]), ..Default::default() });
    let r = step(&mut gate, &s, Instant::now()).unwrap();
    assert!(!r.mice.is_finite());
    s.odometry = None;
    s.step = 1;
    s.time = 0.1;
    assert!(!step(&mut gate, &s, Instant::now()).unwrap().odometry);
}

#[test]
fn a_repeated_step_is_answered_again_without_a_new_cycle() {
    let mut gate = Gate::new("stub", "home-1", 2);
    let now = Instant::now();
    step(&mut gate, &sense(0, 0.0), now).unwrap();
    match gate.admit(&bytes(&sense(0, 0.0)), now).unwrap() {
        Admitted::Repeat(a) => assert_eq!(a, b"answer 0"),
        Admitted::Step(_) => panic!("ran the step twice"),
    }
    assert_eq!(gate.dropped().total(), 0);
}

#[test]
fn every_kind_of_bad_message_is_counted_under_its_reason_and_changes_nothing() {
    let mut gate = Gate::new("stub", "home-1", 2);
    let now = Instant::now();
    step(&mut gate, &sense(0, 0.0), now).unwrap();
    step(&mut gate, &sense(1, 0.1), now).unwrap();
    let mut cases: Vec<(Vec<u8>, &str)> = vec![
        (b"\xff\xfe not json".to_vec(), "malformed"),
        (br#"{"protocol": 1, "world": "stub"}"#.to_vec(), "malformed"),
        (vec![b' '; MAX_MESSAGE + 1], "too_large"),
    ];
    let mut v2 = sense(2, 0.2);
    v2.protocol = 2;
    cases.push((bytes(&v2), "protocol"));
    for (world, robot, run) in
        [("other", "home-1", "run-a"), ("stub", "home-2", "run-a"), ("stub", "home-1", "run-b")]
    {
        let mut s = sense(2, 0.2);
        (s.world, s.robot, s.run) = (world.into(), robot.into(), run.into());
        cases.push((bytes(&s), "stranger"));
    }
    cases.push((bytes(&sense(0, 0.3)), "out_of_order"));
    cases.push((bytes(&sense(1, 0.3)), "out_of_order"));
    for t in [0.05, 0.1, 11.0, -1.0] {
        cases.push((bytes(&sense(2, t)), "clock"));
    }
    let mut wheels = sense(2, 0.2);
    wheels.odometry.as_mut().unwrap().wheels = Some(vec![0.1; 3]);
    cases.push((bytes(&wheels), "malformed"));
    let mut attack = sense(2, 0.2);
    attack.game.attack = 0.5;
    cases.push((bytes(&attack), "malformed"));
    let mut sonar = sense(2, 0.2);
    sonar.sonars = Some(vec![SonarReading { bearing: 0.0, range: Some(-1.0) }]);
    cases.push((bytes(&sonar), "malformed"));
    let n = cases.len() as u64;
    for (b, reason) in cases {
        let e = gate.admit(&b, now).expect_err(reason);
        assert_eq!(e.reason(), reason, "{e}");
    }
    let d = gate.dropped();
    assert_eq!(d.total(), n);
    assert_eq!((d.stranger, d.clock, d.out_of_order, d.too_large, d.protocol), (3, 4, 2, 1, 1));
    // Nothing of it moved the gate: the next good step is taken.
    assert_eq!(step(&mut gate, &sense(2, 0.2), now).unwrap().step, 2);
}

#[test]
fn a_new_run_is_followed_only_from_its_step_0_after_the_old_one_fell_silent() {
    let mut gate = Gate::new("stub", "home-1", 2);
    let t0 = Instant::now();
    step(&mut gate, &sense(5, 0.5), t0).unwrap();
    let mut other = sense(0, 0.0);
    other.run = "run-b".into();
    assert_eq!(gate.admit(&bytes(&other), t0).unwrap_err().reason(), "stranger");
    let later = t0 + Duration::from_secs(2);
    other.step = 3;
    assert_eq!(gate.admit(&bytes(&other), later).unwrap_err().reason(), "stranger");
    other.step = 0;
    assert_eq!(step(&mut gate, &other, later).unwrap().step, 0);
    assert_eq!(gate.run(), Some("run-b"));
}

fn image_sense(image: ImageData) -> Vec<u8> {
    let mut s = sense(0, 0.0);
    s.camera = Some(CameraReading { time: 0.0, pan: Some(0.2), image: Some(image), objects: None });
    bytes(&s)
}

fn b64(b: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(b)
}

#[test]
fn images_arrive_as_raw_rgb_or_jpeg_and_a_wrong_one_is_malformed() {
    let (w, h) = (8u32, 6u32);
    let rgb: Vec<u8> = (0..w * h * 3).map(|i| (i * 7 % 256) as u8).collect();
    let raw = ImageData { width: w, height: h, encoding: Encoding::Rgb8, data: b64(&rgb) };
    let mut gate = Gate::new("stub", "home-1", 2);
    let Admitted::Step(r) = gate.admit(&image_sense(raw.clone()), Instant::now()).unwrap() else {
        panic!()
    };
    let frame = r.camera.unwrap();
    assert_eq!(frame.image.unwrap().rgb, rgb);
    assert_eq!(frame.pan, Some(0.2));

    let mut jpeg = Vec::new();
    image::RgbImage::from_raw(w, h, rgb.clone())
        .unwrap()
        .write_to(&mut std::io::Cursor::new(&mut jpeg), image::ImageFormat::Jpeg)
        .unwrap();
    let coded = ImageData { width: w, height: h, encoding: Encoding::Jpeg, data: b64(&jpeg) };
    let mut gate = Gate::new("stub", "home-1", 2);
    let Admitted::Step(r) = gate.admit(&image_sense(coded.clone()), Instant::now()).unwrap() else {
        panic!()
    };
    assert_eq!(r.camera.unwrap().image.unwrap().rgb.len(), rgb.len());

    let bad = [
        ImageData { data: b64(&rgb[1..]), ..raw.clone() },
        ImageData { data: "not base64!".into(), ..raw.clone() },
        ImageData { width: 0, ..raw.clone() },
        ImageData { width: 5000, ..raw.clone() },
        ImageData { width: 4, ..coded.clone() },
        ImageData { data: b64(&jpeg[..jpeg.len() / 2]), ..coded },
    ];
    let mut gate = Gate::new("stub", "home-1", 2);
    for image in bad {
        assert_eq!(
            gate.admit(&image_sense(image), Instant::now()).unwrap_err().reason(),
            "malformed"
        );
    }
}

#[test]
fn an_end_counts_only_from_the_robots_world_and_run() {
    let mut gate = Gate::new("stub", "home-1", 2);
    assert!(gate.admit_end(br#"{"protocol":1,"world":"stub","run":"run-a","steps":1}"#).is_err());
    step(&mut gate, &sense(0, 0.0), Instant::now()).unwrap();
    assert!(gate.admit_end(br#"{"protocol":1,"world":"stub","run":"run-x","steps":1}"#).is_err());
    assert!(gate.admit_end(b"[]").is_err());
    assert_eq!(
        gate.admit_end(br#"{"protocol":1,"world":"stub","run":"run-a","steps":1}"#).unwrap().steps,
        1
    );
    assert_eq!(gate.dropped().total(), 3);
}

#[test]
fn the_published_schemas_are_the_types_schemas() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../schemas/devices/1");
    let write = std::env::var_os("MRT_WRITE_SCHEMAS").is_some();
    for (name, schema) in mrt_devices::schemas() {
        let text = serde_json::to_string_pretty(&schema).unwrap() + "\n";
        let path = dir.join(name);
        if write {
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(&path, &text).unwrap();
        }
        let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            on_disk == text,
            "{} differs from the types' schema: run MRT_WRITE_SCHEMAS=1 cargo test -p mrt-devices",
            path.display()
        );
    }
}

proptest! {
    #[test]
    fn no_bytes_panic_the_gate(b in proptest::collection::vec(any::<u8>(), 0..512)) {
        let mut gate = Gate::new("stub", "home-1", 2);
        let _ = gate.admit(&b, Instant::now());
        let _ = gate.admit_end(&b);
    }

    #[test]
    fn no_values_in_a_well_formed_sense_panic_the_gate(
        step_ in any::<u64>(), time in any::<f64>(), x in any::<f64>(), w in 0u32..5000, h in 0u32..5000,
    ) {
        let mut gate = Gate::new("stub", "home-1", 2);
        let mut s = sense(step_, time);
        s.odometry.as_mut().unwrap().wheels = Some(vec![x, x]);
        s.game.attack = x;
        let _ = gate.admit(&bytes(&s), Instant::now());
        let _ = gate.admit(&image_sense(ImageData { width: w, height: h, encoding: Encoding::Rgb8, data: b64(&[0; 12]) }), Instant::now());
    }
}
