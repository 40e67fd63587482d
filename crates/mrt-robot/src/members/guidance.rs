//! The guidance Member (`guide-<n>`): the behaviors' command through the Guidance µAgent
//! once a cycle, into the motor driver's command.

use super::*;
use mrt_core::frames::{Framed, Team};
use mrt_core::Twist;

/// Guidance of one robot: the behaviors' command through the Guidance µAgent with the latest
/// world state and sonar scan.
pub(super) struct GuidanceMember {
    pub(super) robot: usize,
    pub(super) guidance: Guidance,
    pub(super) world: WorldSnapshot,
    pub(super) scan: SonarScan,
    /// The planner's latest path, and when it came (s, the world's clock).
    pub(super) path: Option<(PlannedPath, f64)>,
    /// The goal last asked of the planner, and when.
    pub(super) asked: Option<(Framed<Team, Pose2>, f64)>,
    /// Turning to look for landmarks when the world model needs to localize, on a robot
    /// whose camera cannot pan (`None` with a pan joint: the gaze looks instead).
    pub(super) look: Option<LookAround>,
    /// The behaviors' latest command, not yet guided.
    pub(super) command: Option<RobotCommand>,
    pub(super) inputs: Inputs<GuidanceMember>,
}

impl GuidanceMember {
    /// What guidance reads: the behaviors' command, the world state, the sonars, the
    /// planner's paths.
    pub(super) fn inputs() -> Inputs<GuidanceMember> {
        Inputs::<Self>::new()
            .on::<RobotCommand>(RequestType::Local, |g, c| g.command = Some(c.clone()))
            .on::<WorldSnapshot>(RequestType::Local, |g, w| g.world.clone_from(w))
            .on::<SonarScan>(RequestType::Local, |g, s| g.scan.clone_from(s))
            .on::<PlannedPath>(RequestType::Local, |g, p| {
                g.path = Some((p.clone(), g.world.time.as_secs_f64()));
            })
    }

    /// A target to reach along a planned path (`plan`): the planner is asked when its path
    /// is for another goal or a second old; meanwhile the command drives to the path's
    /// carrot in path mode, or, before any path, as the target says without planning.
    fn follow(&mut self, cmd: &mut RobotCommand, me: Framed<Team, Pose2>, ctx: &mut Context<'_>) {
        let Some(target) = cmd.target.filter(|t| t.plan) else { return };
        let now = self.world.time.as_secs_f64();
        let to = target.pose;
        let current = self.path.as_ref().filter(|(p, _)| plans_for(p, to));
        let stale = current.is_none_or(|(_, at)| now - at >= REPLAN);
        let waiting =
            self.asked.is_some_and(|(goal, at)| same_goal(goal, to) && now - at < REPLAN / 2.0);
        if stale && !waiting {
            ctx.publish(PlanRequest { to });
            self.asked = Some((to, now));
        }
        let next = current.and_then(|(p, _)| carrot(&p.poses, me));
        cmd.target = Some(match next {
            // Path mode: position mode to the carrot, halted by the sonars.
            Some(pose) => Target { pose, avoid: false, plan: true },
            None => Target { plan: false, ..target },
        });
    }
}

impl Member for GuidanceMember {
    fn name(&self) -> String {
        format!("guide-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.subscribe(ctx);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.clone().drain(self, ctx)?;
        if let Some(mut cmd) = self.command.take() {
            let now = self.world.time.as_secs_f64();
            let (needs, played) =
                (self.world.needs_localization, self.world.game_state == GameState::Playing);
            if let Some(rate) = self.look.as_mut().and_then(|l| l.step(now, needs, played)) {
                cmd = RobotCommand { twist: Twist::new(0.0, 0.0, rate), ..RobotCommand::default() };
            }
            let me = self.world.my_pos.pose;
            let ball = self.world.global_ball;
            let ball = (ball.quality >= 0.1).then(|| Framed::new(ball.pose.inner.position()));
            self.follow(&mut cmd, me, ctx);
            let guided = self.guidance.guide(&cmd, me, ball, &self.scan.sonars);
            ctx.publish(MotorCommand { twist: guided.twist, kick: cmd.kick.is_some() });
        }
        Ok(())
    }
}
