//! What the sensor drivers publish (MRT manual §2.1: sensing modules): the optical mice and
//! wheels ([`Odometry`], manual ch. 4), the camera's object detections ([`CameraFrame`]), the
//! sonar ring ([`SonarScan`], ISocRob-2000 report §2), and the game controller's news
//! ([`GameInfo`]).

use crate::robot::{lps, GameState};
use mrt_core::frames::{Field, Framed, Robot};
use mrt_core::{Point2, Pose2};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// One sonar reading: where the sonar looks and how far the echo is (ISocRob-2000 report §2,
/// §3.2.3).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Sonar {
    /// Direction of the sonar in the robot frame, rad (0 = forward, counter-clockwise).
    pub bearing: f64,
    /// Distance from the robot centre to the echo, m. NaN or infinite means no echo (`null`
    /// in JSON, which has neither).
    #[serde(deserialize_with = "range_or_no_echo")]
    #[cfg_attr(feature = "schema", schemars(with = "Option<f64>"))]
    pub range: f64,
}

/// A sonar's range as written: JSON (human-readable formats) writes a range of no echo as
/// `null`, read back as an infinite range; binary formats carry the number itself.
fn range_or_no_echo<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    if d.is_human_readable() {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
    } else {
        f64::deserialize(d)
    }
}

impl Sonar {
    /// A reading.
    pub const fn new(bearing: f64, range: f64) -> Self {
        Self { bearing, range }
    }

    /// The bearing of sonar `i` of `n` equally spaced around the body, sonar 0 forward (the
    /// ISocRob robots have sixteen, ISocRob-2000 report §2).
    pub fn ring_bearing(i: usize, n: usize) -> f64 {
        if n == 0 {
            return 0.0;
        }
        2.0 * PI * (i % n) as f64 / n as f64
    }
}

/// One reading of the sonar ring (robot frame, m from the centre, ring order; no echo is an
/// infinite range), published by the sonar driver every cycle.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SonarScan {
    /// The sonars.
    pub sonars: Vec<Sonar>,
}

/// The four numbers the two mice give for one sampling period, metres, each in its own frame
/// (`x̄` along the joining line, positive to the robot's right; `ȳ` forward; manual §4.1).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MiceReadings {
    /// `x̄_l`: left mouse, lateral.
    pub x_left: f64,
    /// `ȳ_l`: left mouse, longitudinal.
    pub y_left: f64,
    /// `x̄_r`: right mouse, lateral.
    pub x_right: f64,
    /// `ȳ_r`: right mouse, longitudinal.
    pub y_right: f64,
}

impl MiceReadings {
    /// Readings `(x̄_l, ȳ_l, x̄_r, ȳ_r)`.
    pub const fn new(x_left: f64, y_left: f64, x_right: f64, y_right: f64) -> Self {
        Self { x_left, y_left, x_right, y_right }
    }

    /// Whether all four numbers are finite.
    pub fn is_finite(&self) -> bool {
        self.x_left.is_finite()
            && self.y_left.is_finite()
            && self.x_right.is_finite()
            && self.y_right.is_finite()
    }
}

/// The robot's motion over one sampling period, in the robot frame at the start of the period:
/// `(Δx, Δy)` metres, `Δθ` radians counter-clockwise (manual §4.1).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Displacement {
    /// `Δx`, forward, m.
    pub dx: f64,
    /// `Δy`, to the left, m.
    pub dy: f64,
    /// `Δθ`, rad.
    pub dtheta: f64,
}

impl Displacement {
    /// A displacement.
    pub const fn new(dx: f64, dy: f64, dtheta: f64) -> Self {
        Self { dx, dy, dtheta }
    }

    /// As a relative pose, to [`Pose2::compose`] onto the previous pose.
    pub fn as_pose(&self) -> Pose2 {
        Pose2::new(self.dx, self.dy, self.dtheta)
    }
}

/// What the odometry sensors read over one control cycle, published by the odometry driver
/// (manual ch. 4).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Odometry {
    /// The two optical mice, each in its own frame (MRT manual ch. 4), m.
    pub mice: MiceReadings,
    /// The wheel encoders' motion, in the robot frame at the start of the cycle.
    pub wheels: Displacement,
    /// The robot was put down by hand at this pose (field frame, m) since the last reading:
    /// the motion above counts from there. The operator tells the robot, as a team does when
    /// it places its robots before a match.
    pub placed: Option<Framed<Field, Pose2>>,
}

/// Indices into [`CameraFrame::sightings`] and [`Percepts::sightings`]: the objects a camera
/// tells apart by colour (ISocRob-2000 report §3.2.1), in the one order every part of MRT
/// uses. The field map says where each stands (`mrt_world::field::FieldMap::object`).
pub mod sighting {
    /// The ball.
    pub const BALL: usize = 0;
    /// The east net (the centre of its goal line).
    pub const EAST_NET: usize = 1;
    /// The west net.
    pub const WEST_NET: usize = 2;
    /// The corner post at the north-east corner, the first landmark.
    pub const NE_CORNER: usize = 3;
    /// The corner post at the south-east corner.
    pub const SE_CORNER: usize = 4;
    /// The corner post at the north-west corner.
    pub const NW_CORNER: usize = 5;
    /// The corner post at the south-west corner.
    pub const SW_CORNER: usize = 6;
    /// The post at the north end of the half-way line.
    pub const NORTH_HALFWAY: usize = 7;
    /// The post at the south end of the half-way line, the last landmark.
    pub const SOUTH_HALFWAY: usize = 8;
    /// The first landmark: landmarks are `LANDMARK0..COUNT`.
    pub const LANDMARK0: usize = NE_CORNER;
    /// How many objects the camera knows.
    pub const COUNT: usize = SOUTH_HALFWAY + 1;
}

/// How many objects the camera knows: the ball, two nets, six landmarks ([`sighting`]).
pub const FIELD_OBJECTS: usize = sighting::COUNT;

// The world model anchors each sighting in an LPS slot of the same index.
const _: () = assert!(FIELD_OBJECTS == lps::COUNT && sighting::LANDMARK0 == lps::LANDMARK0);

/// One object detected in one frame: distance (m) and bearing (rad, counter-clockwise from
/// the robot's heading), with the sensor's noise.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sighting {
    /// Distance, m.
    pub distance: f64,
    /// Bearing, rad.
    pub bearing: f64,
}

/// The colour of the marker band a robot wears round its top (RoboCup Middle Size League:
/// magenta or cyan, one per team for a match), which tells its team: MAP's classifier reads it
/// to make a Robot a Teammate or an Opponent (MRT manual ch. 8).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Marker {
    /// Magenta (the simulator's home team).
    Magenta,
    /// Cyan (the simulator's away team).
    Cyan,
}

impl Marker {
    /// The other team's colour.
    pub fn other(self) -> Marker {
        match self {
            Marker::Magenta => Marker::Cyan,
            Marker::Cyan => Marker::Magenta,
        }
    }
}

/// Another robot in one camera frame (object sensor or vision): the percept MAP anchors as a
/// Robot, a Teammate or an Opponent (MRT manual ch. 8).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobotSighting {
    /// Distance and bearing of its nearest point (its foot on the floor) from the robot's
    /// centre, m and rad.
    pub sighting: Sighting,
    /// Standard deviations `(distance m, bearing rad)`, when the sensor knows them.
    #[serde(default)]
    pub sigma: Option<(f64, f64)>,
    /// The colour of its marker, when seen; `None`: a robot of unknown team (its top out of
    /// view, too far, hidden).
    #[serde(default)]
    pub marker: Option<Marker>,
}

/// What the game controller tells every robot each cycle (field frame, m): the referee's
/// state of TeamChaos' `getCurrentState()` (ThinkingCap/TeamChaos report §3.3) and the robot's place in the
/// kickoff formation. Its own message, published by the game controller's driver (a radio
/// listening to the referee box on a real field), not part of any camera frame.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GameInfo {
    /// The referee's state.
    pub state: GameState,
    /// The direction the robot's team attacks: +1 east, −1 west.
    pub attack: f64,
    /// The robot's place in the kickoff formation (field frame, m), in READY.
    pub kickoff_pose: Option<Framed<Field, Pose2>>,
    /// The marker colour the robot's own team wears in this match (`None`: not told; then
    /// every other robot stays of unknown team).
    #[serde(default)]
    pub marker: Option<Marker>,
}

/// One camera frame, published by the camera driver: the image the camera took (the vision's
/// input), or, from an object sensor, the distance and bearing of the ball, the nets and the
/// landmarks, told apart by colour (ISocRob-2000 report §3.2.1).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CameraFrame {
    /// Time of the frame, s.
    pub time: f64,
    /// What was seen, in [`FIELD_OBJECTS`] order: ball, east net, west net, then the
    /// landmarks of the field map (`None`: not seen this frame).
    pub sightings: [Option<Sighting>; FIELD_OBJECTS],
    /// Other robots in view.
    #[serde(default)]
    pub robots: Vec<RobotSighting>,
    /// The camera's image, when the camera renders or grabs one (the vision µAgent's input,
    /// ISocRob-2000 report §3.2.1); `None` from the object sensor alone.
    #[serde(default)]
    pub image: Option<Image>,
    /// The camera's pan joint when the frame was taken, rad (`None`: the camera has no joint
    /// and stands where its camera file puts it).
    #[serde(default)]
    pub pan: Option<f64>,
    /// The omnidirectional up camera's image taken at the same time, when the robot has one
    /// (ISocRob-2000 report §2.2: a camera under a mirror on the robot's top).
    #[serde(default)]
    pub up_image: Option<Image>,
}

/// What the vision µAgent found in one camera image (ISocRob-2000 report §3.2.1), robot frame:
/// the objects in the object sensor's form (so the world model reads both alike), their
/// uncertainty and pixel evidence, the field-line points and the obstacles.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Percepts {
    /// Time of the image, s.
    pub time: f64,
    /// Ball, nets and landmarks in [`FIELD_OBJECTS`] order, from the robot's centre.
    pub sightings: [Option<Sighting>; FIELD_OBJECTS],
    /// Standard deviations of each sighting, `(distance m, bearing rad)`: what one pixel of
    /// error at that place in the image amounts to.
    pub sigmas: [Option<(f64, f64)>; FIELD_OBJECTS],
    /// How many pixels each sighting rests on.
    pub pixels: [u32; FIELD_OBJECTS],
    /// Points of the white field lines on the floor (m).
    #[cfg_attr(feature = "schema", schemars(with = "Vec<[f64; 2]>"))]
    pub line_points: Vec<Framed<Robot, Point2>>,
    /// Other robots: the nearest point of each, from the robot's centre, with its marker
    /// when the image shows it.
    #[serde(default)]
    pub robots: Vec<RobotSighting>,
    /// The landmark posts seen, each with the half of the field it stands on but not which
    /// post of that half it is (the world model tells them apart).
    #[serde(default)]
    pub posts: Vec<PostSighting>,
    /// Goals cut by the image's side, whose net is therefore not in `sightings`: the corner
    /// of each on the floor at its side that is in view (an upright, or a back corner seen
    /// obliquely; which one, the world model tells). `east`: a corner of the east goal.
    #[serde(default)]
    pub goal_corners: Vec<PostSighting>,
    /// The camera's pan joint when the image was taken, rad (`None`: not known): where the
    /// camera looked, so that the world model knows what it should have seen.
    #[serde(default)]
    pub pan: Option<f64>,
    /// Where in the image the objects above were found (pixels), for monitors that draw them
    /// over the camera's picture (ISocRob-2000 report §3.2.7, the Monitor's vision window).
    /// `None` from a vision that does not say; nothing reads it to decide anything.
    #[serde(default)]
    pub detections: Option<ImageDetections>,
}

/// What the vision found where in one camera image (pixels from the image's top-left corner,
/// x to the right, y down): what a monitor draws over the picture (ISocRob-2000 report §3.2.7).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ImageDetections {
    /// The image's width, pixels (to scale the boxes to the picture shown).
    pub width: u32,
    /// The image's height, pixels.
    pub height: u32,
    /// Each object found, ball first; field-line points last and at most
    /// [`ImageDetections::MAX_LINE_POINTS`] of them (spread over all found).
    pub items: Vec<ImageDetection>,
}

impl ImageDetections {
    /// The most field-line points a message carries.
    pub const MAX_LINE_POINTS: usize = 24;
}

/// One object in an image ([`ImageDetections`]): a box round its centre, pixels.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImageDetection {
    /// What it is.
    pub kind: DetectionKind,
    /// The centre's column.
    pub x: f32,
    /// The centre's row.
    pub y: f32,
    /// The box's width (a ball's diameter; 0 for a point).
    pub w: f32,
    /// The box's height (a ball's diameter; 0 for a point).
    pub h: f32,
}

/// What an [`ImageDetection`] is.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DetectionKind {
    /// The ball (a circle: its blob's centre of mass and apparent diameter).
    Ball,
    /// A goal seen whole (its net in [`Percepts::sightings`]).
    Net,
    /// The corner of a goal cut by the image's side ([`Percepts::goal_corners`]): a point.
    GoalCorner,
    /// A landmark post ([`Percepts::posts`]).
    Post,
    /// Another robot ([`Percepts::robots`]), its box resting on its foot.
    Robot,
    /// A point of a white field line ([`Percepts::line_points`]): a point.
    Line,
}

/// A landmark post in a camera image (ISocRob-2000 report §3.2.1: landmarks told apart by
/// colour): its outer bands wear the colour of the goal of its half, so the image tells the
/// half, not which of the half's posts it is.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PostSighting {
    /// Distance and bearing of its axis from the robot's centre.
    pub sighting: Sighting,
    /// Standard deviations `(distance m, bearing rad)`.
    pub sigma: (f64, f64),
    /// It wears the east goal's colour outside (the posts of the east half; see
    /// `mrt_world::field::FieldMap::east_pattern`).
    pub east: bool,
    /// How many pixels it rests on.
    pub pixels: u32,
}

/// An RGB image, 8 bits per channel, row by row from the top-left corner (`3·width` bytes a
/// row): what a camera driver grabs or the simulator renders (ISocRob-2000 report §3.2.1).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Image {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `width × height × 3` bytes: red, green, blue of each pixel.
    pub rgb: Vec<u8>,
}

impl Image {
    /// A black `width × height` image.
    pub fn new(width: u32, height: u32) -> Image {
        Image { width, height, rgb: vec![0; width as usize * height as usize * 3] }
    }

    /// Whether the buffer holds exactly `width × height` pixels (a message from the network
    /// may not).
    pub fn is_consistent(&self) -> bool {
        (self.width as usize)
            .checked_mul(self.height as usize)
            .and_then(|n| n.checked_mul(3))
            .is_some_and(|n| n == self.rgb.len())
    }

    /// The pixel at column `col`, row `row`, or `None` outside the image.
    pub fn pixel(&self, col: u32, row: u32) -> Option<[u8; 3]> {
        if col >= self.width || row >= self.height {
            return None;
        }
        let i = (row as usize * self.width as usize + col as usize) * 3;
        self.rgb.get(i..i + 3).map(|p| [p[0], p[1], p[2]])
    }
}

impl std::fmt::Debug for Image {
    /// Size only: a frame's bytes would fill a log.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Image({}×{}, {} bytes)", self.width, self.height, self.rgb.len())
    }
}
