//! The physical world on `rapier2d`, seen from above: a walled field with two goals, a ball
//! that rolls, bounces and is kicked, and round robots driven by velocity commands.
//!
//! Frame: metres, origin at the centre spot, +x towards the east goal, +y to the north,
//! headings counter-clockwise from +x. Nothing here knows about teams or rules (see
//! the referee, `referee.rs`).

use crate::config::SimConfig;
use mrt_core::{Pose2, Twist};
use rapier2d::prelude::*;

struct Robot {
    body: RigidBodyHandle,
    drive: Twist,
    /// Simulated time when the kicker is charged again.
    kick_ready_at: f64,
    /// How often the robot was put down by hand, and where last.
    placed: (u32, Pose2),
    /// How often it was carried elsewhere without being told ([`World::carry_robot`]).
    carried: u32,
}

/// The physical world.
pub struct World {
    cfg: SimConfig,
    physics: PhysicsWorld,
    ball: RigidBodyHandle,
    robots: Vec<Robot>,
    time: f64,
}

pub(crate) fn v(x: f64, y: f64) -> Vector {
    Vector::new(x as f32, y as f32)
}

impl World {
    /// An empty field with the ball on the centre spot and `robots` robots lined up on the
    /// south side line (place them with [`World::place_robot`]).
    pub fn new(cfg: &SimConfig, robots: usize) -> World {
        let mut physics = PhysicsWorld { gravity: Vector::ZERO, ..Default::default() };
        physics.integration_parameters.dt = cfg.rules.physics_step as f32;
        let f = &cfg.field;
        let (hl, hw) = (f.length / 2.0, f.width / 2.0);
        let (wx, wy) = (hl + f.border, hw + f.border);
        let wall = 0.1;
        let walls = physics.insert_body(RigidBodyBuilder::fixed());
        // `bounce`: walls give the ball back, goal nets swallow it.
        let add = |physics: &mut PhysicsWorld,
                   (cx, cy): (f64, f64),
                   (hx, hy): (f64, f64),
                   bounce: f32| {
            let c = ColliderBuilder::cuboid(hx as f32, hy as f32)
                .translation(v(cx, cy))
                .restitution(bounce)
                .restitution_combine_rule(CoefficientCombineRule::Min)
                .friction(0.2);
            physics.colliders.insert_with_parent(c, walls, &mut physics.bodies);
        };
        // Outer walls.
        add(&mut physics, (0.0, wy + wall), (wx + 2.0 * wall, wall), 0.5);
        add(&mut physics, (0.0, -wy - wall), (wx + 2.0 * wall, wall), 0.5);
        add(&mut physics, (wx + wall, 0.0), (wall, wy + 2.0 * wall), 0.5);
        add(&mut physics, (-wx - wall, 0.0), (wall, wy + 2.0 * wall), 0.5);
        // Goals: a back and two sides behind each goal line.
        let (gw, gd) = (f.goal_width / 2.0, f.goal_depth);
        for side in [-1.0, 1.0] {
            add(&mut physics, (side * (hl + gd + wall), 0.0), (wall, gw + wall), 0.0);
            for s in [-1.0, 1.0] {
                add(
                    &mut physics,
                    (side * (hl + gd / 2.0), s * (gw + wall)),
                    (gd / 2.0 + wall, wall),
                    0.0,
                );
            }
        }
        let b = &cfg.ball;
        let ball_area = std::f64::consts::PI * b.radius * b.radius;
        let (ball, _) = physics.insert(
            RigidBodyBuilder::dynamic().linear_damping(b.rolling_damping as f32).ccd_enabled(true),
            ColliderBuilder::ball(b.radius as f32)
                .density((b.mass / ball_area) as f32)
                .restitution(b.restitution as f32)
                .friction(0.3),
        );
        let r = &cfg.body;
        let robot_area = std::f64::consts::PI * r.radius * r.radius;
        let robots = (0..robots)
            .map(|i| {
                let x = -hl + 1.0 + i as f64 * (2.5 * r.radius);
                let (body, _) = physics.insert(
                    RigidBodyBuilder::dynamic().translation(v(x, -hw - f.border / 2.0)),
                    ColliderBuilder::ball(r.radius as f32)
                        .density((r.mass / robot_area) as f32)
                        .restitution(0.2)
                        .friction(0.5),
                );
                Robot {
                    body,
                    drive: Twist::ZERO,
                    kick_ready_at: 0.0,
                    placed: (0, Pose2::default()),
                    carried: 0,
                }
            })
            .collect();
        World { cfg: cfg.clone(), physics, ball, robots, time: 0.0 }
    }

    /// The configuration.
    pub fn config(&self) -> &SimConfig {
        &self.cfg
    }

    /// Simulated seconds since the start.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Number of robots.
    pub fn robot_count(&self) -> usize {
        self.robots.len()
    }

    /// The ball's centre.
    pub fn ball(&self) -> (f64, f64) {
        let t = self.physics.bodies[self.ball].translation();
        (f64::from(t.x), f64::from(t.y))
    }

    /// The ball's velocity.
    pub fn ball_velocity(&self) -> (f64, f64) {
        let l = self.physics.bodies[self.ball].linvel();
        (f64::from(l.x), f64::from(l.y))
    }

    /// Puts the ball at rest at `(x, y)`.
    pub fn place_ball(&mut self, x: f64, y: f64) {
        let body = &mut self.physics.bodies[self.ball];
        body.set_translation(v(x, y), true);
        body.set_linvel(Vector::ZERO, true);
        body.set_angvel(0.0, true);
    }

    /// A robot's pose (`None` for an unknown index).
    pub fn robot(&self, i: usize) -> Option<Pose2> {
        let body = &self.physics.bodies[self.robots.get(i)?.body];
        let t = body.translation();
        Some(Pose2::new(f64::from(t.x), f64::from(t.y), f64::from(body.rotation().angle())))
    }

    /// Puts a robot at rest at a pose, with a stopped drive.
    pub fn place_robot(&mut self, i: usize, pose: Pose2) {
        let Some(r) = self.robots.get_mut(i) else { return };
        r.drive = Twist::ZERO;
        r.placed = (r.placed.0.wrapping_add(1), pose);
        let body = &mut self.physics.bodies[r.body];
        body.set_position(Pose::new(v(pose.x, pose.y), pose.theta as f32), true);
        body.set_linvel(Vector::ZERO, true);
        body.set_angvel(0.0, true);
    }

    /// Lifts robot `i` and puts it down at `pose`, at rest, without telling it: the kidnapped
    /// robot of localization tests (its mice, off the floor, feel nothing of the carry).
    pub fn carry_robot(&mut self, i: usize, pose: Pose2) {
        let Some(r) = self.robots.get_mut(i) else { return };
        r.drive = Twist::ZERO;
        r.carried = r.carried.wrapping_add(1);
        let body = &mut self.physics.bodies[r.body];
        body.set_position(Pose::new(v(pose.x, pose.y), pose.theta as f32), true);
        body.set_linvel(Vector::ZERO, true);
        body.set_angvel(0.0, true);
    }

    /// How many times robot `i` was carried with [`World::carry_robot`] (0 for an unknown
    /// index).
    pub fn carried(&self, i: usize) -> u32 {
        self.robots.get(i).map_or(0, |r| r.carried)
    }

    /// How many times robot `i` was put down with [`World::place_robot`], and where last
    /// (`(0, origin)` for a robot never placed or an unknown index).
    pub fn placement(&self, i: usize) -> (u32, Pose2) {
        self.robots.get(i).map_or((0, Pose2::default()), |r| r.placed)
    }

    /// Robot `i`'s velocity set-point (what its wheels turn at; the body may lag behind or be
    /// blocked).
    pub fn drive_setpoint(&self, i: usize) -> Twist {
        self.robots.get(i).map_or(Twist::ZERO, |r| r.drive)
    }

    /// Sets a robot's velocity set-point (limited to the robot's top speeds).
    pub fn drive(&mut self, i: usize, drive: Twist) {
        let r = &self.cfg.body;
        let finite = |x: f64| if x.is_finite() { x } else { 0.0 };
        let (mut fw, mut left) = (finite(drive.vx), finite(drive.vy));
        let speed = fw.hypot(left);
        if speed > r.max_speed {
            fw *= r.max_speed / speed;
            left *= r.max_speed / speed;
        }
        let turn = finite(drive.omega).clamp(-r.max_turn_rate, r.max_turn_rate);
        if let Some(robot) = self.robots.get_mut(i) {
            robot.drive = Twist::new(fw, left, turn);
        }
    }

    /// Fires robot `i`'s kicker: if it is charged and the ball lies in front of the robot
    /// within reach, the ball leaves along the robot's heading at the kick speed. Returns
    /// whether the ball was kicked.
    pub fn kick(&mut self, i: usize) -> bool {
        let Some(pose) = self.robot(i) else { return false };
        let rc = &self.cfg.body;
        let Some(robot) = self.robots.get_mut(i) else { return false };
        if self.time < robot.kick_ready_at {
            return false;
        }
        robot.kick_ready_at = self.time + rc.kick_recharge;
        let (bx, by) = self.ball();
        let (dx, dy) = (bx - pose.x, by - pose.y);
        let reach = rc.radius + self.cfg.ball.radius + rc.kick_reach;
        let bearing = mrt_core::normalize_angle(dy.atan2(dx) - pose.theta);
        if dx.hypot(dy) > reach || bearing.abs() > rc.kick_half_angle {
            return false;
        }
        let (c, s) = (pose.theta.cos(), pose.theta.sin());
        let body = &mut self.physics.bodies[self.ball];
        body.set_linvel(v(rc.kick_speed * c, rc.kick_speed * s), true);
        true
    }

    /// What a ring of `count` sonars around robot `i` measures (m from the robot's edge, the
    /// first sonar straight ahead, then counter-clockwise, evenly spaced, as the SuperScout's
    /// sixteen): each beam of half-width `half_beam` is three rays (centre and edges) that see
    /// walls, goals, robots and the ball; the nearest hit counts, `range` when nothing is hit.
    /// Noise is the caller's (the sensor models, `sensor.rs`).
    pub fn sonar(&self, i: usize, count: usize, half_beam: f64, range: f64) -> Vec<f64> {
        let (Some(pose), Some(robot)) = (self.robot(i), self.robots.get(i)) else {
            return Vec::new();
        };
        let ring = SonarRing { count, half_beam, range, radius: self.cfg.body.radius };
        ring.cast(&self.physics, robot.body, pose)
    }

    /// Advances the world by one physics step: robots accelerate towards their set-points
    /// (within the acceleration limit), then rapier moves everything.
    pub fn step(&mut self) {
        let dt = self.cfg.rules.physics_step;
        let max_dv = self.cfg.body.max_accel * dt;
        let max_dw = 4.0 * self.cfg.body.max_turn_rate * dt;
        for r in &self.robots {
            accelerate(&mut self.physics.bodies[r.body], r.drive, max_dv, max_dw);
        }
        self.physics.step();
        self.time += dt;
    }
}

/// Changes `body`'s velocity towards the set-point `drive` (robot frame) by at most `max_dv`
/// (m/s) and `max_dw` (rad/s): one physics step of a robot's motors.
pub(crate) fn accelerate(body: &mut RigidBody, drive: Twist, max_dv: f64, max_dw: f64) {
    let th = f64::from(body.rotation().angle());
    let (c, s) = (th.cos(), th.sin());
    let target = (drive.vx * c - drive.vy * s, drive.vx * s + drive.vy * c);
    let now = body.linvel();
    let (dvx, dvy) = (target.0 - f64::from(now.x), target.1 - f64::from(now.y));
    let dv = dvx.hypot(dvy);
    let k = if dv > max_dv { max_dv / dv } else { 1.0 };
    body.set_linvel(v(f64::from(now.x) + dvx * k, f64::from(now.y) + dvy * k), true);
    let w = f64::from(body.angvel());
    let dw = (drive.omega - w).clamp(-max_dw, max_dw);
    body.set_angvel((w + dw) as f32, true);
}

/// A ring of sonars round a robot of `radius` (m), as [`World::sonar`] describes it.
pub(crate) struct SonarRing {
    pub(crate) count: usize,
    pub(crate) half_beam: f64,
    pub(crate) range: f64,
    pub(crate) radius: f64,
}

impl SonarRing {
    /// Each sonar's distance from the robot's edge at `pose` to the nearest thing in
    /// `physics` other than the robot's own `body` (`range` when nothing is hit).
    pub(crate) fn cast(
        &self,
        physics: &PhysicsWorld,
        body: RigidBodyHandle,
        pose: Pose2,
    ) -> Vec<f64> {
        let query =
            physics.query_pipeline_with_filter(QueryFilter::default().exclude_rigid_body(body));
        let (r, range, half_beam) = (self.radius, self.range, self.half_beam);
        (0..self.count)
            .map(|k| {
                let centre = pose.theta + 2.0 * std::f64::consts::PI * k as f64 / self.count as f64;
                [centre - half_beam, centre, centre + half_beam]
                    .into_iter()
                    .map(|a| {
                        let (c, s) = (a.cos(), a.sin());
                        let ray = Ray::new(v(pose.x + r * c, pose.y + r * s), v(c, s));
                        query
                            .cast_ray(&ray, range as f32, true)
                            .map_or(range, |(_, toi)| f64::from(toi))
                    })
                    .fold(range, f64::min)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn world(robots: usize) -> World {
        World::new(&SimConfig::default(), robots)
    }

    #[test]
    fn a_free_ball_rolls_to_a_stop_and_walls_keep_it_in() {
        let mut w = world(0);
        w.place_ball(0.0, 0.0);
        // Kick it north at 6 m/s: rolling friction slows it (damping 0.4/s: about 6/0.4 = 15 m
        // of travel without walls), the north wall at y = 7 bounces it back.
        w.physics.bodies[w.ball].set_linvel(v(0.0, 6.0), true);
        let mut max_y: f64 = 0.0;
        for _ in 0..2000 {
            w.step();
            max_y = max_y.max(w.ball().1);
        }
        let (bx, by) = w.ball();
        let speed = w.ball_velocity().0.hypot(w.ball_velocity().1);
        assert!(max_y < 7.0 && max_y > 6.5, "stopped by the wall at 7 m: {max_y}");
        assert!(by < max_y - 0.5, "bounced back: {by}");
        assert!(bx.abs() < 1e-3 && speed < 0.3, "({bx}, {by}) at {speed} m/s after 20 s");
    }

    #[test]
    fn robots_accelerate_within_their_limits_and_respect_top_speed() {
        let mut w = world(1);
        w.place_robot(0, Pose2::new(0.0, 0.0, 0.0));
        w.drive(0, Twist { vx: 5.0, vy: 0.0, omega: 0.0 });
        w.step();
        let after_one = w.robot(0).unwrap().x;
        // 2 m/s² for 10 ms: 0.02 m/s, so about 0.2 mm in the first step.
        assert!(after_one > 0.0 && after_one < 0.001, "{after_one}");
        for _ in 0..300 {
            w.step();
        }
        let v = w.physics.bodies[w.robots[0].body].linvel();
        assert!((f64::from(v.x) - 1.2).abs() < 1e-3, "top speed 1.2 m/s: {}", v.x);
    }

    #[test]
    fn a_robot_turns_and_drives_along_its_heading() {
        let mut w = world(1);
        w.place_robot(0, Pose2::new(0.0, 0.0, std::f64::consts::FRAC_PI_2));
        w.drive(0, Twist { vx: 1.0, vy: 0.0, omega: 0.0 });
        for _ in 0..200 {
            w.step();
        }
        let p = w.robot(0).unwrap();
        assert!(p.x.abs() < 0.01 && p.y > 1.0, "heading north: {p:?}");
    }

    #[test]
    fn the_kicker_needs_the_ball_in_front_and_a_charged_tank() {
        let mut w = world(1);
        w.place_robot(0, Pose2::new(0.0, 0.0, 0.0));
        w.place_ball(0.40, 0.0); // 0.25 + 0.11 + 0.04 in front
        assert!(w.kick(0));
        assert!((w.ball_velocity().0 - 6.0).abs() < 1e-3);
        w.place_ball(0.40, 0.0);
        assert!(!w.kick(0), "recharging");
        for _ in 0..100 {
            w.step();
        }
        w.place_robot(0, Pose2::new(0.0, 0.0, 0.0));
        w.place_ball(-0.40, 0.0);
        assert!(!w.kick(0), "behind the robot");
        w.place_ball(1.0, 0.0);
        assert!(!w.kick(0), "out of reach");
    }

    #[test]
    fn the_ball_enters_a_goal_but_not_the_wall_beside_it() {
        let mut w = world(0);
        w.place_ball(8.0, 0.0);
        w.physics.bodies[w.ball].set_linvel(v(5.0, 0.0), true);
        for _ in 0..200 {
            w.step();
        }
        let (x, y) = w.ball();
        assert!(x > 9.0 && x < 9.6 && y.abs() < 1.0, "in the east goal: ({x}, {y})");
        w.place_ball(8.0, 3.0);
        w.physics.bodies[w.ball].set_linvel(v(5.0, 0.0), true);
        for _ in 0..200 {
            w.step();
        }
        let (x, _) = w.ball();
        assert!(x < 10.0, "stopped by the east wall at 10 m: {x}");
    }

    /// Sonar geometry by hand: robot at (8, 0) facing east, radius 0.25 m. Straight ahead lies
    /// the goal mouth: the net's back is at 9 + 0.6 = 9.6 m, so sonar 0 reads 9.6 − 8.25 = 1.35.
    /// Sonar 4 (90°, north) would see the north wall at 7 − 0.25 = 6.75 m, beyond a 5 m range:
    /// 5. A ball 1 m behind (at x = 7) is seen by sonar 8 at 1 − 0.25 − 0.11 = 0.64 m.
    #[test]
    fn sonars_see_walls_goals_and_the_ball() {
        let mut w = world(1);
        w.place_robot(0, Pose2::new(8.0, 0.0, 0.0));
        w.place_ball(7.0, 0.0);
        w.step();
        let s = w.sonar(0, 16, 0.0, 5.0);
        assert_eq!(s.len(), 16);
        assert!((s[0] - 1.35).abs() < 0.01, "{s:?}");
        assert_eq!(s[4], 5.0, "{s:?}");
        assert!((s[8] - 0.64).abs() < 0.01, "{s:?}");
        assert!(w.sonar(9, 16, 0.1, 5.0).is_empty(), "no such robot");
    }

    /// The beam width matters: a ball 0.45 m off the axis of sonar 8 is missed by a thin beam
    /// (the centre ray passes 0.45 m from the ball's centre, more than its 0.11 m radius) and
    /// caught by a ±0.5 rad beam's edge ray. By hand: that ray starts on the robot's edge at
    /// (8 − 0.25·cos 0.5, 0.25·sin 0.5) = (7.781, 0.120) heading (−0.878, 0.479); the ball's
    /// centre (7.2, 0.45) lies 0.668 m along it and 0.012 m beside it, so the ray meets the ball
    /// at 0.668 − √(0.11² − 0.012²) = 0.559 m.
    #[test]
    fn a_wide_beam_sees_what_a_thin_one_misses() {
        let mut w = world(1);
        w.place_robot(0, Pose2::new(8.0, 0.0, 0.0));
        w.place_ball(7.2, 0.45);
        w.step();
        assert_eq!(w.sonar(0, 16, 0.0, 5.0)[8], 5.0);
        let wide = w.sonar(0, 16, 0.5, 5.0)[8];
        assert!((wide - 0.559).abs() < 0.005, "{wide}");
    }

    #[test]
    fn same_inputs_same_trajectory() {
        let run = || {
            let mut w = world(2);
            w.place_robot(0, Pose2::new(-1.0, 0.0, 0.0));
            w.place_robot(1, Pose2::new(1.0, 0.2, std::f64::consts::PI));
            w.drive(0, Twist { vx: 1.0, vy: 0.0, omega: 0.3 });
            w.drive(1, Twist { vx: 1.0, vy: 0.1, omega: 0.0 });
            for _ in 0..500 {
                w.step();
            }
            (w.robot(0), w.robot(1), w.ball())
        };
        assert_eq!(run(), run());
    }
}
