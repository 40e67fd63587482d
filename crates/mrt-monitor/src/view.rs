//! What the web monitor shows: a [`Timeline`] of frames, one per instant of the bus's clock,
//! each the simulator's [`Truth`] and every robot's beliefs ([`RobotView`]) at that instant,
//! built from the same topics a recording holds (`/<robot>/<type>` and `/truth`), read back
//! from a file ([`Timeline::of_recording`]) or fed live by a [`Recorder`](crate::Recorder)'s
//! listener (`mrt sim --serve`).
//!
//! Everything in a frame is in the field frame (metres from the centre spot, x towards the
//! east goal, radians): the robots' team-frame beliefs (`WorldSnapshot`, `PlannedPath`) are
//! turned with the direction the robot's team attacks (`GameInfo::attack`).

use crate::camera::CompressedImage;
use crate::replay::{Recording, ReplayError};
use mrt_core::frames::{Attack, Framed, Team};
use mrt_core::{Point2, Pose2, Time};
use mrt_msgs::{
    BehaviorStatus, GameInfo, GameState, HfsmStructure, ImageDetections, Localization, Percepts,
    PlannedPath, RobotClass, RobotCommand, Sighting, WorldSnapshot,
};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, VecDeque};
use std::sync::{Arc, Mutex};

/// What the simulator knows and the robots do not, recorded each cycle on the topic `/truth`
/// beside the robots' messages (`mrt sim --record`): field frame, m, m/s, rad.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Truth {
    /// The ball's place.
    pub ball: (f64, f64),
    /// The ball's velocity.
    pub ball_velocity: (f64, f64),
    /// Every robot's pose, home's then away's.
    pub robots: Vec<Pose2>,
    /// How many of `robots` are home's.
    pub home: usize,
    /// Goals, home : away.
    pub score: (u32, u32),
    /// The referee's state.
    pub state: GameState,
}

/// Which match a recording holds, recorded once at its start on the topic `/match`
/// (`mrt sim --record`): what a replay needs to re-run a robot's behaviors.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct MatchInfo {
    /// The home team's stack (`milan`, `chaos`, `isocrob`, `chaser`).
    pub home: String,
    /// The away team's stack (`None`: home alone on the field).
    pub away: Option<String>,
    /// The match's seed.
    pub seed: u64,
    /// Robots a team; robot 0 of each keeps goal.
    pub team_size: usize,
    /// The robots' control period, s.
    pub period: f64,
    /// What the recording keeps ([`RecordProfile`](crate::RecordProfile)): a compact one
    /// cannot re-run a robot's behaviors exactly (`mrt replay --robot` says so). Absent in
    /// recordings made before it was recorded: full.
    #[serde(default)]
    pub profile: crate::RecordProfile,
}

/// The most frames a timeline keeps (two hours at the robots' 10 Hz): older ones are dropped
/// first, so that a live monitor's memory stays bounded however long the robots run.
pub const MAX_FRAMES: usize = 72_000;

/// A robot another robot anchored (MAP), in the field frame.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AnchorView {
    /// Where it is, m.
    pub at: (f64, f64),
    /// Teammate, opponent or unknown.
    pub class: RobotClass,
    /// How much the anchor is trusted, 0 to 1.
    pub reliability: f64,
}

/// What one robot believes at one instant, in the field frame (m, rad), as its messages told
/// it: the last of each type at or before the frame's time.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RobotView {
    /// Its topics' prefix, e.g. `home/2`.
    pub name: String,
    /// Its place in the truth's robots (home's, then away's), when known.
    pub truth_index: Option<usize>,
    /// The direction its team attacks, +1 east, −1 west (`GameInfo`).
    pub attack: f64,
    /// Where it believes it is (`Localization`).
    pub pose: Option<Pose2>,
    /// One standard deviation of that position, m.
    pub sigma_xy: f64,
    /// One standard deviation of that heading, rad.
    pub sigma_theta: f64,
    /// The pose's quality, 0 to 1.
    pub quality: f64,
    /// Where it believes the ball is (its own tracker, `Localization::ball`).
    pub ball: Option<(f64, f64)>,
    /// How long ago it last saw the ball, s.
    pub ball_seen_ago: f64,
    /// The team's ball (`WorldSnapshot::global_ball`), when its quality is above 0.
    pub team_ball: Option<(f64, f64)>,
    /// The team ball's quality.
    pub team_ball_quality: f64,
    /// The robots it anchored.
    pub anchors: Vec<AnchorView>,
    /// Its role (`getRole`).
    pub role: String,
    /// Its SCARE activity, functionality and sub-task, e.g. `BringBall: ReachBall`.
    pub job: String,
    /// Whether it holds the ball booking.
    pub ball_booked: bool,
    /// Whether its world model needs landmarks to localize it.
    pub needs_localization: bool,
    /// The game state it believes.
    pub game_state: GameState,
    /// The path SPIKE planned for it, field frame, m.
    pub path: Vec<(f64, f64)>,
    /// Its HFSM's active path (`BehaviorStatus::path`).
    pub hfsm: String,
    /// The behavior that ran.
    pub behavior: Option<String>,
    /// Its behaviors' activations (the HBM's or Mr. BRIAN's), name and degree.
    pub activations: Vec<(String, f64)>,
    /// The behavior errors it reported last.
    pub errors: Vec<String>,
    /// Its last command: linear (m/s) and rotational (rad/s) velocity, and a kick.
    pub command: Option<CommandView>,
    /// What its vision found in its last image (`Percepts`), in its own frame.
    pub seen: Option<SeenView>,
    /// The frame at which its last recorded camera image was taken ([`Timeline::image`];
    /// what its vision found in that image: [`Timeline::image_seen`]).
    pub image: Option<usize>,
    /// The frame at which the shape of its HFSM now in force was first told
    /// ([`Timeline::hfsm`]; the shape is kept once, not in every frame).
    #[serde(default)]
    pub hfsm_structure: Option<usize>,
}

/// What a robot's vision found in one image (`Percepts`), in the robot's frame (x forward, y
/// to the left, m): the page draws it from where the robot believes it is.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SeenView {
    /// The ball.
    pub ball: Option<(f64, f64)>,
    /// The nets and the field's landmarks.
    pub landmarks: Vec<(f64, f64)>,
    /// The landmark posts.
    pub posts: Vec<(f64, f64)>,
    /// The other robots' nearest points.
    pub robots: Vec<(f64, f64)>,
    /// Points of the white field lines.
    pub lines: Vec<(f64, f64)>,
}

impl SeenView {
    fn of(p: &Percepts) -> SeenView {
        let at = |s: &Sighting| (s.distance * s.bearing.cos(), s.distance * s.bearing.sin());
        let mut sightings = p.sightings.iter();
        let ball = sightings.next().copied().flatten().map(|s| at(&s));
        SeenView {
            ball,
            landmarks: sightings.flatten().map(at).collect(),
            posts: p.posts.iter().map(|q| at(&q.sighting)).collect(),
            robots: p.robots.iter().map(|r| at(&r.sighting)).collect(),
            lines: p.line_points.iter().map(|q| (q.inner.x, q.inner.y)).collect(),
        }
    }
}

/// A robot's command as the monitor shows it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CommandView {
    /// Forward, m/s.
    pub vlin: f64,
    /// Sideways, m/s.
    pub vlat: f64,
    /// Turning, rad/s.
    pub vrot: f64,
    /// Whether it kicks.
    pub kick: bool,
}

/// One instant: the truth (when recorded) and every robot's beliefs.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    /// The bus's clock, s.
    pub t: f64,
    /// The simulator's truth at `t`, when there is one.
    pub truth: Option<Truth>,
    /// Every robot heard so far, by name.
    pub robots: Vec<RobotView>,
}

/// The field the robots' world models know (`WorldSnapshot::field`), in metres.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FieldView {
    /// From the centre spot to a goal line.
    pub half_length: f64,
    /// From the centre line to a side line.
    pub half_width: f64,
    /// From the middle of a goal to a post.
    pub goal_half_width: f64,
    /// From the goal line to the penalty area's line.
    pub penalty_area_depth: f64,
}

/// Frames in time order (module doc), each kept as the JSON the web page reads.
#[derive(Debug, Default)]
pub struct Timeline {
    frames: VecDeque<(f64, Arc<str>)>,
    /// How many frames were dropped from the front ([`MAX_FRAMES`]).
    dropped: usize,
    /// The instant being gathered, and whether a message came for it.
    now: Option<Time>,
    truth: Option<Truth>,
    robots: BTreeMap<String, RobotView>,
    /// Camera images by robot.
    images: BTreeMap<String, Images>,
    /// The last image detections by robot, waiting for their image (`time`, [`SeenImage`] as
    /// JSON).
    seen_pending: BTreeMap<String, (f64, Arc<str>)>,
    /// HFSM shapes by robot.
    structures: BTreeMap<String, Structures>,
    field: Option<FieldView>,
    /// Messages of a known type that did not parse, counted and left out.
    unreadable: u64,
    finished: bool,
}

/// One robot's camera images, oldest first.
type Images = VecDeque<Shot>;

/// One camera image of a robot.
#[derive(Debug)]
struct Shot {
    /// The frame it came in.
    index: usize,
    /// When it was taken, s (its timestamp).
    time: f64,
    /// The JPEG.
    jpeg: Arc<[u8]>,
    /// What the robot's vision found in it ([`SeenImage`] as JSON), once its percepts came.
    seen: Option<Arc<str>>,
}

/// What a robot's vision found in one camera image, where in the image
/// (`Percepts::detections`): what the page draws over the picture (ISocRob-2000 report §3.2.7,
/// the Monitor's window per vision channel).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SeenImage {
    /// The image's time, s (the same as the picture's).
    pub time: f64,
    /// The objects, pixels.
    pub detections: ImageDetections,
}

/// Percepts and images are paired by the image's time, to within this, s.
const SAME_IMAGE: f64 = 5e-4;

/// The shapes of one robot's HFSM ([`HfsmStructure`] as JSON), each with the frame it was
/// first told in, oldest first; one entry per change, not per message.
type Structures = VecDeque<(usize, Arc<str>)>;

/// A timeline shared by its writer (a recording read back, a live match) and the web server.
pub type SharedTimeline = Arc<Mutex<Timeline>>;

impl Timeline {
    /// An empty timeline.
    pub fn new() -> Timeline {
        Timeline::default()
    }

    /// The same timeline, shared.
    pub fn shared(self) -> SharedTimeline {
        Arc::new(Mutex::new(self))
    }

    /// Every readable message of `recording`, in file order, then [`Timeline::finish`].
    pub fn of_recording(recording: &Recording) -> Result<Timeline, ReplayError> {
        let mut timeline = Timeline::new();
        recording.scan(|e| timeline.ingest(e.topic, e.time, e.json))?;
        timeline.finish();
        Ok(timeline)
    }

    /// Takes one message of `topic` (`/truth` or `/<robot>/<type>`) logged at `time`. A
    /// message later than the instant being gathered closes that instant's frame first; an
    /// earlier one (out of order) updates the beliefs of the instant being gathered. Types
    /// the monitor does not draw are passed over; a message of a drawn type that does not
    /// parse is counted ([`Timeline::unreadable`]) and left out.
    pub fn ingest(&mut self, topic: &str, time: Time, json: &[u8]) {
        match self.now {
            Some(now) if time > now => {
                self.close_frame(now);
                self.now = Some(time);
            }
            None => self.now = Some(time),
            _ => {}
        }
        let ok = if topic == "/truth" {
            serde_json::from_slice(json).map(|t| self.truth = Some(t)).is_ok()
        } else {
            let Some((name, ty)) = topic.trim_start_matches('/').rsplit_once('/') else {
                return;
            };
            if ty == "camera" {
                self.camera_image(name, json)
            } else {
                self.robot_message(name, ty, json)
            }
        };
        if !ok {
            self.unreadable += 1;
        }
    }

    /// Whether the message parsed (types not drawn count as parsed).
    fn robot_message(&mut self, name: &str, ty: &str, json: &[u8]) -> bool {
        let index = self.end();
        let view = self.robots.entry(name.to_string()).or_insert_with(|| RobotView {
            name: name.to_string(),
            attack: 1.0,
            ..RobotView::default()
        });
        match ty {
            "GameInfo" => parse(json).map(|g: GameInfo| view.attack = g.attack).is_some(),
            "Localization" => parse(json).map(|l: Localization| view.localization(&l)).is_some(),
            "WorldSnapshot" => match parse::<WorldSnapshot>(json) {
                Some(w) => {
                    view.world(&w);
                    let f = w.field;
                    self.field.get_or_insert(FieldView {
                        half_length: f.half_length,
                        half_width: f.half_width,
                        goal_half_width: f.goal_half_width,
                        penalty_area_depth: f.penalty_area_depth,
                    });
                    true
                }
                None => false,
            },
            "PlannedPath" => parse(json).map(|p: PlannedPath| view.planned(&p)).is_some(),
            "BehaviorStatus" => parse(json).map(|b: BehaviorStatus| view.status(b)).is_some(),
            "RobotCommand" => parse(json).map(|c: RobotCommand| view.command(&c)).is_some(),
            "Percepts" => match parse::<Percepts>(json) {
                Some(p) => {
                    view.seen = Some(SeenView::of(&p));
                    if let Some(detections) = p.detections {
                        self.image_detections(name, SeenImage { time: p.time, detections });
                    }
                    true
                }
                None => false,
            },
            "HfsmStructure" => match parse::<HfsmStructure>(json) {
                Some(h) => {
                    let known = self.structures.entry(name.to_string()).or_default();
                    let Ok(json) = serde_json::to_string(&h) else { return false };
                    // Told again unchanged (for monitors that join late): kept once.
                    if known.back().is_none_or(|(_, last)| **last != *json) {
                        known.push_back((index, json.into()));
                        view.hfsm_structure = Some(index);
                    }
                    true
                }
                None => false,
            },
            _ => true,
        }
    }

    /// Pairs what the vision of robot `name` found with its image of the same time: the
    /// last image kept, or the next one to come.
    fn image_detections(&mut self, name: &str, seen: SeenImage) {
        let Ok(json) = serde_json::to_string(&seen) else { return };
        let shot = self.images.get_mut(name).and_then(|i| i.back_mut());
        match shot {
            Some(shot) if (shot.time - seen.time).abs() <= SAME_IMAGE => {
                shot.seen = Some(json.into());
            }
            _ => {
                self.seen_pending.insert(name.to_string(), (seen.time, json.into()));
            }
        }
    }

    /// Keeps a camera image (`foxglove.CompressedImage`) of robot `name` for the frame being
    /// gathered; whether it parsed.
    fn camera_image(&mut self, name: &str, json: &[u8]) -> bool {
        let Some(image) = parse::<CompressedImage>(json) else { return false };
        let Some(bytes) = image.bytes() else { return false };
        let index = self.end();
        let time = f64::from(image.timestamp.sec) + f64::from(image.timestamp.nsec) * 1e-9;
        let seen = match self.seen_pending.get(name) {
            Some((t, seen)) if (t - time).abs() <= SAME_IMAGE => Some(seen.clone()),
            _ => None,
        };
        let shot = Shot { index, time, jpeg: bytes.into(), seen };
        self.images.entry(name.to_string()).or_default().push_back(shot);
        if let Some(view) = self.robots.get_mut(name) {
            view.image = Some(index);
        }
        true
    }

    /// The camera image (JPEG) of robot `name` last taken at or before frame `index`.
    pub fn image(&self, name: &str, index: usize) -> Option<Arc<[u8]>> {
        self.shot(name, index).map(|s| s.jpeg.clone())
    }

    /// What the vision of robot `name` found in the image [`Timeline::image`] gives for frame
    /// `index` ([`SeenImage`] as JSON): the same image, paired by its time; `None` when its
    /// percepts said nothing of the image.
    pub fn image_seen(&self, name: &str, index: usize) -> Option<Arc<str>> {
        self.shot(name, index).and_then(|s| s.seen.clone())
    }

    fn shot(&self, name: &str, index: usize) -> Option<&Shot> {
        let images = self.images.get(name)?;
        let k = images.partition_point(|s| s.index <= index);
        images.get(k.checked_sub(1)?)
    }

    /// The shape of robot `name`'s HFSM in force at frame `index` ([`HfsmStructure`] as
    /// JSON): the last told at or before it (ThinkingCap/TeamChaos report §4.1, §5.1).
    pub fn hfsm(&self, name: &str, index: usize) -> Option<Arc<str>> {
        let known = self.structures.get(name)?;
        let k = known.partition_point(|(i, _)| *i <= index);
        known.get(k.checked_sub(1)?).map(|(_, json)| json.clone())
    }

    fn close_frame(&mut self, now: Time) {
        let robots = self
            .robots
            .values()
            .map(|r| RobotView {
                truth_index: truth_index(&r.name, self.truth.as_ref()),
                ..r.clone()
            })
            .collect();
        let frame = Frame { t: now.as_secs_f64(), truth: self.truth.clone(), robots };
        let Ok(json) = serde_json::to_string(&frame) else { return };
        if self.frames.len() >= MAX_FRAMES {
            self.frames.pop_front();
            self.dropped += 1;
            for images in self.images.values_mut() {
                while images.front().is_some_and(|s| s.index < self.dropped) {
                    images.pop_front();
                }
            }
            // The shape in force at the first frame kept stays.
            for known in self.structures.values_mut() {
                while known.get(1).is_some_and(|(i, _)| *i <= self.dropped) {
                    known.pop_front();
                }
            }
        }
        self.frames.push_back((frame.t, json.into()));
    }

    /// Closes the last instant's frame: nothing more will come.
    pub fn finish(&mut self) {
        if let Some(now) = self.now.take() {
            self.close_frame(now);
        }
        self.finished = true;
    }

    /// Whether [`Timeline::finish`] was called (a recording read whole, a match over).
    pub fn is_finished(&self) -> bool {
        self.finished
    }

    /// The index of the first frame kept (frames before it were dropped, [`MAX_FRAMES`]).
    pub fn first(&self) -> usize {
        self.dropped
    }

    /// The index after the last frame.
    pub fn end(&self) -> usize {
        self.dropped + self.frames.len()
    }

    /// Frame `index` as JSON ([`Frame`]), when it is kept.
    pub fn frame(&self, index: usize) -> Option<Arc<str>> {
        let k = index.checked_sub(self.dropped)?;
        self.frames.get(k).map(|(_, json)| json.clone())
    }

    /// The time of frame `index`, s.
    pub fn time(&self, index: usize) -> Option<f64> {
        let k = index.checked_sub(self.dropped)?;
        self.frames.get(k).map(|(t, _)| *t)
    }

    /// The field, from the first world snapshot.
    pub fn field(&self) -> Option<FieldView> {
        self.field
    }

    /// How many messages of a drawn type did not parse.
    pub fn unreadable(&self) -> u64 {
        self.unreadable
    }
}

fn parse<T: serde::de::DeserializeOwned>(json: &[u8]) -> Option<T> {
    serde_json::from_slice(json).ok()
}

/// `home/k` is the truth's robot `k`, `away/k` its robot `home + k`.
pub(crate) fn truth_index(name: &str, truth: Option<&Truth>) -> Option<usize> {
    let truth = truth?;
    let (team, k) = name.rsplit_once('/')?;
    let k: usize = k.parse().ok()?;
    let i = match team {
        "home" => Some(k),
        "away" => truth.home.checked_add(k),
        _ => None,
    }?;
    (i < truth.robots.len()).then_some(i)
}

impl RobotView {
    fn attack(&self) -> Attack {
        Attack::from_direction(self.attack)
    }

    /// A team-frame point, in the field frame.
    fn field_point(&self, p: Framed<Team, Point2>) -> (f64, f64) {
        let p = p.to_field(self.attack());
        (p.inner.x, p.inner.y)
    }

    fn localization(&mut self, l: &Localization) {
        self.pose = Some(l.pose.inner);
        self.sigma_xy = l.sigma_xy;
        self.sigma_theta = l.sigma_theta;
        self.quality = l.quality;
        self.ball = l.ball.map(|b| (b.at.inner.x, b.at.inner.y));
        self.ball_seen_ago = l.ball.map_or(f64::INFINITY, |b| b.seen_ago);
    }

    fn world(&mut self, w: &WorldSnapshot) {
        let b = w.global_ball;
        self.team_ball =
            (b.quality > 0.0).then(|| self.field_point(Framed::new(b.pose.inner.position())));
        self.team_ball_quality = b.quality;
        self.anchors = w
            .robots
            .iter()
            .map(|r| AnchorView {
                at: self.field_point(r.at),
                class: r.class,
                reliability: r.reliability,
            })
            .collect();
        self.role = w.role.clone();
        self.job = w.job.as_ref().map_or_else(String::new, |j| {
            if j.functionality.is_empty() || j.functionality == j.activity {
                format!("{}: {}", j.activity, j.subtask)
            } else {
                format!("{} ({}): {}", j.activity, j.functionality, j.subtask)
            }
        });
        self.ball_booked = w.ball_booked;
        self.needs_localization = w.needs_localization;
        self.game_state = w.game_state;
    }

    fn planned(&mut self, p: &PlannedPath) {
        let attack = self.attack();
        self.path = p
            .poses
            .iter()
            .map(|q| {
                let f = q.to_field(attack).inner;
                (f.x, f.y)
            })
            .collect();
    }

    fn status(&mut self, b: BehaviorStatus) {
        self.hfsm = b.path;
        self.behavior = b.behavior;
        self.activations = b.activations;
        self.errors = b.errors;
    }

    fn command(&mut self, c: &RobotCommand) {
        self.command = Some(CommandView {
            vlin: c.twist.vx,
            vlat: c.twist.vy,
            vrot: c.twist.omega,
            kick: c.kick.is_some(),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_msgs::{AnchoredRobot, BallBelief, Estimate};
    use proptest::prelude::*;

    fn at(t: f64) -> Time {
        Time::from_secs_f64(t)
    }

    fn json<T: Serialize>(v: &T) -> Vec<u8> {
        serde_json::to_vec(v).unwrap()
    }

    fn frame(t: &Timeline, i: usize) -> Frame {
        serde_json::from_str(&t.frame(i).unwrap()).unwrap()
    }

    fn truth(score: (u32, u32)) -> Truth {
        Truth {
            ball: (1.0, 2.0),
            ball_velocity: (0.0, 0.0),
            robots: vec![Pose2::new(-3.0, 0.0, 0.0), Pose2::new(3.0, 0.0, 3.0)],
            home: 1,
            score,
            state: GameState::Playing,
        }
    }

    /// Messages of one instant make one frame; a later message closes it. An away robot that
    /// attacks west has its team frame turned half round into the field's: its team ball at
    /// (1, 0.5) is at (−1, −0.5) on the field, the robot it anchored at (2, 0) at (−2, 0), its
    /// planned pose (0.5, −0.25) at (−0.5, 0.25).
    #[test]
    fn one_frame_per_instant_in_the_field_frame() {
        let mut t = Timeline::new();
        t.ingest("/truth", at(0.0), &json(&truth((0, 0))));
        t.ingest(
            "/away/0/GameInfo",
            at(0.0),
            &json(&GameInfo { attack: -1.0, ..Default::default() }),
        );
        let l = Localization {
            pose: Framed::new(Pose2::new(3.0, 0.1, 3.0)),
            sigma_xy: 0.05,
            ball: Some(BallBelief {
                at: Framed::new(Point2::new(1.1, 2.0)),
                velocity: None,
                seen_ago: 0.0,
            }),
            ..Default::default()
        };
        t.ingest("/away/0/Localization", at(0.0), &json(&l));
        let w = WorldSnapshot {
            global_ball: Estimate { pose: Framed::new(Pose2::new(1.0, 0.5, 0.0)), quality: 0.8 },
            robots: vec![AnchoredRobot {
                at: Framed::new(Point2::new(2.0, 0.0)),
                class: RobotClass::Opponent,
                reliability: 0.7,
                ..Default::default()
            }],
            role: "attacker".into(),
            ..Default::default()
        };
        t.ingest("/away/0/WorldSnapshot", at(0.0), &json(&w));
        let pose = Framed::new(Pose2::new(0.5, -0.25, 0.0));
        let path = PlannedPath { poses: vec![pose], ..Default::default() };
        t.ingest("/away/0/PlannedPath", at(0.0), &json(&path));
        let mut seen = Percepts {
            line_points: vec![Framed::new(mrt_core::Point2::new(1.0, -0.5))],
            ..Default::default()
        };
        seen.sightings[mrt_msgs::sighting::BALL] =
            Some(Sighting { distance: 2.0, bearing: std::f64::consts::FRAC_PI_2 });
        t.ingest("/away/0/Percepts", at(0.0), &json(&seen));
        t.ingest("/away/0/SonarScan", at(0.0), b"{}");
        assert_eq!(t.end(), 0, "the instant is still open");
        t.ingest("/truth", at(0.1), &json(&truth((1, 0))));
        assert_eq!(t.end(), 1);
        let f = frame(&t, 0);
        assert_eq!(f.t, 0.0);
        assert_eq!(f.truth.as_ref().unwrap().score, (0, 0));
        let r = &f.robots[0];
        assert_eq!(r.name, "away/0");
        assert_eq!(r.truth_index, Some(1), "after the truth's one home robot");
        assert_eq!(r.pose, Some(Pose2::new(3.0, 0.1, 3.0)));
        assert_eq!(r.ball, Some((1.1, 2.0)));
        assert_eq!(r.team_ball, Some((-1.0, -0.5)));
        assert_eq!(r.anchors[0].at, (-2.0, -0.0));
        assert_eq!(r.anchors[0].class, RobotClass::Opponent);
        assert_eq!(r.path, vec![(-0.5, 0.25)]);
        assert_eq!(r.role, "attacker");
        let seen = r.seen.as_ref().unwrap();
        let ball = seen.ball.unwrap();
        assert!(ball.0.abs() < 1e-12 && (ball.1 - 2.0).abs() < 1e-12, "2 m to its left: {ball:?}");
        assert_eq!(seen.lines, vec![(1.0, -0.5)]);
        assert!(seen.landmarks.is_empty());
        assert_eq!(t.field().unwrap().half_length, w.field.half_length);
        t.finish();
        assert_eq!(t.end(), 2);
        assert_eq!(frame(&t, 1).truth.unwrap().score, (1, 0));
        assert_eq!(frame(&t, 1).robots[0].role, "attacker", "beliefs carry over");
        assert!(t.is_finished() && t.frame(2).is_none());
    }

    /// Camera images are kept by robot with the frame they came in; asking for a frame gives
    /// the last image taken at or before it.
    #[test]
    fn camera_images_are_kept_by_robot_and_frame() {
        let img = mrt_msgs::Image::new(8, 8);
        let jpeg = |t: f64| json(&CompressedImage::jpeg(&img, at(t), "camera").unwrap());
        let mut t = Timeline::new();
        t.ingest("/home/1/WorldSnapshot", at(0.0), &json(&WorldSnapshot::default()));
        t.ingest("/home/1/camera", at(0.0), &jpeg(0.0));
        t.ingest("/home/1/WorldSnapshot", at(0.1), &json(&WorldSnapshot::default()));
        t.ingest("/home/1/WorldSnapshot", at(0.2), &json(&WorldSnapshot::default()));
        t.ingest("/home/1/camera", at(0.2), &jpeg(0.2));
        t.ingest("/home/1/camera", at(0.3), b"{\"data\": 5}");
        t.finish();
        assert_eq!(t.unreadable(), 1);
        assert_eq!(frame(&t, 1).robots[0].image, Some(0));
        assert_eq!(frame(&t, 2).robots[0].image, Some(2));
        let first = t.image("home/1", 1).unwrap();
        assert_eq!(&first[..2], &[0xff, 0xd8]);
        assert!(Arc::ptr_eq(&first, &t.image("home/1", 0).unwrap()));
        assert!(!Arc::ptr_eq(&first, &t.image("home/1", 2).unwrap()));
        assert!(t.image("home/2", 2).is_none() && t.image("home/1", 0).is_some());
    }

    /// What the vision found in an image is served with that image, paired by the image's
    /// time whichever comes first: the percepts of a later image go with the later image,
    /// and percepts of an image not recorded go with none.
    #[test]
    fn image_detections_go_with_their_image() {
        use mrt_msgs::{DetectionKind, ImageDetection, ImageDetections};
        let img = mrt_msgs::Image::new(8, 8);
        let jpeg = |t: f64| json(&CompressedImage::jpeg(&img, at(t), "camera").unwrap());
        let percepts = |t: f64, x: f32| {
            let item = ImageDetection { kind: DetectionKind::Ball, x, y: 4.0, w: 2.0, h: 2.0 };
            let detections = ImageDetections { width: 8, height: 8, items: vec![item] };
            json(&Percepts { time: t, detections: Some(detections), ..Default::default() })
        };
        let seen = |t: &Timeline, i: usize| -> Option<SeenImage> {
            t.image_seen("home/1", i).map(|j| serde_json::from_str(&j).unwrap())
        };
        let mut t = Timeline::new();
        // The image first, then its percepts.
        t.ingest("/home/1/camera", at(0.0), &jpeg(0.0));
        t.ingest("/home/1/Percepts", at(0.0), &percepts(0.0, 1.0));
        // Percepts of an image that was not recorded.
        t.ingest("/home/1/Percepts", at(0.1), &percepts(0.1, 2.0));
        // Percepts first (a listener's order), then their image.
        t.ingest("/home/1/Percepts", at(0.2), &percepts(0.2, 3.0));
        t.ingest("/home/1/camera", at(0.2), &jpeg(0.2));
        // An image whose percepts never came.
        t.ingest("/home/1/camera", at(0.3), &jpeg(0.3));
        t.finish();
        let first = seen(&t, 0).unwrap();
        assert_eq!((first.time, first.detections.items[0].x), (0.0, 1.0));
        assert_eq!(seen(&t, 1).unwrap().detections.items[0].x, 1.0, "frame 1 shows image 0");
        assert_eq!(seen(&t, 2).unwrap().detections.items[0].x, 3.0);
        assert!(seen(&t, 3).is_none() && t.image("home/1", 3).is_some());
        assert_eq!(frame(&t, 2).robots[0].image, Some(2));
    }

    /// The HFSM's shape is kept once per change, not per message nor per frame; each frame
    /// names the shape in force, and the active path stays in the frame.
    #[test]
    fn the_hfsm_shape_is_kept_once_per_change() {
        use mrt_msgs::{HfsmMachine, HfsmState};
        let shape = |states: &[&str]| HfsmStructure {
            file: "p.hfsm.lua".into(),
            root: "P".into(),
            machines: vec![HfsmMachine {
                name: "P".into(),
                initial: states[0].into(),
                states: states
                    .iter()
                    .map(|s| HfsmState { name: (*s).into(), runs: None })
                    .collect(),
                transitions: Vec::new(),
            }],
        };
        let status = |path: &str| BehaviorStatus { path: path.into(), ..Default::default() };
        let mut t = Timeline::new();
        t.ingest("/home/0/HfsmStructure", at(0.0), &json(&shape(&["A", "B"])));
        t.ingest("/home/0/BehaviorStatus", at(0.0), &json(&status("P/A")));
        t.ingest("/home/0/HfsmStructure", at(0.1), &json(&shape(&["A", "B"])));
        t.ingest("/home/0/BehaviorStatus", at(0.1), &json(&status("P/B")));
        t.ingest("/home/0/HfsmStructure", at(0.2), &json(&shape(&["A", "C"])));
        t.ingest("/home/0/HfsmStructure", at(0.3), b"{\"root\": 7}");
        t.finish();
        assert_eq!(t.unreadable(), 1);
        assert_eq!(t.structures["home/0"].len(), 2, "told again unchanged: kept once");
        let f1 = frame(&t, 1);
        assert_eq!((f1.robots[0].hfsm.as_str(), f1.robots[0].hfsm_structure), ("P/B", Some(0)));
        assert_eq!(frame(&t, 3).robots[0].hfsm_structure, Some(2));
        let back: HfsmStructure = serde_json::from_str(&t.hfsm("home/0", 1).unwrap()).unwrap();
        assert_eq!(back, shape(&["A", "B"]));
        let later: HfsmStructure = serde_json::from_str(&t.hfsm("home/0", 3).unwrap()).unwrap();
        assert_eq!(later.machines[0].states[1].name, "C");
        assert!(t.hfsm("home/1", 3).is_none());
        assert!(!t.frame(1).unwrap().contains("\"machines\""), "not copied into frames");
    }

    /// A message of a drawn type that does not parse is counted and changes nothing; a topic
    /// with no robot name is passed over.
    #[test]
    fn unreadable_messages_are_counted_and_left_out() {
        let mut t = Timeline::new();
        t.ingest("/home/1/Localization", at(0.0), b"{\"pose\": 3}");
        t.ingest("/truth", at(0.0), b"[]");
        t.ingest("nothing", at(0.0), b"{}");
        t.ingest("/home/1/Odometry", at(0.0), b"not even JSON");
        t.finish();
        assert_eq!(t.unreadable(), 2);
        let f = frame(&t, 0);
        assert!(f.truth.is_none() && f.robots[0].pose.is_none());
    }

    /// The timeline keeps at most [`MAX_FRAMES`]: the oldest go first and indices stay.
    #[test]
    fn the_oldest_frames_are_dropped_beyond_the_limit() {
        let mut t = Timeline::new();
        for k in 0..=MAX_FRAMES + 1 {
            t.ingest("/truth", Time(k as u64 * 100_000_000), &json(&truth((0, 0))));
        }
        t.finish();
        assert_eq!((t.first(), t.end()), (2, MAX_FRAMES + 2));
        assert!(t.frame(1).is_none());
        assert!((t.time(2).unwrap() - 0.2).abs() < 1e-9);
    }

    proptest! {
        /// Any bytes on any topic: taken or counted, never a panic.
        #[test]
        fn any_message_is_taken_or_counted(
            topic in prop::sample::select(vec![
                "/truth", "/home/0/WorldSnapshot", "/away/1/Localization", "/x/BehaviorStatus",
                "/home/2/RobotCommand", "/home/2/PlannedPath", "/away/0/GameInfo", "//", "",
            ]),
            time in any::<u64>(),
            bytes in prop::collection::vec(any::<u8>(), 0..200),
        ) {
            let mut t = Timeline::new();
            t.ingest(topic, Time(time), &bytes);
            t.finish();
            prop_assert!(t.end() <= 1);
        }
    }
}
