//! Coordinate frames that cannot be mixed by accident (in the spirit of HULKs' `Framed<Field,
//! _>`), and the units at MRT's edges.
//!
//! A robot deals with positions in several frames: the **field** frame (metres from the centre
//! spot, x towards the east goal: the simulator's truth, the world model's map and pose), the
//! **team** frame (the field turned half round for a team that attacks west, so that x always
//! points at the opponent's goal: what behaviors reason in), and the **robot** frame (x forward,
//! y to the left, at the robot's centre: what a camera or a sonar measures). A [`Framed`] value
//! carries its frame in its type; the conversions are named functions, each tested.
//!
//! Units are SI inside (metres, radians, seconds). Two edges use others because a seed's format
//! says so: behaviors write set-points in mm/s and degrees/s and read distances in millimetres
//! (TeamChaos' Lua API, ThinkingCap report §3.3; Mr. BRIAN's rule files, MRT manual ch. 10),
//! and their timers count milliseconds (TeamChaos' `getBehaviorInfo().timer`, an HFSM's time
//! in a state). The functions here are the one place those units are converted
//! ([`twist_from_setpoints`], [`pose_in_metres`], [`millis`], ...); [`MM_PER_M`] and
//! [`MS_PER_S`] are the conversion factors.
//!
//! ```
//! use mrt_core::frames::{Attack, Field, Framed, Robot};
//! use mrt_core::{Point2, Pose2};
//!
//! // A robot at (-2, 0) facing north sees the ball 2 m ahead and 2 m to its right.
//! let me: Framed<Field, Pose2> = Framed::new(Pose2::new(-2.0, 0.0, std::f64::consts::FRAC_PI_2));
//! let seen: Framed<Robot, Point2> = Framed::new(Point2::new(2.0, -2.0));
//! let ball = me.to_field(seen);
//! assert!((ball.inner.x - 0.0).abs() < 1e-12 && (ball.inner.y - 2.0).abs() < 1e-12);
//! // For a team attacking west, the same ball is at (0, -2) in its team frame.
//! let team = ball.to_team(Attack::West);
//! assert!((team.inner.x - 0.0).abs() < 1e-12 && (team.inner.y + 2.0).abs() < 1e-12);
//! ```

use crate::geometry::{normalize_angle, Point2, Pose2, Twist, Vec2};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::f64::consts::PI;
use std::marker::PhantomData;

/// Millimetres per metre: the one conversion to the snapshot's and the rule files' unit.
pub const MM_PER_M: f64 = 1000.0;

/// A length or speed at a millimetre edge (mm, mm/s), in metres (m, m/s).
pub fn metres(mm: f64) -> f64 {
    mm / MM_PER_M
}

/// A length or speed (m, m/s), in millimetres (mm, mm/s) for a millimetre edge.
pub fn millimetres(m: f64) -> f64 {
    m * MM_PER_M
}

/// Milliseconds per second: the one conversion to the behaviors' timers' unit.
pub const MS_PER_S: f64 = 1000.0;

/// A duration (s), in milliseconds (ms) for a millisecond edge.
pub fn millis(seconds: f64) -> f64 {
    seconds * MS_PER_S
}

/// A duration at a millisecond edge (ms), in seconds (s).
pub fn seconds_from_millis(ms: f64) -> f64 {
    ms / MS_PER_S
}

/// A point at a millimetre edge, in metres.
pub fn point_in_metres(mm: Point2) -> Point2 {
    mm / MM_PER_M
}

/// A point in metres, in millimetres for a millimetre edge.
pub fn point_in_millimetres(m: Point2) -> Point2 {
    m * MM_PER_M
}

/// A pose at a millimetre edge (mm, heading in radians), in metres; the heading is kept.
pub fn pose_in_metres(mm: Pose2) -> Pose2 {
    Pose2 { x: metres(mm.x), y: metres(mm.y), theta: mm.theta }
}

/// A pose in metres, in millimetres (heading in radians, kept) for a millimetre edge.
pub fn pose_in_millimetres(m: Pose2) -> Pose2 {
    Pose2 { x: millimetres(m.x), y: millimetres(m.y), theta: m.theta }
}

/// The behaviors' set-points (`setVlin`, `setVlat` in mm/s, `setVrot` in degrees/s: TeamChaos'
/// Lua API and Mr. BRIAN's outputs) as a twist in the robot frame (m/s, rad/s).
pub fn twist_from_setpoints(vlin: f64, vlat: f64, vrot: f64) -> Twist {
    Twist::new(metres(vlin), metres(vlat), vrot.to_radians())
}

/// A twist as the behaviors' set-points `(vlin, vlat, vrot)`: mm/s, mm/s, degrees/s.
pub fn setpoints_of(t: Twist) -> (f64, f64, f64) {
    (millimetres(t.vx), millimetres(t.vy), t.omega.to_degrees())
}

/// The field frame: metres from the centre spot, x towards the east goal, y to the north.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Field;

/// A team's frame: the field frame turned half round for a team that attacks west, so that x
/// always points at the opponent's goal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Team;

/// The robot frame: x forward, y to the left, origin at the robot's centre.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Robot;

/// A value (a [`Pose2`], a [`Point2`]) in frame `F`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Framed<F, T> {
    /// The value, in frame `F`.
    pub inner: T,
    frame: PhantomData<F>,
}

impl<F, T> Framed<F, T> {
    /// `inner`, declared to be in frame `F`.
    pub const fn new(inner: T) -> Self {
        Framed { inner, frame: PhantomData }
    }
}

/// On the wire and in files a framed value is its inner value: the frame is the field's type,
/// documented with the message.
impl<F, T: Serialize> Serialize for Framed<F, T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.inner.serialize(s)
    }
}

impl<'de, F, T: Deserialize<'de>> Deserialize<'de> for Framed<F, T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        T::deserialize(d).map(Framed::new)
    }
}

/// A framed value's schema is its inner value's (see its `Serialize`).
#[cfg(feature = "schema")]
impl<F, T: schemars::JsonSchema> schemars::JsonSchema for Framed<F, T> {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        T::schema_name()
    }

    fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
        T::json_schema(generator)
    }

    fn inline_schema() -> bool {
        T::inline_schema()
    }
}

/// Which goal a team attacks: east (+x of the field frame) or west.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Attack {
    /// Towards +x: the team frame is the field frame.
    #[default]
    East,
    /// Towards −x: the team frame is the field frame turned half round.
    West,
}

impl Attack {
    /// From the game controller's direction (+1 east, −1 west; anything not negative is
    /// east).
    pub fn from_direction(direction: f64) -> Attack {
        if direction < 0.0 {
            Attack::West
        } else {
            Attack::East
        }
    }

    fn sign(self) -> f64 {
        match self {
            Attack::East => 1.0,
            Attack::West => -1.0,
        }
    }

    fn turn(self, theta: f64) -> f64 {
        match self {
            Attack::East => theta,
            Attack::West => normalize_angle(theta + PI),
        }
    }
}

impl Framed<Field, Point2> {
    /// The point in the frame of a team attacking `attack`.
    pub fn to_team(self, attack: Attack) -> Framed<Team, Point2> {
        let s = attack.sign();
        Framed::new(Point2::new(s * self.inner.x, s * self.inner.y))
    }
}

impl Framed<Team, Point2> {
    /// The point in the field frame, for a team attacking `attack`.
    pub fn to_field(self, attack: Attack) -> Framed<Field, Point2> {
        let s = attack.sign();
        Framed::new(Point2::new(s * self.inner.x, s * self.inner.y))
    }
}

impl Framed<Field, Vec2> {
    /// The vector (a velocity, a displacement) in the frame of a team attacking `attack`.
    pub fn to_team(self, attack: Attack) -> Framed<Team, Vec2> {
        Framed::new(self.inner * attack.sign())
    }
}

impl Framed<Team, Vec2> {
    /// The vector in the field frame, for a team attacking `attack`.
    pub fn to_field(self, attack: Attack) -> Framed<Field, Vec2> {
        Framed::new(self.inner * attack.sign())
    }
}

impl Framed<Field, Pose2> {
    /// The pose in the frame of a team attacking `attack`.
    pub fn to_team(self, attack: Attack) -> Framed<Team, Pose2> {
        let s = attack.sign();
        let p = self.inner;
        Framed::new(Pose2::new(s * p.x, s * p.y, attack.turn(p.theta)))
    }

    /// A point the robot at this pose measured in its own frame, in the field frame.
    pub fn to_field(self, p: Framed<Robot, Point2>) -> Framed<Field, Point2> {
        Framed::new(self.inner.transform_point(p.inner))
    }

    /// Where a field point is for the robot at this pose: distance (m) and bearing (rad,
    /// counter-clockwise from its heading, in `(-π, π]`), as a camera measures it.
    pub fn range_bearing(self, p: Framed<Field, Point2>) -> (f64, f64) {
        let (dx, dy) = (p.inner.x - self.inner.x, p.inner.y - self.inner.y);
        (dx.hypot(dy), normalize_angle(dy.atan2(dx) - self.inner.theta))
    }

    /// The field point at distance `range` (m) and `bearing` (rad) from the robot at this pose.
    pub fn at_range_bearing(self, range: f64, bearing: f64) -> Framed<Field, Point2> {
        let a = self.inner.theta + bearing;
        Framed::new(Point2::new(self.inner.x + range * a.cos(), self.inner.y + range * a.sin()))
    }
}

impl Framed<Team, Pose2> {
    /// The pose in the field frame, for a team attacking `attack`.
    pub fn to_field(self, attack: Attack) -> Framed<Field, Pose2> {
        let s = attack.sign();
        let p = self.inner;
        Framed::new(Pose2::new(s * p.x, s * p.y, attack.turn(p.theta)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::FRAC_PI_2;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    #[test]
    fn a_team_attacking_west_sees_the_field_turned_half_round() {
        let p: Framed<Field, Pose2> = Framed::new(Pose2::new(3.0, -1.0, FRAC_PI_2));
        let t = p.to_team(Attack::West).inner;
        assert!(close(t.x, -3.0) && close(t.y, 1.0) && close(t.theta, -FRAC_PI_2), "{t:?}");
        assert_eq!(p.to_team(Attack::East).inner, p.inner, "east: the field frame itself");
        assert_eq!(Attack::from_direction(-1.0), Attack::West);
        assert_eq!(Attack::from_direction(1.0), Attack::East);
        assert_eq!(Attack::from_direction(0.0), Attack::East);
    }

    #[test]
    fn range_and_bearing_by_hand() {
        // At (-2, 0) facing north, the point (0, 2) is 2√2 m away, 45° to the right.
        let me: Framed<Field, Pose2> = Framed::new(Pose2::new(-2.0, 0.0, FRAC_PI_2));
        let (r, b) = me.range_bearing(Framed::new(Point2::new(0.0, 2.0)));
        assert!(close(r, 8f64.sqrt()) && close(b, -PI / 4.0), "{r} {b}");
        let back = me.at_range_bearing(r, b).inner;
        assert!(close(back.x, 0.0) && close(back.y, 2.0));
    }

    #[test]
    fn the_edge_units_convert_once_each_way() {
        let t = twist_from_setpoints(4800.0, -1920.0, 180.0);
        assert!(close(t.vx, 4.8) && close(t.vy, -1.92) && close(t.omega, PI), "{t:?}");
        let (vlin, vlat, vrot) = setpoints_of(t);
        assert!(close(vlin, 4800.0) && close(vlat, -1920.0) && close(vrot, 180.0));
        let p = pose_in_metres(Pose2::new(1500.0, -250.0, 3.0));
        assert!(close(p.x, 1.5) && close(p.y, -0.25) && p.theta == 3.0, "{p:?}");
        assert_eq!(pose_in_millimetres(p), Pose2::new(1500.0, -250.0, 3.0));
        assert_eq!(point_in_metres(Point2::new(500.0, 0.0)), Point2::new(0.5, 0.0));
        assert_eq!(point_in_millimetres(Point2::new(0.5, 0.0)), Point2::new(500.0, 0.0));
    }

    #[test]
    fn durations_convert_to_milliseconds_and_back() {
        assert_eq!(millis(0.125), 125.0);
        assert_eq!(seconds_from_millis(125.0), 0.125);
        assert_eq!(millis(seconds_from_millis(40.0)), 40.0);
        assert_eq!(seconds_from_millis(millis(2.5)), 2.5);
    }

    proptest! {
        #[test]
        fn conversions_round_trip(x in -10.0f64..10.0, y in -8.0f64..8.0, th in -3.1f64..3.1,
                                  px in -5.0f64..5.0, py in -5.0f64..5.0, west: bool) {
            let attack = if west { Attack::West } else { Attack::East };
            let me: Framed<Field, Pose2> = Framed::new(Pose2::new(x, y, th));
            let back = me.to_team(attack).to_field(attack).inner;
            prop_assert!(close(back.x, x) && close(back.y, y));
            prop_assert!(close(normalize_angle(back.theta - th), 0.0));
            let p: Framed<Field, Point2> = Framed::new(Point2::new(px, py));
            let q = p.to_team(attack).to_field(attack).inner;
            prop_assert!(close(q.x, px) && close(q.y, py));
            // Robot frame → field → range and bearing → field again.
            let seen: Framed<Robot, Point2> = Framed::new(Point2::new(px, py));
            let f = me.to_field(seen);
            let (r, b) = me.range_bearing(f);
            prop_assert!(close(r, px.hypot(py)));
            let again = me.at_range_bearing(r, b).inner;
            prop_assert!(close(again.x, f.inner.x) && close(again.y, f.inner.y));
        }
    }
}
