//! The robot's side of the protocol's rules: which messages it takes ([`Gate`]), and the
//! readings a taken step gives its devices ([`Readings`]).

use crate::messages::{
    Dropped, Encoding, End, GameReading, ImageData, ObjectsReading, Pose, RefereeState, Seen,
    Sense, TeamMarker, LANDMARKS, PROTOCOL,
};
use base64::Engine;
use mrt_core::frames::Framed;
use mrt_core::Pose2;
use mrt_msgs::{
    CameraFrame, GameInfo, GameState, Image, Marker, MiceReadings, RobotSighting, Sighting, Sonar,
};
use std::time::{Duration, Instant};

/// The largest message a robot reads, bytes.
pub const MAX_MESSAGE: usize = 32 << 20;
/// The largest image side, pixels.
pub const MAX_IMAGE_SIDE: u32 = 4096;
/// The most a step's clock may jump ahead of the previous step's, s.
pub const MAX_TIME_STEP: f64 = 10.0;
/// How long a run must be silent before a robot follows a new run's step 0.
pub const RUN_SILENCE: Duration = Duration::from_secs(1);

/// Why a message was not used (each counts in [`Dropped`]).
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum Refusal {
    /// Not JSON, not of the schema, or an image that does not decode to its size.
    #[error("malformed: {0}")]
    Malformed(String),
    /// Over [`MAX_MESSAGE`].
    #[error("{0} bytes, more than {MAX_MESSAGE}")]
    TooLarge(usize),
    /// Another protocol version.
    #[error("protocol {0}, this robot speaks {PROTOCOL}")]
    Protocol(u64),
    /// Not this robot's world, name or run.
    #[error("a stranger: {0}")]
    Stranger(String),
    /// A step not after the last answered.
    #[error("step {got} after step {last}")]
    OutOfOrder {
        /// The step received.
        got: u64,
        /// The last step answered.
        last: u64,
    },
    /// A clock that is not finite, goes back or jumps.
    #[error("time {got} s after {last} s")]
    Clock {
        /// The step's time.
        got: f64,
        /// The previous step's.
        last: f64,
    },
}

impl Refusal {
    /// Counts this refusal in `dropped`.
    pub fn count(&self, dropped: &mut Dropped) {
        let slot = match self {
            Refusal::Malformed(_) => &mut dropped.malformed,
            Refusal::TooLarge(_) => &mut dropped.too_large,
            Refusal::Protocol(_) => &mut dropped.protocol,
            Refusal::Stranger(_) => &mut dropped.stranger,
            Refusal::OutOfOrder { .. } => &mut dropped.out_of_order,
            Refusal::Clock { .. } => &mut dropped.clock,
        };
        *slot += 1;
    }

    /// The count's name in [`Dropped`] (for logs).
    pub fn reason(&self) -> &'static str {
        match self {
            Refusal::Malformed(_) => "malformed",
            Refusal::TooLarge(_) => "too_large",
            Refusal::Protocol(_) => "protocol",
            Refusal::Stranger(_) => "stranger",
            Refusal::OutOfOrder { .. } => "out_of_order",
            Refusal::Clock { .. } => "clock",
        }
    }
}

/// What the gate made of a `sense`.
#[derive(Debug)]
pub enum Admitted {
    /// A new step: run a cycle on these readings and answer.
    Step(Box<Readings>),
    /// The last step answered, sent again: send this answer again.
    Repeat(Vec<u8>),
}

/// A taken step's readings, in the robot program's own types.
#[derive(Clone, Debug, PartialEq)]
pub struct Readings {
    /// The world's run.
    pub run: String,
    /// The step.
    pub step: u64,
    /// The world's clock, s.
    pub time: f64,
    /// Whether the step had an odometry reading at all.
    pub odometry: bool,
    /// The mice (all NaN without mice: the encoders count).
    pub mice: MiceReadings,
    /// Each wheel's turn, rad (`None`: no encoders).
    pub wheel_turns: Option<Vec<f64>>,
    /// Where the robot was put down.
    pub placed: Option<Framed<mrt_core::frames::Field, Pose2>>,
    /// The camera's frame: its time, pan and images (`None`: no image).
    pub camera: Option<CameraFrame>,
    /// The game controller.
    pub game: GameInfo,
    /// The sonar ring (`None`: no reading).
    pub sonars: Option<Vec<Sonar>>,
}

/// Whether `name` is a protocol name: 1–64 of `a–z 0–9 - _`.
pub fn is_name(name: &str) -> bool {
    (1..=64).contains(&name.len())
        && name
            .bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-' || b == b'_')
}

/// One robot's admission of what its world sends: which run it follows, the last step it
/// answered and that answer, and what it dropped.
#[derive(Debug)]
pub struct Gate {
    world: String,
    robot: String,
    wheels: usize,
    run: Option<String>,
    last: Option<Answered>,
    heard: Option<Instant>,
    dropped: Dropped,
}

#[derive(Debug)]
struct Answered {
    step: u64,
    time: f64,
    answer: Vec<u8>,
}

impl Gate {
    /// The gate of robot `robot` in world `world`, whose base has `wheels` wheels.
    pub fn new(world: &str, robot: &str, wheels: usize) -> Gate {
        Gate {
            world: world.to_string(),
            robot: robot.to_string(),
            wheels,
            run: None,
            last: None,
            heard: None,
            dropped: Dropped::default(),
        }
    }

    /// What was dropped so far.
    pub fn dropped(&self) -> Dropped {
        self.dropped
    }

    /// The run followed, once a step was taken.
    pub fn run(&self) -> Option<&str> {
        self.run.as_deref()
    }

    /// Steps answered in the current run (the last step + 1).
    pub fn steps(&self) -> u64 {
        self.last.as_ref().map_or(0, |a| a.step + 1)
    }

    /// Reads a `sense` received at `now`; a refusal is counted.
    pub fn admit(&mut self, bytes: &[u8], now: Instant) -> Result<Admitted, Refusal> {
        let r = self.check(bytes, now);
        if let Err(e) = &r {
            e.count(&mut self.dropped);
        }
        r
    }

    fn check(&mut self, bytes: &[u8], now: Instant) -> Result<Admitted, Refusal> {
        if bytes.len() > MAX_MESSAGE {
            return Err(Refusal::TooLarge(bytes.len()));
        }
        // The version first, skimming the rest (a message of another version may be of
        // another shape): the image's text is not copied for it.
        #[derive(serde::Deserialize)]
        struct Version {
            protocol: Option<u64>,
        }
        let version: Version =
            serde_json::from_slice(bytes).map_err(|e| Refusal::Malformed(e.to_string()))?;
        version_is_ours(version.protocol)?;
        let sense: Sense =
            serde_json::from_slice(bytes).map_err(|e| Refusal::Malformed(e.to_string()))?;
        if sense.world != self.world || sense.robot != self.robot {
            return Err(Refusal::Stranger(format!(
                "for robot {:?} of world {:?}",
                sense.robot, sense.world
            )));
        }
        let new_run = self.run.as_deref() != Some(sense.run.as_str());
        if new_run {
            let silent = self.heard.is_none_or(|t| now.duration_since(t) >= RUN_SILENCE);
            if !is_name(&sense.run) || self.run.is_some() && (sense.step != 0 || !silent) {
                return Err(Refusal::Stranger(format!("run {:?}", sense.run)));
            }
        }
        let last = if new_run { None } else { self.last.as_ref() };
        if let Some(last) = last {
            if sense.step == last.step && sense.time == last.time {
                self.heard = Some(now);
                return Ok(Admitted::Repeat(last.answer.clone()));
            }
            if sense.step <= last.step {
                return Err(Refusal::OutOfOrder { got: sense.step, last: last.step });
            }
        }
        let last_time = last.map(|l| l.time);
        let late_enough =
            last_time.is_none_or(|t| sense.time > t && sense.time - t <= MAX_TIME_STEP);
        if !sense.time.is_finite() || sense.time < 0.0 || !late_enough {
            return Err(Refusal::Clock { got: sense.time, last: last_time.unwrap_or(0.0) });
        }
        let readings = readings(&sense, self.wheels)?;
        if new_run {
            self.run = Some(sense.run);
            self.last = None;
        }
        self.heard = Some(now);
        Ok(Admitted::Step(Box::new(readings)))
    }

    /// Keeps the answer to step `step` at `time` (sent again if the step comes again).
    pub fn answered(&mut self, step: u64, time: f64, answer: Vec<u8>) {
        self.last = Some(Answered { step, time, answer });
    }

    /// Reads an `end`: whether it ends this robot's run (anything else is counted).
    pub fn admit_end(&mut self, bytes: &[u8]) -> Result<End, Refusal> {
        let r = (|| {
            if bytes.len() > MAX_MESSAGE {
                return Err(Refusal::TooLarge(bytes.len()));
            }
            let end: End =
                serde_json::from_slice(bytes).map_err(|e| Refusal::Malformed(e.to_string()))?;
            if end.protocol != PROTOCOL {
                return Err(Refusal::Protocol(u64::from(end.protocol)));
            }
            if end.world != self.world || self.run.as_deref() != Some(end.run.as_str()) {
                return Err(Refusal::Stranger(format!(
                    "end of run {:?} of {:?}",
                    end.run, end.world
                )));
            }
            Ok(end)
        })();
        if let Err(e) = &r {
            e.count(&mut self.dropped);
        }
        r
    }
}

/// Whether a message's `protocol` is the version these types speak.
pub(crate) fn version_is_ours(protocol: Option<u64>) -> Result<(), Refusal> {
    match protocol {
        Some(p) if p == u64::from(PROTOCOL) => Ok(()),
        Some(p) => Err(Refusal::Protocol(p)),
        None => Err(Refusal::Malformed("no protocol number".into())),
    }
}

fn bad(what: impl Into<String>) -> Refusal {
    Refusal::Malformed(what.into())
}

fn finite(x: f64, what: &str) -> Result<f64, Refusal> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(bad(format!("{what} is not a finite number")))
    }
}

fn pose(p: &Pose, what: &str) -> Result<Framed<mrt_core::frames::Field, Pose2>, Refusal> {
    Ok(Framed::new(Pose2::new(finite(p.x, what)?, finite(p.y, what)?, finite(p.theta, what)?)))
}

/// A step's readings in the robot's types, every number checked.
fn readings(s: &Sense, wheels: usize) -> Result<Readings, Refusal> {
    let odometry = s.odometry.clone().unwrap_or_default();
    let mice = match odometry.mice {
        Some(m) => MiceReadings::new(
            finite(m.x_left, "odometry.mice")?,
            finite(m.y_left, "odometry.mice")?,
            finite(m.x_right, "odometry.mice")?,
            finite(m.y_right, "odometry.mice")?,
        ),
        None => MiceReadings::new(f64::NAN, f64::NAN, f64::NAN, f64::NAN),
    };
    if let Some(w) = &odometry.wheels {
        if w.len() != wheels {
            return Err(bad(format!("{} wheel turns for a base of {wheels} wheels", w.len())));
        }
        for &x in w {
            finite(x, "odometry.wheels")?;
        }
    }
    let placed = odometry.placed.as_ref().map(|p| pose(p, "odometry.placed")).transpose()?;
    let camera = match &s.camera {
        Some(c) => {
            if c.image.is_none() && c.objects.is_none() {
                return Err(bad("camera has neither an image nor objects"));
            }
            let mut frame = CameraFrame {
                time: finite(c.time, "camera.time")?,
                pan: c.pan.map(|p| finite(p, "camera.pan")).transpose()?,
                image: c.image.as_ref().map(image).transpose()?,
                up_image: s.up_camera.as_ref().map(|u| image(&u.image)).transpose()?,
                ..CameraFrame::default()
            };
            if let Some(o) = &c.objects {
                objects(o, &mut frame)?;
            }
            Some(frame)
        }
        None => None,
    };
    let sonars = match &s.sonars {
        Some(ring) => Some(
            ring.iter()
                .map(|r| {
                    let range = match r.range {
                        Some(x) if x.is_finite() && x >= 0.0 => x,
                        Some(_) => return Err(bad("a sonar range is negative")),
                        None => f64::INFINITY,
                    };
                    Ok(Sonar::new(finite(r.bearing, "a sonar bearing")?, range))
                })
                .collect::<Result<Vec<_>, _>>()?,
        ),
        None => None,
    };
    Ok(Readings {
        run: s.run.clone(),
        step: s.step,
        time: s.time,
        odometry: s.odometry.is_some(),
        mice,
        wheel_turns: odometry.wheels,
        placed,
        camera,
        game: game(&s.game)?,
        sonars,
    })
}

/// An object sensor's frame into `frame`: its sightings in the world model's order (ball,
/// east net, west net, landmarks) and the robots.
fn objects(o: &ObjectsReading, frame: &mut CameraFrame) -> Result<(), Refusal> {
    if o.landmarks.len() > LANDMARKS {
        return Err(bad(format!("{} landmarks, at most {LANDMARKS}", o.landmarks.len())));
    }
    let seen = |s: &Seen| -> Result<Sighting, Refusal> {
        let distance = finite(s.distance, "camera.objects: a distance")?;
        if distance < 0.0 {
            return Err(bad("camera.objects: a distance is negative"));
        }
        Ok(Sighting { distance, bearing: finite(s.bearing, "camera.objects: a bearing")? })
    };
    let all = [&o.ball, &o.east_net, &o.west_net].into_iter().chain(&o.landmarks);
    for (slot, s) in frame.sightings.iter_mut().zip(all) {
        *slot = s.as_ref().map(seen).transpose()?;
    }
    frame.robots = o
        .robots
        .iter()
        .map(|r| {
            let sigma = match r.sigma {
                Some([d, b]) => {
                    Some((finite(d, "a robot's sigma")?, finite(b, "a robot's sigma")?))
                }
                None => None,
            };
            Ok(RobotSighting {
                sighting: seen(&Seen { distance: r.distance, bearing: r.bearing })?,
                sigma,
                marker: r.marker.map(marker),
            })
        })
        .collect::<Result<_, Refusal>>()?;
    Ok(())
}

fn marker(m: TeamMarker) -> Marker {
    match m {
        TeamMarker::Magenta => Marker::Magenta,
        TeamMarker::Cyan => Marker::Cyan,
    }
}

fn game(g: &GameReading) -> Result<GameInfo, Refusal> {
    let attack = finite(g.attack, "game.attack")?;
    if attack != 1.0 && attack != -1.0 {
        return Err(bad("game.attack is neither 1 nor -1"));
    }
    Ok(GameInfo {
        state: match g.state {
            RefereeState::Initial => GameState::Initial,
            RefereeState::Ready => GameState::Ready,
            RefereeState::Set => GameState::Set,
            RefereeState::Playing => GameState::Playing,
            RefereeState::Finished => GameState::Finished,
        },
        attack,
        kickoff_pose: g.kickoff_pose.as_ref().map(|p| pose(p, "game.kickoff_pose")).transpose()?,
        marker: g.marker.map(marker),
    })
}

/// The pixels of an image as it travels: its base64 decoded and, for a JPEG, the file
/// decoded, checked to be of the declared size.
pub fn image(d: &ImageData) -> Result<Image, Refusal> {
    let side = 1..=MAX_IMAGE_SIDE;
    if !side.contains(&d.width) || !side.contains(&d.height) {
        return Err(bad(format!("an image of {} × {} pixels", d.width, d.height)));
    }
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(d.data.as_bytes())
        .map_err(|e| bad(format!("image data: {e}")))?;
    let rgb = match d.encoding {
        Encoding::Rgb8 => bytes,
        Encoding::Jpeg => {
            let mut reader = image::ImageReader::with_format(
                std::io::Cursor::new(bytes),
                image::ImageFormat::Jpeg,
            );
            let mut limits = image::Limits::default();
            limits.max_image_width = Some(MAX_IMAGE_SIDE);
            limits.max_image_height = Some(MAX_IMAGE_SIDE);
            reader.limits(limits);
            let decoded = reader.decode().map_err(|e| bad(format!("image data: {e}")))?;
            let rgb = decoded.to_rgb8();
            if rgb.dimensions() != (d.width, d.height) {
                let (w, h) = rgb.dimensions();
                return Err(bad(format!(
                    "a JPEG of {w} × {h} pixels said to be {} × {}",
                    d.width, d.height
                )));
            }
            rgb.into_raw()
        }
    };
    let image = Image { width: d.width, height: d.height, rgb };
    if !image.is_consistent() {
        return Err(bad(format!(
            "{} bytes of rgb8 for {} × {} pixels",
            image.rgb.len(),
            d.width,
            d.height
        )));
    }
    Ok(image)
}
