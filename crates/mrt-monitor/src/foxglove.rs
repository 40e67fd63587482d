//! Foxglove's well-known schemas beside MRT's own, so that Foxglove and
//! Lichtblick draw a recording without a user's layout:
//!
//! - `/field` (once, at the start) and `/scene` (each cycle, drawn from `/truth`):
//!   `foxglove.SceneUpdate`, the field's lines, each robot as a cylinder in its team's colour
//!   with an arrow for its heading, the ball as a sphere, in the frame `field` (m);
//! - `/<robot>/pose`: `foxglove.FrameTransform`, where the robot believes it is
//!   (`Localization`), parent `field`, child `<robot>`;
//! - `/log`: `foxglove.Log`, the errors and faults the robots report on the bus (a behavior's
//!   errors in `BehaviorStatus`, a refused `BehaviorPush`, a `PlannedPath` with no path).
//!
//! The types follow Foxglove's documented JSON schemas
//! (<https://docs.foxglove.dev/docs/visualization/message-schemas/>): the same field names,
//! times as `{sec, nsec}`, enums (`LineType`, `LogLevel`) as integers. Their JSON schemas are
//! derived from the types here, each titled with Foxglove's name (`foxglove.SceneUpdate`),
//! which is what Foxglove matches on. Camera images (`foxglove.CompressedImage`) are in
//! [`camera`](crate::camera).

use crate::camera::Timestamp;
use crate::view::Truth;
use mrt_core::{Pose2, Time};
use mrt_msgs::{BehaviorPushReply, BehaviorStatus, PlannedPath};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

/// The frame of the field: metres from the centre spot, x towards the east goal.
pub const FIELD_FRAME: &str = "field";

impl Timestamp {
    /// `time` as Foxglove writes it.
    pub fn of(time: Time) -> Timestamp {
        Timestamp {
            sec: u32::try_from(time.0 / 1_000_000_000).unwrap_or(u32::MAX),
            nsec: u32::try_from(time.0 % 1_000_000_000).unwrap_or(0),
        }
    }
}

/// Foxglove's `duration`: a signed number of seconds and nanoseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct Duration {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds past `sec`.
    pub nsec: u32,
}

/// `foxglove.Vector3`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.Vector3")]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `foxglove.Point3`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.Point3")]
pub struct Point3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `foxglove.Quaternion`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.Quaternion")]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

impl Quaternion {
    /// A turn of `theta` radians about z.
    pub fn yaw(theta: f64) -> Quaternion {
        Quaternion { x: 0.0, y: 0.0, z: (theta / 2.0).sin(), w: (theta / 2.0).cos() }
    }
}

/// `foxglove.Pose`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.Pose")]
pub struct Pose {
    /// Where.
    pub position: Vector3,
    /// Which way.
    pub orientation: Quaternion,
}

impl Pose {
    /// At (`x`, `y`, `z`), turned `theta` about z.
    pub fn at(x: f64, y: f64, z: f64, theta: f64) -> Pose {
        Pose { position: Vector3 { x, y, z }, orientation: Quaternion::yaw(theta) }
    }
}

/// `foxglove.Color`: red, green, blue and alpha, 0 to 1.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.Color")]
pub struct Color {
    /// Red.
    pub r: f64,
    /// Green.
    pub g: f64,
    /// Blue.
    pub b: f64,
    /// Alpha.
    pub a: f64,
}

/// The home team's colour (blue, as the web monitor draws it).
pub const HOME: Color = Color { r: 0.2, g: 0.4, b: 1.0, a: 1.0 };
/// The away team's colour (red).
pub const AWAY: Color = Color { r: 0.9, g: 0.2, b: 0.2, a: 1.0 };
/// The ball's colour (orange).
pub const BALL: Color = Color { r: 1.0, g: 0.5, b: 0.0, a: 1.0 };
/// The field lines' colour.
pub const WHITE: Color = Color { r: 1.0, g: 1.0, b: 1.0, a: 1.0 };

/// `foxglove.ArrowPrimitive`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.ArrowPrimitive")]
pub struct ArrowPrimitive {
    /// Its tail and direction (+x).
    pub pose: Pose,
    /// The shaft's length.
    pub shaft_length: f64,
    /// The shaft's diameter.
    pub shaft_diameter: f64,
    /// The head's length.
    pub head_length: f64,
    /// The head's diameter.
    pub head_diameter: f64,
    /// Its colour.
    pub color: Color,
}

/// `foxglove.CubePrimitive`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.CubePrimitive")]
pub struct CubePrimitive {
    /// Its centre and orientation.
    pub pose: Pose,
    /// Its size along each axis.
    pub size: Vector3,
    /// Its colour.
    pub color: Color,
}

/// `foxglove.SpherePrimitive`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.SpherePrimitive")]
pub struct SpherePrimitive {
    /// Its centre and orientation.
    pub pose: Pose,
    /// Its diameter along each axis.
    pub size: Vector3,
    /// Its colour.
    pub color: Color,
}

/// `foxglove.CylinderPrimitive`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.CylinderPrimitive")]
pub struct CylinderPrimitive {
    /// Its centre and orientation (flat faces across z).
    pub pose: Pose,
    /// Its size along each axis.
    pub size: Vector3,
    /// The bottom face's scale (1: a cylinder).
    pub bottom_scale: f64,
    /// The top face's scale.
    pub top_scale: f64,
    /// Its colour.
    pub color: Color,
}

/// `foxglove.LineType`: 0 a strip, 1 a loop, 2 a list of segments.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct LineType(pub u8);

impl LineType {
    /// Points joined one to the next.
    pub const LINE_STRIP: LineType = LineType(0);
    /// A strip closed back to its first point.
    pub const LINE_LOOP: LineType = LineType(1);
    /// Segments of two points each.
    pub const LINE_LIST: LineType = LineType(2);
}

impl JsonSchema for LineType {
    fn schema_name() -> Cow<'static, str> {
        "foxglove.LineType".into()
    }

    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({
            "title": "foxglove.LineType",
            "oneOf": [
                {"title": "LINE_STRIP", "const": 0},
                {"title": "LINE_LOOP", "const": 1},
                {"title": "LINE_LIST", "const": 2}
            ]
        })
    }
}

/// `foxglove.LinePrimitive`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.LinePrimitive")]
pub struct LinePrimitive {
    /// How the points are joined.
    #[serde(rename = "type")]
    pub kind: LineType,
    /// The points' origin.
    pub pose: Pose,
    /// The line's thickness.
    pub thickness: f64,
    /// Whether the thickness is in pixels (true) or in the scene's units.
    pub scale_invariant: bool,
    /// The points.
    pub points: Vec<Point3>,
    /// The colour of the whole line.
    pub color: Color,
    /// A colour per point (none here).
    pub colors: Vec<Color>,
    /// Indices into `points` (none here: all, in order).
    pub indices: Vec<u32>,
}

/// `foxglove.TextPrimitive`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.TextPrimitive")]
pub struct TextPrimitive {
    /// Where.
    pub pose: Pose,
    /// Whether it always faces the camera.
    pub billboard: bool,
    /// Its size.
    pub font_size: f64,
    /// Whether the size is in pixels.
    pub scale_invariant: bool,
    /// Its colour.
    pub color: Color,
    /// The text.
    pub text: String,
}

/// `foxglove.KeyValuePair`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.KeyValuePair")]
pub struct KeyValuePair {
    /// The key.
    pub key: String,
    /// Its value.
    pub value: String,
}

/// `foxglove.SceneEntity`: primitives in one frame. Triangle lists and models are not drawn
/// here; their arrays stay empty (Foxglove's schema requires them).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.SceneEntity")]
pub struct SceneEntity {
    /// When.
    pub timestamp: Timestamp,
    /// Its frame.
    pub frame_id: String,
    /// It replaces any entity of the same id on its topic.
    pub id: String,
    /// How long it stays (0: until replaced).
    pub lifetime: Duration,
    /// Whether it follows its frame as the frame moves.
    pub frame_locked: bool,
    /// Key-value pairs about it.
    pub metadata: Vec<KeyValuePair>,
    /// Arrows.
    pub arrows: Vec<ArrowPrimitive>,
    /// Cubes.
    pub cubes: Vec<CubePrimitive>,
    /// Spheres.
    pub spheres: Vec<SpherePrimitive>,
    /// Cylinders.
    pub cylinders: Vec<CylinderPrimitive>,
    /// Lines.
    pub lines: Vec<LinePrimitive>,
    /// Triangle lists (none).
    pub triangles: Vec<serde_json::Value>,
    /// Texts.
    pub texts: Vec<TextPrimitive>,
    /// Models (none).
    pub models: Vec<serde_json::Value>,
}

impl SceneEntity {
    /// An empty entity `id` in the field's frame at `time`, staying until replaced.
    pub fn new(id: &str, time: Time) -> SceneEntity {
        SceneEntity {
            timestamp: Timestamp::of(time),
            frame_id: FIELD_FRAME.into(),
            id: id.into(),
            lifetime: Duration::default(),
            frame_locked: false,
            metadata: Vec::new(),
            arrows: Vec::new(),
            cubes: Vec::new(),
            spheres: Vec::new(),
            cylinders: Vec::new(),
            lines: Vec::new(),
            triangles: Vec::new(),
            texts: Vec::new(),
            models: Vec::new(),
        }
    }
}

/// `foxglove.SceneEntityDeletion`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.SceneEntityDeletion")]
pub struct SceneEntityDeletion {
    /// When.
    pub timestamp: Timestamp,
    /// 0: the entity `id`; 1: all.
    #[serde(rename = "type")]
    pub kind: u8,
    /// The entity.
    pub id: String,
}

/// `foxglove.SceneUpdate`: entities to add or replace, and to delete.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.SceneUpdate")]
pub struct SceneUpdate {
    /// Entities deleted.
    pub deletions: Vec<SceneEntityDeletion>,
    /// Entities added or replaced.
    pub entities: Vec<SceneEntity>,
}

/// The field's markings, m: what `/field` draws.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldLines {
    /// From the centre spot to a goal line.
    pub half_length: f64,
    /// From the centre line to a side line.
    pub half_width: f64,
    /// From the middle of a goal to a post.
    pub goal_half_width: f64,
    /// A goal's depth behind its line.
    pub goal_depth: f64,
    /// From the goal line to the penalty area's line.
    pub penalty_area_depth: f64,
    /// Half the penalty area's width.
    pub penalty_area_half_width: f64,
    /// The centre circle's radius.
    pub centre_circle_radius: f64,
}

/// How big the scene's bodies are, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bodies {
    /// A robot's radius.
    pub robot_radius: f64,
    /// The ball's radius.
    pub ball_radius: f64,
}

fn point(x: f64, y: f64) -> Point3 {
    Point3 { x, y, z: 0.0 }
}

fn line(kind: LineType, points: Vec<Point3>) -> LinePrimitive {
    LinePrimitive {
        kind,
        pose: Pose::at(0.0, 0.0, 0.0, 0.0),
        thickness: 0.05,
        scale_invariant: false,
        points,
        color: WHITE,
        colors: Vec::new(),
        indices: Vec::new(),
    }
}

impl SceneUpdate {
    /// The field (`/field`): its outline, the centre line and circle, the penalty areas and
    /// the goals, as one entity `field` that stays.
    pub fn field(f: &FieldLines, time: Time) -> SceneUpdate {
        let (l, w) = (f.half_length, f.half_width);
        let mut entity = SceneEntity::new("field", time);
        let rect = |x0: f64, y0: f64, x1: f64, y1: f64| {
            line(
                LineType::LINE_LOOP,
                vec![point(x0, y0), point(x1, y0), point(x1, y1), point(x0, y1)],
            )
        };
        entity.lines.push(rect(-l, -w, l, w));
        entity.lines.push(line(LineType::LINE_LIST, vec![point(0.0, -w), point(0.0, w)]));
        let circle = (0..48)
            .map(|k| {
                let a = f64::from(k) * std::f64::consts::TAU / 48.0;
                point(f.centre_circle_radius * a.cos(), f.centre_circle_radius * a.sin())
            })
            .collect();
        entity.lines.push(line(LineType::LINE_LOOP, circle));
        let (d, h) = (f.penalty_area_depth, f.penalty_area_half_width);
        let (g, gd) = (f.goal_half_width, f.goal_depth);
        for s in [-1.0, 1.0] {
            entity.lines.push(line(
                LineType::LINE_STRIP,
                vec![
                    point(s * l, -h),
                    point(s * (l - d), -h),
                    point(s * (l - d), h),
                    point(s * l, h),
                ],
            ));
            entity.lines.push(line(
                LineType::LINE_STRIP,
                vec![
                    point(s * l, -g),
                    point(s * (l + gd), -g),
                    point(s * (l + gd), g),
                    point(s * l, g),
                ],
            ));
        }
        SceneUpdate { deletions: Vec::new(), entities: vec![entity] }
    }

    /// The truth at `time` (`/scene`): entity `robots`, each robot a cylinder in its team's
    /// colour (home's first, [`Truth::home`] of them) with an arrow along its heading, and
    /// entity `ball`, a sphere.
    pub fn of_truth(truth: &Truth, bodies: &Bodies, time: Time) -> SceneUpdate {
        let r = bodies.robot_radius;
        let mut robots = SceneEntity::new("robots", time);
        for (i, p) in truth.robots.iter().enumerate() {
            let color = if i < truth.home { HOME } else { AWAY };
            robots.cylinders.push(CylinderPrimitive {
                pose: Pose::at(p.x, p.y, r * 0.4, p.theta),
                size: Vector3 { x: 2.0 * r, y: 2.0 * r, z: r * 0.8 },
                bottom_scale: 1.0,
                top_scale: 1.0,
                color,
            });
            robots.arrows.push(ArrowPrimitive {
                pose: Pose::at(p.x, p.y, r * 0.8 + 0.02, p.theta),
                shaft_length: r,
                shaft_diameter: r * 0.2,
                head_length: r * 0.5,
                head_diameter: r * 0.5,
                color: WHITE,
            });
        }
        let b = bodies.ball_radius;
        let mut ball = SceneEntity::new("ball", time);
        ball.spheres.push(SpherePrimitive {
            pose: Pose::at(truth.ball.0, truth.ball.1, b, 0.0),
            size: Vector3 { x: 2.0 * b, y: 2.0 * b, z: 2.0 * b },
            color: BALL,
        });
        SceneUpdate { deletions: Vec::new(), entities: vec![robots, ball] }
    }
}

/// `foxglove.FrameTransform`: where frame `child_frame_id` is in `parent_frame_id`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.FrameTransform")]
pub struct FrameTransform {
    /// When.
    pub timestamp: Timestamp,
    /// The parent frame.
    pub parent_frame_id: String,
    /// The child frame.
    pub child_frame_id: String,
    /// The child's origin in the parent.
    pub translation: Vector3,
    /// The child's orientation in the parent.
    pub rotation: Quaternion,
}

impl FrameTransform {
    /// Robot `robot` believed at `pose` (field frame, m, rad) at `time` (`/<robot>/pose`).
    pub fn believed(robot: &str, pose: &Pose2, time: Time) -> FrameTransform {
        FrameTransform {
            timestamp: Timestamp::of(time),
            parent_frame_id: FIELD_FRAME.into(),
            child_frame_id: robot.into(),
            translation: Vector3 { x: pose.x, y: pose.y, z: 0.0 },
            rotation: Quaternion::yaw(pose.theta),
        }
    }
}

/// `foxglove.LogLevel`: 0 unknown, 1 debug, 2 info, 3 warning, 4 error, 5 fatal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct LogLevel(pub u8);

impl LogLevel {
    /// Information.
    pub const INFO: LogLevel = LogLevel(2);
    /// Something went wrong and the robot went on.
    pub const WARNING: LogLevel = LogLevel(3);
    /// An error.
    pub const ERROR: LogLevel = LogLevel(4);
}

impl JsonSchema for LogLevel {
    fn schema_name() -> Cow<'static, str> {
        "foxglove.LogLevel".into()
    }

    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({
            "title": "foxglove.LogLevel",
            "oneOf": [
                {"title": "UNKNOWN", "const": 0},
                {"title": "DEBUG", "const": 1},
                {"title": "INFO", "const": 2},
                {"title": "WARNING", "const": 3},
                {"title": "ERROR", "const": 4},
                {"title": "FATAL", "const": 5}
            ]
        })
    }
}

/// `foxglove.Log`: one log line.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.Log")]
pub struct Log {
    /// When.
    pub timestamp: Timestamp,
    /// How bad.
    pub level: LogLevel,
    /// What.
    pub message: String,
    /// Who: the robot and the message type or Member, e.g. `home/2 BehaviorStatus`.
    pub name: String,
    /// The file it is about, when the message names one (`attacker.lua:3: ...`).
    pub file: String,
    /// The line in `file` (0: none).
    pub line: u32,
}

impl Log {
    /// A log line of `robot`'s `source` at `time`; `file` and `line` are read from a message
    /// that starts with `file:line:` (a Lua error), else empty and 0.
    pub fn new(robot: &str, source: &str, level: LogLevel, message: &str, time: Time) -> Log {
        let (file, line) = file_line(message).unwrap_or_default();
        Log {
            timestamp: Timestamp::of(time),
            level,
            message: message.into(),
            name: format!("{robot} {source}"),
            file,
            line,
        }
    }
}

/// `file:line:` at the start of `message`.
fn file_line(message: &str) -> Option<(String, u32)> {
    let mut parts = message.splitn(3, ':');
    let (file, line, _) = (parts.next()?, parts.next()?, parts.next()?);
    let line: u32 = line.trim().parse().ok()?;
    (!file.is_empty() && !file.contains(' ')).then(|| (file.to_string(), line))
}

/// The log lines in a bus message of robot `robot` at `time` (module doc); none for most
/// messages.
pub fn logs_of(m: &mrt_dcdt::Msg, robot: &str, time: Time) -> Vec<Log> {
    let mut out = Vec::new();
    if let Ok(s) = m.get::<BehaviorStatus>() {
        for e in &s.errors {
            out.push(Log::new(robot, "BehaviorStatus", LogLevel::ERROR, e, time));
        }
        if !s.reloaded.is_empty() {
            let what = format!("reloaded {}", s.reloaded.join(", "));
            out.push(Log::new(robot, "BehaviorStatus", LogLevel::INFO, &what, time));
        }
    } else if let Ok(r) = m.get::<BehaviorPushReply>() {
        let (level, what) = match &r.error {
            Some(e) => (LogLevel::WARNING, format!("{} refused: {e}", r.file)),
            None => (LogLevel::INFO, format!("{} installed", r.file)),
        };
        let mut log = Log::new(robot, "BehaviorPushReply", level, &what, time);
        if let (Some(line), true) = (r.line, r.error.is_some()) {
            (log.file, log.line) = (r.file.clone(), line);
        }
        out.push(log);
    } else if let Ok(p) = m.get::<PlannedPath>() {
        if !p.error.is_empty() {
            out.push(Log::new(robot, "PlannedPath", LogLevel::WARNING, &p.error, time));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_core::Message;
    use mrt_msgs::GameState;
    use serde_json::{json, Value};

    fn keys(v: &Value) -> Vec<&str> {
        let mut k: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
        k.sort_unstable();
        k
    }

    fn truth() -> Truth {
        Truth {
            ball: (1.0, -0.5),
            ball_velocity: (0.0, 0.0),
            robots: vec![Pose2::new(-3.0, 0.0, 0.0), Pose2::new(3.0, 1.0, std::f64::consts::PI)],
            home: 1,
            score: (0, 0),
            state: GameState::Playing,
        }
    }

    /// A scene update has Foxglove's field names at every level; times are {sec, nsec}; the
    /// home robot is blue and the away one red, turned half round.
    #[test]
    fn a_scene_update_has_foxglove_s_shape() {
        let bodies = Bodies { robot_radius: 0.25, ball_radius: 0.11 };
        let scene = SceneUpdate::of_truth(&truth(), &bodies, Time(2_500_000_000));
        let v = serde_json::to_value(&scene).unwrap();
        assert_eq!(keys(&v), ["deletions", "entities"]);
        let robots = &v["entities"][0];
        assert_eq!(
            keys(robots),
            [
                "arrows",
                "cubes",
                "cylinders",
                "frame_id",
                "frame_locked",
                "id",
                "lifetime",
                "lines",
                "metadata",
                "models",
                "spheres",
                "texts",
                "timestamp",
                "triangles"
            ]
        );
        assert_eq!(robots["timestamp"], json!({"sec": 2, "nsec": 500_000_000}));
        assert_eq!(robots["lifetime"], json!({"sec": 0, "nsec": 0}));
        assert_eq!(robots["frame_id"], "field");
        let c = &robots["cylinders"][0];
        assert_eq!(keys(c), ["bottom_scale", "color", "pose", "size", "top_scale"]);
        assert_eq!(keys(&c["pose"]), ["orientation", "position"]);
        assert_eq!(c["color"], json!({"r": 0.2, "g": 0.4, "b": 1.0, "a": 1.0}));
        assert_eq!(robots["cylinders"][1]["color"]["r"], 0.9);
        let q = &robots["cylinders"][1]["pose"]["orientation"];
        assert!(q["z"].as_f64().unwrap() > 0.999 && q["w"].as_f64().unwrap().abs() < 1e-9);
        assert_eq!(
            keys(&robots["arrows"][0]),
            ["color", "head_diameter", "head_length", "pose", "shaft_diameter", "shaft_length"]
        );
        let ball = &v["entities"][1];
        assert_eq!(ball["spheres"][0]["pose"]["position"], json!({"x": 1.0, "y": -0.5, "z": 0.11}));
        let field = FieldLines {
            half_length: 9.0,
            half_width: 6.0,
            goal_half_width: 1.0,
            goal_depth: 0.6,
            penalty_area_depth: 2.25,
            penalty_area_half_width: 3.25,
            centre_circle_radius: 2.0,
        };
        let f = serde_json::to_value(SceneUpdate::field(&field, Time::ZERO)).unwrap();
        let outline = &f["entities"][0]["lines"][0];
        assert_eq!(
            keys(outline),
            [
                "color",
                "colors",
                "indices",
                "points",
                "pose",
                "scale_invariant",
                "thickness",
                "type"
            ]
        );
        assert_eq!(outline["type"], 1, "a loop");
        assert_eq!(outline["points"][2], json!({"x": 9.0, "y": 6.0, "z": 0.0}));
        let schema = crate::catalogue::schema_of::<SceneUpdate>();
        assert_eq!(schema["title"], "foxglove.SceneUpdate");
    }

    /// A believed pose is a transform from `field` to the robot.
    #[test]
    fn a_believed_pose_is_a_frame_transform() {
        let t = FrameTransform::believed("home/2", &Pose2::new(1.5, -2.0, 0.0), Time(100));
        let v = serde_json::to_value(&t).unwrap();
        assert_eq!(
            keys(&v),
            ["child_frame_id", "parent_frame_id", "rotation", "timestamp", "translation"]
        );
        assert_eq!(v["parent_frame_id"], "field");
        assert_eq!(v["child_frame_id"], "home/2");
        assert_eq!(v["translation"], json!({"x": 1.5, "y": -2.0, "z": 0.0}));
        assert_eq!(v["rotation"], json!({"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}));
        assert_eq!(v["timestamp"], json!({"sec": 0, "nsec": 100}));
        let schema = crate::catalogue::schema_of::<FrameTransform>();
        assert_eq!(schema["title"], "foxglove.FrameTransform");
    }

    fn msg<T: Message>(value: T) -> Box<mrt_dcdt::Msg> {
        let header = mrt_dcdt::MsgHeader {
            msg_type: T::TYPE,
            member_id: mrt_core::MemberId(1),
            agora_id: mrt_core::AgoraId(1),
            priority: 0,
            warranty: mrt_dcdt::DeliveryWarranty::None,
            creation_time: Time(0),
        };
        Box::new(mrt_dcdt::Msg::new(header, value))
    }

    /// Behavior errors and Member faults become `foxglove.Log` lines with Foxglove's fields;
    /// a Lua error's file and line are read from it; other messages have none.
    #[test]
    fn errors_and_faults_become_foxglove_logs() {
        let status = BehaviorStatus {
            errors: vec!["attacker.lua:3: attempt to call a nil value".into()],
            ..Default::default()
        };
        let logs = logs_of(&msg(status), "away/1", Time(1_000_000_000));
        assert_eq!(logs.len(), 1);
        let v = serde_json::to_value(&logs[0]).unwrap();
        assert_eq!(keys(&v), ["file", "level", "line", "message", "name", "timestamp"]);
        assert_eq!(v["level"], 4);
        assert_eq!((v["file"].as_str(), v["line"].as_u64()), (Some("attacker.lua"), Some(3)));
        assert_eq!(v["name"], "away/1 BehaviorStatus");
        assert_eq!(v["timestamp"], json!({"sec": 1, "nsec": 0}));
        let path = PlannedPath { error: "no way round".into(), ..Default::default() };
        let logs = logs_of(&msg(path), "home/3", Time(0));
        assert_eq!(logs[0].message, "no way round");
        assert_eq!(
            (logs[0].level, logs[0].file.as_str(), logs[0].line),
            (LogLevel::WARNING, "", 0)
        );
        assert!(logs_of(&msg(BehaviorStatus::default()), "home/0", Time(0)).is_empty());
        let schema = crate::catalogue::schema_of::<Log>();
        assert_eq!(schema["title"], "foxglove.Log");
        assert_eq!(schema["properties"]["level"]["$ref"], "#/$defs/foxglove.LogLevel", "{schema}");
    }
}
