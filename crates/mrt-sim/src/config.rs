//! The simulator's configuration: field, ball, robots and match rules, read from TOML. Every
//! field has a documented default (Middle Size League proportions, a robot base of the MRT
//! manual's size and speed), so a file only needs what it changes; `configs/sim/default.toml` lists them all.
//!
//! Units: metres, seconds, kilograms, radians.

use serde::{Deserialize, Serialize};
use std::path::Path;

/// The field (Middle Size League proportions).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FieldConfig {
    /// Length between the goal lines.
    pub length: f64,
    /// Width between the side lines.
    pub width: f64,
    /// Free space between the lines and the surrounding walls.
    pub border: f64,
    /// Inner width of a goal.
    pub goal_width: f64,
    /// Depth of a goal behind its line.
    pub goal_depth: f64,
    /// Radius of the centre circle.
    pub centre_circle_radius: f64,
    /// Depth of the penalty area from the goal line.
    pub penalty_area_depth: f64,
    /// Width of the penalty area.
    pub penalty_area_width: f64,
}

impl FieldConfig {
    /// The field's map (`mrt-world`): lines, goals and landmarks, what both the simulated
    /// camera and the robots' world models read.
    pub fn map(&self) -> mrt_world::FieldMap {
        mrt_world::FieldMap {
            length: self.length,
            width: self.width,
            goal_width: self.goal_width,
            goal_depth: self.goal_depth,
            penalty_area_depth: self.penalty_area_depth,
            penalty_area_width: self.penalty_area_width,
            centre_circle_radius: self.centre_circle_radius,
            ..mrt_world::FieldMap::default()
        }
    }
}

impl Default for FieldConfig {
    fn default() -> Self {
        Self {
            length: 18.0,
            width: 12.0,
            border: 1.0,
            goal_width: 2.0,
            goal_depth: 0.6,
            centre_circle_radius: 2.0,
            penalty_area_depth: 2.25,
            penalty_area_width: 6.5,
        }
    }
}

/// The ball (FIFA size 5).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BallConfig {
    /// Radius.
    pub radius: f64,
    /// Mass.
    pub mass: f64,
    /// Bounce off walls and robots, 0 to 1.
    pub restitution: f64,
    /// Rolling friction as linear damping (1/s): a free ball loses this fraction of its speed
    /// per second, roughly.
    pub rolling_damping: f64,
}

impl Default for BallConfig {
    fn default() -> Self {
        Self { radius: 0.11, mass: 0.43, restitution: 0.6, rolling_damping: 0.4 }
    }
}

/// A robot base (defaults: a round 50 cm base on three omni wheels, like the manual's Triskar,
/// up to 1.2 m/s as its IANUS3, with a pneumatic kicker).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BodyConfig {
    /// The wheels: `omni` (three omni wheels, the manual's Triskar) or `differential` (two
    /// central wheels, the manual's IANUS3: no sideways motion).
    pub base: String,
    /// Radius of the round footprint.
    pub radius: f64,
    /// Mass.
    pub mass: f64,
    /// Top linear speed.
    pub max_speed: f64,
    /// Top acceleration.
    pub max_accel: f64,
    /// Top turning rate.
    pub max_turn_rate: f64,
    /// Speed given to the ball by a kick.
    pub kick_speed: f64,
    /// How far in front of the robot's edge the ball may be for a kick to reach it.
    pub kick_reach: f64,
    /// Half-width of the kicker's cone, radians.
    pub kick_half_angle: f64,
    /// Time between two kicks (the tank recharges).
    pub kick_recharge: f64,
}

impl Default for BodyConfig {
    fn default() -> Self {
        Self {
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

/// The rules and the clock.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MatchConfig {
    /// Length of a half.
    pub half_duration: f64,
    /// Robots per team (a goalkeeper and field players).
    pub team_size: usize,
    /// Physics step.
    pub physics_step: f64,
    /// Period of the robots' control cycle (the behaviors' 100 ms).
    pub control_period: f64,
    /// Longest time in READY, walking to the kickoff positions; robots farther than
    /// [`READY_TOLERANCE`] from theirs by then are placed on them. 0: placed at once.
    pub ready_duration: f64,
    /// Time in SET before play starts after a kickoff.
    pub set_duration: f64,
    /// A ball that moved less than `stuck_distance` for this long is dropped elsewhere.
    pub stuck_time: f64,
    /// See `stuck_time`.
    pub stuck_distance: f64,
    /// Times per half that each robot is lifted and carried to a random free spot at a
    /// random moment of play without being told (the kidnapped robot; `mrt sim --kidnap`).
    pub kidnaps: u32,
}

impl Default for MatchConfig {
    fn default() -> Self {
        Self {
            half_duration: 300.0,
            team_size: 4,
            physics_step: 0.01,
            control_period: 0.1,
            ready_duration: 15.0,
            set_duration: 1.0,
            stuck_time: 10.0,
            stuck_distance: 0.2,
            kidnaps: 0,
        }
    }
}

/// The object sensor: what a camera would detect.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensorConfig {
    /// Half of the field of view, radians (π: omnidirectional vision, as on the MSL robots).
    pub half_fov: f64,
    /// Farthest distance at which the ball is detected.
    pub range: f64,
    /// Farthest distance at which the nets and the landmarks (large, brightly coloured) are
    /// detected.
    pub landmark_range: f64,
    /// Standard deviation of the distance error, as a fraction of the distance.
    pub distance_noise: f64,
    /// Standard deviation of the bearing error, radians.
    pub bearing_noise: f64,
    /// Probability of missing a visible object in one frame.
    pub miss_probability: f64,
    /// Where the robots' percepts come from.
    pub percepts: PerceptSource,
}

/// Where the robots' percepts come from (`[sensor] percepts`, `mrt sim --percepts`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PerceptSource {
    /// The object sensor: distance and bearing computed from the world with noise, field of
    /// view, occlusion and misses. About seven times faster than vision: for long series of
    /// matches and for tests ([`SimConfig::oracle`]).
    Oracle,
    /// The default: every robot's camera renders an image (the `render` module)
    /// and the robot's vision µAgent finds the ball, the goals, the posts, the field lines
    /// and the robots in it; nothing else tells the robot where they are.
    #[default]
    Vision,
}

impl Default for SensorConfig {
    fn default() -> Self {
        Self {
            half_fov: std::f64::consts::PI,
            range: 9.0,
            landmark_range: 20.0,
            distance_noise: 0.03,
            bearing_noise: 0.02,
            miss_probability: 0.05,
            percepts: PerceptSource::default(),
        }
    }
}

/// What the simulated cameras draw (the `render` module): the heights of the things that the
/// 2-D physics has no use for, and the image effects, all off by default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderConfig {
    /// Width of the white field lines, m.
    pub line_width: f64,
    /// Height of the goals' coloured walls and crossbar, m.
    pub goal_height: f64,
    /// Height of the walls around the field, m.
    pub wall_height: f64,
    /// Height of a robot's dark cylinder, m (its team marker is a band near the top).
    pub robot_height: f64,
    /// Radius of a landmark post (the corners, the ends of the half-way line), m.
    pub post_radius: f64,
    /// Height of a landmark post, m.
    pub post_height: f64,
    /// Image noise: standard deviation per channel, in levels of 0–255.
    pub noise: f64,
    /// Lighting variation: each frame's brightness is scaled by a factor drawn uniformly
    /// within `1 ± lighting`.
    pub lighting: f64,
    /// Motion blur: the fraction of the previous frame that stays in the next, 0 (off) to 0.9.
    pub motion_blur: f64,
}

impl Default for RenderConfig {
    fn default() -> Self {
        Self {
            line_width: 0.1,
            goal_height: 1.0,
            wall_height: 0.5,
            robot_height: 0.6,
            post_radius: 0.1,
            post_height: 0.8,
            noise: 0.0,
            lighting: 0.0,
            motion_blur: 0.0,
        }
    }
}

impl RenderConfig {
    fn validate(&self) -> Result<(), String> {
        let positive = [
            ("render.line_width", self.line_width),
            ("render.goal_height", self.goal_height),
            ("render.wall_height", self.wall_height),
            ("render.robot_height", self.robot_height),
            ("render.post_radius", self.post_radius),
            ("render.post_height", self.post_height),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0 && v <= 10.0) {
                return Err(format!("{name} must be more than 0 and at most 10 m, not {v}"));
            }
        }
        if !(0.0..=100.0).contains(&self.noise) {
            return Err(format!("render.noise must be 0 to 100 levels, not {}", self.noise));
        }
        if !(0.0..=0.9).contains(&self.lighting) || !(0.0..=0.9).contains(&self.motion_blur) {
            return Err(format!(
                "render.lighting and render.motion_blur must be 0 to 0.9 (got {} and {})",
                self.lighting, self.motion_blur
            ));
        }
        Ok(())
    }
}

/// How near its kickoff position a robot must be for READY to end early, and not to be
/// placed when it ends (m).
pub const READY_TOLERANCE: f64 = 0.3;

/// The ring of sonars (ISocRob's SuperScout: sixteen, evenly spaced).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SonarConfig {
    /// Sonars in the ring, the first straight ahead, then counter-clockwise.
    pub count: usize,
    /// Half the width of a beam, radians.
    pub half_beam: f64,
    /// Farthest echo, m; beyond it a sonar reads nothing.
    pub range: f64,
    /// Standard deviation of a reading, m.
    pub noise: f64,
}

impl Default for SonarConfig {
    fn default() -> Self {
        Self { count: 16, half_beam: 0.2, range: 3.0, noise: 0.01 }
    }
}

/// The odometry sensors: two optical mice underneath (MRT manual ch. 4) and the wheel
/// encoders. These numbers describe the *simulated* sensors; the world-state Member's filter
/// assumes its own (see [`mrt_world::model`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OdometryConfig {
    /// Distance between the two mice (`D` of the manual's §4.1), m.
    pub mice_distance: f64,
    /// Standard deviation of each mouse reading, as a fraction of the distance it moved.
    pub mice_noise: f64,
    /// Probability that a mouse under-reads in one cycle (it lifts, or the floor is too
    /// uniform): its reading is then 50–100 % of the true one, in the true direction (§4.2).
    pub mice_miss_probability: f64,
    /// Largest difference of the two mice's `x̄` accepted as consistent, m per cycle (the
    /// manual's error detection); larger differences are reduced (§4.2) or, failing that,
    /// the cycle uses the wheels.
    pub mice_tolerance: f64,
    /// Standard deviation of the wheel odometry, as a fraction of the motion. The wheels also
    /// count motion that did not happen when the robot is blocked (they slip).
    pub wheel_noise: f64,
}

impl Default for OdometryConfig {
    fn default() -> Self {
        Self {
            mice_distance: 0.2,
            mice_noise: 0.005,
            mice_miss_probability: 0.02,
            mice_tolerance: 0.003,
            wheel_noise: 0.05,
        }
    }
}

impl OdometryConfig {
    /// The two-mice sensor these settings describe.
    pub fn mice(&self) -> Result<mrt_perception::mice::MiceOdometry, String> {
        mrt_perception::mice::MiceOdometry::new(self.mice_distance, self.mice_tolerance)
            .map_err(|e| format!("odometry: {e}"))
    }
}

impl SimConfig {
    /// Robot `id`'s robot file in this world: its base, size, kicker reach, mice, camera noise,
    /// guidance and the field it plays on, from this world's sections, with `stack` driving it
    /// (what `mrt sim --distributed` gives each robot process).
    pub fn robot_file(&self, id: usize, stack: &str) -> mrt_robot::config::RobotFile {
        use mrt_robot::config::{
            BodySection, DevicesSection, GazeSection, RobotFile, RobotSection, SensorsSection,
            VisionSection,
        };
        RobotFile {
            robot: RobotSection {
                id,
                team_size: self.rules.team_size,
                stack: stack.to_string(),
                behaviors: None,
                control_period: self.rules.control_period,
            },
            body: BodySection {
                base: self.robot.base.clone(),
                radius: self.robot.radius,
                kick_reach: self.robot.kick_reach,
                max_speed: self.robot.max_speed,
                max_turn_rate: self.robot.max_turn_rate,
            },
            sensors: SensorsSection {
                mice_distance: self.odometry.mice_distance,
                mice_tolerance: self.odometry.mice_tolerance,
                camera_distance_noise: self.sensor.distance_noise,
                camera_bearing_noise: self.sensor.bearing_noise,
                ball_radius: self.ball.radius,
            },
            field: self.field.map(),
            guidance: self.guidance.clone(),
            devices: DevicesSection::default(),
            vision: VisionSection {
                enabled: self.sensor.percepts == PerceptSource::Vision,
                camera: self.camera.clone(),
                colors: mrt_perception::vision::colors::ColorTable::shipped(),
                post_radius: self.render.post_radius,
                post_height: self.render.post_height,
                up_camera: self.up_camera.clone(),
            },
            gaze: GazeSection {
                half_fov: self.gaze.half_fov.or(match self.sensor.percepts {
                    PerceptSource::Oracle => Some(self.sensor.half_fov),
                    PerceptSource::Vision => None,
                }),
                ..self.gaze.clone()
            },
            localization: self.localization,
        }
    }

    /// What each robot of this world is configured with (the robot program's
    /// [`RobotConfig`](mrt_robot::config::RobotConfig)), from [`SimConfig::robot_file`].
    pub fn robot(&self) -> Result<mrt_robot::config::RobotConfig, String> {
        self.robot_file(0, "chaser").config()
    }
}

/// The whole configuration.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimConfig {
    /// The field.
    pub field: FieldConfig,
    /// The ball.
    pub ball: BallConfig,
    /// The robots (both teams).
    pub robot: BodyConfig,
    /// The rules.
    pub rules: MatchConfig,
    /// The object sensor.
    pub sensor: SensorConfig,
    /// The sonar ring.
    pub sonar: SonarConfig,
    /// Guidance: the robot file's `[guidance]` section, for every robot.
    pub guidance: mrt_robot::config::GuidanceSection,
    /// The odometry sensors.
    pub odometry: OdometryConfig,
    /// Every robot's camera: a camera file's keys (`mrt_perception::camera::CameraFile`;
    /// all of them when the table is given, the shipped `configs/vision/camera.toml` when not).
    pub camera: mrt_perception::camera::CameraFile,
    /// Every robot's omnidirectional up camera, when the robots carry one (`[up_camera]`, an
    /// omni camera file's keys, `configs/vision/omni.toml`; none by default): with vision
    /// percepts, the simulator renders its image too and the robots' vision finds the ball
    /// all around in it (ISocRob seed `003` §2.2, §3.2.1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub up_camera: Option<mrt_perception::camera::OmniFile>,
    /// What the cameras draw.
    pub render: RenderConfig,
    /// Every robot's camera pan joint and gaze control (a robot file's `[gaze]`; off by
    /// default: the cameras look straight ahead). Without `half_fov`, the robots take the
    /// object sensor's `[sensor] half_fov` (oracle percepts) or their camera's (vision).
    pub gaze: mrt_robot::config::GazeSection,
    /// How every robot knows where it is (a robot file's `[localization]`).
    pub localization: mrt_robot::config::LocalizationSection,
}

/// What went wrong reading a configuration file (the file, and the line and column of a
/// syntax error).
pub type ConfigError = mrt_core::FileError;

impl SimConfig {
    /// The default world with the object sensor's percepts instead of rendered images and
    /// vision: the fast mode (`mrt sim --percepts oracle`) for long series and for tests whose
    /// subject is not perception.
    pub fn oracle() -> SimConfig {
        let mut cfg = SimConfig::default();
        cfg.sensor.percepts = PerceptSource::Oracle;
        cfg
    }

    /// Parses a configuration; `file` names it in errors.
    pub fn from_toml(text: &str, file: &str) -> Result<SimConfig, ConfigError> {
        let cfg: SimConfig = toml::from_str(text)
            .map_err(|e| ConfigError::parse(file, text, e.span().map(|s| s.start), e.message()))?;
        cfg.validate()
            .map_err(|message| ConfigError::Invalid { file: file.to_string(), message })?;
        Ok(cfg)
    }

    /// Reads a configuration file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<SimConfig, ConfigError> {
        let (text, file) = mrt_core::FileError::read(path.as_ref())?;
        SimConfig::from_toml(&text, &file)
    }

    /// The configuration as a TOML file that [`SimConfig::from_toml`] reads back (what the
    /// robots of a distributed match are given).
    pub fn to_toml(&self) -> Result<String, String> {
        toml::to_string(self).map_err(|e| e.to_string())
    }

    /// Checks that every value makes sense.
    pub fn validate(&self) -> Result<(), String> {
        let positive = [
            ("field.length", self.field.length),
            ("field.width", self.field.width),
            ("field.goal_width", self.field.goal_width),
            ("field.goal_depth", self.field.goal_depth),
            ("ball.radius", self.ball.radius),
            ("ball.mass", self.ball.mass),
            ("robot.radius", self.robot.radius),
            ("robot.mass", self.robot.mass),
            ("robot.max_speed", self.robot.max_speed),
            ("robot.max_accel", self.robot.max_accel),
            ("robot.max_turn_rate", self.robot.max_turn_rate),
            ("rules.half_duration", self.rules.half_duration),
            ("rules.physics_step", self.rules.physics_step),
            ("rules.control_period", self.rules.control_period),
            ("sensor.range", self.sensor.range),
            ("sensor.landmark_range", self.sensor.landmark_range),
            ("sonar.range", self.sonar.range),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{name} must be a positive number, not {v}"));
            }
        }
        let at_least = [
            ("field.length", self.field.length, 2.0),
            ("field.width", self.field.width, 2.0),
            ("rules.stuck_time", self.rules.stuck_time, 0.1),
            ("rules.stuck_distance", self.rules.stuck_distance, 0.001),
            ("sensor.half_fov", self.sensor.half_fov, 0.01),
            ("robot.kick_half_angle", self.robot.kick_half_angle, 0.0),
            ("robot.kick_reach", self.robot.kick_reach, 0.0),
            ("field.centre_circle_radius", self.field.centre_circle_radius, 0.0),
            ("field.penalty_area_depth", self.field.penalty_area_depth, 0.0),
            ("field.penalty_area_width", self.field.penalty_area_width, 0.0),
        ];
        for (name, v, min) in at_least {
            if !(v.is_finite() && v >= min) {
                return Err(format!("{name} must be at least {min}, not {v}"));
            }
        }
        if self.rules.kidnaps > 100 {
            return Err(format!("rules.kidnaps must be at most 100, not {}", self.rules.kidnaps));
        }
        if self.sensor.half_fov > std::f64::consts::PI
            || self.robot.kick_half_angle > std::f64::consts::PI
        {
            return Err("sensor.half_fov and robot.kick_half_angle must be at most π".into());
        }
        // Physical bounds: a field no hall holds, or a time step that would take a match years
        // to simulate, is a typo.
        let within = [
            ("field.length", self.field.length, 2.0, 200.0),
            ("field.width", self.field.width, 2.0, 200.0),
            ("field.border", self.field.border, 0.0, 20.0),
            ("rules.physics_step", self.rules.physics_step, 1e-4, 1.0),
            ("rules.control_period", self.rules.control_period, 1e-3, 10.0),
        ];
        for (name, v, min, max) in within {
            if !(min..=max).contains(&v) {
                return Err(format!("{name} must be between {min} and {max}, not {v}"));
            }
        }
        if self.field.penalty_area_depth >= self.field.length / 2.0
            || self.field.penalty_area_width > self.field.width
        {
            return Err("the penalty area must fit in its half of the field".into());
        }
        let non_negative = [
            ("field.border", self.field.border),
            ("ball.rolling_damping", self.ball.rolling_damping),
            ("robot.kick_speed", self.robot.kick_speed),
            ("robot.kick_recharge", self.robot.kick_recharge),
            ("rules.set_duration", self.rules.set_duration),
            ("sensor.distance_noise", self.sensor.distance_noise),
            ("sensor.bearing_noise", self.sensor.bearing_noise),
            ("rules.ready_duration", self.rules.ready_duration),
            ("sonar.noise", self.sonar.noise),
            ("sonar.half_beam", self.sonar.half_beam),
            ("odometry.mice_noise", self.odometry.mice_noise),
            ("odometry.wheel_noise", self.odometry.wheel_noise),
        ];
        for (name, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{name} must be zero or more, not {v}"));
            }
        }
        let unit = [
            ("ball.restitution", self.ball.restitution),
            ("sensor.miss_probability", self.sensor.miss_probability),
            ("odometry.mice_miss_probability", self.odometry.mice_miss_probability),
        ];
        for (name, v) in unit {
            if !(0.0..=1.0).contains(&v) {
                return Err(format!("{name} must be between 0 and 1, not {v}"));
            }
        }
        mrt_robot::base::Base::parse(&self.robot.base)?;
        if self.field.goal_width >= self.field.width {
            return Err("field.goal_width must be smaller than field.width".into());
        }
        if !(1..=11).contains(&self.rules.team_size) {
            return Err(format!("rules.team_size must be 1 to 11, not {}", self.rules.team_size));
        }
        if self.rules.control_period < self.rules.physics_step {
            return Err("rules.control_period must be at least rules.physics_step".into());
        }
        if !(1..=64).contains(&self.sonar.count) || self.sonar.half_beam > 1.0 {
            return Err(format!(
                "sonar.count must be 1 to 64 (not {}) and sonar.half_beam at most 1 rad",
                self.sonar.count
            ));
        }
        self.render.validate()?;
        self.camera.camera().map_err(|e| format!("camera: {e}"))?;
        if let Some(up) = &self.up_camera {
            up.camera().map_err(|e| format!("up_camera: {e}"))?;
        }
        self.check_derived()?;
        self.odometry.mice()?;
        self.robot()?;
        Ok(())
    }

    /// The quantities the simulator derives from several values (without them `[robot]
    /// radius = 0.6` would pass validation, then the referee panicked on a `clamp` whose minimum exceeded
    /// its maximum). Each error names the field to change.
    fn check_derived(&self) -> Result<(), String> {
        let (f, r, b) = (&self.field, self.robot.radius, self.ball.radius);
        let (hl, hw) = (f.length / 2.0, f.width / 2.0);
        // Physics: bodies of these sizes and masses must have a density an f32 holds.
        if !(MIN_BODY_RADIUS..=1.0).contains(&r) || !(MIN_BODY_RADIUS..=1.0).contains(&b) {
            return Err(format!(
                "robot.radius and ball.radius must be {MIN_BODY_RADIUS} to 1 m, not {r} and {b}"
            ));
        }
        if self.robot.mass > MAX_MASS || self.ball.mass > MAX_MASS {
            return Err(format!("robot.mass and ball.mass must be at most {MAX_MASS} kg"));
        }
        if self.rules.half_duration > MAX_HALF_DURATION {
            return Err(format!(
                "rules.half_duration must be at most {MAX_HALF_DURATION} s (one day), not {}",
                self.rules.half_duration
            ));
        }
        // The referee lets a team enter on its side line with robots 2r + 0.05 m apart, at
        // most ENTRY_SPACING apart.
        if 2.0 * r + 0.05 > ENTRY_SPACING {
            return Err(format!(
                "robot.radius must be at most {} m (robots enter the field 2 × radius + 0.05 m \
                 apart, at most {ENTRY_SPACING} m), not {r}",
                (ENTRY_SPACING - 0.05) / 2.0
            ));
        }
        // Kickoff: a robot stands at most hl − r − 0.1 from the centre; the kicker stands
        // 2r + ball radius from it, on its own side of the ball.
        let farthest = hl - r - 0.1;
        if 2.0 * r + b > farthest {
            return Err(format!(
                "field.length must be at least {:.3} m for robots of robot.radius {r} m: at \
                 kickoff the kicker stands 2 × robot.radius + ball.radius = {:.3} m from the \
                 centre spot, and no robot may stand farther than field.length / 2 − \
                 robot.radius − 0.1 m = {farthest:.3} m from it",
                2.0 * (3.0 * r + b + 0.1),
                2.0 * r + b
            ));
        }
        // Kickoff: a team's field players spread over field.width in team_size − 1 lanes.
        let lanes = self.rules.team_size.max(2) - 1;
        let lane_width = f.width / (lanes as f64 + 1.0);
        if lane_width < 2.0 * r {
            return Err(format!(
                "rules.team_size {} does not fit across field.width {} m: the {lanes} field \
                 players of a team line up {lane_width:.3} m apart at kickoff, less than a \
                 robot's width (2 × robot.radius = {} m)",
                self.rules.team_size,
                f.width,
                2.0 * r
            ));
        }
        // Goals: the ball must fit in; both stacks' goalkeepers stand 0.1 m inside the posts.
        if f.goal_width < MIN_GOAL_WIDTH || f.goal_width <= 2.0 * b {
            return Err(format!(
                "field.goal_width must be at least {MIN_GOAL_WIDTH} m (goalkeepers keep 0.1 m \
                 inside the posts) and wider than the ball (2 × ball.radius = {} m), not {}",
                2.0 * b,
                f.goal_width
            ));
        }
        if f.penalty_area_width < f.goal_width {
            return Err(format!(
                "field.penalty_area_width ({}) must be at least field.goal_width ({}): the area \
                 surrounds the goal",
                f.penalty_area_width, f.goal_width
            ));
        }
        if f.centre_circle_radius >= hl.min(hw) {
            return Err(format!(
                "field.centre_circle_radius must be less than half the field's length and \
                 width ({} m), not {}",
                hl.min(hw),
                f.centre_circle_radius
            ));
        }
        Ok(())
    }
}

/// The smallest radius of the robots and the ball, m: smaller bodies would have densities
/// (mass / area) beyond what the physics engine's `f32` holds.
pub const MIN_BODY_RADIUS: f64 = 0.01;
/// The heaviest robot or ball, kg.
pub const MAX_MASS: f64 = 1e4;
/// The longest half, s (one day): a match is simulated cycle by cycle, and a drawing keeps
/// every cycle's frame.
pub const MAX_HALF_DURATION: f64 = 86_400.0;
/// The widest spacing of a team entering on its side line, m (`referee`).
pub const ENTRY_SPACING: f64 = 1.2;
/// The narrowest goal, m: the goalkeepers of every stack keep 0.1 m inside the posts.
pub const MIN_GOAL_WIDTH: f64 = 0.2;

/// The default configuration with the object sensor's fast percepts, halves of `seconds` and
/// `team` robots a side (tests whose subject is not perception).
#[cfg(test)]
pub(crate) fn short(seconds: f64, team: usize) -> SimConfig {
    let mut cfg = SimConfig::oracle();
    cfg.rules.half_duration = seconds;
    cfg.rules.team_size = team;
    cfg
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_file_gives_the_documented_defaults() {
        let cfg = SimConfig::from_toml("", "empty.toml").unwrap();
        assert_eq!(cfg, SimConfig::default());
        assert_eq!((cfg.field.length, cfg.field.width, cfg.robot.max_speed), (18.0, 12.0, 1.2));
    }

    #[test]
    fn a_partial_file_changes_only_what_it_names() {
        let cfg = SimConfig::from_toml("[rules]\nteam_size = 2\n", "two.toml").unwrap();
        assert_eq!(cfg.rules.team_size, 2);
        assert_eq!(cfg.rules.half_duration, 300.0);
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let e = SimConfig::from_toml("[field]\nlength = 18.0\nwidht = 12.0\n", "typo.toml")
            .unwrap_err();
        let text = e.to_string();
        assert!(text.starts_with("typo.toml:3:1: ") && text.contains("widht"), "{text}");
        let e = SimConfig::from_toml("[ball]\nradius = -1\n", "neg.toml").unwrap_err();
        assert!(e.to_string().contains("ball.radius must be a positive number"), "{e}");
        let e = SimConfig::from_toml("[rules]\nteam_size = 0\n", "zero.toml").unwrap_err();
        assert!(e.to_string().contains("team_size"), "{e}");
    }

    #[test]
    fn values_that_would_break_the_rules_are_refused() {
        for (text, needle) in [
            ("[field]\nlength = 0.5\n", "field.length must be at least 2"),
            ("[rules]\nstuck_time = -1.0\n", "rules.stuck_time"),
            ("[rules]\ncontrol_period = 1e30\n", "control_period"),
            ("[sensor]\nhalf_fov = 7.0\n", "half_fov"),
            ("[field]\npenalty_area_depth = 12.0\n", "penalty area"),
            ("[robot]\nbase = \"legs\"\n", "robot.base must be differential or omni"),
            ("[rules]\nphysics_step = 1e-9\n", "rules.physics_step must be between 0.0001 and 1"),
            ("[field]\nlength = 1e6\n", "field.length must be between 2 and 200"),
            ("[field]\nwidth = 1e6\n", "field.width must be between 2 and 200"),
            ("[odometry]\nmice_distance = 1e-300\n", "between 0.01 and 2 m"),
            ("[rules]\nhalf_duration = 1e12\n", "rules.half_duration must be at most 86400 s"),
        ] {
            let e = SimConfig::from_toml(text, "bad.toml").unwrap_err().to_string();
            assert!(e.contains(needle), "{text}: {e}");
        }
    }

    proptest::proptest! {
        #[test]
        fn random_text_never_panics(text in "\\PC{0,200}") {
            let _ = SimConfig::from_toml(&text, "random.toml");
        }

        #[test]
        fn random_bytes_never_panic(bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..300)) {
            let _ = SimConfig::from_toml(&String::from_utf8_lossy(&bytes), "random.toml");
        }
    }
}

#[cfg(test)]
mod shipped {
    use super::*;

    /// `configs/sim/default.toml` documents exactly the built-in defaults.
    #[test]
    fn the_shipped_default_file_equals_the_built_in_defaults() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../configs/sim/default.toml");
        assert_eq!(SimConfig::from_file(path).unwrap(), SimConfig::default());
        let mut odd = SimConfig::default();
        odd.rules.half_duration = 12.5;
        odd.rules.team_size = 2;
        let text = odd.to_toml().unwrap();
        assert_eq!(SimConfig::from_toml(&text, "written").unwrap(), odd, "written and read back");
    }
}
