//! The two-mice calibration rig (MRT manual §4.2; `mrt sim --calibrate-mice`): one simulated
//! robot is driven through the manual's procedure, ten straight runs of 500 mm and five
//! counter-clockwise turns in place of 360°, its two mice (mounted anywhere, see
//! [`default_mounting`]) counting what they feel with the simulator's mouse errors
//! ([`crate::sensor::mouse_errors`]: noise and under-reading, per control period). Their
//! counts make a calibration log ([`CalibrationLog`]), which
//! [`mrt_perception::mice_calibration`] turns into the estimated mounting.
//!
//! The rig is a test bench: it stops each run where the truth says the robot has gone 500 mm
//! or turned 360° (the tape measure of a real calibration), and its report compares the
//! estimates with the simulated mounting. The estimation itself sees only the counts.
//!
//! The simulated mice under-read with probability `p = mice_miss_probability` per reading, by
//! 0–50 % (uniform): on average they count `1 − p/4` of the motion. That is a property of the
//! floor, which calibration is there to absorb (manual §4.2: "the resolution of the mouse,
//! which depends from the surface"): the resolution to expect is the mounting's times
//! `1 − p/4` ([`RigReport::expected_resolution`]); positions and angles are unaffected (the
//! loss divides out).

use crate::config::SimConfig;
use crate::error::SimError;
use crate::sensor::mouse_errors;
use crate::world::World;
use mrt_core::Twist;
use mrt_core::{normalize_angle, Pose2};
use mrt_perception::mice_calibration::log::CalibrationLog;
use mrt_perception::mice_calibration::{
    MiceCalibration, MiceMounting, Mouse, MouseMounting, Procedure, Run, RunKind, CPI,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// The mounting the rig simulates unless told otherwise: IANUS3-like, the mice on opposite
/// corners of the body's diagonal (manual §12.7), neither parallel to the robot's axis nor to
/// each other, counting at different resolutions: the left one at (90, 110) mm turned by +20°
/// at 400 cpi, the right one at (−70, −120) mm turned by −35° at 380 cpi.
pub fn default_mounting() -> MiceMounting {
    MiceMounting {
        left: MouseMounting {
            x: 0.09,
            y: 0.11,
            sigma: 20f64.to_radians(),
            resolution: 400.0 * CPI,
        },
        right: MouseMounting {
            x: -0.07,
            y: -0.12,
            sigma: (-35f64).to_radians(),
            resolution: 380.0 * CPI,
        },
    }
}

/// How close the rig's estimates must come to the simulated mounting (`docs/mice.md` justifies
/// the defaults from the simulated noise).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Resolution, relative to [`RigReport::expected_resolution`].
    pub resolution: f64,
    /// Each mouse's orientation `σ` and the pair's `δ`, rad.
    pub angle: f64,
    /// Each mouse's position (each coordinate), m.
    pub position: f64,
    /// `D`, m.
    pub distance: f64,
}

impl Default for Tolerances {
    /// Resolution 1 %, angles 0.5°, positions 2 mm, `D` 3 mm.
    fn default() -> Self {
        Tolerances {
            resolution: 0.01,
            angle: 0.5f64.to_radians(),
            position: 0.002,
            distance: 0.003,
        }
    }
}

/// What the rig did and found.
#[derive(Clone, Debug)]
pub struct RigReport {
    /// The simulated mounting.
    pub truth: MiceMounting,
    /// The procedure followed.
    pub procedure: Procedure,
    /// The counts of every run.
    pub log: CalibrationLog,
    /// What the calibration made of them.
    pub calibration: MiceCalibration,
    /// The simulated mice's mean fraction of the motion they count (`1 − p/4`, module doc).
    pub read_fraction: f64,
    /// Simulated seconds the procedure took.
    pub seconds: f64,
    /// Dead reckoning on a test drive after the calibration, through the estimated mounting
    /// and through the simulated one.
    pub validation: Validation,
}

/// The calibration put to use: after the procedure the robot drives a test path (arcs left
/// and right, a straight, a turn in place) and its mice's counts, with their errors, are
/// integrated into a pose ([`MiceMounting::displacement`]) through the estimated mounting and,
/// for reference, through the simulated one (the best any calibration can do with those
/// mice).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Validation {
    /// Length of the path the robot drove, m.
    pub path: f64,
    /// Distance from the true end of the path to where the calibrated odometry puts it, m.
    pub error_calibrated: f64,
    /// The same through the simulated mounting, m.
    pub error_true_mounting: f64,
    /// Heading error at the end through the calibrated mounting, rad.
    pub heading_error_calibrated: f64,
    /// The same through the simulated mounting, rad.
    pub heading_error_true_mounting: f64,
    /// Distance error through the calibrated mounting with the §4.2 error reduction
    /// ([`MiceMounting::reduce`]; a reading it cannot repair is used as it is), m.
    pub error_reduced: f64,
    /// Its heading error, rad.
    pub heading_error_reduced: f64,
}

impl RigReport {
    /// The resolution the calibration should find for a mouse: its mounting's, times the
    /// simulated mice's mean read fraction (module doc), counts per metre.
    pub fn expected_resolution(&self, which: Mouse) -> f64 {
        self.truth.mouse(which).resolution * self.read_fraction
    }

    /// `Ok` when every estimate is within `tol` of the simulated mounting, else the list of
    /// those that are not.
    pub fn check(&self, tol: &Tolerances) -> Result<(), Vec<String>> {
        let mut bad = Vec::new();
        let c = &self.calibration;
        for (which, e) in [(Mouse::Left, &c.left), (Mouse::Right, &c.right)] {
            let t = self.truth.mouse(which);
            let k = self.expected_resolution(which);
            let name = which.name();
            if (e.resolution.value / k - 1.0).abs() > tol.resolution {
                bad.push(format!("{name} resolution {} vs {k}", e.resolution.value));
            }
            if normalize_angle(e.sigma.value - t.sigma).abs() > tol.angle {
                bad.push(format!("{name} σ {} vs {}", e.sigma.value, t.sigma));
            }
            if (e.x.value - t.x).abs() > tol.position || (e.y.value - t.y).abs() > tol.position {
                bad.push(format!(
                    "{name} position ({}, {}) vs ({}, {})",
                    e.x.value, e.y.value, t.x, t.y
                ));
            }
        }
        if (c.distance.value - self.truth.distance()).abs() > tol.distance {
            bad.push(format!("D {} vs {}", c.distance.value, self.truth.distance()));
        }
        if normalize_angle(c.delta.value - self.truth.delta()).abs() > tol.angle {
            bad.push(format!("δ {} vs {}", c.delta.value, self.truth.delta()));
        }
        if bad.is_empty() {
            Ok(())
        } else {
            Err(bad)
        }
    }
}

/// Top speed and turning rate of the rig's runs (m/s, rad/s), and the gain of its stopping
/// (1/s): a careful push.
const SPEED: f64 = 0.2;
const TURN_RATE: f64 = 1.0;
const GAIN: f64 = 4.0;
/// A run ends when the robot is this close to its goal (m or rad) and at rest: 0.02 % of a
/// straight run (the physics keeps positions in `f32`, 0.1 µm near the rig's start).
const ARRIVED: f64 = 1e-4;
/// The longest a run may take, simulated seconds.
const RUN_LIMIT: f64 = 60.0;

/// One robot on the field of `cfg`, driven through the manual's procedure (10 straight runs,
/// 5 turns) with mice mounted as `truth`, the randomness of their errors from `seed`.
pub fn run(cfg: &SimConfig, truth: &MiceMounting, seed: u64) -> Result<RigReport, SimError> {
    let procedure = Procedure::default();
    let mut world = World::new(cfg, 1);
    // Out of the ball's way, with room for the runs, near the origin where `f32` is finest.
    let start =
        Pose2::new(-(0.25 * cfg.field.length).min(1.5), (0.25 * cfg.field.width).min(1.5), 0.0);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut log = CalibrationLog::default();
    for kind in [RunKind::Straight, RunKind::Turn] {
        let (n, goal) = match kind {
            RunKind::Straight => (Procedure::MANUAL_STRAIGHT_RUNS, procedure.length),
            RunKind::Turn => (Procedure::MANUAL_TURNS, procedure.turn),
        };
        for i in 0..n {
            let r = drive(&mut world, start, kind, goal, truth, &mut rng)
                .map_err(|e| SimError::Match(format!("{} run {}: {e}", kind.name(), i + 1)))?;
            match kind {
                RunKind::Straight => log.straight.push(r),
                RunKind::Turn => log.turns.push(r),
            }
        }
    }
    let calibration = log.calibrate(&procedure)?;
    let validation = validate(&mut world, start, truth, &calibration.mounting(), &mut rng)?;
    let p = cfg.odometry.mice_miss_probability.clamp(0.0, 1.0);
    Ok(RigReport {
        truth: *truth,
        procedure,
        log,
        calibration,
        read_fraction: 1.0 - 0.25 * p,
        seconds: world.time(),
        validation,
    })
}

/// The test drive of [`Validation`]: set-points held for a while each, the mice read every
/// control period.
fn validate(
    world: &mut World,
    start: Pose2,
    truth: &MiceMounting,
    estimate: &MiceMounting,
    rng: &mut ChaCha8Rng,
) -> Result<Validation, SimError> {
    let cfg = world.config().clone();
    let per_read = (cfg.rules.control_period / cfg.rules.physics_step).round().max(1.0) as u64;
    // (forward m/s, turn rad/s, seconds): left and right arcs, a straight, a turn, to rest.
    let legs =
        [(0.3, 0.6, 2.5), (0.3, -0.6, 2.5), (0.2, 0.0, 2.0), (0.0, 1.0, 2.0), (0.0, 0.0, 1.0)];
    world.place_robot(0, start);
    let (mut last, mut path) = (start, 0.0);
    let (mut cal, mut ideal, mut reduced) = (Pose2::default(), Pose2::default(), Pose2::default());
    for (forward, turn, seconds) in legs {
        world.drive(0, Twist { vx: forward, vy: 0.0, omega: turn });
        for step in 1..=(seconds / cfg.rules.physics_step).round() as u64 {
            world.step();
            if step % per_read != 0 {
                continue;
            }
            let now = world.robot(0).ok_or_else(|| SimError::Match("the robot is gone".into()))?;
            let d = now.relative_to(&last);
            path += d.x.hypot(d.y);
            last = now;
            let mut r = truth.run_for(d.x, d.y, normalize_angle(d.theta));
            for c in [&mut r.left, &mut r.right] {
                mouse_errors(&mut c.x, &mut c.y, &cfg.odometry, rng);
            }
            let step = |m: &MiceMounting, r: &Run, pose: &mut Pose2| {
                if let Some((d, _)) = m.displacement(r) {
                    *pose = pose.compose(&d.as_pose());
                }
            };
            step(estimate, &r, &mut cal);
            step(truth, &r, &mut ideal);
            // §4.2's tolerance: 0.3 mm, plus 1 % of the motion (the noise grows with it).
            let length = |m: &MouseMounting, c| {
                let (x, y) = m.to_robot(c);
                x.hypot(y)
            };
            let tol =
                3e-4 + 0.01 * (length(&estimate.left, r.left) + length(&estimate.right, r.right));
            let fixed = estimate.reduce(&r, tol).unwrap_or(r);
            step(estimate, &fixed, &mut reduced);
        }
    }
    let end = last.relative_to(&start);
    let error =
        |p: &Pose2| ((p.x - end.x).hypot(p.y - end.y), normalize_angle(p.theta - end.theta));
    let (
        (error_calibrated, heading_error_calibrated),
        (error_true_mounting, heading_error_true_mounting),
    ) = (error(&cal), error(&ideal));
    let (error_reduced, heading_error_reduced) = error(&reduced);
    Ok(Validation {
        error_reduced,
        heading_error_reduced,
        path,
        error_calibrated,
        error_true_mounting,
        heading_error_calibrated,
        heading_error_true_mounting,
    })
}

/// One run: the robot put down at `start`, driven straight ahead by `goal` metres or turned in
/// place by `goal` radians, its mice read every control period; their counts, rounded to
/// whole counts.
fn drive(
    world: &mut World,
    start: Pose2,
    kind: RunKind,
    goal: f64,
    truth: &MiceMounting,
    rng: &mut ChaCha8Rng,
) -> Result<Run, SimError> {
    let cfg = world.config().clone();
    let per_read = (cfg.rules.control_period / cfg.rules.physics_step).round().max(1.0) as u64;
    let steps = (RUN_LIMIT / cfg.rules.physics_step).ceil() as u64;
    world.place_robot(0, start);
    let (mut last_read, mut prev) = (start, start);
    let mut turned = 0.0;
    let mut total = Run::default();
    let mut read = |from: &mut Pose2, now: Pose2, total: &mut Run| {
        let d = now.relative_to(from);
        let mut r = truth.run_for(d.x, d.y, normalize_angle(d.theta));
        for (sum, c) in [(&mut total.left, &mut r.left), (&mut total.right, &mut r.right)] {
            mouse_errors(&mut c.x, &mut c.y, &cfg.odometry, rng);
            sum.x += c.x;
            sum.y += c.y;
        }
        *from = now;
    };
    for step in 1..=steps {
        let now = world.robot(0).ok_or_else(|| SimError::Match("the robot is gone".into()))?;
        turned += normalize_angle(now.theta - prev.theta);
        let moved = now.relative_to(&prev);
        let at_rest = moved.x.hypot(moved.y) < 1e-6 && moved.theta.abs() < 1e-6;
        prev = now;
        let left = match kind {
            RunKind::Straight => goal - now.relative_to(&start).x,
            RunKind::Turn => goal - turned,
        };
        if left.abs() < ARRIVED && at_rest && step > 1 {
            read(&mut last_read, now, &mut total);
            let round = |c: &mut mrt_perception::mice_calibration::Counts| {
                c.x = c.x.round();
                c.y = c.y.round();
            };
            round(&mut total.left);
            round(&mut total.right);
            return Ok(total);
        }
        let drive = match kind {
            RunKind::Straight => {
                Twist { vx: (GAIN * left).clamp(-SPEED, SPEED), vy: 0.0, omega: 0.0 }
            }
            RunKind::Turn => {
                Twist { vx: 0.0, vy: 0.0, omega: (GAIN * left).clamp(-TURN_RATE, TURN_RATE) }
            }
        };
        world.drive(0, drive);
        world.step();
        if step % per_read == 0 {
            let now = world.robot(0).ok_or_else(|| SimError::Match("the robot is gone".into()))?;
            read(&mut last_read, now, &mut total);
        }
    }
    Err(SimError::Match(format!("not done after {RUN_LIMIT} simulated seconds")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_core::frames::millimetres;

    /// The rig recovers the simulated mounting within the stated tolerances, with the
    /// simulator's default mouse errors (0.5 % noise per reading and axis, 2 % of readings
    /// short by up to half), and the truth lies within 4 standard errors of each estimate.
    #[test]
    fn the_rig_recovers_the_simulated_mounting() {
        let cfg = SimConfig::default();
        let truth = default_mounting();
        let wall = std::time::Instant::now();
        let report = run(&cfg, &truth, 1).unwrap();
        let took = wall.elapsed();
        assert_eq!(report.check(&Tolerances::default()), Ok(()), "{report:#?}");
        let c = &report.calibration;
        for (which, e) in [(Mouse::Left, &c.left), (Mouse::Right, &c.right)] {
            let t = truth.mouse(which);
            let k = report.expected_resolution(which);
            assert!((e.resolution.value - k).abs() < 4.0 * e.resolution.std_error, "{e:?} {k}");
            assert!(normalize_angle(e.sigma.value - t.sigma).abs() < 4.0 * e.sigma.std_error);
            assert!((e.x.value - t.x).abs() < 4.0 * e.x.std_error, "{e:?}");
            assert!((e.y.value - t.y).abs() < 4.0 * e.y.std_error, "{e:?}");
        }
        assert_eq!((c.straight_runs, c.turns), (10, 5));
        // Put to use on a 1.9 m drive: the calibrated dead reckoning ends within 2 % of the
        // path of the truth (the mice's misses, not corrected here, cost 0.5–1 %), no more than
        // 0.5 % of the path worse than through the simulated mounting itself.
        let v = report.validation;
        assert!(v.path > 1.5 && v.error_calibrated < 0.02 * v.path, "{v:?}");
        assert!(v.error_calibrated < v.error_true_mounting + 0.005 * v.path, "{v:?}");
        assert!(v.heading_error_calibrated.abs() < 2f64.to_radians(), "{v:?}");
        assert!(v.error_reduced < 0.01 * v.path, "{v:?}");
        assert!(report.seconds < 120.0, "{}", report.seconds);
        assert!(took.as_secs_f64() < 5.0, "{took:?}");
        // The log the rig wrote reads back to the same calibration.
        let text = report.log.to_text(&report.procedure);
        let again = CalibrationLog::parse("rig.csv", text.as_bytes()).unwrap();
        assert_eq!(again.calibrate(&report.procedure).unwrap(), *c);
    }

    /// Other seeds, other noise: still within the tolerances.
    #[test]
    fn the_tolerances_hold_for_other_seeds() {
        let (cfg, truth) = (SimConfig::default(), default_mounting());
        for seed in 2..=6 {
            let report = run(&cfg, &truth, seed).unwrap();
            assert_eq!(report.check(&Tolerances::default()), Ok(()), "seed {seed}");
        }
    }

    /// The manual's own mounting (§4.1: parallel mice 0.2 m apart across the robot, σ = 0,
    /// δ = 0) is one case among others.
    #[test]
    fn the_manual_mounting_too() {
        let truth = MiceMounting::parallel(0.2, 400.0 * CPI).unwrap();
        let report = run(&SimConfig::default(), &truth, 7).unwrap();
        assert_eq!(report.check(&Tolerances::default()), Ok(()), "{report:#?}");
        assert!(report.calibration.delta.value.abs() < 0.5f64.to_radians());
    }

    /// Noise-free mice: the estimates are as good as the rig's stopping and the counts'
    /// rounding allow (well under a tenth of the tolerances).
    #[test]
    fn exact_mice_give_the_mounting_back() {
        let mut cfg = SimConfig::default();
        cfg.odometry.mice_noise = 0.0;
        cfg.odometry.mice_miss_probability = 0.0;
        let truth = default_mounting();
        let report = run(&cfg, &truth, 2).unwrap();
        let tight = Tolerances {
            resolution: 1e-3,
            angle: 0.05f64.to_radians(),
            position: 2e-4,
            distance: 3e-4,
        };
        assert_eq!(report.check(&tight), Ok(()), "{report:#?}");
    }

    /// The accuracy of `docs/mice.md`: the worst error of each estimate over 200 seeds (run
    /// with `--ignored --nocapture`; about 20 s).
    #[test]
    #[ignore]
    fn survey_of_200_seeds() {
        let cfg = SimConfig::default();
        let truth = default_mounting();
        // Resolution (relative), σ (°), positions (mm), D (mm), δ (°).
        let mut worst = [0.0f64; 5];
        // Test drive: mean end error through the calibrated and the simulated mounting, m.
        let mut drive = [0.0f64; 3];
        for seed in 0..200 {
            let r = run(&cfg, &truth, seed).unwrap();
            drive[0] += r.validation.error_calibrated / 200.0;
            drive[1] += r.validation.error_true_mounting / 200.0;
            drive[2] += r.validation.error_reduced / 200.0;
            let c = &r.calibration;
            for (which, e) in [(Mouse::Left, &c.left), (Mouse::Right, &c.right)] {
                let t = truth.mouse(which);
                let k = (e.resolution.value / r.expected_resolution(which) - 1.0).abs();
                let sigma = normalize_angle(e.sigma.value - t.sigma).abs().to_degrees();
                let p = millimetres((e.x.value - t.x).abs().max((e.y.value - t.y).abs()));
                worst[0] = worst[0].max(k);
                worst[1] = worst[1].max(sigma);
                worst[2] = worst[2].max(p);
            }
            worst[3] = worst[3].max(millimetres((c.distance.value - truth.distance()).abs()));
            let delta = normalize_angle(c.delta.value - truth.delta()).abs().to_degrees();
            worst[4] = worst[4].max(delta);
        }
        eprintln!(
            "worst of 200 seeds: resolution {:.2} %, σ {:.3}°, position {:.2} mm, D {:.2} mm, \
             δ {:.3}°",
            100.0 * worst[0],
            worst[1],
            worst[2],
            worst[3],
            worst[4]
        );
        eprintln!(
            "test drive: mean end error {:.1} mm calibrated, {:.1} mm through the simulated \
             mounting, {:.1} mm calibrated with §4.2's reduction",
            millimetres(drive[0]),
            millimetres(drive[1]),
            millimetres(drive[2])
        );
        let tol = Tolerances::default();
        assert!(worst[0] < tol.resolution && worst[2] < millimetres(tol.position));
    }
}
