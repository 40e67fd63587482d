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

use mrt_core::frames::{Framed, Team};
use mrt_core::{Point2, Pose2};
use mrt_dcdt::{Context, Inputs, Member, MemberError, MsgRef, RequestType};
use mrt_msgs::{PlanRequest, PlannedPath, WorldSnapshot};
use mrt_plan::spike::{PlanMap, Shape, Spike, SpikeParams};
use mrt_plan::PlanError;

/// Anchored robots at least this reliable are planned round.
pub const PLAN_RELIABILITY: f64 = 0.3;

/// Guidance drives towards the path's pose this far ahead of the robot, m.
pub const LOOKAHEAD: f64 = 0.5;

/// A path older than this is asked for again (the robots round it move), s.
pub const REPLAN: f64 = 1.0;

/// The planner Member of one robot (module doc).
pub(crate) struct Planner {
    robot: usize,
    params: SpikeParams,
    /// The latest world snapshot, kept as received and read only when a request comes (no
    /// copy each cycle).
    world: Option<MsgRef>,
    /// SPIKE on the field last planned on: its size between the lines, m.
    spike: Option<((f64, f64), Spike)>,
    /// The latest request, not yet answered.
    request: Option<PlanRequest>,
    inputs: Inputs<Planner>,
}

impl Planner {
    /// The planner of robot `robot`, whose footprint has radius `radius` (m).
    pub(crate) fn new(robot: usize, radius: f64) -> Planner {
        let params = SpikeParams { robot_radius: radius, ..SpikeParams::default() };
        let inputs = Inputs::new()
            .on::<PlanRequest>(RequestType::Local, |p: &mut Planner, r| p.request = Some(*r))
            .on_msg::<WorldSnapshot>(RequestType::Local, |p, m| p.world = Some(m.clone()));
        Planner { robot, params, world: None, spike: None, request: None, inputs }
    }

    /// SPIKE on the field the world snapshot names (made again when the field changes).
    fn spike(&mut self, field: &mrt_msgs::Field) -> Result<&Spike, PlanError> {
        let size = (2.0 * field.half_length, 2.0 * field.half_width);
        let current = match self.spike.take() {
            Some((s, spike)) if s == size => (s, spike),
            _ => (size, Spike::new(PlanMap::soccer_field(size.0, size.1)?, self.params)?),
        };
        Ok(&self.spike.insert(current).1)
    }

    /// The answer to a request for `to`, from world snapshot `w`.
    fn plan(&mut self, w: &WorldSnapshot, to: Framed<Team, Pose2>) -> PlannedPath {
        let radius = self.params.robot_radius;
        let moving: Vec<Shape> = w
            .robots
            .iter()
            .filter(|r| r.reliability >= PLAN_RELIABILITY)
            .map(|r| Shape::Disc { centre: r.at.inner, radius })
            .collect();
        let from = w.my_pos.pose.inner.position();
        let planned =
            self.spike(&w.field).and_then(|s| s.plan_among(from, to.inner.position(), &moving));
        match planned {
            Ok(plan) => {
                let mut poses: Vec<Framed<Team, Pose2>> =
                    plan.poses.iter().copied().map(Framed::new).collect();
                if let Some(last) = poses.last_mut() {
                    last.inner.theta = to.inner.theta;
                }
                PlannedPath { to, poses, length: plan.length, error: String::new() }
            }
            Err(e) => PlannedPath { to, error: e.to_string(), ..PlannedPath::default() },
        }
    }
}

impl Member for Planner {
    fn name(&self) -> String {
        format!("planner-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.subscribe(ctx);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.clone().drain(self, ctx)?;
        if let Some(r) = self.request.take() {
            let latest = self.world.clone();
            let w = latest.as_ref().map(|m| m.get::<WorldSnapshot>()).transpose()?;
            let path = self.plan(w.unwrap_or(&WorldSnapshot::default()), r.to);
            ctx.publish(path);
        }
        Ok(())
    }
}

/// Where guidance drives next on `path` from `me`: the first pose past the one nearest the
/// robot that is at least [`LOOKAHEAD`] away, or the path's last pose. `None` for an empty
/// path.
pub fn carrot(
    path: &[Framed<Team, Pose2>],
    me: Framed<Team, Pose2>,
) -> Option<Framed<Team, Pose2>> {
    carrot_by(path, me.inner.position(), |p| p.inner.position(), LOOKAHEAD)
}

/// The first pose of `path` past the one nearest `me` that is at least `lookahead` away (in
/// the path's unit), or the path's last pose; `None` for an empty path.
pub fn carrot_at(path: &[Pose2], me: Pose2, lookahead: f64) -> Option<Pose2> {
    carrot_by(path, me.position(), Pose2::position, lookahead)
}

/// [`carrot_at`] for poses of any kind, `at` telling where each is.
fn carrot_by<P: Copy>(
    path: &[P],
    me: Point2,
    at: impl Fn(&P) -> Point2,
    lookahead: f64,
) -> Option<P> {
    let d = |p: &P| (at(p) - me).norm();
    let nearest = (0..path.len()).min_by(|&a, &b| d(&path[a]).total_cmp(&d(&path[b])))?;
    path[nearest..].iter().find(|p| d(p) >= lookahead).or(path.last()).copied()
}

/// Whether `path` was planned for `to` ([`same_goal`]).
pub fn plans_for(path: &PlannedPath, to: Framed<Team, Pose2>) -> bool {
    same_goal(path.to, to)
}

/// Whether two goals are one for the planner: within 0.2 m and 0.3 rad.
pub fn same_goal(a: Framed<Team, Pose2>, b: Framed<Team, Pose2>) -> bool {
    let (a, b) = (a.inner, b.inner);
    (a.x - b.x).hypot(a.y - b.y) <= 0.2 && mrt_core::normalize_angle(a.theta - b.theta).abs() <= 0.3
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x: f64, y: f64, theta: f64) -> Framed<Team, Pose2> {
        Framed::new(Pose2::new(x, y, theta))
    }

    #[test]
    fn the_carrot_is_half_a_metre_ahead_on_the_path_then_the_goal() {
        let path: Vec<Framed<Team, Pose2>> =
            (0..=8).map(|k| at(0.25 * f64::from(k), 0.0, 0.0)).collect();
        // At (0.26, 0.1): nearest pose (0.25, 0); the first from there 0.5 m away is (0.75, 0)
        // (distance hypot(0.49, 0.1) = 0.5001).
        assert_eq!(carrot(&path, at(0.26, 0.1, 0.0)), Some(at(0.75, 0.0, 0.0)));
        // Near the end: the goal.
        assert_eq!(carrot(&path, at(1.9, 0.0, 0.0)), Some(at(2.0, 0.0, 0.0)));
        assert_eq!(carrot(&[], at(0.0, 0.0, 0.0)), None);
        let planned = PlannedPath { to: at(2.0, 0.0, 0.0), ..PlannedPath::default() };
        assert!(plans_for(&planned, at(2.15, 0.0, 0.2)));
        assert!(!plans_for(&planned, at(2.3, 0.0, 0.0)));
    }

    /// The planner on a field with a robot anchored between the start and the goal: the path
    /// goes round it, keeping the two radii and 0.1 m of safety from its centre.
    #[test]
    fn the_planner_goes_round_an_anchored_robot() {
        let mut planner = Planner::new(0, 0.25);
        let mut w = WorldSnapshot::default();
        w.field.half_length = 9.0;
        w.field.half_width = 6.0;
        w.my_pos.pose = at(-3.0, 0.0, 0.0);
        w.robots.push(mrt_msgs::AnchoredRobot { reliability: 0.9, ..Default::default() });
        let path = planner.plan(&w, at(3.0, 0.0, 1.0));
        assert!(path.error.is_empty(), "{path:?}");
        assert!(path.length > 6.0 && path.length < 6.5, "{}", path.length);
        let nearest =
            path.poses.iter().map(|p| p.inner.x.hypot(p.inner.y)).fold(f64::INFINITY, f64::min);
        assert!(nearest >= 0.59, "{nearest}");
        assert_eq!(path.poses.last().map(|p| p.inner.theta), Some(1.0));
        // A goal inside the walls' band is moved out; one far outside the field is refused.
        let outside = planner.plan(&w, at(50.0, 0.0, 0.0));
        assert!(outside.poses.is_empty() && outside.error.contains("no path"), "{outside:?}");
    }
}
