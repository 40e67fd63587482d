//! The object sensor: what a robot's camera would detect, as distance and bearing with
//! range-dependent noise, a field of view, occlusion by other robots and random misses. It is
//! the documented stand-in for camera images and colour vision (a later issue), and stays as
//! the fast mode.
//!
//! [`Perception`] turns detections into the robot's [`WorldSnapshot`], in the robot's team
//! frame (millimetres; x towards the opponent's net, whichever half the team plays in): an
//! object not seen this frame keeps its last estimate, moved with the robot's own motion, with
//! its reliability decaying, like the seed's LPS anchors.
//!
//! The team side of the world state is [`merge_team`]: teammates as their [`MateReport`]s
//! tell them, and the global ball from the best sighting, one's own or a teammate's.

use crate::config::{SensorConfig, SonarConfig};
use crate::referee::{Referee, Team};
use crate::world::World;
use mrt_core::robot::{lps, Estimate, Lpo, Mate, WorldSnapshot};
use mrt_core::{normalize_angle, Pose2, Time, Vec2};
use mrt_plan::guidance::Sonar;
use rand::{Rng, RngCore};
use std::f64::consts::PI;

/// Reliability kept per control cycle by an object that was not seen again.
pub const DECAY: f64 = 0.85;

/// A teammate's ball counts this much of its own quality: a second-hand sighting, one cycle
/// old, is trusted a little less than one's own.
pub const SHARED_BALL: f64 = 0.9;

/// What a robot tells its teammates every cycle (team frame, mm): its own pose and its own
/// sighting of the ball (never what it heard from others, so stale news does not circulate).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MateReport {
    /// The robot's player number.
    pub id: u32,
    /// Whether it keeps goal.
    pub keeper: bool,
    /// Where it believes it is.
    pub pose: Estimate,
    /// Where it believes the ball is (quality 0 when it has no idea).
    pub ball: Estimate,
}

impl MateReport {
    /// The report of robot `id` on its world snapshot (before [`merge_team`]).
    pub fn of(id: u32, keeper: bool, w: &WorldSnapshot) -> MateReport {
        MateReport { id, keeper, pose: w.my_pos, ball: w.global_ball }
    }
}

/// The team side of the world state: `w.mates` from the teammates' reports (in their order),
/// and the global ball replaced by a teammate's sighting when that is better than one's own
/// (quality × [`SHARED_BALL`]). The LPS stays what the robot itself perceived.
pub fn merge_team<'a>(w: &mut WorldSnapshot, reports: impl IntoIterator<Item = &'a MateReport>) {
    w.mates.clear();
    for r in reports {
        w.mates.push(Mate { id: r.id, at: r.pose, keeper: r.keeper });
        let shared = r.ball.quality * SHARED_BALL;
        if shared > w.global_ball.quality {
            w.global_ball = Estimate { pose: r.ball.pose, quality: shared };
        }
    }
}

/// Standard normal sample (Box–Muller), from any RNG.
/// What robot `i`'s sonar ring hears (robot frame, m from the centre, ring order; no echo is
/// an infinite range): [`World::sonar`]'s edge distances plus the radius, with noise.
pub fn sonar_ring(world: &World, i: usize, cfg: &SonarConfig, rng: &mut dyn RngCore) -> Vec<Sonar> {
    let radius = world.config().robot.radius;
    world
        .sonar(i, cfg.count, cfg.half_beam, cfg.range)
        .into_iter()
        .enumerate()
        .map(|(k, edge)| {
            let range = if edge >= cfg.range - 1e-9 {
                f64::INFINITY
            } else {
                (edge + radius + cfg.noise * gauss(rng)).max(0.0)
            };
            Sonar::new(Sonar::ring_bearing(k, cfg.count), range)
        })
        .collect()
}

fn gauss(rng: &mut dyn RngCore) -> f64 {
    let u1: f64 = rng.random_range(f64::EPSILON..1.0);
    let u2: f64 = rng.random_range(0.0..1.0);
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// What a robot remembers of one LPS object: where it was last seen (field frame, m), its
/// reliability, and when it was seen (s).
#[derive(Clone, Copy, Debug)]
struct Memory {
    at: (f64, f64),
    reliability: f64,
    seen: f64,
}

/// One robot's view: its LPS memory, in the field frame, between cycles.
#[derive(Clone, Debug)]
pub struct Perception {
    robot: usize,
    /// Last estimate of each LPS object.
    memory: Vec<Option<Memory>>,
}

/// Field positions (m) of the LPS objects for `team`: ball, opponent's net, own net, and six
/// landmarks (the four corners and the two ends of the half-way line).
fn targets(world: &World, referee: &Referee, team: Team) -> [(f64, f64); lps::COUNT] {
    let f = &world.config().field;
    let (hl, hw) = (f.length / 2.0, f.width / 2.0);
    let dir = referee.attack_direction(team);
    let ball = world.ball();
    // Landmarks are named in the team frame, so LANDMARK0 is always the opponent's left corner
    // whichever half the team plays in.
    let l = |x: f64, y: f64| (dir * x, dir * y);
    [
        ball,
        l(hl, 0.0),
        l(-hl, 0.0),
        l(hl, hw),
        l(hl, -hw),
        l(-hl, hw),
        l(-hl, -hw),
        l(0.0, hw),
        l(0.0, -hw),
    ]
}

/// Whether the segment from `a` to `b` passes within `radius` of `c`.
fn blocks(a: (f64, f64), b: (f64, f64), c: (f64, f64), radius: f64) -> bool {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    if len2 == 0.0 {
        return false;
    }
    let t = (((c.0 - a.0) * dx + (c.1 - a.1) * dy) / len2).clamp(0.0, 1.0);
    let (px, py) = (a.0 + t * dx, a.1 + t * dy);
    // Only objects strictly between the two ends hide the target.
    t > 0.0 && t < 1.0 && (px - c.0).hypot(py - c.1) < radius
}

impl Perception {
    /// A robot that has seen nothing yet.
    pub fn new(robot: usize) -> Perception {
        Perception { robot, memory: vec![None; lps::COUNT] }
    }

    /// Looks once and returns the world snapshot for this cycle.
    pub fn look(
        &mut self,
        world: &World,
        referee: &Referee,
        cfg: &SensorConfig,
        rng: &mut dyn RngCore,
    ) -> WorldSnapshot {
        let me = world.robot(self.robot).unwrap_or_default();
        let team = referee.team_of(self.robot);
        let now = world.time();
        let r_robot = world.config().robot.radius;
        let robots: Vec<(f64, f64)> = (0..world.robot_count())
            .filter(|&i| i != self.robot)
            .filter_map(|i| world.robot(i).map(|p| (p.x, p.y)))
            .collect();
        for (k, target) in targets(world, referee, team).into_iter().enumerate() {
            let (dx, dy) = (target.0 - me.x, target.1 - me.y);
            let dist = dx.hypot(dy);
            let bearing = normalize_angle(dy.atan2(dx) - me.theta);
            let occluded =
                k == lps::BALL && robots.iter().any(|&c| blocks((me.x, me.y), target, c, r_robot));
            let range = if k == lps::BALL { cfg.range } else { cfg.landmark_range };
            let visible = dist <= range && bearing.abs() <= cfg.half_fov && !occluded;
            let missed = rng.random_bool(cfg.miss_probability.clamp(0.0, 1.0));
            if visible && !missed {
                let d = (dist * (1.0 + cfg.distance_noise * gauss(rng))).max(0.0);
                let b = bearing + cfg.bearing_noise * gauss(rng);
                let a = me.theta + b;
                let seen = (me.x + d * a.cos(), me.y + d * a.sin());
                self.memory[k] = Some(Memory { at: seen, reliability: 1.0, seen: now });
            } else if let Some(m) = &mut self.memory[k] {
                m.reliability *= DECAY;
            }
        }
        self.snapshot(world, referee, me, team)
    }

    fn snapshot(&self, world: &World, referee: &Referee, me: Pose2, team: Team) -> WorldSnapshot {
        let now = world.time();
        let dir = referee.attack_direction(team);
        // Team frame: x towards the opponent's net. Field → team is a half turn when the team
        // attacks west.
        let to_team = |x: f64, y: f64| (dir * x * 1000.0, dir * y * 1000.0);
        let heading = if dir > 0.0 { me.theta } else { normalize_angle(me.theta + PI) };
        let mut w = WorldSnapshot {
            time: Time::from_secs_f64(now),
            game_state: referee.state(),
            field: world.config().field.map(),
            ..Default::default()
        };
        for (k, m) in self.memory.iter().enumerate() {
            let Some(Memory { at: (x, y), reliability: rel, seen }) = *m else { continue };
            let (dx, dy) = (x - me.x, y - me.y);
            w.lps[k] = Lpo {
                rho: dx.hypot(dy) * 1000.0,
                theta: normalize_angle(dy.atan2(dx) - me.theta),
                reliability: rel,
                seen_ago: now - seen,
            };
        }
        let (mx, my) = to_team(me.x, me.y);
        w.my_pos = Estimate { pose: Pose2::new(mx, my, heading), quality: 0.9 };
        w.kickoff_pose = referee.kickoff_pose(self.robot).map(|p| {
            let (x, y) = to_team(p.x, p.y);
            let theta = if dir > 0.0 { p.theta } else { normalize_angle(p.theta + PI) };
            Pose2::new(x, y, theta)
        });
        if let Some(Memory { at: (bx, by), reliability: rel, .. }) = self.memory[lps::BALL] {
            let (x, y) = to_team(bx, by);
            w.global_ball = Estimate { pose: Pose2::new(x, y, 0.0), quality: rel };
        }
        // The ball's velocity only when it is seen this frame (a tracker would estimate it).
        if self.memory[lps::BALL].is_some_and(|m| m.seen == now) {
            let (vx, vy) = world.ball_velocity();
            w.ball_vel = Vec2::new(dir * vx * 1000.0, dir * vy * 1000.0);
        }
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::SimConfig;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn exact() -> SensorConfig {
        SensorConfig {
            distance_noise: 0.0,
            bearing_noise: 0.0,
            miss_probability: 0.0,
            ..Default::default()
        }
    }

    fn setup() -> (World, Referee) {
        let mut w = World::new(&SimConfig::default(), 8);
        let mut r = Referee::new(4);
        r.start(&mut w);
        (w, r)
    }

    #[test]
    fn distance_and_bearing_in_the_team_frame() {
        let (mut w, r) = setup();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        // Home attacks east. Robot 1 at (-2, 0) facing north; ball at (0, 2): 2.828 m away,
        // 45° to the right of the heading (bearing -π/4).
        w.place_robot(1, Pose2::new(-2.0, 0.0, std::f64::consts::FRAC_PI_2));
        w.place_ball(0.0, 2.0);
        let s = Perception::new(1).look(&w, &r, &exact(), &mut rng);
        let ball = s.lps[lps::BALL];
        assert!((ball.rho - 2828.427).abs() < 0.01, "{ball:?}");
        assert!((ball.theta + std::f64::consts::FRAC_PI_4).abs() < 1e-6, "{ball:?}"); // f32 physics
        assert_eq!(ball.reliability, 1.0);
        // The own net (west, (-9, 0)) is 7 m away on the left (bearing +π/2); the opponent's
        // net is 11 m away: beyond the ball's 9 m range, within the landmarks' 20 m.
        let net = s.lps[lps::NET2];
        assert!((net.rho - 7000.0).abs() < 0.01, "{net:?}");
        assert!((net.theta - std::f64::consts::FRAC_PI_2).abs() < 1e-6, "{net:?}");
        assert_eq!(s.lps[lps::NET1].reliability, 1.0);
        assert!((s.lps[lps::NET1].rho - 11000.0).abs() < 0.01, "{:?}", s.lps[lps::NET1]);
        let short = SensorConfig { landmark_range: 9.0, ..exact() };
        let s2 = Perception::new(1).look(&w, &r, &short, &mut rng);
        assert_eq!(s2.lps[lps::NET1].reliability, 0.0, "11 m: beyond a 9 m landmark range");
        assert_eq!((s.my_pos.pose.x, s.my_pos.pose.y), (-2000.0, 0.0));
        // An away robot sees the same field turned half round: x towards the west goal.
        w.place_robot(5, Pose2::new(2.0, 1.0, std::f64::consts::PI));
        let s = Perception::new(5).look(&w, &r, &exact(), &mut rng);
        assert!((s.my_pos.pose.x + 2000.0).abs() < 1e-9 && (s.my_pos.pose.y + 1000.0).abs() < 1e-9);
        assert!(s.my_pos.pose.theta.abs() < 1e-6, "facing its attack direction");
        assert_eq!(s.field.half_length, 9000.0);
    }

    #[test]
    fn a_robot_in_between_hides_the_ball_and_the_memory_fades() {
        let (mut w, r) = setup();
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        w.place_robot(1, Pose2::new(-3.0, 0.0, 0.0));
        w.place_ball(0.0, 0.0);
        let mut p = Perception::new(1);
        let first = p.look(&w, &r, &exact(), &mut rng);
        assert_eq!(first.lps[lps::BALL].reliability, 1.0);
        w.place_robot(6, Pose2::new(-1.5, 0.05, 0.0)); // in the line of sight
        let hidden = p.look(&w, &r, &exact(), &mut rng);
        assert!((hidden.lps[lps::BALL].reliability - DECAY).abs() < 1e-12);
        assert!((hidden.lps[lps::BALL].rho - 3000.0).abs() < 1e-6, "last estimate kept");
    }

    #[test]
    fn a_narrow_field_of_view_and_range_limit_what_is_seen() {
        let (mut w, r) = setup();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let cfg = SensorConfig { half_fov: 0.5, range: 5.0, landmark_range: 5.0, ..exact() };
        w.place_robot(1, Pose2::new(-5.0, 0.0, std::f64::consts::PI)); // facing west
        w.place_ball(-1.0, 0.0);
        let s = Perception::new(1).look(&w, &r, &cfg, &mut rng);
        assert_eq!(s.lps[lps::BALL].reliability, 0.0, "4 m behind the robot");
        assert_eq!(s.lps[lps::NET2].reliability, 1.0, "own net 4 m ahead");
        assert_eq!(s.lps[lps::NET1].reliability, 0.0, "opponent's net 14 m behind");
        assert_eq!(
            s.lps[lps::LANDMARK0 + 2].reliability,
            0.0,
            "corner (-9, 6): 7.2 m, out of range"
        );
    }

    #[test]
    fn teammates_and_their_better_ball_sightings_merge_into_the_world_state() {
        let mut w = WorldSnapshot {
            global_ball: Estimate { pose: Pose2::new(100.0, 0.0, 0.0), quality: 0.5 },
            ..Default::default()
        };
        let report = |id, q, x| MateReport {
            id,
            keeper: id == 0,
            pose: Estimate { pose: Pose2::new(-1000.0 * f64::from(id), 0.0, 0.0), quality: 0.9 },
            ball: Estimate { pose: Pose2::new(x, 50.0, 0.0), quality: q },
        };
        // 0.9 × 0.5 = 0.45 < 0.5: one's own sighting stays; 0.9 × 0.8 = 0.72 wins.
        let reports = [report(0, 0.5, 200.0), report(2, 0.8, 300.0), report(3, 0.7, 400.0)];
        merge_team(&mut w, &reports);
        assert_eq!(
            w.mates.iter().map(|m| (m.id, m.keeper)).collect::<Vec<_>>(),
            [(0, true), (2, false), (3, false)]
        );
        assert_eq!(w.mates[1].at.pose.x, -2000.0);
        assert!((w.global_ball.quality - 0.72).abs() < 1e-12, "{:?}", w.global_ball);
        assert_eq!((w.global_ball.pose.x, w.global_ball.pose.y), (300.0, 50.0));
        // A robot that sees the ball well keeps its own estimate.
        let mut sharp = WorldSnapshot {
            global_ball: Estimate { quality: 1.0, ..Default::default() },
            ..Default::default()
        };
        merge_team(&mut sharp, &reports);
        assert_eq!(sharp.global_ball.quality, 1.0);
        // The report carries the robot's own sighting, not the merged one.
        let r = MateReport::of(7, false, &w);
        assert_eq!((r.id, r.ball.quality), (7, w.global_ball.quality));
    }

    #[test]
    fn noise_is_seeded_and_proportional_to_distance() {
        let (mut w, r) = setup();
        // Off the kickoff lanes (y = 0, ±3), so nobody stands in the line of sight.
        w.place_robot(1, Pose2::new(-6.0, 1.5, 0.0));
        w.place_ball(0.0, 1.5);
        let cfg = SensorConfig { miss_probability: 0.0, ..Default::default() };
        let sample = |seed| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            (0..400)
                .map(|_| Perception::new(1).look(&w, &r, &cfg, &mut rng).lps[lps::BALL].rho)
                .collect::<Vec<_>>()
        };
        assert_eq!(sample(7), sample(7), "same seed, same noise");
        let v = sample(8);
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt();
        // 3 % of 6 m = 180 mm.
        assert!((mean - 6000.0).abs() < 40.0 && (sd - 180.0).abs() < 30.0, "{mean} ± {sd}");
    }
}
