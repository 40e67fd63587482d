//! The object sensor: what a robot's camera would detect, as distance and bearing with
//! range-dependent noise, a field of view, occlusion by other robots and random misses. It is
//! the fast stand-in for rendered images and the robots' colour vision (`[sensor] percepts =
//! "oracle"`).
//!
//! The odometry sensors ([`Odometer`]) are two optical mice (MRT manual ch. 4) and the wheel
//! encoders. Both drivers report raw readings ([`CameraFrame`], [`Odometry`]); the robot's
//! world-state Member turns them into its world snapshot (`mrt-world`).
//!

use crate::config::{OdometryConfig, SensorConfig, SonarConfig};
use crate::referee::Referee;
use crate::world::World;
use mrt_core::frames::{Field, Framed};
use mrt_core::Twist;
use mrt_core::{normalize_angle, Pose2};
use mrt_msgs::{sighting, MiceReadings};
use mrt_perception::mice::MiceOdometry;
use mrt_plan::guidance::Sonar;
use mrt_robot::base::Base;
use rand::{Rng, RngCore};

/// The robots' bodies as the odometry and sonar drivers read them: the soccer [`World`] and
/// the indoor world (`indoor::IndoorWorld`, which imports this module).
pub trait Bodies {
    /// Robot `i`'s pose, `None` when there is no such robot.
    fn robot(&self, i: usize) -> Option<Pose2>;
    /// How often robot `i` was put down by hand, and where last.
    fn placement(&self, i: usize) -> (u32, Pose2);
    /// How often robot `i` was carried elsewhere without being told.
    fn carried(&self, i: usize) -> u32;
    /// Robot `i`'s velocity set-point.
    fn drive_setpoint(&self, i: usize) -> Twist;
    /// The robots' radius, m.
    fn robot_radius(&self) -> f64;
    /// Robot `i`'s sonar ring: each sonar's distance from the robot's edge ([`World::sonar`]).
    fn sonar(&self, i: usize, count: usize, half_beam: f64, range: f64) -> Vec<f64>;
}

impl Bodies for World {
    fn robot(&self, i: usize) -> Option<Pose2> {
        World::robot(self, i)
    }
    fn placement(&self, i: usize) -> (u32, Pose2) {
        World::placement(self, i)
    }
    fn carried(&self, i: usize) -> u32 {
        World::carried(self, i)
    }
    fn drive_setpoint(&self, i: usize) -> Twist {
        World::drive_setpoint(self, i)
    }
    fn robot_radius(&self) -> f64 {
        self.config().body.radius
    }
    fn sonar(&self, i: usize, count: usize, half_beam: f64, range: f64) -> Vec<f64> {
        World::sonar(self, i, count, half_beam, range)
    }
}

/// What robot `i`'s sonar ring hears (robot frame, m from the centre, ring order; no echo is
/// an infinite range): [`World::sonar`]'s edge distances plus the radius, with noise.
pub fn sonar_ring(
    world: &dyn Bodies,
    i: usize,
    cfg: &SonarConfig,
    rng: &mut dyn RngCore,
) -> Vec<Sonar> {
    let radius = world.robot_radius();
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

/// Standard normal sample (Box–Muller), from any RNG.
pub(crate) fn gauss(rng: &mut dyn RngCore) -> f64 {
    let u1: f64 = rng.random_range(f64::EPSILON..1.0);
    let u2: f64 = rng.random_range(0.0..1.0);
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// Field positions (m) of the objects the camera knows, in [`FIELD_OBJECTS`] order: the ball,
/// then the field map's nets and landmarks ([`mrt_world::field`]). The camera tells them apart
/// by colour, not by team: the world model maps them onto the team's LPS slots.
fn targets(world: &World) -> [(f64, f64); FIELD_OBJECTS] {
    let map = world.config().field;
    let mut at = [world.ball(); FIELD_OBJECTS];
    for (k, slot) in at.iter_mut().enumerate().skip(1) {
        if let Some(p) = map.object(k) {
            *slot = (p.x, p.y);
        }
    }
    at
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
    t > 0.0 && t < 1.0 && (px - c.0).powi(2) + (py - c.1).powi(2) < radius * radius
}

pub use mrt_msgs::{CameraFrame, GameInfo, Marker, RobotSighting, Sighting, FIELD_OBJECTS};

/// What the game controller tells robot `robot` now: the referee's state, the direction its
/// team attacks, its place in the kickoff formation.
pub fn game_info(referee: &Referee, robot: usize) -> GameInfo {
    GameInfo {
        state: referee.state(),
        attack: referee.attack_direction(referee.team_of(robot)),
        kickoff_pose: referee.kickoff_pose(robot).map(Framed::new),
        marker: Some(referee.team_of(robot).marker()),
    }
}

/// What the camera of robot `robot`, its pan joint at `pan` (rad), sees now (the object
/// sensor): every object within its range and field of view, not hidden behind another robot
/// (the ball, the other robots) and not missed, as distance and bearing (robot frame) with
/// range-dependent noise; the other robots at their nearest point, with the marker colour
/// `marker_of` gives each (within the ball's range the band round a robot's top is always
/// seen: the object sensor does not model a marker out of view).
pub fn look(
    world: &World,
    robot: usize,
    pan: f64,
    cfg: &SensorConfig,
    marker_of: impl Fn(usize) -> Marker,
    rng: &mut dyn RngCore,
) -> CameraFrame {
    let me = world.robot(robot).unwrap_or_default();
    let r_robot = world.config().body.radius;
    let robots: Vec<(usize, (f64, f64))> = (0..world.robot_count())
        .filter(|&i| i != robot)
        .filter_map(|i| world.robot(i).map(|p| (i, (p.x, p.y))))
        .collect();
    let mut frame = CameraFrame { time: world.time(), ..Default::default() };
    let noise = &world.config().sensors;
    let noisy = |dist: f64, bearing: f64, rng: &mut dyn RngCore| Sighting {
        distance: (dist * (1.0 + noise.camera_distance_noise * gauss(rng))).max(0.0),
        bearing: normalize_angle(bearing + noise.camera_bearing_noise * gauss(rng)),
    };
    let in_view = |bearing: f64| normalize_angle(bearing - pan).abs() <= cfg.half_fov;
    let miss = cfg.miss_probability.clamp(0.0, 1.0);
    for (k, target) in targets(world).into_iter().enumerate() {
        // The truth, in the robot's frame: what a perfect camera would measure.
        let (dist, bearing) = Framed::<Field, _>::new(me)
            .range_bearing(Framed::new(mrt_core::Point2::new(target.0, target.1)));
        let occluded = k == sighting::BALL
            && robots.iter().any(|&(_, c)| blocks((me.x, me.y), target, c, r_robot));
        let range = if k == sighting::BALL { cfg.range } else { cfg.landmark_range };
        let visible = dist <= range && in_view(bearing) && !occluded;
        let missed = rng.random_bool(miss);
        if visible && !missed {
            frame.sightings[k] = Some(noisy(dist, bearing, rng));
        }
    }
    // The other robots, after the fixed objects (whose random draws stay where they were).
    for &(i, c) in &robots {
        let (dist, bearing) =
            Framed::<Field, _>::new(me).range_bearing(Framed::new(mrt_core::Point2::new(c.0, c.1)));
        let occluded =
            robots.iter().any(|&(j, other)| j != i && blocks((me.x, me.y), c, other, r_robot));
        let visible = dist <= cfg.range && in_view(bearing) && !occluded;
        let missed = rng.random_bool(miss);
        if visible && !missed {
            frame.robots.push(RobotSighting {
                sighting: noisy((dist - r_robot).max(0.0), bearing, rng),
                sigma: None,
                marker: Some(marker_of(i)),
            });
        }
    }
    // No velocity: a camera does not measure one (the world model tracks the ball).
    frame
}

pub use mrt_msgs::Odometry;

/// What a simulated mouse gets wrong in one reading `(x, y)` (any unit: the errors are
/// relative): with probability `mice_miss_probability` it under-reads, 50–100 % of the motion
/// in the true direction (MRT manual §4.2), then each axis is off by `mice_noise` times the
/// motion's length (Gaussian).
pub fn mouse_errors(x: &mut f64, y: &mut f64, cfg: &OdometryConfig, rng: &mut dyn RngCore) {
    let length = x.hypot(*y);
    if rng.random_bool(cfg.mice_miss_probability.clamp(0.0, 1.0)) {
        let read = rng.random_range(0.5..1.0);
        *x *= read;
        *y *= read;
    }
    *x += cfg.mice_noise * length * gauss(rng);
    *y += cfg.mice_noise * length * gauss(rng);
}

/// The odometry driver of one simulated robot: mice and wheels since its last reading.
#[derive(Clone, Debug)]
pub struct Odometer {
    robot: usize,
    mice: MiceOdometry,
    base: Base,
    last: Option<Pose2>,
    placements: u32,
    carries: u32,
}

/// What a robot's mice and wheel encoders counted since the last reading, as the devices
/// count it: the mice's motion in their own frames (m), each wheel's turn (rad, in wheel
/// order), and where the robot was put down meanwhile.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Counts {
    /// The two optical mice, each in its own frame (MRT manual ch. 4), m.
    pub mice: MiceReadings,
    /// Each wheel's turn, rad, in the base's wheel order.
    pub wheel_turns: Vec<f64>,
    /// Put down by hand at this pose (field frame, m) since the last reading.
    pub placed: Option<Framed<Field, Pose2>>,
}

impl Odometer {
    /// The driver of robot `robot`'s mice (`mice`: their geometry) and the wheels of its
    /// `base`.
    pub fn new(robot: usize, mice: MiceOdometry, base: Base) -> Odometer {
        Odometer { robot, mice, base, last: None, placements: 0, carries: 0 }
    }

    /// Reads the sensors as [`Odometer::count`] does and gives the wheels' motion as the
    /// robot's encoder driver would: the arc their turns drive ([`Base::motion`]).
    pub fn read(
        &mut self,
        world: &dyn Bodies,
        cfg: &OdometryConfig,
        period: f64,
        rng: &mut dyn RngCore,
    ) -> Odometry {
        let counts = self.count(world, cfg, period, rng);
        self.odometry(counts)
    }

    /// The reading of `counts` as the robot's drivers give it: the wheels' turns as the arc
    /// they drive.
    pub fn odometry(&self, counts: Counts) -> Odometry {
        let wheels = self.base.motion(&counts.wheel_turns).unwrap_or_default();
        Odometry { mice: counts.mice, wheels, placed: counts.placed }
    }

    /// Reads the sensors: the mice see the body's true motion since the last reading (as the
    /// manual's forward model gives it, §4.1), with noise and occasional under-reading (§4.2);
    /// each wheel turns at the speed the body's velocity set-point asks of it over `period`
    /// (they slip when the body is blocked), each with a noise of its own.
    pub fn count(
        &mut self,
        world: &dyn Bodies,
        cfg: &OdometryConfig,
        period: f64,
        rng: &mut dyn RngCore,
    ) -> Counts {
        let now = world.robot(self.robot).unwrap_or_default();
        let (count, at) = world.placement(self.robot);
        let mut placed = None;
        let carries = world.carried(self.robot);
        let from = if count != self.placements {
            self.placements = count;
            placed = Some(Framed::new(at));
            at
        } else if carries != self.carries {
            // Lifted and carried: the mice, off the floor, felt nothing.
            self.carries = carries;
            now
        } else {
            self.last.unwrap_or(now)
        };
        self.last = Some(now);
        let d = now.relative_to(&from);
        let mut mice = self.mice.readings_for(d.x, d.y, normalize_angle(d.theta));
        mouse_errors(&mut mice.x_left, &mut mice.y_left, cfg, rng);
        mouse_errors(&mut mice.x_right, &mut mice.y_right, cfg, rng);
        let twist = world.drive_setpoint(self.robot);
        let wheel_turns = self
            .base
            .wheels_for(&twist)
            .into_iter()
            .map(|w| w * period * (1.0 + cfg.wheel_noise * gauss(rng)))
            .collect();
        Counts { mice, wheel_turns, placed }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::SimConfig;
    use mrt_core::frames::millimetres;
    use mrt_msgs::GameState;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn exact() -> SensorConfig {
        SensorConfig { miss_probability: 0.0, ..Default::default() }
    }

    /// The default world, its cameras without noise.
    fn setup() -> (World, Referee) {
        let mut cfg = SimConfig::default();
        (cfg.sensors.camera_distance_noise, cfg.sensors.camera_bearing_noise) = (0.0, 0.0);
        setup_with(&cfg)
    }

    fn setup_with(cfg: &SimConfig) -> (World, Referee) {
        let mut w = World::new(cfg, 8);
        let mut r = Referee::new(4);
        r.start(&mut w);
        (w, r)
    }

    use mrt_msgs::sighting::{EAST_NET, NW_CORNER, WEST_NET};

    #[test]
    fn distance_and_bearing_of_what_the_camera_sees() {
        let (mut w, r) = setup();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        // Robot 1 at (-2, 0) facing north; ball at (0, 2): 2.828 m away, 45° to the right of
        // the heading (bearing -π/4).
        w.place_robot(1, Pose2::new(-2.0, 0.0, std::f64::consts::FRAC_PI_2));
        w.place_ball(0.0, 2.0);
        let f = look(&w, 1, 0.0, &exact(), |_| Marker::Cyan, &mut rng);
        let ball = f.sightings[sighting::BALL].unwrap();
        assert!((ball.distance - 2.828427).abs() < 1e-5, "{ball:?}");
        assert!((ball.bearing + std::f64::consts::FRAC_PI_4).abs() < 1e-6, "{ball:?}"); // f32
                                                                                        // The west net (-9, 0) is 7 m away on the left (bearing +π/2); the east net is 11 m
                                                                                        // away: beyond the ball's 9 m range, within the landmarks' 20 m.
        let net = f.sightings[WEST_NET].unwrap();
        assert!(
            (net.distance - 7.0).abs() < 1e-5
                && (net.bearing - std::f64::consts::FRAC_PI_2).abs() < 1e-6
        );
        assert!((f.sightings[EAST_NET].unwrap().distance - 11.0).abs() < 1e-5);
        let short = SensorConfig { landmark_range: 9.0, ..exact() };
        let f2 = look(&w, 1, 0.0, &short, |_| Marker::Cyan, &mut rng);
        assert_eq!(f2.sightings[EAST_NET], None, "11 m: beyond a 9 m landmark range");
        // The game controller's news: home attacks east in the first half, away west.
        let g = game_info(&r, 1);
        assert_eq!((g.attack, g.state), (1.0, GameState::Ready));
        assert_eq!(game_info(&r, 5).attack, -1.0);
        assert_eq!(g.kickoff_pose.map(|p| p.inner), r.kickoff_pose(1));
        assert_eq!(f.time, w.time());
        assert!(f.sightings[sighting::BALL].is_some());
    }

    #[test]
    fn a_robot_in_between_hides_the_ball() {
        let (mut w, _) = setup();
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        w.place_robot(1, Pose2::new(-3.0, 0.0, 0.0));
        w.place_ball(0.0, 0.0);
        assert!(look(&w, 1, 0.0, &exact(), |_| Marker::Cyan, &mut rng).sightings[sighting::BALL]
            .is_some());
        w.place_robot(6, Pose2::new(-1.5, 0.05, 0.0)); // in the line of sight
        let hidden = look(&w, 1, 0.0, &exact(), |_| Marker::Cyan, &mut rng);
        assert_eq!(hidden.sightings[sighting::BALL], None);
        assert!(hidden.sightings[WEST_NET].is_some(), "landmarks stand above the robots");
    }

    #[test]
    fn a_narrow_field_of_view_and_range_limit_what_is_seen() {
        let (mut w, _) = setup();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let cfg = SensorConfig { half_fov: 0.5, range: 5.0, landmark_range: 5.0, ..exact() };
        w.place_robot(1, Pose2::new(-5.0, 0.0, std::f64::consts::PI)); // facing west
        w.place_ball(-1.0, 0.0);
        let f = look(&w, 1, 0.0, &cfg, |_| Marker::Cyan, &mut rng);
        assert_eq!(f.sightings[sighting::BALL], None, "4 m behind the robot");
        assert!(f.sightings[WEST_NET].is_some(), "west net 4 m ahead");
        assert_eq!(f.sightings[EAST_NET], None, "east net 14 m behind");
        assert_eq!(f.sightings[NW_CORNER], None, "corner (-9, 6): 7.2 m, out of range");
        // The pan joint turned half round: the camera looks east, at the ball, and the
        // bearing stays in the robot's frame.
        let turned = look(&w, 1, std::f64::consts::PI, &cfg, |_| Marker::Cyan, &mut rng);
        let ball = turned.sightings[sighting::BALL].expect("the ball is in view");
        assert!((ball.bearing.abs() - std::f64::consts::PI).abs() < 1e-6, "{ball:?}");
        assert_eq!(turned.sightings[WEST_NET], None, "now behind the camera");
    }

    #[test]
    fn the_mice_read_the_body_motion_and_the_wheels_the_set_point() {
        let (mut w, _) = setup();
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let exact =
            OdometryConfig { mice_noise: 0.0, mice_miss_probability: 0.0, wheel_noise: 0.0 };
        let mice = SimConfig::default().robot().unwrap().mice;
        let mut odo = Odometer::new(2, mice, Base::parse("omni").unwrap());
        // The first reading tells where the robot was put down (start of the match).
        let first = odo.read(&w, &exact, 0.1, &mut rng);
        let placed = w.placement(2).1;
        assert_eq!(first.placed.map(|p| p.inner), Some(placed));
        let d = mice.displacement(&first.mice).unwrap();
        assert!(d.dx.hypot(d.dy) < 1e-6 && d.dtheta.abs() < 1e-6, "f32 physics: {d:?}");
        // Twist forward, sideways and turning for 0.3 s: the mice invert to the body's true
        // motion (manual §4.1; they read it whole, as one arc), the wheels to the set-point.
        let start = Pose2::new(0.0, 0.0, 0.3);
        w.place_robot(2, start);
        odo.read(&w, &exact, 0.1, &mut rng);
        let drive = Twist { vx: 0.8, vy: 0.3, omega: 1.0 };
        w.drive(2, drive);
        for _ in 0..30 {
            w.step();
        }
        let o = odo.read(&w, &exact, 0.1, &mut rng);
        assert_eq!(o.placed, None);
        let truth = w.robot(2).unwrap().relative_to(&start);
        let d = mice.displacement(&o.mice).unwrap();
        assert!((d.dx - truth.x).abs() < 1e-6 && (d.dy - truth.y).abs() < 1e-6, "{d:?} {truth:?}");
        assert!((d.dtheta - truth.theta).abs() < 1e-6, "{d:?} {truth:?}");
        assert!(d.dx > 0.05 && d.dtheta > 0.1, "it moved (accelerating from rest): {d:?}");
        // Wheels: 0.1 s of the set-point along an arc: 1 rad/s for 0.1 s is 0.1 rad.
        assert!((o.wheels.dtheta - 0.1).abs() < 1e-12, "{:?}", o.wheels);
        assert!((o.wheels.dx - 0.08).abs() < 0.005 && (o.wheels.dy - 0.03).abs() < 0.005);
        // A robot put down again: the reading counts from where it was put.
        let there = Pose2::new(3.0, -1.0, -2.0);
        w.place_robot(2, there);
        let again = odo.read(&w, &exact, 0.1, &mut rng);
        assert_eq!(again.placed.map(|p| p.inner), Some(there));
        assert!(mice.displacement(&again.mice).unwrap().dx.abs() < 1e-6);
    }

    #[test]
    fn a_mouse_sometimes_under_reads_and_noise_is_proportional() {
        let (mut w, _) = setup();
        let cfg = OdometryConfig { mice_miss_probability: 0.5, ..Default::default() };
        let mice = SimConfig::default().robot().unwrap().mice;
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut odo = Odometer::new(1, mice, Base::parse("omni").unwrap());
        w.place_robot(1, Pose2::new(0.0, 0.0, 0.0));
        odo.read(&w, &cfg, 0.1, &mut rng);
        let (mut short, mut total) = (0, 0);
        for _ in 0..200 {
            w.drive(1, Twist { vx: 0.5, vy: 0.5, omega: 0.0 });
            for _ in 0..10 {
                w.step();
            }
            let o = odo.read(&w, &cfg, 0.1, &mut rng);
            // One mouse under-read when their lengths differ by more than the noise (0.5 %).
            let (l, r) = (o.mice.x_left.hypot(o.mice.y_left), o.mice.x_right.hypot(o.mice.y_right));
            total += 1;
            if (l - r).abs() > 0.04 * l.max(r) {
                short += 1;
            }
            if w.robot(1).unwrap().x.abs() > 4.0 || w.robot(1).unwrap().y.abs() > 4.0 {
                w.place_robot(1, Pose2::new(0.0, 0.0, 0.0));
                odo.read(&w, &cfg, 0.1, &mut rng);
            }
        }
        // P(at least one of two mice misses) = 1 − 0.5² = 0.75; a miss shorter than 4 % is
        // not counted (P = 0.08 of a miss): ≈ 0.75 − 0.06 = 0.69.
        let rate = f64::from(short) / f64::from(total);
        assert!((0.55..0.8).contains(&rate), "{rate}");
    }

    #[test]
    fn noise_is_seeded_and_proportional_to_distance() {
        let (mut w, _) = setup_with(&SimConfig::default());
        // Off the kickoff lanes (y = 0, ±3), so nobody stands in the line of sight.
        w.place_robot(1, Pose2::new(-6.0, 1.5, 0.0));
        w.place_ball(0.0, 1.5);
        let cfg = SensorConfig { miss_probability: 0.0, ..Default::default() };
        let sample = |seed| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            (0..400)
                .filter_map(|_| {
                    look(&w, 1, 0.0, &cfg, |_| Marker::Cyan, &mut rng).sightings[sighting::BALL]
                })
                .map(|s| millimetres(s.distance))
                .collect::<Vec<_>>()
        };
        assert_eq!(sample(7), sample(7), "same seed, same noise");
        let v = sample(8);
        assert_eq!(v.len(), 400, "no misses configured");
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt();
        // 3 % of 6 m = 180 mm.
        assert!((mean - 6000.0).abs() < 40.0 && (sd - 180.0).abs() < 30.0, "{mean} ± {sd}");
    }
}
