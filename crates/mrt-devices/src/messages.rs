//! The messages of the device protocol (docs/devices.md), as they are on the wire: UTF-8 JSON,
//! SI units. Fields a robot does not know are ignored, so a world may send more.

use mrt_core::Twist;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The protocol version these types speak: the `protocol` field of every message and the
/// second part of every key.
pub const PROTOCOL: u32 = 1;

/// One step's readings of one robot's devices, world → robot.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Sense {
    /// The protocol version: 1.
    pub protocol: u32,
    /// The world's name (as in the key).
    pub world: String,
    /// The id the world picked at its start.
    pub run: String,
    /// The robot's name (as in the key).
    pub robot: String,
    /// 0, 1, 2, … one more each step.
    pub step: u64,
    /// The world's clock at this step, s.
    pub time: f64,
    /// The mice and wheel encoders since the previous step (`None`: no reading).
    #[serde(default)]
    pub odometry: Option<OdometryReading>,
    /// The front camera (`None`: no image this step).
    #[serde(default)]
    pub camera: Option<CameraReading>,
    /// The omnidirectional up camera, for a robot that carries one.
    #[serde(default)]
    pub up_camera: Option<UpCameraReading>,
    /// The sonar ring, in ring order (`None`: no reading).
    #[serde(default)]
    pub sonars: Option<Vec<SonarReading>>,
    /// The game controller.
    pub game: GameReading,
}

/// The mice and the wheel encoders since the previous step.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct OdometryReading {
    /// The two optical mice, each in its own frame (MRT manual §4.1), m; `None`: no mice.
    #[serde(default)]
    pub mice: Option<Mice>,
    /// Each wheel's turn, rad, in the base's wheel order; `None`: no encoders.
    #[serde(default)]
    pub wheels: Option<Vec<f64>>,
    /// Put down here by hand or by the referee since the previous step (field frame).
    #[serde(default)]
    pub placed: Option<Pose>,
}

/// The two mice's motion, each in its own frame, m (MRT manual §4.1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Mice {
    /// `x̄_l`: the left mouse, lateral.
    pub x_left: f64,
    /// `ȳ_l`: the left mouse, longitudinal.
    pub y_left: f64,
    /// `x̄_r`: the right mouse, lateral.
    pub x_right: f64,
    /// `ȳ_r`: the right mouse, longitudinal.
    pub y_right: f64,
}

/// A pose in the field frame: m from the centre spot, rad counter-clockwise from +x.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Pose {
    /// m.
    pub x: f64,
    /// m.
    pub y: f64,
    /// rad.
    pub theta: f64,
}

/// One front-camera frame: its image, or what an object sensor saw (at least one of them).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct CameraReading {
    /// When it was taken (world clock), s.
    pub time: f64,
    /// The pan joint's angle then, rad counter-clockwise (`None`: the camera has no joint).
    #[serde(default)]
    pub pan: Option<f64>,
    /// The image (`None`: an object sensor's frame, [`CameraReading::objects`]).
    #[serde(default)]
    pub image: Option<ImageData>,
    /// What an object sensor in the camera's place saw, for a world that knows it without
    /// drawing an image (`mrt sim --percepts oracle`); the robot's vision then has nothing to
    /// do and the world model reads these as they are.
    #[serde(default)]
    pub objects: Option<ObjectsReading>,
}

/// What an object sensor saw in one frame: distance and bearing from the robot's centre
/// (robot frame, counter-clockwise from straight ahead), `None` for what it did not see.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ObjectsReading {
    /// The ball.
    #[serde(default)]
    pub ball: Option<Seen>,
    /// The net at +x.
    #[serde(default)]
    pub east_net: Option<Seen>,
    /// The net at −x.
    #[serde(default)]
    pub west_net: Option<Seen>,
    /// The field map's landmarks, in the map's order (the robot file's `[field]`), at most
    /// [`LANDMARKS`].
    #[serde(default)]
    pub landmarks: Vec<Option<Seen>>,
    /// Other robots in view: the nearest point of each (its foot on the floor).
    #[serde(default)]
    pub robots: Vec<RobotSeen>,
}

/// The most landmarks an [`ObjectsReading`] tells.
pub const LANDMARKS: usize = mrt_msgs::sighting::COUNT - mrt_msgs::sighting::LANDMARK0;

/// One object's distance and bearing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Seen {
    /// m, ≥ 0.
    pub distance: f64,
    /// rad.
    pub bearing: f64,
}

/// One robot in view.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct RobotSeen {
    /// m, ≥ 0.
    pub distance: f64,
    /// rad.
    pub bearing: f64,
    /// The sensor's standard deviations `[distance m, bearing rad]`, when it knows them.
    #[serde(default)]
    pub sigma: Option<[f64; 2]>,
    /// The colour of its marker band, when seen.
    #[serde(default)]
    pub marker: Option<TeamMarker>,
}

/// One image of the omnidirectional up camera.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct UpCameraReading {
    /// The image.
    pub image: ImageData,
}

/// An image as it travels.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ImageData {
    /// Columns, 1–4096.
    pub width: u32,
    /// Rows, 1–4096.
    pub height: u32,
    /// How `data` holds the pixels.
    pub encoding: Encoding,
    /// The bytes, standard base64.
    pub data: String,
}

/// How an [`ImageData`] holds its pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Encoding {
    /// Rows from the top, three bytes a pixel, red first.
    #[default]
    Rgb8,
    /// A baseline JPEG file.
    Jpeg,
}

/// One sonar's echo.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SonarReading {
    /// Its direction in the robot frame, rad counter-clockwise from straight ahead.
    pub bearing: f64,
    /// From the robot's centre to the echo, m (`None`: no echo).
    #[serde(default)]
    pub range: Option<f64>,
}

/// The game controller's news.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct GameReading {
    /// The referee's state.
    pub state: RefereeState,
    /// `1`: the robot's team attacks towards +x, `-1`: towards −x.
    pub attack: f64,
    /// The robot's place in the kickoff formation (field frame).
    #[serde(default)]
    pub kickoff_pose: Option<Pose>,
    /// The marker band the robot's team wears.
    #[serde(default)]
    pub marker: Option<TeamMarker>,
}

/// The referee's state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum RefereeState {
    /// Before the game.
    #[default]
    Initial,
    /// Robots walk to their kickoff places.
    Ready,
    /// Robots wait for the kickoff.
    Set,
    /// The game runs.
    Playing,
    /// The half or the game is over.
    Finished,
}

/// A team's marker band.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum TeamMarker {
    /// Magenta.
    Magenta,
    /// Cyan.
    Cyan,
}

/// The robot's answer to one step, robot → world.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Act {
    /// The protocol version: 1.
    pub protocol: u32,
    /// The world's name.
    pub world: String,
    /// The world's run.
    pub run: String,
    /// The robot's name.
    pub robot: String,
    /// The step answered.
    pub step: u64,
    /// Each wheel's speed set-point, rad/s, in the order of [`OdometryReading::wheels`];
    /// `None`: keep the previous ones.
    pub wheels: Option<Vec<f64>>,
    /// The body velocity these wheel speeds give (robot frame); `None` with `wheels`.
    pub twist: Option<Twist>,
    /// Fire the kicker now.
    pub kick: bool,
    /// The camera's pan set-point, rad (`None`: leave the joint where it is).
    pub pan: Option<f64>,
    /// Faults of the robot's software booked this cycle.
    pub faults: Vec<String>,
}

/// The match is over, world → all its robots.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct End {
    /// The protocol version: 1.
    pub protocol: u32,
    /// The world's name.
    pub world: String,
    /// The world's run.
    pub run: String,
    /// Steps played.
    pub steps: u64,
}

/// A robot's last word, robot → world.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Bye {
    /// The protocol version: 1.
    pub protocol: u32,
    /// The world's name.
    pub world: String,
    /// The world's run.
    pub run: String,
    /// The robot's name.
    pub robot: String,
    /// Steps the robot answered.
    pub steps: u64,
    /// Its Members that failed to start, failed jobs or panicked.
    pub faults: Vec<Fault>,
    /// Messages it could not use.
    pub dropped: Dropped,
}

/// A Member's trouble during the match.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Fault {
    /// The Member's name.
    pub name: String,
    /// Errors, panics and restarts.
    pub count: u64,
    /// Whether it never completed a cycle.
    pub never_ran: bool,
    /// Its last error.
    pub error: String,
}

/// Messages a robot counted and dropped, by reason (docs/devices.md, "What the robot refuses").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct Dropped {
    /// Not JSON, not of the schema, or an image that does not decode to its size.
    pub malformed: u64,
    /// Over [`crate::MAX_MESSAGE`] bytes.
    pub too_large: u64,
    /// Another protocol version.
    pub protocol: u64,
    /// Not this robot's world, name or run.
    pub stranger: u64,
    /// A step not after the last answered.
    pub out_of_order: u64,
    /// A clock that is not finite, goes back or jumps.
    pub clock: u64,
}

impl Dropped {
    /// All drops.
    pub fn total(&self) -> u64 {
        self.malformed
            + self.too_large
            + self.protocol
            + self.stranger
            + self.out_of_order
            + self.clock
    }
}
