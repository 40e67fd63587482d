//! The second embedded world: a building where one robot follows a list of path points (the
//! MRT manual's Roby and FollowMe applications, §2.3), started by
//! `mrt sim --world indoor` (docs/indoor.md).
//!
//! Three files in `configs/worlds/indoor/`, embedded in the binary:
//! - `map.toml`: the building as a SPIKE map (walls, doors, furniture): what the robot knows,
//!   and what this module builds the walls from;
//! - `mission.toml`: the robot's path points ([`mrt_robot::mission::Mission`]);
//! - `world.toml`: what the map does not say ([`IndoorEvents`]): a door someone closes, a
//!   person walking to and fro.
//!
//! The world is rapier2d seen from above, like the soccer world: the walls and furniture are
//! fixed colliders, a closed door is a wall that appears at its time, a person is a moving
//! disc. The robot is driven by velocity set-points with the soccer robots' acceleration
//! limits, and reads its two mice and its sonar ring through the same drivers
//! ([`crate::sensor::Odometer`], [`crate::sensor::sonar_ring`]). Its program,
//! [`mrt_robot::mission::Roby`], sees nothing else.
//!
//! ```
//! let (map, mission, events) = mrt_sim::indoor::embedded()?;
//! assert_eq!(mission.points.len(), 4);
//! assert!(!map.doors.is_empty() && !events.door_closes.is_empty());
//! # Ok::<(), mrt_sim::SimError>(())
//! ```

use crate::config::SimConfig;
use crate::error::SimError;
use crate::sensor::{sonar_ring, Bodies, Odometer};
use crate::world::{accelerate, v, SonarRing};
use mrt_core::SimClock;
use mrt_core::Twist;
use mrt_core::{FileError, Point2, Pose2};
use mrt_dcdt::SteppedExecutor;
use mrt_msgs::{CameraFrame, GameInfo, Odometry, Sonar};
use mrt_plan::spike::{PlanMap, Shape};
use mrt_robot::base::Base;
use mrt_robot::devices::{DeviceError, Devices, SharedDevices};
use mrt_robot::members::member_faults;
use mrt_robot::mission::{add_roby, Mission, MissionEvent, Roby, RobyBody};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rapier2d::prelude::*;
use serde::Deserialize;
use std::sync::{Arc, Mutex};

/// The embedded building (`configs/worlds/indoor/map.toml`).
pub const MAP: &str = include_str!("../../../configs/worlds/indoor/map.toml");
/// The embedded mission (`configs/worlds/indoor/mission.toml`).
pub const MISSION: &str = include_str!("../../../configs/worlds/indoor/mission.toml");
/// The embedded events (`configs/worlds/indoor/world.toml`).
pub const EVENTS: &str = include_str!("../../../configs/worlds/indoor/world.toml");

/// Thickness of the simulated walls, m (the map's walls are lines).
const WALL: f64 = 0.05;

/// A door that someone closes at a time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DoorCloses {
    /// When, s.
    pub at: f64,
    /// One jamb.
    pub from: Point2,
    /// The other.
    pub to: Point2,
}

/// A person walking to and fro between two points at a steady speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Person {
    /// Their radius, m.
    pub radius: f64,
    /// Where they start.
    pub from: Point2,
    /// Where they turn round.
    pub to: Point2,
    /// m/s.
    pub speed: f64,
}

impl Person {
    /// Where they are at time `t` (s).
    pub fn at(&self, t: f64) -> Point2 {
        let length = (self.to - self.from).norm();
        if length <= 0.0 || self.speed <= 0.0 {
            return self.from;
        }
        let walked = (self.speed * t.max(0.0)) % (2.0 * length);
        let s = if walked <= length { walked } else { 2.0 * length - walked } / length;
        self.from + (self.to - self.from) * s
    }
}

/// What happens in the building that its map does not say (`world.toml`).
#[derive(Clone, Debug, PartialEq)]
pub struct IndoorEvents {
    /// The mission ends at this time at the latest, s.
    pub duration: f64,
    /// Doors that close.
    pub door_closes: Vec<DoorCloses>,
    /// People walking about.
    pub persons: Vec<Person>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EventsFile {
    duration_s: f64,
    #[serde(default)]
    door_closes: Vec<DoorFile>,
    #[serde(default)]
    person: Vec<PersonFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DoorFile {
    at_s: f64,
    from: [f64; 2],
    to: [f64; 2],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PersonFile {
    radius: f64,
    from: [f64; 2],
    to: [f64; 2],
    speed: f64,
}

impl IndoorEvents {
    /// Reads the events from the TOML `text` of `file`.
    ///
    /// # Errors
    /// [`FileError::Parse`] with line and column for malformed TOML or an unknown key;
    /// [`FileError::Invalid`] for a duration outside (0, 1 day], a number that is not finite
    /// or beyond 10 km, a negative time, a radius or speed outside (0, 100].
    pub fn from_toml(text: &str, file: &str) -> Result<IndoorEvents, FileError> {
        let parsed: EventsFile = toml::from_str(text)
            .map_err(|e| FileError::parse(file, text, e.span().map(|s| s.start), e.message()))?;
        let invalid = |message: String| FileError::Invalid { file: file.to_string(), message };
        let point = |[x, y]: [f64; 2], what: &str| {
            if x.is_finite() && y.is_finite() && x.abs() <= 1e4 && y.abs() <= 1e4 {
                Ok(Point2::new(x, y))
            } else {
                Err(invalid(format!("{what}: not finite or beyond 10 km")))
            }
        };
        if !(parsed.duration_s > 0.0 && parsed.duration_s <= 86_400.0) {
            return Err(invalid(format!("duration_s {} must be in (0, 86400]", parsed.duration_s)));
        }
        let mut door_closes = Vec::new();
        for (k, d) in parsed.door_closes.into_iter().enumerate() {
            if !(d.at_s.is_finite() && d.at_s >= 0.0) {
                return Err(invalid(format!("door_closes {}: at_s must be ≥ 0", k + 1)));
            }
            let what = format!("door_closes {}", k + 1);
            door_closes.push(DoorCloses {
                at: d.at_s,
                from: point(d.from, &what)?,
                to: point(d.to, &what)?,
            });
        }
        let mut persons = Vec::new();
        for (k, p) in parsed.person.into_iter().enumerate() {
            let ok = |v: f64| v > 0.0 && v <= 100.0;
            if !ok(p.radius) || !ok(p.speed) {
                return Err(invalid(format!(
                    "person {}: radius and speed must be in (0, 100]",
                    k + 1
                )));
            }
            let what = format!("person {}", k + 1);
            persons.push(Person {
                radius: p.radius,
                from: point(p.from, &what)?,
                to: point(p.to, &what)?,
                speed: p.speed,
            });
        }
        Ok(IndoorEvents { duration: parsed.duration_s, door_closes, persons })
    }
}

/// The embedded building, mission and events.
///
/// # Errors
/// A message naming the embedded file that does not read (a build from a broken checkout).
pub fn embedded() -> Result<(PlanMap, Mission, IndoorEvents), SimError> {
    let map = PlanMap::from_toml(MAP, "configs/worlds/indoor/map.toml")?;
    let mission = Mission::from_toml(MISSION, "configs/worlds/indoor/mission.toml")?;
    let events = IndoorEvents::from_toml(EVENTS, "configs/worlds/indoor/world.toml")?;
    Ok((map, mission, events))
}

/// The building in rapier2d with one robot (module doc).
pub struct IndoorWorld {
    physics: PhysicsWorld,
    robot: RigidBodyHandle,
    drive: Twist,
    /// The doors that close, each with the wall it becomes and whether it is closed yet.
    doors: Vec<(DoorCloses, ColliderHandle, bool)>,
    persons: Vec<(Person, RigidBodyHandle)>,
    cfg: SimConfig,
    time: f64,
}

impl IndoorWorld {
    /// The building of `map` with the `events`' doors and people, one robot of `cfg`'s size
    /// at `start`.
    pub fn new(map: &PlanMap, events: &IndoorEvents, start: Pose2, cfg: &SimConfig) -> IndoorWorld {
        let mut physics = PhysicsWorld { gravity: Vector::ZERO, ..Default::default() };
        physics.integration_parameters.dt = cfg.rules.physics_step as f32;
        let fixed = physics.insert_body(RigidBodyBuilder::fixed());
        let wall = |a: Point2, b: Point2| {
            let (mid, d) = (Point2::from((a.coords + b.coords) / 2.0), b - a);
            ColliderBuilder::cuboid((d.norm() / 2.0 + WALL / 2.0) as f32, (WALL / 2.0) as f32)
                .position(Pose::new(v(mid.x, mid.y), d.y.atan2(d.x) as f32))
                .friction(0.3)
        };
        let (lo, hi) = (map.min, map.max);
        let corners = [lo, Point2::new(hi.x, lo.y), hi, Point2::new(lo.x, hi.y)];
        for k in 0..4 {
            physics.colliders.insert_with_parent(
                wall(corners[k], corners[(k + 1) % 4]),
                fixed,
                &mut physics.bodies,
            );
        }
        for shape in &map.shapes {
            let c = match shape {
                Shape::Wall { a, b } => wall(*a, *b),
                Shape::Disc { centre, radius } => {
                    ColliderBuilder::ball(*radius as f32).translation(v(centre.x, centre.y))
                }
                Shape::Polygon(corners) => {
                    let vertices = corners.iter().map(|p| v(p.x, p.y)).collect();
                    let n = corners.len() as u32;
                    let edges = (0..n).map(|k| [k, (k + 1) % n]).collect();
                    ColliderBuilder::polyline(vertices, Some(edges))
                }
            };
            physics.colliders.insert_with_parent(c, fixed, &mut physics.bodies);
        }
        let doors = events
            .door_closes
            .iter()
            .map(|d| {
                let c = wall(d.from, d.to).enabled(false);
                (*d, physics.colliders.insert_with_parent(c, fixed, &mut physics.bodies), false)
            })
            .collect();
        let persons = events
            .persons
            .iter()
            .map(|p| {
                let at = p.at(0.0);
                let (body, _) = physics.insert(
                    RigidBodyBuilder::kinematic_position_based().translation(v(at.x, at.y)),
                    ColliderBuilder::ball(p.radius as f32),
                );
                (*p, body)
            })
            .collect();
        let r = &cfg.body;
        let area = std::f64::consts::PI * r.radius * r.radius;
        let (robot, _) = physics.insert(
            RigidBodyBuilder::dynamic().pose(Pose::new(v(start.x, start.y), start.theta as f32)),
            ColliderBuilder::ball(r.radius as f32).density((r.mass / area) as f32).friction(0.5),
        );
        IndoorWorld {
            physics,
            robot,
            drive: Twist::ZERO,
            doors,
            persons,
            cfg: cfg.clone(),
            time: 0.0,
        }
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Sets the robot's velocity set-point, within its top speeds.
    pub fn drive(&mut self, drive: Twist) {
        let r = &self.cfg.body;
        let clamp = |x: f64, m: f64| if x.is_finite() { x.clamp(-m, m) } else { 0.0 };
        self.drive = Twist::new(
            clamp(drive.vx, r.max_speed),
            clamp(drive.vy, r.max_speed),
            clamp(drive.omega, r.max_turn_rate),
        );
    }

    /// Where the people are now, with their radii.
    pub fn persons(&self) -> Vec<(Point2, f64)> {
        self.persons.iter().map(|(p, _)| (p.at(self.time), p.radius)).collect()
    }

    /// The doors closed so far, as their jambs.
    pub fn closed_doors(&self) -> Vec<(Point2, Point2)> {
        self.doors.iter().filter(|d| d.2).map(|d| (d.0.from, d.0.to)).collect()
    }

    /// One physics step: doors close when due, people walk, the robot accelerates towards
    /// its set-point, rapier moves everything.
    pub fn step(&mut self) {
        let dt = self.cfg.rules.physics_step;
        for d in &mut self.doors {
            if !d.2 && self.time >= d.0.at {
                if let Some(c) = self.physics.colliders.get_mut(d.1) {
                    c.set_enabled(true);
                }
                d.2 = true;
            }
        }
        for (p, body) in &self.persons {
            let at = p.at(self.time + dt);
            if let Some(b) = self.physics.bodies.get_mut(*body) {
                b.set_next_kinematic_translation(v(at.x, at.y));
            }
        }
        let r = &self.cfg.body;
        let (max_dv, max_dw) = (r.max_accel * dt, 4.0 * r.max_turn_rate * dt);
        if let Some(body) = self.physics.bodies.get_mut(self.robot) {
            accelerate(body, self.drive, max_dv, max_dw);
        }
        self.physics.step();
        self.time += dt;
    }
}

impl Bodies for IndoorWorld {
    fn robot(&self, i: usize) -> Option<Pose2> {
        let body = self.physics.bodies.get(self.robot).filter(|_| i == 0)?;
        let t = body.translation();
        Some(Pose2::new(f64::from(t.x), f64::from(t.y), f64::from(body.rotation().angle())))
    }
    fn placement(&self, _: usize) -> (u32, Pose2) {
        (0, Pose2::default())
    }
    fn carried(&self, _: usize) -> u32 {
        0
    }
    fn drive_setpoint(&self, _: usize) -> Twist {
        self.drive
    }
    fn robot_radius(&self) -> f64 {
        self.cfg.body.radius
    }
    fn sonar(&self, i: usize, count: usize, half_beam: f64, range: f64) -> Vec<f64> {
        let Some(pose) = Bodies::robot(self, i) else { return Vec::new() };
        let ring = SonarRing { count, half_beam, range, radius: self.cfg.body.radius };
        ring.cast(&self.physics, self.robot, pose)
    }
}

/// One moment of the mission, once a second.
#[derive(Clone, Debug, PartialEq)]
pub struct IndoorSample {
    /// Simulated time, s.
    pub time: f64,
    /// Where the robot was.
    pub truth: Pose2,
    /// Where it believed it was.
    pub belief: Pose2,
    /// The path it followed then.
    pub path: Vec<Point2>,
    /// The occupied cells it believed in.
    pub occupied: Vec<Point2>,
    /// The people, with their radii.
    pub persons: Vec<(Point2, f64)>,
}

/// What the mission did.
#[derive(Clone, Debug, PartialEq)]
pub struct IndoorReport {
    /// The seed of the sensors' noise.
    pub seed: u64,
    /// The robot's events: plans, re-plans, points reached or given up.
    pub events: Vec<MissionEvent>,
    /// Whether the robot finished its mission within the world's duration.
    pub finished: bool,
    /// Simulated time at the end, s.
    pub duration: f64,
    /// The robot's true path, one pose per control cycle.
    pub trajectory: Vec<Pose2>,
    /// Once a second: truth, belief, path, occupied cells, people.
    pub samples: Vec<IndoorSample>,
    /// The doors closed by the end.
    pub closed_doors: Vec<(Point2, Point2)>,
    /// How far the robot's belief was from the truth at the end, m.
    pub final_error: f64,
    /// The path points, in order.
    pub points: Vec<Point2>,
    /// How often the sonars corrected the robot's dead reckoning.
    pub fixes: u64,
    /// The robot program's faults: Members that failed or panicked, devices that refused.
    pub faults: Vec<String>,
}

impl IndoorReport {
    /// Points reached.
    pub fn reached(&self) -> usize {
        self.events.iter().filter(|e| matches!(e, MissionEvent::Reached { .. })).count()
    }

    /// Plans made because the way was blocked or a job timed out.
    pub fn replans(&self) -> usize {
        use mrt_robot::mission::Replan;
        let again = |e: &&MissionEvent| matches!(e, MissionEvent::Planned { why, .. } if *why != Replan::New);
        self.events.iter().filter(again).count()
    }
}

/// The building's simulation and the robot's sensors, shared by its devices.
struct Building {
    world: IndoorWorld,
    odometer: Odometer,
    rng: ChaCha8Rng,
    cfg: SimConfig,
    base: Base,
    faults: Vec<String>,
}

/// The indoor robot's [`Devices`]: its mice and wheels, its sonar ring and its motors in the
/// building; no camera, game controller or kicker.
struct IndoorDevices(Arc<Mutex<Building>>);

impl IndoorDevices {
    fn with<T>(&self, f: impl FnOnce(&mut Building) -> T) -> Result<T, DeviceError> {
        let mut b = self.0.lock().map_err(|_| DeviceError::Poisoned("building"))?;
        Ok(f(&mut b))
    }
}

impl Devices for IndoorDevices {
    fn odometry(&mut self) -> Result<Odometry, DeviceError> {
        self.with(|b| {
            let period = b.cfg.rules.control_period;
            b.odometer.read(&b.world, &b.cfg.odometry, period, &mut b.rng)
        })
    }

    fn camera(&mut self) -> Result<CameraFrame, DeviceError> {
        Err(DeviceError::Absent("camera"))
    }

    fn game(&mut self) -> Result<GameInfo, DeviceError> {
        Err(DeviceError::Absent("game controller (there is none indoors)"))
    }

    fn sonars(&mut self) -> Result<Vec<Sonar>, DeviceError> {
        self.with(|b| sonar_ring(&b.world, 0, &b.cfg.sonar, &mut b.rng))
    }

    fn set_duty(&mut self, duty: &[f64]) -> Result<(), DeviceError> {
        self.with(|b| {
            let twist = b.base.twist_for(duty).map_err(|e| DeviceError::Refused(e.to_string()))?;
            b.world.drive(twist);
            Ok(())
        })?
    }

    fn kick(&mut self) -> Result<(), DeviceError> {
        Err(DeviceError::Absent("kicker"))
    }

    fn fault(&mut self, message: &str) -> Result<(), DeviceError> {
        self.with(|b| b.faults.push(message.to_string()))
    }
}

fn lock<T>(m: &Mutex<T>) -> Result<std::sync::MutexGuard<'_, T>, SimError> {
    m.lock().map_err(|_| SimError::Poisoned("indoor world's"))
}

/// Runs `mission` in the building `map` with `events` until it ends or the events' duration
/// passes; `seed` seeds the sensors' noise; `progress` hears the simulated time now and then.
/// The robot's program runs on an Agora ([`mrt_robot::mission::add_roby`]): its drivers read
/// the building through [`Devices`], as they would a real robot's.
///
/// # Errors
/// The robot's program refuses the configuration (a robot size SPIKE cannot plan for), the
/// mice or robot configuration is invalid, or the Agora cannot be built.
pub fn run_mission(
    cfg: &SimConfig,
    seed: u64,
    (map, mission, events): (&PlanMap, &Mission, &IndoorEvents),
    mut progress: impl FnMut(f64),
) -> Result<IndoorReport, SimError> {
    let robot = cfg.robot()?;
    let mut body = RobyBody::new(robot.mice);
    body.guard = mrt_plan::guidance::VelocityGuard::new(cfg.body.radius + 0.1, 0.35)?;
    body.radius = cfg.body.radius;
    body.position.max_speed = body.position.max_speed.min(cfg.body.max_speed);
    body.position.steering = robot.base.steering();
    body.half_beam = cfg.sonar.half_beam;
    let roby = Arc::new(Mutex::new(Roby::new(map.clone(), mission.clone(), body)?));
    let building = Arc::new(Mutex::new(Building {
        world: IndoorWorld::new(map, events, mission.start, cfg),
        odometer: Odometer::new(0, robot.mice, robot.base),
        rng: ChaCha8Rng::seed_from_u64(seed),
        cfg: cfg.clone(),
        base: robot.base,
        faults: Vec::new(),
    }));
    let period = robot.period();
    let mut exec = SteppedExecutor::new(SimClock::new(), period);
    let mut agora = exec.agora_builder(1u32).build()?;
    let devices: SharedDevices = Arc::new(Mutex::new(IndoorDevices(building.clone())));
    add_roby(&mut agora, (0, period, robot.base), roby.clone(), devices)?;
    exec.add_agora(agora)?;
    let steps = (cfg.rules.control_period / cfg.rules.physics_step).round().max(1.0) as usize;
    let (mut trajectory, mut samples) = (Vec::new(), Vec::new());
    let mut next_sample = 0.0;
    loop {
        let (now, truth) = {
            let b = lock(&building)?;
            (b.world.time(), Bodies::robot(&b.world, 0).unwrap_or_default())
        };
        if now >= events.duration || lock(&roby)?.finished() {
            break;
        }
        exec.run_for(period);
        trajectory.push(truth);
        if now >= next_sample {
            next_sample += 1.0;
            let r = lock(&roby)?;
            let persons = lock(&building)?.world.persons();
            samples.push(IndoorSample {
                time: now,
                truth,
                belief: r.pose(),
                path: r.path().map(|p| p.waypoints.clone()).unwrap_or_default(),
                occupied: r.occupied(),
                persons,
            });
            progress(now);
        }
        let mut b = lock(&building)?;
        for _ in 0..steps {
            b.world.step();
        }
    }
    let reports = exec.finish();
    let b = lock(&building)?;
    let r = lock(&roby)?;
    let truth = Bodies::robot(&b.world, 0).unwrap_or_default();
    let belief = r.pose();
    let mut faults = b.faults.clone();
    for report in &reports {
        faults.extend(
            member_faults(report).iter().map(|f| format!("{} ({}×): {}", f.name, f.count, f.error)),
        );
    }
    Ok(IndoorReport {
        seed,
        events: r.events().to_vec(),
        finished: r.finished(),
        duration: b.world.time(),
        trajectory,
        samples,
        closed_doors: b.world.closed_doors(),
        final_error: (truth.x - belief.x).hypot(truth.y - belief.y),
        points: mission.points.iter().map(|p| p.at).collect(),
        fixes: r.fixes(),
        faults,
    })
}
