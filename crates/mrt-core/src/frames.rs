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
//! says so: the behaviors' world snapshot and commands are in millimetres and degrees per second
//! (TeamChaos' Lua API, seed `001` §3.3; Mr. BRIAN's rule files, MRT manual ch. 10).
//! [`MM_PER_M`] is the one conversion factor.
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

use crate::geometry::{normalize_angle, Point2, Pose2};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::f64::consts::PI;
use std::marker::PhantomData;

/// Millimetres per metre: the one conversion to the snapshot's and the rule files' unit.
pub const MM_PER_M: f64 = 1000.0;

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
