//! The planner Member of one robot (SPIKE, MRT manual ch. 9, [`mrt_plan::spike`]) and how
//! guidance follows its paths.
//!
//! On each [`PlanRequest`] the `planner-<n>` Member plans a path from the robot's pose (its
//! latest [`WorldSnapshot`]) to the goal, on the field it plays on. The robots its world model
//! anchored are moving obstacles: each is a disc of the robot's own radius, if its reliability
//! is at least [`PLAN_RELIABILITY`]. The answer is a [`PlannedPath`]: the poses, or why there
//! are none.
//!
//! Guidance asks for a plan when a behavior's target says `plan`
//! ([`mrt_msgs::Target::plan`]). It asks again when the target moves or the path is a second
//! old. Meanwhile it drives in position mode towards a point [`LOOKAHEAD`] ahead on the path
//! ([`carrot`]), with the sonars halting the robot as in velocity mode.

use mrt_core::{Point2, Pose2};
use mrt_dcdt::{Context, Member, MemberError, MsgRef, RequestType};
use mrt_msgs::{PlanRequest, PlannedPath, WorldSnapshot};
use mrt_plan::spike::{PlanMap, Shape, Spike, SpikeParams};

/// Anchored robots at least this reliable are planned round.
pub const PLAN_RELIABILITY: f64 = 0.3;

/// Guidance drives towards the path's pose this far ahead of the robot, mm.
pub const LOOKAHEAD: f64 = 500.0;

/// A path older than this is asked for again (the robots round it move), s.
pub const REPLAN: f64 = 1.0;

/// The planner Member of one robot (module doc).
pub(crate) struct Planner {
    robot: usize,
    params: SpikeParams,
    /// The latest world snapshot, kept as received and read only when a request comes (no
    /// copy each cycle).
    world: Option<MsgRef>,
    /// SPIKE on the field last planned on: its size between the lines, mm.
    spike: Option<((f64, f64), Spike)>,
}

impl Planner {
    /// The planner of robot `robot`, whose footprint has radius `radius` (m).
    pub(crate) fn new(robot: usize, radius: f64) -> Planner {
        let params = SpikeParams { robot_radius: radius, ..SpikeParams::default() };
        Planner { robot, params, world: None, spike: None }
    }

    /// SPIKE on the field the world snapshot names (made again when the field changes).
    fn spike(&mut self, field: &mrt_msgs::Field) -> Result<&Spike, String> {
        let size = (2.0 * field.half_length, 2.0 * field.half_width);
        if self.spike.as_ref().is_none_or(|(s, _)| *s != size) {
            let map = PlanMap::soccer_field(size.0 / 1000.0, size.1 / 1000.0)
                .map_err(|e| e.to_string())?;
            let spike = Spike::new(map, self.params).map_err(|e| e.to_string())?;
            self.spike = Some((size, spike));
        }
        self.spike.as_ref().map(|(_, s)| s).ok_or_else(|| "no planner".to_string())
    }

    /// The answer to a request for `to` (team frame, mm), from world snapshot `w`.
    fn plan(&mut self, w: &WorldSnapshot, to: Pose2) -> PlannedPath {
        let me = w.my_pos.pose;
        let radius = self.params.robot_radius;
        let moving: Vec<Shape> = w
            .robots
            .iter()
            .filter(|r| r.reliability >= PLAN_RELIABILITY)
            .map(|r| Shape::Disc { centre: Point2::new(r.x / 1000.0, r.y / 1000.0), radius })
            .collect();
        let from = Point2::new(me.x / 1000.0, me.y / 1000.0);
        let goal = Point2::new(to.x / 1000.0, to.y / 1000.0);
        let planned = self
            .spike(&w.field)
            .and_then(|s| s.plan_among(from, goal, &moving).map_err(|e| e.to_string()));
        match planned {
            Ok(plan) => {
                let mut poses: Vec<Pose2> = plan
                    .poses
                    .iter()
                    .map(|p| Pose2::new(p.x * 1000.0, p.y * 1000.0, p.theta))
                    .collect();
                if let Some(last) = poses.last_mut() {
                    last.theta = to.theta;
                }
                PlannedPath { to, poses, length: plan.length, error: String::new() }
            }
            Err(error) => PlannedPath { to, error, ..PlannedPath::default() },
        }
    }
}

impl Member for Planner {
    fn name(&self) -> String {
        format!("planner-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<PlanRequest>(RequestType::Local);
        ctx.subscribe_to::<WorldSnapshot>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut request = None;
        while let Some(m) = ctx.receive_msg() {
            if m.is::<WorldSnapshot>() {
                self.world = Some(m);
            } else {
                request = Some(*m.get::<PlanRequest>()?);
            }
        }
        if let Some(r) = request {
            let latest = self.world.clone();
            let w = latest.as_ref().map(|m| m.get::<WorldSnapshot>()).transpose()?;
            let path = self.plan(w.unwrap_or(&WorldSnapshot::default()), r.to);
            ctx.publish(path);
        }
        Ok(())
    }
}

/// Where guidance drives next on `path` from `me` (team frame, mm): the first pose past the
/// one nearest the robot that is at least [`LOOKAHEAD`] away, or the path's last pose.
/// `None` for an empty path.
pub fn carrot(path: &[Pose2], me: Pose2) -> Option<Pose2> {
    carrot_at(path, me, LOOKAHEAD)
}

/// The first pose of `path` past the one nearest `me` that is at least `lookahead` away
/// (in the path's unit), or the path's last pose; `None` for an empty path.
pub fn carrot_at(path: &[Pose2], me: Pose2, lookahead: f64) -> Option<Pose2> {
    let d = |p: &Pose2| (p.x - me.x).hypot(p.y - me.y);
    let nearest = (0..path.len()).min_by(|&a, &b| d(&path[a]).total_cmp(&d(&path[b])))?;
    path[nearest..].iter().find(|p| d(p) >= lookahead).or(path.last()).copied()
}

/// Whether `path` was planned for `to` ([`same_goal`]).
pub fn plans_for(path: &PlannedPath, to: Pose2) -> bool {
    same_goal(path.to, to)
}

/// Whether two goals are one for the planner: within 200 mm and 0.3 rad.
pub fn same_goal(a: Pose2, b: Pose2) -> bool {
    (a.x - b.x).hypot(a.y - b.y) <= 200.0
        && mrt_core::normalize_angle(a.theta - b.theta).abs() <= 0.3
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_carrot_is_half_a_metre_ahead_on_the_path_then_the_goal() {
        let path: Vec<Pose2> =
            (0..=8).map(|k| Pose2::new(250.0 * f64::from(k), 0.0, 0.0)).collect();
        // At (260, 100): nearest pose (250, 0); the first from there 500 mm away is (750, 0)
        // (distance hypot(490, 100) = 500.1).
        assert_eq!(carrot(&path, Pose2::new(260.0, 100.0, 0.0)), Some(Pose2::new(750.0, 0.0, 0.0)));
        // Near the end: the goal.
        assert_eq!(carrot(&path, Pose2::new(1900.0, 0.0, 0.0)), Some(Pose2::new(2000.0, 0.0, 0.0)));
        assert_eq!(carrot(&[], Pose2::default()), None);
        let planned = PlannedPath { to: Pose2::new(2000.0, 0.0, 0.0), ..PlannedPath::default() };
        assert!(plans_for(&planned, Pose2::new(2150.0, 0.0, 0.2)));
        assert!(!plans_for(&planned, Pose2::new(2300.0, 0.0, 0.0)));
    }

    /// The planner on a field with a robot anchored between the start and the goal: the path
    /// goes round it, keeping the two radii and 0.1 m of safety from its centre.
    #[test]
    fn the_planner_goes_round_an_anchored_robot() {
        let mut planner = Planner::new(0, 0.25);
        let mut w = WorldSnapshot::default();
        w.field.half_length = 9000.0;
        w.field.half_width = 6000.0;
        w.my_pos.pose = Pose2::new(-3000.0, 0.0, 0.0);
        w.robots.push(mrt_msgs::AnchoredRobot {
            x: 0.0,
            y: 0.0,
            reliability: 0.9,
            ..Default::default()
        });
        let path = planner.plan(&w, Pose2::new(3000.0, 0.0, 1.0));
        assert!(path.error.is_empty(), "{path:?}");
        assert!(path.length > 6.0 && path.length < 6.5, "{}", path.length);
        let nearest = path.poses.iter().map(|p| p.x.hypot(p.y)).fold(f64::INFINITY, f64::min);
        assert!(nearest >= 590.0, "{nearest}");
        assert_eq!(path.poses.last().map(|p| p.theta), Some(1.0));
        // A goal inside the walls' band is moved out; one far outside the field is refused.
        let outside = planner.plan(&w, Pose2::new(50_000.0, 0.0, 0.0));
        assert!(outside.poses.is_empty() && outside.error.contains("no path"), "{outside:?}");
    }
}
