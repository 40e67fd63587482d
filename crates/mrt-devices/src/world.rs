//! The world's side of the protocol, for a world written in Rust (`mrt sim --distributed`):
//! readings in the robot program's own types as they travel ([`odometry`], [`camera`],
//! [`game`], [`sonars`]: what the robot's [`Gate`](crate::Gate) reads back, number for number),
//! and which of its robots' messages the world takes ([`Answers`]).

use crate::gate::Refusal;
use crate::messages::{
    Act, Bye, CameraReading, Dropped, Encoding, GameReading, ImageData, Mice, ObjectsReading,
    OdometryReading, Pose, RefereeState, RobotSeen, Seen, SonarReading, TeamMarker,
    UpCameraReading, PROTOCOL,
};
use crate::Keys;
use base64::Engine;
use mrt_core::Pose2;
use mrt_msgs::{
    sighting, CameraFrame, GameInfo, GameState, Image, Marker, MiceReadings, Sighting, Sonar,
};

fn pose(p: &Pose2) -> Pose {
    Pose { x: p.x, y: p.y, theta: p.theta }
}

/// The odometry of one step: the mice (`None` when they read nothing: a robot without mice),
/// each wheel's turn (rad), where the robot was put down.
pub fn odometry(
    mice: &MiceReadings,
    wheel_turns: Option<Vec<f64>>,
    placed: Option<&Pose2>,
) -> OdometryReading {
    let m = [mice.x_left, mice.y_left, mice.x_right, mice.y_right];
    OdometryReading {
        mice: m.iter().all(|x| x.is_finite()).then_some(Mice {
            x_left: m[0],
            y_left: m[1],
            x_right: m[2],
            y_right: m[3],
        }),
        wheels: wheel_turns,
        placed: placed.map(pose),
    }
}

/// An image as it travels: rgb8, base64 (lossless, as a simulator's images should be).
pub fn image_data(image: &Image) -> ImageData {
    ImageData {
        width: image.width,
        height: image.height,
        encoding: Encoding::Rgb8,
        data: base64::engine::general_purpose::STANDARD.encode(&image.rgb),
    }
}

fn marker(m: Marker) -> TeamMarker {
    match m {
        Marker::Magenta => TeamMarker::Magenta,
        Marker::Cyan => TeamMarker::Cyan,
    }
}

fn seen(s: &Sighting) -> Seen {
    Seen { distance: s.distance, bearing: s.bearing }
}

/// A camera frame as it travels: its image, and the object sensor's sightings when the frame
/// has no image (an image's frame carries none: the robot's vision finds them). The up
/// camera's image goes beside it.
pub fn camera(frame: &CameraFrame) -> (CameraReading, Option<UpCameraReading>) {
    let objects = frame.image.is_none().then(|| {
        let at = |k: usize| frame.sightings.get(k).copied().flatten().as_ref().map(seen);
        ObjectsReading {
            ball: at(sighting::BALL),
            east_net: at(sighting::EAST_NET),
            west_net: at(sighting::WEST_NET),
            landmarks: (sighting::LANDMARK0..frame.sightings.len()).map(at).collect(),
            robots: frame
                .robots
                .iter()
                .map(|r| RobotSeen {
                    distance: r.sighting.distance,
                    bearing: r.sighting.bearing,
                    sigma: r.sigma.map(|(d, b)| [d, b]),
                    marker: r.marker.map(marker),
                })
                .collect(),
        }
    });
    let reading = CameraReading {
        time: frame.time,
        pan: frame.pan,
        image: frame.image.as_ref().map(image_data),
        objects,
    };
    (reading, frame.up_image.as_ref().map(|i| UpCameraReading { image: image_data(i) }))
}

/// The game controller's news as it travels.
pub fn game(g: &GameInfo) -> GameReading {
    GameReading {
        state: match g.state {
            GameState::Initial => RefereeState::Initial,
            GameState::Ready => RefereeState::Ready,
            GameState::Set => RefereeState::Set,
            GameState::Playing => RefereeState::Playing,
            GameState::Finished => RefereeState::Finished,
        },
        attack: g.attack,
        kickoff_pose: g.kickoff_pose.as_ref().map(|p| pose(&p.inner)),
        marker: g.marker.map(marker),
    }
}

/// The sonar ring as it travels (an infinite or NaN range: no echo).
pub fn sonars(ring: &[Sonar]) -> Vec<SonarReading> {
    ring.iter()
        .map(|s| SonarReading {
            bearing: s.bearing,
            range: (s.range.is_finite() && s.range >= 0.0).then_some(s.range),
        })
        .collect()
}

/// A robot's message that the world took.
#[derive(Clone, Debug, PartialEq)]
pub enum Answer {
    /// Robot `.0`'s answer to the step asked.
    Act(usize, Act),
    /// Robot `.0`'s last word.
    Bye(usize, Bye),
}

/// The world's rules for its robots' messages: an `act` counts when it answers the step
/// asked, from the robot its key names, of this world and run, with numbers that are numbers
/// and as many wheels as the base has; a `bye` when it is of this run. Everything else is
/// counted by reason ([`Answers::dropped`]) and left alone, so the robot's last answer holds.
pub struct Answers {
    world: String,
    run: String,
    robots: Vec<Keys>,
    wheels: usize,
    dropped: Dropped,
}

impl Answers {
    /// The rules of world `world`'s run `run` for robots `robots` (their names), on bases of
    /// `wheels` wheels.
    pub fn new(world: &str, run: &str, robots: &[String], wheels: usize) -> Result<Self, Refusal> {
        if !crate::is_name(run) {
            return Err(Refusal::Malformed(format!("{:?} is not a run id", run.escape_debug())));
        }
        let robots = robots.iter().map(|r| Keys::new(world, r)).collect::<Result<_, _>>()?;
        Ok(Answers {
            world: world.into(),
            run: run.into(),
            robots,
            wheels,
            dropped: Dropped::default(),
        })
    }

    /// The world's run.
    pub fn run(&self) -> &str {
        &self.run
    }

    /// Robot `i`'s keys.
    pub fn keys(&self, i: usize) -> Option<&Keys> {
        self.robots.get(i)
    }

    /// The robots' keys, in robot order.
    pub fn robots(&self) -> &[Keys] {
        &self.robots
    }

    /// The key expressions of every message the world's robots send, `act` and `bye` (and
    /// not the world's own `sense`, which lies beside them).
    pub fn subscriptions(&self) -> [String; 2] {
        let robots = format!("mrt/devices/{PROTOCOL}/{}/*", self.world);
        [format!("{robots}/act"), format!("{robots}/bye")]
    }

    /// What the world's drops were, by reason (`out_of_order`: an answer to another step).
    pub fn dropped(&self) -> Dropped {
        self.dropped
    }

    /// Takes the message `bytes` put on `key`, answering step `step` (`None`: no step is
    /// asked, acts are late). `None`: dropped and counted.
    pub fn take(&mut self, key: &str, bytes: &[u8], step: Option<u64>) -> Option<Answer> {
        match self.admit(key, bytes, step) {
            Ok(a) => Some(a),
            Err(refusal) => {
                refusal.count(&mut self.dropped);
                None
            }
        }
    }

    fn admit(&self, key: &str, bytes: &[u8], step: Option<u64>) -> Result<Answer, Refusal> {
        if bytes.len() > crate::MAX_MESSAGE {
            return Err(Refusal::TooLarge(bytes.len()));
        }
        let i =
            self.robots.iter().position(|k| k.act() == key || k.bye() == key).ok_or_else(|| {
                Refusal::Stranger(format!("key {:?}", key.escape_debug().to_string()))
            })?;
        let keys = &self.robots[i];
        let header: Header =
            serde_json::from_slice(bytes).map_err(|e| Refusal::Malformed(e.to_string()))?;
        crate::gate::version_is_ours(header.protocol)?;
        if header.world.as_deref() != Some(keys.world())
            || header.robot.as_deref() != Some(keys.robot())
            || header.run.as_deref() != Some(self.run.as_str())
        {
            return Err(Refusal::Stranger(format!(
                "robot {:?} of world {:?}, run {:?}",
                header.robot.unwrap_or_default().escape_debug().to_string(),
                header.world.unwrap_or_default().escape_debug().to_string(),
                header.run.unwrap_or_default().escape_debug().to_string()
            )));
        }
        if key == keys.bye() {
            let bye: Bye =
                serde_json::from_slice(bytes).map_err(|e| Refusal::Malformed(e.to_string()))?;
            return Ok(Answer::Bye(i, bye));
        }
        let act: Act =
            serde_json::from_slice(bytes).map_err(|e| Refusal::Malformed(e.to_string()))?;
        match step {
            Some(s) if s == act.step => {}
            _ => return Err(Refusal::OutOfOrder { got: act.step, last: step.unwrap_or(0) }),
        }
        let bad = |what: &str| Refusal::Malformed(format!("act: {what}"));
        if let Some(w) = &act.wheels {
            if w.len() != self.wheels || w.iter().any(|x| !x.is_finite()) {
                return Err(bad("wheels are not one finite speed per wheel"));
            }
        }
        if let Some(t) = &act.twist {
            if ![t.vx, t.vy, t.omega].iter().all(|x| x.is_finite()) {
                return Err(bad("twist is not finite"));
            }
        }
        if act.pan.is_some_and(|p| !p.is_finite()) {
            return Err(bad("pan is not finite"));
        }
        Ok(Answer::Act(i, act))
    }
}

/// The fields every message of a robot starts with, read before the rest.
#[derive(serde::Deserialize)]
struct Header {
    protocol: Option<u64>,
    world: Option<String>,
    run: Option<String>,
    robot: Option<String>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Admitted, Gate, Sense};
    use mrt_core::frames::Framed;
    use mrt_msgs::RobotSighting;
    use std::time::Instant;

    fn frame(with_image: bool) -> CameraFrame {
        let mut f =
            CameraFrame { time: 0.30000000000000004, pan: Some(-0.1), ..Default::default() };
        f.sightings[sighting::BALL] = Some(Sighting { distance: 1.0 / 3.0, bearing: 0.1 });
        f.sightings[sighting::NORTH_HALFWAY] = Some(Sighting { distance: 4.2, bearing: -2.9 });
        f.robots.push(RobotSighting {
            sighting: Sighting { distance: 2.0, bearing: 0.7 },
            sigma: Some((0.1, 0.02)),
            marker: Some(Marker::Cyan),
        });
        if with_image {
            f.sightings = Default::default();
            f.robots.clear();
            f.image = Some(Image { width: 2, height: 1, rgb: vec![1, 2, 3, 250, 251, 252] });
        }
        f
    }

    /// What a world writes with these functions, a robot's gate reads back exactly: the same
    /// numbers, bit for bit, so a match over the protocol is the match in one process.
    #[test]
    fn a_robots_readings_travel_and_come_back_the_same() {
        for with_image in [false, true] {
            let mice = MiceReadings::new(0.1, -1e-17, 0.7, 1.0 / 7.0);
            let placed = Pose2::new(-1.5, 2.0 / 3.0, 3.1);
            let turns = vec![0.1 + 0.2, -2.0 / 9.0];
            let info = GameInfo {
                state: GameState::Ready,
                attack: -1.0,
                kickoff_pose: Some(Framed::new(Pose2::new(-2.0, 0.5, 0.1))),
                marker: Some(Marker::Magenta),
            };
            let ring = [Sonar::new(0.0, 2.5), Sonar::new(0.39, f64::INFINITY)];
            let cam = frame(with_image);
            let (camera, up_camera) = camera(&cam);
            let sense = Sense {
                protocol: PROTOCOL,
                world: "sim".into(),
                run: "r1".into(),
                robot: "home-0".into(),
                step: 3,
                time: 0.30000000000000004,
                odometry: Some(odometry(&mice, Some(turns.clone()), Some(&placed))),
                camera: Some(camera),
                up_camera,
                sonars: Some(sonars(&ring)),
                game: game(&info),
            };
            let bytes = serde_json::to_vec(&sense).unwrap();
            let mut gate = Gate::new("sim", "home-0", 2);
            let Ok(Admitted::Step(r)) = gate.admit(&bytes, Instant::now()) else { panic!() };
            assert_eq!(r.time, sense.time);
            assert_eq!(r.mice, mice);
            assert_eq!(r.wheel_turns, Some(turns));
            assert_eq!(r.placed.map(|p| p.inner), Some(placed));
            assert_eq!(r.camera, Some(cam));
            assert_eq!(r.game, info);
            let back = r.sonars.unwrap();
            assert_eq!(back[0], ring[0]);
            assert!(back[1].range.is_infinite());
        }
    }

    fn answers() -> Answers {
        Answers::new("sim", "r1", &["home-0".into(), "away-0".into()], 3).unwrap()
    }

    fn act(robot: &str, step: u64) -> Act {
        Act {
            protocol: PROTOCOL,
            world: "sim".into(),
            run: "r1".into(),
            robot: robot.into(),
            step,
            wheels: Some(vec![1.0, 2.0, 3.0]),
            ..Act::default()
        }
    }

    #[test]
    fn the_world_takes_answers_to_the_step_asked_from_the_robot_its_key_names() {
        let mut a = answers();
        let key = a.keys(1).unwrap().act();
        let bytes = serde_json::to_vec(&act("away-0", 4)).unwrap();
        assert_eq!(a.take(&key, &bytes, Some(4)), Some(Answer::Act(1, act("away-0", 4))));
        // Late, early, or no step asked.
        assert_eq!(a.take(&key, &bytes, Some(5)), None);
        assert_eq!(a.take(&key, &bytes, None), None);
        assert_eq!(a.dropped().out_of_order, 2);
        // Another robot's answer on this robot's key, another run, an unknown key.
        let home = serde_json::to_vec(&act("home-0", 4)).unwrap();
        assert_eq!(a.take(&key, &home, Some(4)), None);
        let other = serde_json::to_vec(&Act { run: "r2".into(), ..act("away-0", 4) }).unwrap();
        assert_eq!(a.take(&key, &other, Some(4)), None);
        assert_eq!(a.take("mrt/devices/1/sim/nobody/act", &bytes, Some(4)), None);
        assert_eq!(a.dropped().stranger, 3);
        // The world subscribes to its robots' acts and byes, not to its own readings.
        let [acts, byes] = a.subscriptions();
        assert_eq!(
            (acts.as_str(), byes.as_str()),
            ("mrt/devices/1/sim/*/act", "mrt/devices/1/sim/*/bye")
        );
        // Wrong wheels, not a number, not JSON, another protocol.
        let two = serde_json::to_vec(&Act { wheels: Some(vec![1.0, 2.0]), ..act("away-0", 4) });
        assert_eq!(a.take(&key, &two.unwrap(), Some(4)), None);
        let nan = br#"{"protocol":1,"world":"sim","run":"r1","robot":"away-0","step":4,"wheels":null,"twist":null,"kick":false,"pan":1e999,"faults":[]}"#;
        assert_eq!(a.take(&key, nan, Some(4)), None);
        assert_eq!(a.take(&key, b"\xff{", Some(4)), None);
        assert_eq!(a.take(&key, br#"{"protocol": 2}"#, Some(4)), None);
        assert_eq!((a.dropped().malformed, a.dropped().protocol), (3, 1));
        let bye = Bye {
            protocol: PROTOCOL,
            world: "sim".into(),
            run: "r1".into(),
            robot: "home-0".into(),
            ..Bye::default()
        };
        let key = a.keys(0).unwrap().bye();
        let taken = a.take(&key, &serde_json::to_vec(&bye).unwrap(), None);
        assert_eq!(taken, Some(Answer::Bye(0, bye)));
    }

    proptest::proptest! {
        /// Nothing a robot sends makes the world's rules panic.
        #[test]
        fn any_bytes_are_taken_or_counted(bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..300)) {
            let mut a = answers();
            let key = a.keys(0).unwrap().act();
            let before = a.dropped().total();
            if a.take(&key, &bytes, Some(0)).is_none() {
                proptest::prop_assert_eq!(a.dropped().total(), before + 1);
            }
        }
    }
}
