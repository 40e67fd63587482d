//! The simulator's configuration, read from TOML: a robot file's sections for every robot
//! (`[field]`, `[ball]`, `[body]`, `[sensors]`, `[guidance]`, `[vision]`, `[gaze]`,
//! `[localization]`, the robot program's own types from [`mrt_robot::config`], so each robot
//! parameter has one definition and one default), and the world's own: the rules, the object
//! sensor, the sonars, how the odometry errs, what the cameras draw. What a robot knows of the
//! world is what the world is: the field map is the field, the camera noise the object
//! sensor's. Every value has a documented default (Middle Size League proportions, a robot
//! base of the MRT manual's size and speed), so a file only needs what it changes;
//! `configs/sim/default.toml` lists them all.
//!
//! Units: metres, seconds, kilograms, radians.

use crate::error::SimError;
use serde::{Deserialize, Serialize};
use std::path::Path;

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

/// The object sensor: what a camera would detect, with the camera's noise (`[sensors]
/// camera_distance_noise`, `camera_bearing_noise`).
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
            miss_probability: 0.05,
            percepts: PerceptSource::default(),
        }
    }
}

/// What the simulated cameras draw (the `render` module): the heights of the things that the
/// 2-D physics has no use for, and the image effects, all off by default. The landmark posts
/// are the robots' `[vision] post_radius` and `post_height`.
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

/// The odometry sensors' errors: two optical mice underneath (MRT manual ch. 4) and the wheel
/// encoders. The mice's mounting is the robot's (`[sensors] mice_distance`); these numbers
/// are how the *simulated* sensors err, which the robots do not know.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OdometryConfig {
    /// Standard deviation of each mouse reading, as a fraction of the distance it moved.
    pub mice_noise: f64,
    /// Probability that a mouse under-reads in one cycle (it lifts, or the floor is too
    /// uniform): its reading is then 50–100 % of the true one, in the true direction (§4.2).
    pub mice_miss_probability: f64,
    /// Standard deviation of the wheel odometry, as a fraction of the motion. The wheels also
    /// count motion that did not happen when the robot is blocked (they slip).
    pub wheel_noise: f64,
}

impl Default for OdometryConfig {
    fn default() -> Self {
        Self { mice_noise: 0.005, mice_miss_probability: 0.02, wheel_noise: 0.05 }
    }
}

impl SimConfig {
    /// Robot `id`'s robot file in this world, with `stack` driving it (what `mrt sim
    /// --distributed` gives each robot process): this world's robot sections as they are,
    /// its rules' team size and control period, and vision on when the world renders images.
    pub fn robot_file(&self, id: usize, stack: &str) -> mrt_robot::config::RobotFile {
        use mrt_robot::config::{DevicesSection, GazeSection, RobotFile, RobotSection};
        RobotFile {
            robot: RobotSection {
                id,
                team_size: self.rules.team_size,
                stack: stack.to_string(),
                behaviors: None,
                control_period: self.rules.control_period,
            },
            body: self.body.clone(),
            sensors: self.sensors.clone(),
            ball: self.ball.clone(),
            field: self.field,
            guidance: self.guidance.clone(),
            devices: DevicesSection::default(),
            vision: mrt_robot::config::VisionSection {
                enabled: self.sensor.percepts == PerceptSource::Vision,
                ..self.vision.clone()
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
    pub fn robot(&self) -> Result<mrt_robot::config::RobotConfig, SimError> {
        Ok(self.robot_file(0, "chaser").config()?)
    }
}

/// The whole configuration.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimConfig {
    /// The field (a robot file's `[field]`: the robots' map is the field they play on).
    pub field: mrt_world::FieldMap,
    /// The ball (a robot file's `[ball]`).
    pub ball: mrt_robot::config::BallSection,
    /// Every robot's body, both teams (a robot file's `[body]`).
    pub body: mrt_robot::config::BodySection,
    /// Every robot's mice mounting and camera noise (a robot file's `[sensors]`).
    pub sensors: mrt_robot::config::SensorsSection,
    /// The rules.
    pub rules: MatchConfig,
    /// The object sensor and where the robots' percepts come from.
    pub sensor: SensorConfig,
    /// The sonar ring.
    pub sonar: SonarConfig,
    /// Every robot's guidance (a robot file's `[guidance]`).
    pub guidance: mrt_robot::config::GuidanceSection,
    /// How the simulated odometry errs.
    pub odometry: OdometryConfig,
    /// Every robot's cameras, colour classes and the landmark posts' shape (a robot file's
    /// `[vision]`: `[vision.camera]`, `[vision.up_camera]`, `[vision.colors.*]`); the
    /// simulator renders what these cameras see. `enabled` is set by `[sensor] percepts`.
    pub vision: mrt_robot::config::VisionSection,
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
        cfg.checked()
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
    pub fn to_toml(&self) -> Result<String, SimError> {
        Ok(toml::to_string(self)?)
    }

    /// Checks that every value makes sense.
    pub fn validate(&self) -> Result<(), SimError> {
        self.checked().map_err(SimError::Config)
    }

    fn checked(&self) -> Result<(), String> {
        let positive = [
            ("field.length", self.field.length),
            ("field.width", self.field.width),
            ("field.goal_width", self.field.goal_width),
            ("field.goal_depth", self.field.goal_depth),
            ("ball.radius", self.ball.radius),
            ("ball.mass", self.ball.mass),
            ("body.radius", self.body.radius),
            ("body.mass", self.body.mass),
            ("body.max_speed", self.body.max_speed),
            ("body.max_accel", self.body.max_accel),
            ("body.max_turn_rate", self.body.max_turn_rate),
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
            ("body.kick_half_angle", self.body.kick_half_angle, 0.0),
            ("body.kick_reach", self.body.kick_reach, 0.0),
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
            || self.body.kick_half_angle > std::f64::consts::PI
        {
            return Err("sensor.half_fov and body.kick_half_angle must be at most π".into());
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
            ("body.kick_speed", self.body.kick_speed),
            ("body.kick_recharge", self.body.kick_recharge),
            ("rules.set_duration", self.rules.set_duration),
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
        mrt_robot::base::Base::parse(&self.body.base).map_err(|e| format!("body.{e}"))?;
        if self.vision.enabled {
            return Err("vision.enabled is not for a simulator file: the robots run their \
                        vision when sensor.percepts is \"vision\""
                .into());
        }
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
        self.check_derived()?;
        self.robot().map_err(|e| e.to_string())?;
        Ok(())
    }

    /// The quantities the simulator derives from several values (without them `[body]
    /// radius = 0.6` would pass validation, then the referee panicked on a `clamp` whose minimum exceeded
    /// its maximum). Each error names the field to change.
    fn check_derived(&self) -> Result<(), String> {
        let (f, r, b) = (&self.field, self.body.radius, self.ball.radius);
        let (hl, hw) = (f.length / 2.0, f.width / 2.0);
        // Physics: bodies of these sizes and masses must have a density an f32 holds.
        if !(MIN_BODY_RADIUS..=1.0).contains(&r) || !(MIN_BODY_RADIUS..=1.0).contains(&b) {
            return Err(format!(
                "body.radius and ball.radius must be {MIN_BODY_RADIUS} to 1 m, not {r} and {b}"
            ));
        }
        if self.body.mass > MAX_MASS || self.ball.mass > MAX_MASS {
            return Err(format!("body.mass and ball.mass must be at most {MAX_MASS} kg"));
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
                "body.radius must be at most {} m (robots enter the field 2 × radius + 0.05 m \
                 apart, at most {ENTRY_SPACING} m), not {r}",
                (ENTRY_SPACING - 0.05) / 2.0
            ));
        }
        // Kickoff: a robot stands at most hl − r − 0.1 from the centre; the kicker stands
        // 2r + ball radius from it, on its own side of the ball.
        let farthest = hl - r - 0.1;
        if 2.0 * r + b > farthest {
            return Err(format!(
                "field.length must be at least {:.3} m for robots of body.radius {r} m: at \
                 kickoff the kicker stands 2 × body.radius + ball.radius = {:.3} m from the \
                 centre spot, and no robot may stand farther than field.length / 2 − \
                 body.radius − 0.1 m = {farthest:.3} m from it",
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
                 robot's width (2 × body.radius = {} m)",
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
        assert_eq!((cfg.field.length, cfg.field.width, cfg.body.max_speed), (18.0, 12.0, 1.2));
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
            ("[body]\nbase = \"legs\"\n", "body.base must be differential or omni"),
            ("[rules]\nphysics_step = 1e-9\n", "rules.physics_step must be between 0.0001 and 1"),
            ("[field]\nlength = 1e6\n", "field.length must be between 2 and 200"),
            ("[field]\nwidth = 1e6\n", "field.width must be between 2 and 200"),
            ("[sensors]\nmice_distance = 1e-300\n", "between 0.01 and 2 m"),
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
