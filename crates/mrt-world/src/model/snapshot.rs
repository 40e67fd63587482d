//! The world model's edge: the [`WorldSnapshot`] the behaviors read, in the team frame.

use super::*;

impl WorldModel {
    /// The world snapshot in the team frame.
    pub(super) fn snapshot(&self, frame: &CameraFrame) -> WorldSnapshot {
        let me: Framed<Field, Pose2> = Framed::new(self.pose);
        let attack = Attack::from_direction(self.game.attack);
        let mut w = WorldSnapshot {
            time: Time::from_secs_f64(frame.time),
            game_state: self.game.state,
            field: self.map.snapshot(),
            ..Default::default()
        };
        for (slot, lpo) in w.lps.iter_mut().enumerate() {
            let object = if attack == Attack::West { ATTACKING_WEST[slot] } else { slot };
            let Some(Memory { at, reliability, seen }) = self.memory[object] else {
                continue;
            };
            let (range, bearing) = me.range_bearing(at);
            *lpo = Lpo { rho: range, theta: bearing, reliability, seen_ago: frame.time - seen };
        }
        w.my_pos = Estimate { pose: me.to_team(attack), quality: self.quality() };
        w.needs_localization = self.needs_localization();
        w.kickoff_pose = self.game.kickoff_pose.map(|p| p.to_team(attack));
        if let Some(Memory { at, reliability, .. }) = self.memory[lps::BALL] {
            let ball = at.to_team(attack).inner;
            let pose = Framed::new(Pose2::new(ball.x, ball.y, 0.0));
            w.global_ball = Estimate { pose, quality: reliability };
        }
        w.robots = self.anchored_robots(frame.time, attack);
        if let Some(v) = self.ball_velocity {
            w.ball_vel = v.to_team(attack);
        }
        w
    }

    /// The anchored robots out of the find phase, in the team frame, nearest first.
    pub(super) fn anchored_robots(&self, time: f64, attack: Attack) -> Vec<AnchoredRobot> {
        let me: Framed<Field, Pose2> = Framed::new(self.pose);
        let own = self.game.marker;
        let mut out: Vec<AnchoredRobot> = self
            .robots
            .anchors()
            .iter()
            .filter(|a| a.phase(time) != Phase::Find)
            .map(|a| {
                let (x, y) = a.position(time);
                let at: Framed<Field, Point2> = Framed::new(Point2::new(x, y));
                let (rho, theta) = me.range_bearing(at);
                let (vx, vy) = a.velocity();
                AnchoredRobot {
                    id: a.id(),
                    class: a.class(own),
                    at: at.to_team(attack),
                    velocity: Framed::<Field, _>::new(Vec2::new(vx, vy)).to_team(attack),
                    at_sigma: a.sigma(time),
                    rho,
                    theta,
                    reliability: a.reliability(time),
                    seen_ago: time - a.last_seen(),
                }
            })
            .collect();
        out.sort_by(|a, b| a.rho.total_cmp(&b.rho));
        out
    }
}
