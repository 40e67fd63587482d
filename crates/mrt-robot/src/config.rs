//! What belongs to one robot, apart from any simulator's world: its base, its body's size and
//! kicker reach, its sensors (the mice's mounting, the camera's noise), the field it plays on,
//! its guidance, its control period and its team's size. A robot reads it from its robot file
//! ([`RobotFile`], `mrt robot --config FILE`, `configs/robot/`); the simulator builds the same
//! file from its world configuration (`mrt_sim::config::SimConfig::robot_file`).

use crate::base::Base;
use crate::error::RobotError;
use crate::spec::{RobotSpec, Stack};
use mrt_perception::camera::{CameraFile, Omni, OmniFile, Pinhole};
use mrt_perception::mice::MiceOdometry;
use mrt_perception::vision::colors::ColorTable;
use mrt_perception::vision::posts::PostShape;
use mrt_plan::guidance::Guidance;
use mrt_world::gaze::{GazeConfig, PanJoint};
pub use mrt_world::relocalize::Localizer;
use mrt_world::{FieldMap, WorldModel};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The camera's measurement noise as the world model assumes it (one definition, the world
/// model's).
pub use mrt_world::relocalize::CameraNoise;

/// One robot's configuration (module doc). SI units: metres, seconds, radians.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotConfig {
    /// The control period: every cycle of the robot's Members, s.
    pub control_period: f64,
    /// The wheels and their limits.
    pub base: Base,
    /// Radius of the round footprint, m.
    pub radius: f64,
    /// How far in front of the robot's edge the ball may be for a kick to reach it, m.
    pub kick_reach: f64,
    /// Radius of the ball, m.
    pub ball_radius: f64,
    /// The field played on.
    pub field: FieldMap,
    /// The two optical mice's mounting (manual ch. 4).
    pub mice: MiceOdometry,
    /// The camera's noise.
    pub camera: CameraNoise,
    /// Guidance between the behaviors and the motors (ISocRob-2000 report §3.2.3).
    pub guidance: Guidance,
    /// Robots per team (robot 0 of each keeps goal).
    pub team_size: usize,
    /// The vision µAgent's camera and colour classes, when it runs on the camera's images
    /// (`None`: the camera driver's frames carry percepts already, as the simulator's object
    /// sensor does).
    pub vision: Option<VisionSetup>,
    /// The PAM's gaze control of the camera's pan joint (ThinkingCap/TeamChaos report §2.1), when the
    /// camera has one (`None`: the camera stays where its file puts it).
    pub gaze: Option<GazeConfig>,
    /// Which estimator keeps the robot's pose ([`mrt_world::relocalize`]).
    pub localizer: Localizer,
    /// The ball's rolling friction as its tracker assumes it, 1/s ([`BallSection`]).
    pub ball_damping: f64,
    /// Whether MUREA searches on goal corners too ([`LocalizationSection::goal_corners`]).
    pub goal_corners: bool,
}

/// What the vision µAgent needs (ISocRob-2000 report §3.2.1).
#[derive(Clone, Debug, PartialEq)]
pub struct VisionSetup {
    /// The camera's geometry, pan joint at rest.
    pub camera: Pinhole,
    /// The colour classes.
    pub colors: ColorTable,
    /// The landmark posts' shape.
    pub posts: PostShape,
    /// The omnidirectional up camera, when the robot has one.
    pub up_camera: Option<Omni>,
}

/// How far the vision finds robots, m (the markers are told to 7 m on rendered frames:
/// `crates/mrt-sim/tests/render.rs`).
pub const VISION_ROBOT_RANGE: f64 = 7.0;

impl RobotConfig {
    /// The robot's world model as it starts: its field map, its mice, its camera's noise, the
    /// pose unknown until it is put down; other robots are taken to be its own size.
    pub fn world_model(&self) -> WorldModel {
        let model =
            WorldModel::new(self.field, self.mice, self.camera.distance, self.camera.bearing)
                .with_localizer(self.localizer)
                .with_ball_damping(self.ball_damping)
                .with_goal_corners(self.goal_corners)
                .with_robot_radius(self.radius);
        // With vision the camera's view is known: a robot it should see and does not fades
        // fast. (The simulator's object sensor tells no view: its anchors fade alike.)
        let model = match &self.vision {
            Some(v) => model.with_view(v.camera.half_fov(), VISION_ROBOT_RANGE),
            None => model,
        };
        // A robot with the up camera sees the field lines all around: ISocRob's self mode.
        match self.vision.as_ref().and_then(|v| v.up_camera) {
            Some(_) => model.with_self_mode(),
            None => model,
        }
    }

    /// The control period as a `Duration` (a non-finite or negative period is 0).
    pub fn period(&self) -> std::time::Duration {
        std::time::Duration::try_from_secs_f64(self.control_period).unwrap_or_default()
    }
}

/// What went wrong reading a robot file (the file, and the line and column of a syntax error).
pub type RobotFileError = mrt_core::FileError;

/// `[robot]`: which robot this is and what drives it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RobotSection {
    /// The robot's number in its match or team (its Agora is `id + 1`; `id % team_size == 0`
    /// keeps goal).
    pub id: usize,
    /// Robots per team.
    pub team_size: usize,
    /// The behavior stack: `chaos`, `milan` or `chaser`.
    pub stack: String,
    /// TeamChaos behaviors to run instead of the compiled-in ones (relative to the file).
    pub behaviors: Option<PathBuf>,
    /// The control period, s.
    pub control_period: f64,
}

impl Default for RobotSection {
    fn default() -> Self {
        RobotSection {
            id: 0,
            team_size: 4,
            stack: "chaos".into(),
            behaviors: None,
            control_period: 0.1,
        }
    }
}

/// `[body]`: the base and the body's size, speed, mass and kicker. The robot program reads its
/// base, radius, kick reach and top speeds; a simulated world reads all of it (the body's
/// physics: mass, acceleration, the kicker's strength and recharge).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BodySection {
    /// `omni` (three omni wheels, the manual's Triskar) or `differential` (two central wheels,
    /// the manual's IANUS3: no sideways motion).
    pub base: String,
    /// Radius of the round footprint, m.
    pub radius: f64,
    /// Mass, kg.
    pub mass: f64,
    /// Top linear speed, m/s (guidance's position mode).
    pub max_speed: f64,
    /// Top acceleration, m/s².
    pub max_accel: f64,
    /// Top turning rate, rad/s.
    pub max_turn_rate: f64,
    /// Speed the kicker gives the ball, m/s.
    pub kick_speed: f64,
    /// How far in front of the robot's edge the ball may be for a kick to reach it, m.
    pub kick_reach: f64,
    /// Half-width of the kicker's cone, rad.
    pub kick_half_angle: f64,
    /// Time between two kicks (the pneumatic tank recharges), s.
    pub kick_recharge: f64,
}

impl Default for BodySection {
    /// A round 50 cm base on three omni wheels, like the manual's Triskar, up to 1.2 m/s as
    /// its IANUS3, with a pneumatic kicker.
    fn default() -> Self {
        BodySection {
            base: "omni".into(),
            radius: 0.25,
            mass: 30.0,
            max_speed: 1.2,
            max_accel: 2.0,
            max_turn_rate: 4.0,
            kick_speed: 6.0,
            kick_reach: 0.12,
            kick_half_angle: 0.5,
            kick_recharge: 1.0,
        }
    }
}

/// `[ball]`: the ball played with (FIFA size 5 by default). The robot program reads its radius
/// (the vision's distances, guidance) and its rolling friction (MAP's ball tracker); a
/// simulated world rolls it with all of these.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BallSection {
    /// Radius, m.
    pub radius: f64,
    /// Mass, kg.
    pub mass: f64,
    /// Bounce off walls and robots, 0 to 1.
    pub restitution: f64,
    /// The carpet's rolling friction as linear damping of the ball's velocity, 1/s: a ball
    /// rolled at `v` stops after about `v / rolling_damping` metres. Measure it on your carpet.
    pub rolling_damping: f64,
}

impl Default for BallSection {
    fn default() -> Self {
        BallSection {
            radius: 0.11,
            mass: 0.43,
            restitution: 0.6,
            rolling_damping: mrt_world::model::BALL_DAMPING,
        }
    }
}

/// `[sensors]`: the mice's mounting and the camera's noise (a simulated world's object sensor
/// applies the same noise).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensorsSection {
    /// Distance between the two mice (`D` of the manual's §4.1), m.
    pub mice_distance: f64,
    /// Tolerance of the `x̄_r = x̄_l` check, m.
    pub mice_tolerance: f64,
    /// The camera's relative distance error.
    pub camera_distance_noise: f64,
    /// The camera's bearing error, rad.
    pub camera_bearing_noise: f64,
}

impl Default for SensorsSection {
    fn default() -> Self {
        SensorsSection {
            mice_distance: 0.2,
            mice_tolerance: 0.003,
            camera_distance_noise: 0.03,
            camera_bearing_noise: 0.02,
        }
    }
}

/// `[guidance]` (ISocRob-2000 report §3.2.3).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GuidanceSection {
    /// Velocity mode halts the translation when a sonar within `half_cone` of the direction
    /// of motion reads less than this, m from the robot's centre.
    pub safety_distance: f64,
    /// See `safety_distance`, rad.
    pub half_cone: f64,
}

impl Default for GuidanceSection {
    /// 0.35 m from the centre (0.1 m from a 0.25 m robot's edge), ±30°.
    fn default() -> Self {
        GuidanceSection { safety_distance: 0.35, half_cone: std::f64::consts::PI / 6.0 }
    }
}

/// `[vision]`: whether the vision µAgent turns the camera's images into percepts, with the
/// camera's geometry (`[vision.camera]`, a camera file's keys) and the colour classes
/// (`[vision.colors.ball]`, ... a colour file's tables; the shipped `configs/vision/colors.toml`
/// when left out).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VisionSection {
    /// Run the vision µAgent.
    pub enabled: bool,
    /// The camera.
    pub camera: CameraFile,
    /// The colour classes.
    pub colors: ColorTable,
    /// The landmark posts' radius, m.
    pub post_radius: f64,
    /// The landmark posts' height, m (three bands of equal height).
    pub post_height: f64,
    /// ISocRob's omnidirectional up camera (`[vision.up_camera]`, an omni camera file's keys,
    /// `configs/vision/omni.toml`), when the robot has one: the ball all around it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub up_camera: Option<OmniFile>,
}

impl Default for VisionSection {
    fn default() -> Self {
        let posts = PostShape::default();
        VisionSection {
            enabled: false,
            camera: CameraFile::default(),
            colors: ColorTable::shipped(),
            post_radius: posts.radius,
            post_height: posts.height,
            up_camera: None,
        }
    }
}

/// `[gaze]`: the camera's pan joint and the PAM's gaze control that turns it to the object the
/// behaviors need most (ThinkingCap/TeamChaos report §2.1, [`mrt_world::gaze`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GazeSection {
    /// Run the gaze control (the camera has a pan joint).
    pub enabled: bool,
    /// The rightmost pan, rad.
    pub pan_min: f64,
    /// The leftmost pan, rad.
    pub pan_max: f64,
    /// The joint's top speed, rad/s.
    pub pan_speed: f64,
    /// How long a fixation is held once its object is in view, s.
    pub dwell: f64,
    /// Half the camera's horizontal field of view, rad (default: from `[vision.camera]` when
    /// the vision µAgent runs; required otherwise).
    pub half_fov: Option<f64>,
}

impl Default for GazeSection {
    fn default() -> Self {
        GazeSection {
            enabled: false,
            pan_min: -1.5,
            pan_max: 1.5,
            pan_speed: 3.0,
            dwell: 0.3,
            half_fov: None,
        }
    }
}

impl GazeSection {
    /// The gaze control, checked, when enabled (`camera`: the vision µAgent's, if it runs).
    fn config(&self, camera: Option<&Pinhole>) -> Result<Option<GazeConfig>, String> {
        if !self.enabled {
            return Ok(None);
        }
        let joint = PanJoint { min: self.pan_min, max: self.pan_max, max_speed: self.pan_speed };
        if !joint.is_valid() {
            return Err(format!(
                "gaze: pan_min {} ≤ pan_max {} and pan_speed {} > 0 must be finite numbers",
                self.pan_min, self.pan_max, self.pan_speed
            ));
        }
        if !(self.dwell.is_finite() && self.dwell >= 0.0) {
            return Err(format!("gaze.dwell must be a finite number >= 0, not {}", self.dwell));
        }
        let half_fov = match (self.half_fov, camera) {
            (Some(h), _) => h,
            (None, Some(c)) => c.half_fov(),
            (None, None) => {
                return Err("gaze.half_fov is needed when the vision µAgent does not run".into())
            }
        };
        if !(half_fov.is_finite() && half_fov > 0.0) {
            return Err(format!("gaze.half_fov must be a finite number > 0, not {half_fov}"));
        }
        Ok(Some(GazeConfig { joint, half_fov, dwell: self.dwell }))
    }
}

/// `[localization]`: how the robot knows where it is (MRT manual ch. 7,
/// [`mrt_world::relocalize`]) and how it follows the ball.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LocalizationSection {
    /// `murea` (the default: the EKF tracks, MUREA finds the robot again when it is lost or
    /// was carried), `gm` (ThinkingCap's fuzzy grid does) or `ekf` (the EKF alone).
    pub localizer: Localizer,
    /// Whether MUREA also searches on the corner of a goal cut by the image's side (the
    /// vision's `goal_corners`). Off by default: it finds some kidnapped robots sooner and
    /// puts good trackers elsewhere more often (docs/localization.md, "Goal corners").
    pub goal_corners: bool,
}

/// `[devices]`: what the robot's drivers talk to.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DevicesSection {
    /// `world` (the default and, in this mrt, the only kind): a world that speaks the device
    /// protocol over zenoh (docs/devices.md: `mrt sim --distributed`, MuJoCo, a Python world,
    /// a real robot's bridge; [`crate::world`]). A team whose robot has its own hardware
    /// implements [`crate::devices::Devices`] in Rust (ARCHITECTURE.md, "Adding a real
    /// robot").
    pub kind: String,
    /// The robot's Agora configuration file (MRT manual §3.3.1), relative to this file: the
    /// teammates' network (optional: a robot without one hears no teammate).
    pub net: Option<PathBuf>,
    /// For `world`: the world's name, as in its keys.
    pub world: Option<String>,
    /// For `world`: the robot's name in that world (default `robot-<id>`).
    pub name: Option<String>,
    /// For `world`: zenoh endpoints that reach the world (`tcp/127.0.0.1:7470`); empty: the
    /// world is found by multicast scouting.
    pub connect: Vec<String>,
}

impl Default for DevicesSection {
    fn default() -> Self {
        DevicesSection {
            kind: "world".into(),
            net: None,
            world: None,
            name: None,
            connect: Vec::new(),
        }
    }
}

/// A robot file (`mrt robot --config FILE`, `configs/robot/`): everything that belongs to one
/// robot, in SI units. Every section and value has a default (a Triskar base on the Middle Size
/// League field), so a file only says what differs.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RobotFile {
    /// Which robot, which stack.
    pub robot: RobotSection,
    /// Its body.
    pub body: BodySection,
    /// Its sensors.
    pub sensors: SensorsSection,
    /// The ball it plays with.
    pub ball: BallSection,
    /// The field it plays on (metres).
    pub field: FieldMap,
    /// Its guidance.
    pub guidance: GuidanceSection,
    /// Its devices.
    pub devices: DevicesSection,
    /// Its vision.
    pub vision: VisionSection,
    /// Its camera's pan joint and gaze control.
    pub gaze: GazeSection,
    /// How it knows where it is.
    pub localization: LocalizationSection,
}

impl RobotFile {
    /// Parses a robot file; `file` names it in errors (with line and column for TOML errors).
    pub fn from_toml(text: &str, file: &str) -> Result<RobotFile, RobotFileError> {
        let parsed: RobotFile = toml::from_str(text).map_err(|e| {
            RobotFileError::parse(file, text, e.span().map(|s| s.start), e.message())
        })?;
        let invalid = |message| RobotFileError::Invalid { file: file.to_string(), message };
        parsed.checked_config().map_err(invalid)?;
        parsed.checked_spec().map_err(invalid)?;
        Ok(parsed)
    }

    /// Reads a robot file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<RobotFile, RobotFileError> {
        let (text, file) = mrt_core::FileError::read(path.as_ref())?;
        RobotFile::from_toml(&text, &file)
    }

    /// The file as TOML that [`RobotFile::from_toml`] reads back.
    pub fn to_toml(&self) -> Result<String, RobotError> {
        Ok(toml::to_string(self)?)
    }

    /// Which robot and which stack ([`RobotSpec`]).
    pub fn spec(&self) -> Result<RobotSpec, RobotError> {
        self.checked_spec().map_err(RobotError::Config)
    }

    /// The robot's configuration, every value checked.
    pub fn config(&self) -> Result<RobotConfig, RobotError> {
        self.checked_config().map_err(RobotError::Config)
    }

    fn checked_spec(&self) -> Result<RobotSpec, String> {
        let r = &self.robot;
        let stack = Stack::parse(&r.stack).map_err(|e| format!("robot.stack: {e}"))?;
        let n = r.team_size;
        if !(1..=11).contains(&n) {
            return Err(format!("robot.team_size must be 1 to 11, not {n}"));
        }
        if r.id >= 2 * n {
            return Err(format!("robot.id must be below 2 × team_size = {}, not {}", 2 * n, r.id));
        }
        Ok(RobotSpec { robot: r.id, keeper: r.id % n == 0, mate: r.id % n, stack })
    }

    fn checked_config(&self) -> Result<RobotConfig, String> {
        use mrt_plan::guidance::{PositionParams, PotentialField, PotentialParams, VelocityGuard};
        let (r, b, s) = (&self.robot, &self.body, &self.sensors);
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(format!("{name} must be a finite number > 0, not {v}"))
            }
        };
        let control_period = positive("robot.control_period", r.control_period)?;
        if control_period > 10.0 {
            return Err(format!("robot.control_period must be at most 10 s, not {control_period}"));
        }
        let base = Base::parse(&b.base).map_err(|e| format!("body.{e}"))?;
        let radius = positive("body.radius", b.radius)?;
        let f = &self.field;
        for (name, v) in [
            ("field.length", f.length),
            ("field.width", f.width),
            ("field.goal_width", f.goal_width),
            ("field.penalty_area_depth", f.penalty_area_depth),
            ("field.penalty_area_width", f.penalty_area_width),
            ("field.centre_circle_radius", f.centre_circle_radius),
            ("ball.radius", self.ball.radius),
        ] {
            positive(name, v)?;
        }
        let mice = MiceOdometry::new(s.mice_distance, s.mice_tolerance)
            .map_err(|e| format!("sensors: {e}"))?;
        let position = PositionParams {
            steering: base.steering(),
            max_speed: positive("body.max_speed", b.max_speed)?,
            max_omega: positive("body.max_turn_rate", b.max_turn_rate)?,
            position_tolerance: 0.05,
            angle_tolerance: 0.05,
            ..PositionParams::default()
        };
        let obstacles = PotentialParams { robot_radius: radius, ..PotentialParams::default() };
        let g = &self.guidance;
        let guard = VelocityGuard::new(g.safety_distance, g.half_cone)
            .map_err(|e| format!("guidance: {e}"))?;
        let field =
            PotentialField::new(position, obstacles).map_err(|e| format!("guidance: {e}"))?;
        let non_negative = |name: &str, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(v)
            } else {
                Err(format!("{name} must be a finite number >= 0, not {v}"))
            }
        };
        let vision = {
            let v = &self.vision;
            let camera = v.camera.camera().map_err(|e| format!("vision.camera: {e}"))?;
            v.colors.check().map_err(|e| format!("vision.colors: {e}"))?;
            let posts = PostShape {
                radius: positive("vision.post_radius", v.post_radius)?,
                height: positive("vision.post_height", v.post_height)?,
            };
            let up_camera = match &v.up_camera {
                Some(f) => Some(f.camera().map_err(|e| format!("vision.up_camera: {e}"))?),
                None => None,
            };
            v.enabled.then(|| VisionSetup { camera, colors: v.colors.clone(), posts, up_camera })
        };
        Ok(RobotConfig {
            control_period,
            base,
            radius,
            kick_reach: non_negative("body.kick_reach", b.kick_reach)?,
            ball_radius: self.ball.radius,
            field: self.field,
            mice,
            camera: CameraNoise {
                distance: non_negative("sensors.camera_distance_noise", s.camera_distance_noise)?,
                bearing: non_negative("sensors.camera_bearing_noise", s.camera_bearing_noise)?,
            },
            guidance: Guidance::new(guard, field, self.ball.radius),
            team_size: r.team_size,
            gaze: self.gaze.config(vision.as_ref().map(|v| &v.camera))?,
            vision,
            localizer: self.localization.localizer,
            ball_damping: non_negative("ball.rolling_damping", self.ball.rolling_damping)?,
            goal_corners: self.localization.goal_corners,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn an_empty_file_is_the_default_robot() {
        let f = RobotFile::from_toml("", "robot.toml").unwrap();
        assert_eq!(f, RobotFile::default());
        let c = f.config().unwrap();
        assert_eq!((c.control_period, c.radius, c.team_size), (0.1, 0.25, 4));
        assert_eq!(c.field, FieldMap::default());
        let spec = f.spec().unwrap();
        assert!(spec.keeper, "robot 0 keeps goal");
        let back = RobotFile::from_toml(&f.to_toml().unwrap(), "again.toml").unwrap();
        assert_eq!(back, f, "written and read back");
    }

    #[test]
    fn errors_name_the_file_line_column_and_value() {
        let e = RobotFile::from_toml("[robot]\nid = 1\nstak = \"milan\"\n", "r.toml").unwrap_err();
        assert!(e.to_string().starts_with("r.toml:3:1: unknown field `stak`"), "{e}");
        let e = RobotFile::from_toml("[body]\nradius = -1\n", "r.toml").unwrap_err();
        assert_eq!(e.to_string(), "r.toml: body.radius must be a finite number > 0, not -1");
        let e = RobotFile::from_toml("[robot]\nid = 9\nteam_size = 2\n", "r.toml").unwrap_err();
        assert!(e.to_string().contains("robot.id must be below 2 × team_size = 4"), "{e}");
        let e = RobotFile::from_toml("[robot]\nstack = \"lego\"\n", "r.toml").unwrap_err();
        assert!(e.to_string().contains("unknown team stack 'lego'"), "{e}");
        let e = RobotFile::from_toml("[sensors]\nmice_distance = 0\n", "r.toml").unwrap_err();
        assert!(e.to_string().starts_with("r.toml: sensors: "), "{e}");
    }

    #[test]
    fn gaze_is_checked_and_takes_its_field_of_view_from_the_camera() {
        let read = |t: &str| RobotFile::from_toml(t, "r.toml").map(|f| f.config().unwrap().gaze);
        assert_eq!(read("").unwrap(), None, "off by default");
        let e = read("[gaze]\nenabled = true\n").unwrap_err();
        assert!(e.to_string().contains("gaze.half_fov is needed"), "{e}");
        let g = read("[gaze]\nenabled = true\nhalf_fov = 0.4\n").unwrap().unwrap();
        assert_eq!((g.half_fov, g.dwell, g.joint.max_speed), (0.4, 0.3, 3.0));
        // The shipped camera: 160 px from the principal point to the side at fx = 260 px.
        let g = read("[gaze]\nenabled = true\n[vision]\nenabled = true\n").unwrap().unwrap();
        assert!((g.half_fov - (160.0f64 / 260.0).atan()).abs() < 1e-12, "{}", g.half_fov);
        for bad in ["pan_min = 2.0", "pan_speed = 0.0", "dwell = -1.0", "half_fov = nan"] {
            let fov = if bad.starts_with("half_fov") { "" } else { "half_fov = 0.4\n" };
            let e = read(&format!("[gaze]\nenabled = true\n{fov}{bad}\n")).unwrap_err();
            let e = e.to_string();
            assert!(e.starts_with("r.toml: gaze"), "{bad}: {e}");
        }
    }

    #[test]
    fn the_ball_damping_reaches_the_world_model_and_is_checked() {
        let read = |t: &str| RobotFile::from_toml(t, "r.toml").map(|f| f.config().unwrap());
        let c = read("").unwrap();
        assert_eq!(c.ball_damping, mrt_world::model::BALL_DAMPING);
        assert_eq!(c.world_model().ball_damping(), 0.4);
        let c =
            read("[ball]\nrolling_damping = 0.9\n[localization]\nlocalizer = \"gm\"\n").unwrap();
        assert_eq!(c.world_model().ball_damping(), 0.9);
        assert_eq!(c.world_model().localizer(), Localizer::Gm);
        assert!(!c.goal_corners, "goal corners are off unless asked for");
        let c = read("[localization]\ngoal_corners = true\n").unwrap();
        assert!(c.goal_corners);
        let e = read("[ball]\nrolling_damping = -0.1\n").unwrap_err().to_string();
        assert_eq!(e, "r.toml: ball.rolling_damping must be a finite number >= 0, not -0.1");
    }

    proptest! {
        /// Random bytes never panic the parser: a robot file or an error.
        #[test]
        fn random_text_is_parsed_or_refused(text in "\\PC{0,300}") {
            let _ = RobotFile::from_toml(&text, "fuzz.toml");
        }

        /// Random values in every field give a robot or a clear error, never a panic.
        #[test]
        fn random_values_are_checked(period in -1e3f64..1e3, radius in -1.0f64..2.0,
                                     id in 0usize..40, n in 0usize..14, d in -1.0f64..1.0) {
            let text = format!(
                "[robot]\nid = {id}\nteam_size = {n}\ncontrol_period = {period:?}\n\
                 [body]\nradius = {radius:?}\n[sensors]\nmice_distance = {d:?}\n"
            );
            if let Ok(f) = RobotFile::from_toml(&text, "p.toml") {
                let c = f.config().unwrap();
                prop_assert!(c.control_period > 0.0 && c.radius > 0.0);
            }
        }
    }
}
