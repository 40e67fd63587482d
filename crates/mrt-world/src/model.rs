//! The world-state Member's model: a robot's own estimate of where it is and of what it saw,
//! from its odometry and its object sensor only (never from the simulator's truth).
//!
//! - **Pose**: an extended Kalman filter on `(x, y, θ)` in the field frame (m, rad). Each
//!   cycle it *predicts* with the odometry: the two optical mice by the manual's ch. 4
//!   equations ([`MiceOdometry::displacement`]), reduced by §4.2 when their `x̄` disagree, and
//!   the wheels when the mice cannot be trusted (the readings stay inconsistent after the
//!   reduction). It then *corrects* with every net and landmark the camera saw (distance and
//!   bearing to a known position on the field map), and with the field-line points near it
//!   (each one's distance from the line it lies on, `WorldModel::correct_lines`). A sighting
//!   that disagrees with the estimate by more than [`GATE`] (Mahalanobis distance squared, 2
//!   degrees of freedom) is rejected as an outlier; when most sightings of a frame are
//!   rejected the filter admits it is lost, widens its uncertainty and takes the same
//!   sightings again. (With the default sensors this happens a few times a match per robot,
//!   mostly after a mouse under-read while the robot drove straight: its `x̄` is then 0 on
//!   both mice, so the manual's check cannot see the error, and the heading jumps.)
//! - **LPS** (seed `001` §3, the perceptual anchors): each object keeps the field position
//!   where it was last seen, computed from the pose estimate; an object not seen in a frame
//!   keeps it, so its robot-relative position moves with the robot's own estimated motion,
//!   and its reliability decays by [`DECAY`] per cycle.
//! - **Other robots** (MAP, manual ch. 8): each robot percept, its centre a robot's radius
//!   beyond the nearest point the camera saw, is placed on the field with the pose's
//!   uncertainty and anchored ([`crate::anchor`]): classified by its marker, associated, tracked.
//! - **Snapshot**: everything in the team frame of [`WorldSnapshot`] (mm, x towards the
//!   opponent's net, whichever half the team plays in, as the game controller says).
//!
//! The pose's quality is `exp(−σ_xy / 0.5 m − σ_θ / 0.5 rad)` from the filter's covariance
//! (`σ_xy` the root mean square of the x and y standard deviations): above 0.9 when the
//! robot sees the landmarks, falling as it goes without them.

use crate::anchor::{AnchorCounts, Anchors, Phase, RobotPercept};
use crate::field::FieldMap;
use crate::gm::FuzzyGrid;
use crate::murea::{Fix, Perception};
use crate::relocalize::{self, CameraNoise, FrameSeen, Localizer, Relocalizer};
use crate::track::{
    sighting_covariance, Track, TrackCounts, BALL_ACCEL, BALL_MANEUVER, BALL_TOP_SPEED,
};
use mrt_core::frames::{Attack, Field, Framed};
use mrt_core::{normalize_angle, Point2, Pose2, Time, Vec2};
use mrt_msgs::robot::{lps, AnchoredRobot, Estimate, Lpo, WorldSnapshot};
use mrt_msgs::{
    sighting, BallBelief, CameraFrame, GameInfo, Localization, Odometry, Percepts, PostSighting,
    RobotSighting, Sighting, Sonar, SonarScan, FIELD_OBJECTS,
};
use mrt_perception::mice::{Displacement, MiceOdometry};
use nalgebra::{Matrix2, Matrix2x3, Matrix3, Vector2, Vector3};
use std::f64::consts::PI;

/// A post is named only when the next best landmark of its pattern fits this many times
/// worse (squared Mahalanobis distances).
pub const AMBIGUITY: f64 = 9.0;

/// The EKF's view of one sighting ([`WorldModel::innovation`]).
struct Innovation {
    h: Matrix2x3<f64>,
    nu: Vector2<f64>,
    s_inv: Matrix2<f64>,
    r: Matrix2<f64>,
    d2: f64,
}

/// Field-line points farther than this do not correct the pose, m: their place on the floor
/// rests on a pixel row that spans many centimetres there.
pub const LINE_RANGE: f64 = 4.0;
/// Field-line points nearer than this do not correct the pose either, m: a point at the
/// robot's own centre carries no bearing (no camera sees the floor under itself).
pub const LINE_MIN_RANGE: f64 = 0.05;
/// At most this many field-line points of a frame correct the pose, the nearest first.
pub const LINE_CORRECTIONS: usize = 12;
/// A field-line point corrects the pose only when the line it lies beside is nearer than
/// the next line by this much, m ([`FieldMap::line_fit`]).
pub const LINE_CLEARANCE: f64 = 0.5;
/// Field-line points farther from their line than this (squared Mahalanobis distance, 1
/// degree of freedom: 1 true point in 100) are outliers.
pub const LINE_GATE: f64 = 6.63;
/// The points of one frame are not independent (one camera pose, one pixel grid): each point's
/// variance is taken this many times larger than its own. (1, 2 and 4 gave the same errors
/// within the spread of seeds 1–7; 2 with 12 points the lowest 95th percentile.)
pub const LINE_INFLATION: f64 = 2.0;

/// Reliability kept per control cycle by an object that was not seen again.
pub const DECAY: f64 = 0.85;

/// Sightings farther from the estimate than this (squared Mahalanobis distance, 2 degrees of
/// freedom: about 1 in 3000 true sightings) are outliers.
pub const GATE: f64 = 16.0;

/// Process noise assumed for the mice: standard deviation per cycle as a fraction of the
/// motion, plus a turn error per metre travelled (rad/m).
const MICE_SIGMA: (f64, f64) = (0.03, 0.05);
/// The same for the wheels (they slip).
const WHEEL_SIGMA: (f64, f64) = (0.15, 0.3);
/// Process noise added every cycle whatever the motion (m, rad): the filter never becomes
/// so sure of itself that it refuses the camera.
const FLOOR: (f64, f64) = (0.002, 0.002);
/// Uncertainty after being put down by hand (m, rad).
const PLACED_SIGMA: (f64, f64) = (0.05, 0.05);
/// Uncertainty after a relocalization (m, rad): MUREA's tolerances, about.
const RELOCATED_SIGMA: (f64, f64) = (0.15, 0.08);
/// The fuzzy grid is sure of its estimate when its spread is below this (m, rad) and no other
/// answer 1.5 m away is worth this much of it...
const GRID_SURE: (f64, f64, f64) = (0.5, 0.3, 0.5);
/// ... and sure the filter is elsewhere when they are farther apart than three spreads and
/// at least this (m, rad), and the grid holds the filter's pose possible less than this ...
const GRID_ELSEWHERE: (f64, f64, f64) = (0.5, 0.35, 0.1);
/// ... in this many frames in a row: then the filter is moved to the grid's estimate.
const GRID_PATIENCE: u32 = 3;
/// Uncertainty added when the filter finds itself lost (m, rad).
const LOST_SIGMA: (f64, f64) = (1.0, 0.5);
/// The robot needs to localize ([`WorldModel::needs_localization`]) when the goals and posts
/// it sees have disagreed with its pose, none agreeing, for this long (s).
pub const DOUBTED: f64 = 0.5;

/// LPS slot → field object (sensor order) for a team attacking west: its frame is the field
/// turned half round, so its opponent's net is the west net, its "north-east" corner the
/// field's south-west one, and so on.
const ATTACKING_WEST: [usize; FIELD_OBJECTS] = [0, 2, 1, 6, 5, 4, 3, 8, 7];

/// Where one object was last seen (field frame, m), how reliable that is, and when (s).
#[derive(Clone, Copy, Debug)]
struct Memory {
    at: Framed<Field, Point2>,
    reliability: f64,
    seen: f64,
}

/// MAP's tracker of a ball rolling with `damping` (1/s): the quiet and the manoeuvre model
/// mixed by the IMM ([`crate::track`]).
fn ball_track(damping: f64) -> Track {
    Track::new(damping, BALL_ACCEL).with_maneuver(BALL_MANEUVER).with_top_speed(BALL_TOP_SPEED)
}

/// How fast the uncertainty of an unseen ball grows, m/s (it may roll away).
pub const BALL_SPREAD: f64 = 0.5;

pub use mrt_msgs::FilterCounts;

/// One robot's world state between cycles.
#[derive(Clone, Debug)]
pub struct WorldModel {
    map: FieldMap,
    mice: MiceOdometry,
    /// The camera's errors as this model assumes them.
    noise: CameraNoise,
    pose: Pose2,
    /// Whether the relocalizer is given the goal corners ([`WorldModel::with_goal_corners`]).
    goal_corners: bool,
    /// The pose by odometry alone, never corrected: the frame the ball is tracked in
    /// ([`WorldModel::track_ball`]). It drifts slowly but never jumps, so a correction of the
    /// pose does not move the ball's track.
    odom: Pose2,
    cov: Matrix3<f64>,
    memory: [Option<Memory>; FIELD_OBJECTS],
    counts: FilterCounts,
    /// The game controller's latest news (which way the team attacks, the state).
    game: GameInfo,
    /// MAP's Kalman tracker of the ball, fed by the vision's percepts.
    ball_track: Track,
    /// MUREA watching the filter, with [`Localizer::Murea`].
    relocalizer: Option<Box<Relocalizer>>,
    /// The fuzzy grid watching the filter, with [`Localizer::Gm`].
    grid: Option<Box<FuzzyGrid>>,
    /// Frames in a row the grid was sure the filter is elsewhere.
    grid_disagrees: u32,
    /// Whether the field-line points may correct the pose ([`WorldModel::correct_lines`]):
    /// since the last frame whose goals and posts all agreed with the pose, and none since
    /// disagreed.
    lines_trusted: bool,
    /// The last frame's time, s.
    now: f64,
    /// Since when the goals and posts seen disagree with the pose, none agreeing, s.
    doubted: Option<f64>,
    /// One standard deviation of the ball's place when it was last seen, m.
    ball_seen_sigma: f64,
    /// The ball's velocity in the field frame (m/s) when the last frame gave one.
    ball_velocity: Option<(f64, f64)>,
    /// MAP's anchors of the other robots.
    robots: Anchors,
    /// The radius this model gives the other robots, m (their centre is this far beyond the
    /// nearest point the camera sees).
    robot_radius: f64,
    /// The sonar ring's latest reading.
    sonars: Vec<Sonar>,
    /// What the camera covers, when known: half its horizontal field of view (rad) and how far
    /// it sees robots (m).
    view: Option<(f64, f64)>,
}

/// An anchor this close to the edge of the camera's view (rad) is not counted as in view: a
/// robot half out of the image is not found whole.
pub const VIEW_MARGIN: f64 = 0.1;

/// A sonar echo's range error, m (the ISocRob ring's: a centimetre; `[sonar] noise` of the
/// simulator).
pub const SONAR_RANGE_SIGMA: f64 = 0.02;
/// A sonar echo's bearing error, rad: anywhere in a beam of ±0.2 rad (the simulator's
/// `[sonar] half_beam`), the standard deviation of a uniform spread.
pub const SONAR_BEARING_SIGMA: f64 = 0.2 / 1.732;
/// Echoes within this distance of where the robot believes the ball is are the ball's, and
/// within it of a goal post the post's, m.
pub const BALL_ECHO: f64 = 0.3;
/// Echoes farther than this outside the field lines are walls, goals or posts, m.
pub const OFF_FIELD: f64 = 0.3;
/// Echoes farther than this are not read as robots, m: the beam's width there (±0.2 rad)
/// spans more than a robot.
pub const ECHO_RANGE: f64 = 1.5;
/// Echoes of neighbouring sonars within this distance of each other are one robot's, m.
pub const SAME_ECHO: f64 = 0.35;

/// The radius of the other robots unless told ([`WorldModel::with_robot_radius`]), m: a Middle
/// Size robot's (the simulator's default).
pub const ROBOT_RADIUS: f64 = 0.25;

/// The rolling friction of the ball on the carpet, as a linear damping of its velocity (1/s):
/// the simulator's default; [`WorldModel::with_ball_damping`] sets another carpet's.
pub const BALL_DAMPING: f64 = 0.4;

impl WorldModel {
    /// A robot on the field `map` with two mice `mice`, whose camera has the relative
    /// distance error `distance_noise` and the bearing error `bearing_noise` (rad), that does
    /// not know yet where it is.
    pub fn new(map: FieldMap, mice: MiceOdometry, distance_noise: f64, bearing_noise: f64) -> Self {
        WorldModel {
            map,
            mice,
            noise: CameraNoise { distance: distance_noise, bearing: bearing_noise },
            pose: Pose2::default(),
            odom: Pose2::default(),
            goal_corners: false,
            cov: Matrix3::from_diagonal(&Vector3::new(100.0, 100.0, PI * PI)),
            memory: [None; FIELD_OBJECTS],
            counts: FilterCounts::default(),
            game: GameInfo::default(),
            ball_track: ball_track(BALL_DAMPING),
            relocalizer: None,
            grid: None,
            grid_disagrees: 0,
            lines_trusted: false,
            now: 0.0,
            doubted: None,
            ball_velocity: None,
            ball_seen_sigma: 0.0,
            robots: Anchors::default(),
            robot_radius: ROBOT_RADIUS,
            sonars: Vec::new(),
            view: None,
        }
    }

    /// The same model whose relocalizer also searches on the corner of a goal cut by the
    /// image's side (`Percepts::goal_corners`), when `on`. Off by default. Vision matches with
    /// them, 2026-11-26: without kidnaps (`mrt sim --matches 4 --seed 1`) 206 relocalizations
    /// instead of 145, 17 of them false instead of 6, a position mean error of 5.8 cm instead
    /// of 2.4 cm; with `--matches 8 --kidnap 2`, 254 of 256 carried robots found instead of
    /// 253. A corner cannot say which of its goal's four it is, and with a few line points the
    /// search takes a pose that explains them as well as the true one.
    pub fn with_goal_corners(mut self, on: bool) -> Self {
        self.goal_corners = on;
        self
    }

    /// The same model knowing what its camera covers: `half_fov` either side of where the pan
    /// joint points (rad) and robots up to `range` (m). An anchored robot predicted in view and
    /// not seen then fades at [`crate::anchor::MISSED`] a second (the camera should have seen
    /// it). Without it (the default) every unseen anchor fades alike.
    pub fn with_view(mut self, half_fov: f64, range: f64) -> Self {
        let ok = half_fov.is_finite() && half_fov > 0.0 && range.is_finite() && range > 0.0;
        self.view = ok.then_some((half_fov, range));
        self
    }

    /// The sonar ring's reading (ISocRob seed `003` §2): kept for the next frame's anchoring,
    /// where an echo keeps a robot the camera does not see in track ([`Anchors::observe`]).
    pub fn sonars(&mut self, scan: &SonarScan) {
        self.sonars.clone_from(&scan.sonars);
    }

    /// The same model for other robots of radius `radius` (m; a positive number, else
    /// [`ROBOT_RADIUS`]).
    pub fn with_robot_radius(mut self, radius: f64) -> Self {
        self.robot_radius = if radius.is_finite() && radius > 0.0 { radius } else { ROBOT_RADIUS };
        self
    }

    /// The anchors of the other robots (MAP, [`crate::anchor`]).
    pub fn robot_anchors(&self) -> &Anchors {
        &self.robots
    }

    /// What the anchoring of the other robots did so far.
    pub fn robot_anchor_counts(&self) -> AnchorCounts {
        self.robots.counts()
    }

    /// The same model keeping its pose with `localizer` (the EKF alone unless told).
    pub fn with_localizer(mut self, localizer: Localizer) -> Self {
        self.relocalizer = match localizer {
            Localizer::Murea => Some(Box::new(Relocalizer::new(&self.map))),
            Localizer::Ekf | Localizer::Gm => None,
        };
        self.grid = (localizer == Localizer::Gm).then(|| Box::new(FuzzyGrid::field(&self.map)));
        self
    }

    /// The same model with its relocalizer in ISocRob's self mode (a robot whose up camera
    /// sees the field lines all around; [`Relocalizer::with_self_mode`]). Without MUREA as
    /// the localizer this changes nothing.
    pub fn with_self_mode(mut self) -> Self {
        let map = self.map;
        self.relocalizer = self.relocalizer.map(|r| Box::new(r.with_self_mode(&map)));
        self
    }

    /// The same model for a ball whose rolling friction damps its velocity by `damping` (1/s).
    pub fn with_ball_damping(mut self, damping: f64) -> Self {
        self.ball_track = ball_track(damping);
        self
    }

    /// The ball's rolling friction as its tracker assumes it, 1/s.
    pub fn ball_damping(&self) -> f64 {
        self.ball_track.damping
    }

    /// One standard deviation of where the robot believes the ball is (m): the last sighting's
    /// and the pose's then, growing by [`BALL_SPREAD`] a second since (`None`: never seen).
    pub fn ball_sigma(&self) -> Option<f64> {
        self.memory[lps::BALL]
            .map(|m| self.ball_seen_sigma + BALL_SPREAD * (self.now - m.seen).max(0.0))
    }

    /// What the ball's tracker did with the sightings so far.
    pub fn ball_track_counts(&self) -> TrackCounts {
        self.ball_track.counts()
    }

    /// Which localizer keeps the pose.
    pub fn localizer(&self) -> Localizer {
        if self.relocalizer.is_some() {
            Localizer::Murea
        } else if self.grid.is_some() {
            Localizer::Gm
        } else {
            Localizer::Ekf
        }
    }

    /// The pose estimate (field frame, m).
    pub fn pose(&self) -> Framed<Field, Pose2> {
        Framed::new(self.pose)
    }

    /// Standard deviations of the estimate: position (m, root mean square of x and y) and
    /// heading (rad).
    pub fn sigma(&self) -> (f64, f64) {
        (
            ((self.cov[(0, 0)] + self.cov[(1, 1)]) / 2.0).max(0.0).sqrt(),
            self.cov[(2, 2)].max(0.0).sqrt(),
        )
    }

    /// Whether the robot needs to localize: the goals and posts it sees (or MUREA's window)
    /// have disagreed with its pose for [`DOUBTED`] s, none agreeing (it was carried, or its
    /// pose went wrong), and no relocalization has settled it. This is the perceptual need that
    /// ThinkingCap's behaviors state with `trackLandMarks` (seed `001` §2.1), stated by the
    /// world model itself: with a pan joint the gaze looks for landmarks, without one the
    /// robot turns ([`WorldSnapshot::needs_localization`]).
    pub fn needs_localization(&self) -> bool {
        self.doubted.is_some_and(|t| self.now - t >= DOUBTED)
    }

    /// The pose's quality, 0 to 1 (module doc).
    pub fn quality(&self) -> f64 {
        let (xy, theta) = self.sigma();
        (-xy / 0.5 - theta / 0.5).exp()
    }

    /// What the filter used and refused so far.
    pub fn counts(&self) -> FilterCounts {
        self.counts
    }

    /// The estimate for monitors: pose, uncertainty, quality, counts and the ball's belief.
    pub fn localization(&self) -> Localization {
        let (sigma_xy, sigma_theta) = self.sigma();
        let ball = self.memory[lps::BALL].map(|m| BallBelief {
            at: (m.at.inner.x, m.at.inner.y),
            velocity: self.ball_velocity.filter(|_| m.seen == self.now),
            seen_ago: self.now - m.seen,
        });
        Localization {
            pose: self.pose(),
            sigma_xy,
            sigma_theta,
            quality: self.quality(),
            counts: self.counts,
            ball,
        }
    }

    /// The game controller's news: the snapshots that follow are in the team's frame of
    /// `game.attack` and carry its state and kickoff pose.
    pub fn game(&mut self, game: GameInfo) {
        self.game = game;
    }

    /// Sets the pose, as when the robot is put down by hand.
    pub fn place(&mut self, pose: Framed<Field, Pose2>) {
        self.pose = pose.inner;
        self.doubted = None;
        let (xy, theta) = PLACED_SIGMA;
        self.cov = Matrix3::from_diagonal(&Vector3::new(xy * xy, xy * xy, theta * theta));
        self.lines_trusted = true;
        if let Some(r) = &mut self.relocalizer {
            r.forget();
        }
        if let Some(g) = &mut self.grid {
            g.place(pose.inner);
        }
        // Moved by hand: the odometry did not feel it, so neither the ball's track (odometry
        // frame) nor the robots' (field frame of the pose that was) holds any more.
        self.ball_track.reset();
        self.robots.reset();
    }

    /// Puts the filter where the relocalizer's `fix` says, as sure as MUREA's accuracy and
    /// the perceptions' tolerances allow.
    fn relocate(&mut self, fix: &Fix) {
        self.relocate_to(fix.pose, fix.cell.0, fix.cell.2);
    }

    /// Puts the filter at `pose`, at least `xy` (m) and `theta` (rad) unsure.
    fn relocate_to(&mut self, pose: Pose2, xy: f64, theta: f64) {
        self.pose = pose;
        let (xy, theta) = (RELOCATED_SIGMA.0.max(xy), RELOCATED_SIGMA.1.max(theta));
        self.cov = Matrix3::from_diagonal(&Vector3::new(xy * xy, xy * xy, theta * theta));
        self.counts.relocalized += 1;
        self.lines_trusted = false;
        self.robots.reset();
    }

    /// One cycle's odometry: a placement resets the pose, then the motion moves it.
    pub fn odometry(&mut self, o: &Odometry) {
        if let Some(p) = o.placed {
            self.place(p);
        }
        match self.mice.motion(&o.mice) {
            Some((d, reduced)) => {
                if reduced {
                    self.counts.reduced += 1;
                } else {
                    self.counts.mice += 1;
                }
                self.predict(&d, MICE_SIGMA);
            }
            None => {
                self.counts.wheels += 1;
                self.predict(&o.wheels, WHEEL_SIGMA);
            }
        }
    }

    /// The EKF prediction: the pose moves by `d` (robot frame); the uncertainty grows with
    /// `sigma` = (fraction of the motion, turn error per metre).
    fn predict(&mut self, d: &Displacement, sigma: (f64, f64)) {
        if !(d.dx.is_finite() && d.dy.is_finite() && d.dtheta.is_finite()) {
            return;
        }
        let (s, c) = self.pose.theta.sin_cos();
        let f = Matrix3::new(
            1.0,
            0.0,
            -s * d.dx - c * d.dy,
            0.0,
            1.0,
            c * d.dx - s * d.dy,
            0.0,
            0.0,
            1.0,
        );
        let dist = d.dx.hypot(d.dy);
        let fwd = sigma.0 * d.dx.abs() + FLOOR.0;
        let side = sigma.0 * d.dy.abs() + FLOOR.0;
        let turn = sigma.0 * d.dtheta.abs() + sigma.1 * dist + FLOOR.1;
        let q = Matrix3::from_diagonal(&Vector3::new(fwd * fwd, side * side, turn * turn));
        let rot = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
        self.cov = f * self.cov * f.transpose() + rot * q * rot.transpose();
        let p = self.pose.compose(&d.as_pose());
        self.pose = Pose2::new(p.x, p.y, normalize_angle(p.theta));
        let o = self.odom.compose(&d.as_pose());
        self.odom = Pose2::new(o.x, o.y, normalize_angle(o.theta));
        if let Some(r) = &mut self.relocalizer {
            r.moved(d.as_pose());
        }
        if let Some(g) = &mut self.grid {
            g.predict(d.as_pose());
        }
    }

    /// Field position (m) of field object `k` (1..: nets and landmarks, sensor order).
    /// Where camera object `k` stands on the map (`None` for the ball).
    fn landmark(&self, k: usize) -> Option<(f64, f64)> {
        self.map.object(k).map(|p| (p.x, p.y))
    }

    /// The EKF's view of one sighting `z` of a landmark at `at` with the sensor's own
    /// standard deviations `sigma` (where known): the measurement Jacobian, the innovation, its
    /// covariance's inverse, the measurement noise and the squared Mahalanobis distance.
    /// `None` when the landmark is too close to linearise or the numbers are not finite.
    fn innovation(
        &self,
        at: (f64, f64),
        z: &Sighting,
        sigma: Option<(f64, f64)>,
    ) -> Option<Innovation> {
        let (dx, dy) = (at.0 - self.pose.x, at.1 - self.pose.y);
        let q = dx * dx + dy * dy;
        let rho = q.sqrt();
        if rho < 0.3 || !(z.distance.is_finite() && z.bearing.is_finite()) {
            return None;
        }
        let h = Matrix2x3::new(-dx / rho, -dy / rho, 0.0, dy / q, -dx / q, -1.0);
        let nu = Vector2::new(
            z.distance - rho,
            normalize_angle(z.bearing - (dy.atan2(dx) - self.pose.theta)),
        );
        // The vision µAgent's own estimate, where larger: a far net's distance rests on a
        // pixel row that spans half a metre of floor.
        let (sd, sb) = self.noise.sigma(z.distance, sigma);
        let r = Matrix2::new(sd * sd, 0.0, 0.0, sb * sb);
        let s_inv = (h * self.cov * h.transpose() + r).try_inverse()?;
        let d2 = (nu.transpose() * s_inv * nu)[(0, 0)];
        d2.is_finite().then_some(Innovation { h, nu, s_inv, r, d2 })
    }

    /// The EKF correction by one sighting of a landmark at `at`. Returns whether it was
    /// accepted (not gated out).
    fn correct(&mut self, at: (f64, f64), z: &Sighting, sigma: Option<(f64, f64)>) -> bool {
        let Some(Innovation { h, nu, s_inv, r, d2 }) = self.innovation(at, z, sigma) else {
            return true; // too close to linearise; nothing learnt, nothing wrong
        };
        if d2 > GATE {
            return false;
        }
        let k = self.cov * h.transpose() * s_inv;
        // Joseph form: stays symmetric and positive.
        let i_kh = Matrix3::identity() - k * h;
        self.commit(k * nu, i_kh * self.cov * i_kh.transpose() + k * r * k.transpose());
        true
    }

    /// Moves the pose by an EKF correction's `step` and sets its covariance to `cov`, unless
    /// either is not finite: then both stay as they were and the refusal is counted.
    /// Returns whether it was applied.
    fn commit(&mut self, step: Vector3<f64>, cov: Matrix3<f64>) -> bool {
        if !(step.iter().chain(cov.iter()).all(|v| v.is_finite())) {
            self.counts.refused += 1;
            return false;
        }
        self.pose = Pose2::new(
            self.pose.x + step[0],
            self.pose.y + step[1],
            normalize_angle(self.pose.theta + step[2]),
        );
        self.cov = cov;
        true
    }

    /// Which landmark a post of the vision is (data association): of the posts wearing its
    /// pattern ([`FieldMap::east_pattern`]), the one its sighting fits best by the squared
    /// Mahalanobis distance, when that fit passes the [`GATE`] and the second best fits
    /// [`AMBIGUITY`] times worse or fails the gate. A robot unsure where it is leaves its
    /// posts unnamed (the nets, unique, put it right first).
    fn associate(&self, post: &PostSighting) -> Option<usize> {
        let mut fits: Vec<(usize, f64)> = (lps::LANDMARK0..FIELD_OBJECTS)
            .filter(|&k| self.map.east_pattern(k) == Some(post.east))
            .filter_map(|k| {
                let at = self.landmark(k)?;
                Some((k, self.innovation(at, &post.sighting, Some(post.sigma))?.d2))
            })
            .collect();
        fits.sort_by(|a, b| a.1.total_cmp(&b.1));
        let (best, d2) = *fits.first()?;
        let clear = fits.get(1).is_none_or(|&(_, next)| next > GATE || next > AMBIGUITY * d2);
        (d2 <= GATE && clear).then_some(best)
    }

    /// One camera frame: the nets and landmarks correct the pose, every sighting refreshes the
    /// LPS memory, the ball's tracker gives its velocity (a velocity in the frame is not read:
    /// no camera measures one), and the snapshot is built. Call after this cycle's
    /// [`WorldModel::odometry`].
    pub fn camera(&mut self, frame: &CameraFrame) -> WorldSnapshot {
        let none = [None; FIELD_OBJECTS];
        let perceived = self.global().then(|| {
            relocalize::perceptions(&self.map, self.noise, FrameSeen::of(&frame.sightings))
        });
        let velocity =
            frame.sightings[sighting::BALL].map(|z| self.track_ball(frame.time, &z, None));
        let robots = &frame.robots;
        let frame_pan = frame.pan;
        let frame = CameraFrame {
            time: frame.time,
            sightings: frame.sightings,
            ball_velocity: velocity,
            ..Default::default()
        };
        self.observe(&frame, &none, robots, frame_pan, perceived, &[])
    }

    /// [`WorldModel::camera`] with each sighting's own standard deviations, where known, and
    /// the frame's perceptions for the relocalizer.
    fn observe(
        &mut self,
        frame: &CameraFrame,
        sigmas: &[Option<(f64, f64)>; FIELD_OBJECTS],
        robots: &[RobotSighting],
        pan: Option<f64>,
        mut perceived: Option<Vec<Perception>>,
        line_points: &[(f64, f64)],
    ) -> WorldSnapshot {
        let relocalized = self.counts.relocalized;
        // MUREA first checks the odometry's prediction against what the robot sees.
        let for_murea = if self.relocalizer.is_some() { perceived.take() } else { None };
        if let (Some(r), Some(perceived)) = (&mut self.relocalizer, for_murea) {
            let searches = r.counts().searches;
            let fix = r.frame(frame.time, perceived, self.pose);
            self.counts.searches += r.counts().searches - searches;
            if let Some(fix) = fix {
                self.relocate(&fix);
            }
        }
        // Or the fuzzy grid follows the frame, and moves the filter when sure it is elsewhere.
        if let (Some(g), Some(perceived)) = (&mut self.grid, &perceived) {
            g.observe(perceived);
            let e = g.estimate();
            let off = (e.pose.position() - self.pose.position()).norm();
            let turn = normalize_angle(e.pose.theta - self.pose.theta).abs();
            let sure =
                e.second < GRID_SURE.2 && e.sigma_xy < GRID_SURE.0 && e.sigma_theta < GRID_SURE.1;
            let elsewhere = (off > (3.0 * e.sigma_xy).max(GRID_ELSEWHERE.0)
                || turn > (3.0 * e.sigma_theta).max(GRID_ELSEWHERE.1))
                && g.possibility(self.pose) < GRID_ELSEWHERE.2;
            self.grid_disagrees = if sure && elsewhere { self.grid_disagrees + 1 } else { 0 };
            if self.grid_disagrees >= GRID_PATIENCE {
                self.grid_disagrees = 0;
                self.relocate_to(e.pose, e.sigma_xy, e.sigma_theta);
            }
        }
        let (seen, rejected) = self.correct_all(frame, sigmas);
        let mut disagree = rejected;
        if seen >= 3 && 2 * rejected > seen {
            // Most landmarks disagree: the estimate is wrong, not the camera. Widen the
            // uncertainty and listen to the same sightings again.
            self.counts.lost += 1;
            let (xy, theta) = LOST_SIGMA;
            self.cov += Matrix3::from_diagonal(&Vector3::new(xy * xy, xy * xy, theta * theta));
            disagree = self.correct_all(frame, sigmas).1;
        }
        // The lines fit a wrong pose nearly as well as the right one (they are everywhere,
        // and alike): they refine a pose that the goals and posts confirmed, and wait after a
        // frame that the pose does not explain (a robot carried elsewhere, a wrong fix).
        let misfit = self.relocalizer.as_ref().is_some_and(|r| r.last_fits() == Some(false));
        if rejected > 0 || misfit {
            self.lines_trusted = false;
        } else if seen > 0 {
            self.lines_trusted = true;
        }
        if self.counts.relocalized > relocalized || (seen > disagree && !misfit) {
            self.doubted = None;
        } else if seen > 0 || misfit {
            self.doubted.get_or_insert(frame.time);
        }
        if self.lines_trusted && self.sigma().0 <= LINE_CLEARANCE / 2.0 {
            self.correct_lines(line_points);
        }
        let me: Framed<Field, Pose2> = Framed::new(self.pose);
        self.now = frame.time;
        self.ball_velocity = frame.ball_velocity.map(|(vx, vy)| {
            let (s, c) = self.pose.theta.sin_cos();
            (c * vx - s * vy, s * vx + c * vy)
        });
        if let Some(z) = frame.sightings[sighting::BALL] {
            // How sure the ball's place is: the sighting's error and the corrected pose's.
            let sd = self.noise.sigma(z.distance, sigmas[sighting::BALL]);
            let (_, r) = self.sighted_at(z.distance, z.bearing, sd);
            self.ball_seen_sigma = (r.trace() / 2.0).max(0.0).sqrt();
        }
        for (k, z) in frame.sightings.iter().enumerate() {
            match z {
                Some(z) => {
                    let at = me.at_range_bearing(z.distance, z.bearing);
                    self.memory[k] = Some(Memory { at, reliability: 1.0, seen: frame.time });
                }
                None => {
                    if let Some(m) = &mut self.memory[k] {
                        m.reliability *= DECAY;
                    }
                }
            }
        }
        self.anchor_robots(frame.time, robots, pan);
        self.snapshot(frame)
    }

    /// MAP on the frame's robot percepts: each placed on the field from the corrected pose,
    /// with its covariance (the sighting's error and the pose's), then anchored.
    fn anchor_robots(&mut self, time: f64, robots: &[RobotSighting], pan: Option<f64>) {
        let me: Framed<Field, Pose2> = Framed::new(self.pose);
        let percepts: Vec<RobotPercept> = robots
            .iter()
            .map(|z| {
                let centre = z.sighting.distance + self.robot_radius;
                let sd = self.noise.sigma(z.sighting.distance, z.sigma);
                let (at, r) = self.sighted_at(centre, z.sighting.bearing, sd);
                RobotPercept { at, r, marker: z.marker }
            })
            .collect();
        let echoes = self.echoes(&me);
        // Where the camera looked: within its view, less a margin, and its range.
        let view = self.view.map(|(half, range)| (half - VIEW_MARGIN, range, pan.unwrap_or(0.0)));
        let in_view = |(x, y): (f64, f64)| {
            view.is_some_and(|(half, range, pan)| {
                let (r, b) = me.range_bearing(Framed::new(Point2::new(x, y)));
                r <= range && normalize_angle(b - pan).abs() <= half
            })
        };
        self.robots.observe(time, &percepts, &echoes, in_view);
    }

    /// The sonar echoes that may be robots, as percepts of their centres: an echo is a
    /// robot's near side, so its centre is a radius beyond; echoes of the ball (where the
    /// robot believes it is), of the goals' posts and of what stands off the field are left
    /// out.
    fn echoes(&self, me: &Framed<Field, Pose2>) -> Vec<RobotPercept> {
        let ball = self.memory[lps::BALL].filter(|m| m.reliability >= 0.5).map(|m| m.at.inner);
        let (hl, hw) = (self.map.half_length() + OFF_FIELD, self.map.half_width() + OFF_FIELD);
        // Each sonar's echo point (field frame), in ring order; `None`: no echo, or not a
        // robot's.
        let points: Vec<Option<(Point2, &Sonar)>> = self
            .sonars
            .iter()
            .map(|s| {
                if !(s.range.is_finite() && s.range > 0.0 && s.bearing.is_finite()) {
                    return None;
                }
                if s.range > ECHO_RANGE {
                    return None;
                }
                let echo = me.at_range_bearing(s.range, s.bearing).inner;
                let off = echo.x.abs() > hl || echo.y.abs() > hw;
                let at_ball = ball.is_some_and(|b| (b - echo).norm() <= BALL_ECHO);
                // A goal's posts stand on its line: (±half length, ±half the goal's width).
                let post = (echo.x.abs() - self.map.half_length())
                    .hypot(echo.y.abs() - self.map.goal_width / 2.0);
                (!(off || at_ball || post <= BALL_ECHO)).then_some((echo, s))
            })
            .collect();
        // One robot echoes in two or three neighbouring sonars: echoes of neighbours within
        // SAME_ECHO of each other are one robot, seen at its nearest echo.
        let joined = |a: usize, b: usize| match (points[a], points[b]) {
            (Some((p, _)), Some((q, _))) => (p - q).norm() <= SAME_ECHO,
            _ => false,
        };
        mrt_core::ring_runs(points.len(), joined)
            .iter()
            .filter_map(|run| {
                let nearest = run
                    .iter()
                    .filter_map(|&k| points[k].map(|(_, s)| s))
                    .min_by(|a, b| a.range.total_cmp(&b.range))?;
                let sd = (SONAR_RANGE_SIGMA, SONAR_BEARING_SIGMA);
                let (at, r) =
                    self.sighted_at(nearest.range + self.robot_radius, nearest.bearing, sd);
                Some(RobotPercept { at, r, marker: None })
            })
            .collect()
    }

    /// What the vision µAgent found in one image (a [`Percepts`]): read like a camera frame
    /// whose ball velocity is estimated here from the ball's successive places on the field.
    /// Call after this cycle's [`WorldModel::odometry`].
    pub fn percepts(&mut self, p: &Percepts) -> WorldSnapshot {
        if let Some(r) = &mut self.relocalizer {
            r.lines(&p.line_points);
        }
        // The relocalizer takes the posts by their pattern: naming them rests on the pose.
        let perceived = self.global().then(|| {
            let corners: &[PostSighting] = if self.goal_corners { &p.goal_corners } else { &[] };
            let seen = FrameSeen {
                sigmas: &p.sigmas,
                posts: &p.posts,
                goal_corners: corners,
                line_points: &p.line_points,
                ..FrameSeen::of(&p.sightings)
            };
            relocalize::perceptions(&self.map, self.noise, seen)
        });
        let mut frame = CameraFrame { time: p.time, sightings: p.sightings, ..Default::default() };
        let mut sigmas = p.sigmas;
        // The posts, named by where the robot believes it is; a landmark claimed by two posts
        // is left out (one of them is wrong).
        let mut named = [0u8; FIELD_OBJECTS];
        let names: Vec<Option<usize>> = p.posts.iter().map(|post| self.associate(post)).collect();
        names.iter().flatten().for_each(|&k| named[k] += 1);
        for (post, k) in p.posts.iter().zip(names) {
            if let Some(k) = k.filter(|&k| named[k] == 1 && frame.sightings[k].is_none()) {
                frame.sightings[k] = Some(post.sighting);
                sigmas[k] = Some(post.sigma);
                self.counts.posts_named += 1;
            }
        }
        frame.ball_velocity = p.sightings[sighting::BALL]
            .map(|z| self.track_ball(p.time, &z, p.sigmas[sighting::BALL]));
        self.observe(&frame, &sigmas, &p.robots, p.pan, perceived, &p.line_points)
    }

    /// MAP's tracker fed with one sighting of the ball; returns the ball's velocity in the
    /// robot's frame. The track lies in the odometry's frame ([`WorldModel::odom`]), not the
    /// field's: there a correction of the pose (a few centimetres, a degree, every frame that
    /// sees a landmark) would move every sighting after it and read as the ball's motion. The
    /// sighting's covariance is the camera's alone; odometry over a few frames errs far less.
    /// The place stays the sighting's in the field frame (the track lags behind kicks and a
    /// relocalized pose: 0.33 m mean error against 0.20 m).
    fn track_ball(&mut self, time: f64, z: &Sighting, sigma: Option<(f64, f64)>) -> (f64, f64) {
        let sd = self.noise.sigma(z.distance, sigma);
        let o = self.odom;
        let a = o.theta + z.bearing;
        let at = (o.x + z.distance * a.cos(), o.y + z.distance * a.sin());
        let r = sighting_covariance(z.distance, z.bearing, o.theta, sd, Matrix2::zeros(), 0.0);
        let (vx, vy) = if self.ball_track.update(time, at, r) {
            self.ball_track.velocity()
        } else {
            // Gated out (a false sighting, or the first after a kick): the prediction.
            self.ball_track.predicted(time).map_or((0.0, 0.0), |(_, _, vx, vy)| (vx, vy))
        };
        let (s, c) = o.theta.sin_cos();
        (c * vx + s * vy, -s * vx + c * vy)
    }

    /// Where an object seen at `range` (m) and `bearing` (rad, robot frame) with standard
    /// deviations `sigma` stands on the field by the pose estimate (m), and that place's
    /// covariance (m²): the sighting's error and the pose's ([`sighting_covariance`]).
    fn sighted_at(
        &self,
        range: f64,
        bearing: f64,
        sigma: (f64, f64),
    ) -> ((f64, f64), Matrix2<f64>) {
        let at = Framed::<Field, _>::new(self.pose).at_range_bearing(range, bearing).inner;
        let pose_xy = self.cov.fixed_view::<2, 2>(0, 0).into_owned();
        let r =
            sighting_covariance(range, bearing, self.pose.theta, sigma, pose_xy, self.cov[(2, 2)]);
        ((at.x, at.y), r)
    }

    /// Whether a global localizer (MUREA or the grid) reads the frames' perceptions.
    fn global(&self) -> bool {
        self.relocalizer.is_some() || self.grid.is_some()
    }

    /// Corrects the pose with every net and landmark of `frame`. Returns how many were seen
    /// and how many of them were rejected.
    fn correct_all(
        &mut self,
        frame: &CameraFrame,
        sigmas: &[Option<(f64, f64)>; FIELD_OBJECTS],
    ) -> (u64, u64) {
        let (mut seen, mut rejected) = (0, 0);
        for (k, z) in frame.sightings.iter().enumerate() {
            let (Some(z), Some(at)) = (z, self.landmark(k)) else { continue };
            seen += 1;
            if self.correct(at, z, sigmas[k]) {
                self.counts.corrections += 1;
            } else {
                rejected += 1;
            }
        }
        self.counts.rejected += rejected;
        (seen, rejected)
    }

    /// Corrects the pose with the field-line points of a frame (robot frame, m): up to
    /// [`LINE_CORRECTIONS`] of them within [`LINE_RANGE`], the nearest first, each that lies
    /// beside one line of the map by the current estimate ([`FieldMap::line_fit`]). A point
    /// measures its signed distance from that line, which is 0 when the pose is right: a
    /// scalar EKF update whose Jacobian is the line's normal `n` for the position and
    /// `n · ∂p/∂θ` for the heading. A point tells nothing along its line, so a frame of one
    /// line corrects the pose across it only, and the corner of two lines fixes the position.
    /// This is how ISocRob's "self" localization used the lines (seed `003` §3.2.1), as an
    /// EKF update instead of a Hough match: the lines are in nearly every frame, the goals and
    /// posts far and few.
    fn correct_lines(&mut self, line_points: &[(f64, f64)]) {
        let mut near: Vec<(f64, f64, f64)> = line_points
            .iter()
            .map(|&(x, y)| (x.hypot(y), x, y))
            .filter(|&(d, _, _)| d.is_finite() && (LINE_MIN_RANGE..=LINE_RANGE).contains(&d))
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0));
        for &(d, x, y) in near.iter().take(LINE_CORRECTIONS) {
            let at = self.pose.transform_point(Point2::new(x, y));
            let Some(fit) = self.map.line_fit(at, LINE_CLEARANCE) else { continue };
            let n = fit.normal;
            // The point seen from the robot in the field frame; turned a quarter, its
            // derivative by the heading.
            let seen = at - self.pose.position();
            let turn = Vector2::new(-seen.y, seen.x);
            let h = nalgebra::RowVector3::new(n.x, n.y, n.dot(&turn));
            // The point's error along the normal: the range's along the line of sight, the
            // bearing's across it.
            let (sd, sb) = self.noise.sigma(d, None);
            let sight = seen / d.max(1e-6);
            let along = n.dot(&sight).powi(2);
            let r = LINE_INFLATION * (sd * sd * along + (d * sb).powi(2) * (1.0 - along));
            let s_var = (h * self.cov * h.transpose())[(0, 0)] + r;
            let nu = -fit.residual;
            let d2 = nu * nu / s_var;
            if !d2.is_finite() || s_var <= 0.0 || d2 > LINE_GATE {
                continue;
            }
            let k = self.cov * h.transpose() / s_var;
            let i_kh = Matrix3::identity() - k * h;
            if self.commit(k * nu, i_kh * self.cov * i_kh.transpose() + k * r * k.transpose()) {
                self.counts.line_corrections += 1;
            }
        }
    }

    /// The world snapshot in the team frame.
    fn snapshot(&self, frame: &CameraFrame) -> WorldSnapshot {
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
        if let Some((vx, vy)) = self.ball_velocity {
            // The velocity turned by the estimated heading into the field frame (`observe`),
            // then into the team's.
            let v: Framed<Field, Vec2> = Framed::new(Vec2::new(vx, vy));
            w.ball_vel = v.to_team(attack);
        }
        w
    }

    /// The anchored robots out of the find phase, in the team frame, nearest first.
    fn anchored_robots(&self, time: f64, attack: Attack) -> Vec<AnchoredRobot> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_msgs::robot::GameState;

    fn model() -> WorldModel {
        // The default field: 18 m × 12 m. Mice 0.2 m apart, 3 mm tolerance.
        let mice = MiceOdometry::new(0.2, 0.003).unwrap();
        WorldModel::new(FieldMap::default(), mice, 0.03, 0.02)
    }

    /// The game controller's news while playing, attacking east (`attack` 1) or west (−1).
    fn playing(attack: f64) -> GameInfo {
        GameInfo { state: GameState::Playing, attack, kickoff_pose: None, marker: None }
    }

    /// Exact sightings, from `at`, of the field objects at `objects` (field frame, m).
    fn frame(at: Pose2, time: f64, objects: &[(usize, (f64, f64))]) -> CameraFrame {
        let mut f = CameraFrame { time, ..Default::default() };
        for &(k, (x, y)) in objects {
            let (dx, dy) = (x - at.x, y - at.y);
            f.sightings[k] = Some(Sighting {
                distance: dx.hypot(dy),
                bearing: normalize_angle(dy.atan2(dx) - at.theta),
            });
        }
        f
    }

    /// Every landmark of the default field's map, sensor order (1..=8).
    fn landmarks() -> Vec<(usize, (f64, f64))> {
        let map = FieldMap::default();
        (1..FIELD_OBJECTS).filter_map(|k| map.object(k).map(|p| (k, (p.x, p.y)))).collect()
    }

    fn exact_mice(d: Pose2) -> Odometry {
        let mice = MiceOdometry::new(0.2, 0.003).unwrap();
        Odometry { mice: mice.readings_for(d.x, d.y, d.theta), ..Default::default() }
    }

    #[test]
    fn the_mice_alone_carry_the_pose_along_the_path() {
        let mut m = model();
        m.place(Framed::new(Pose2::new(-2.0, 1.0, 0.5)));
        let mut truth = Pose2::new(-2.0, 1.0, 0.5);
        // A curve with a sideways component (omni base), 50 cycles.
        let step = Pose2::new(0.08, 0.02, 0.06);
        for _ in 0..50 {
            m.odometry(&exact_mice(step));
            truth = truth.compose(&step);
        }
        let p = m.pose().inner;
        assert!((p.x - truth.x).abs() < 1e-9 && (p.y - truth.y).abs() < 1e-9, "{p:?} {truth:?}");
        assert!(normalize_angle(p.theta - truth.theta).abs() < 1e-9);
        assert_eq!(m.counts().mice, 50);
        // Without a landmark the uncertainty only grows: 50 cycles of 8 cm with 3 % error.
        let (xy, _) = m.sigma();
        assert!(xy > PLACED_SIGMA.0, "{xy}");
        assert!(m.quality() < 0.9);
    }

    #[test]
    fn landmarks_pull_a_wrong_estimate_back_to_the_truth() {
        let mut m = model();
        let truth = Pose2::new(3.0, -2.0, 2.0);
        // The robot believes it is 0.6 m and 0.15 rad off, and knows it is unsure.
        m.place(Framed::new(Pose2::new(3.4, -2.45, 2.15)));
        m.cov = Matrix3::from_diagonal(&Vector3::new(0.25, 0.25, 0.04));
        for t in 0..5 {
            m.odometry(&exact_mice(Pose2::default()));
            m.camera(&frame(truth, f64::from(t) * 0.1, &landmarks()));
        }
        let p = m.pose().inner;
        assert!((p.x - truth.x).hypot(p.y - truth.y) < 0.01, "{p:?}");
        assert!(normalize_angle(p.theta - truth.theta).abs() < 0.005, "{p:?}");
        assert_eq!((m.counts().corrections, m.counts().rejected), (40, 0));
        // Sure of itself now: 8 landmarks a frame at 3 % and 0.02 rad.
        assert!(m.quality() > 0.75, "{}", m.quality());
    }

    #[test]
    fn an_outlier_is_rejected_and_a_lost_robot_finds_itself() {
        let mut m = model();
        let truth = Pose2::new(0.0, 0.0, 0.0);
        m.place(Framed::new(truth));
        for t in 0..3 {
            m.odometry(&exact_mice(Pose2::default()));
            m.camera(&frame(truth, f64::from(t) * 0.1, &landmarks()));
        }
        // One net reported 3 m too close: gated out, the pose does not move.
        let mut bad = frame(truth, 0.3, &landmarks());
        if let Some(s) = &mut bad.sightings[sighting::EAST_NET] {
            s.distance -= 3.0;
        }
        m.odometry(&exact_mice(Pose2::default()));
        m.camera(&bad);
        assert_eq!(m.counts().rejected, 1);
        assert!(
            m.pose().inner.x.abs() < 0.01 && m.pose().inner.y.abs() < 0.01,
            "{:?}",
            m.pose().inner
        );
        // Kidnapped: moved 2 m without odometry. Every landmark disagrees → lost, widen, and
        // the following frames bring it back.
        let kidnapped = Pose2::new(2.0, 1.0, 0.0);
        for t in 4..14 {
            m.odometry(&exact_mice(Pose2::default()));
            m.camera(&frame(kidnapped, f64::from(t) * 0.1, &landmarks()));
        }
        assert!(m.counts().lost >= 1, "{:?}", m.counts());
        let p = m.pose().inner;
        assert!((p.x - 2.0).hypot(p.y - 1.0) < 0.05, "{p:?} {:?}", m.counts());
    }

    /// What a camera with a 60° field of view at `at` sees of the landmarks within 9 m.
    fn narrow_frame(at: Pose2, time: f64) -> CameraFrame {
        let near: Vec<_> = landmarks()
            .into_iter()
            .filter(|&(_, (x, y))| {
                let (dx, dy) = (x - at.x, y - at.y);
                dx.hypot(dy) < 9.0 && normalize_angle(dy.atan2(dx) - at.theta).abs() < 0.52
            })
            .collect();
        frame(at, time, &near)
    }

    /// A robot carried across the field facing the other way sees only what it did not
    /// expect: the EKF alone gates it all out (or widens onto the wrong landmarks), MUREA finds
    /// the robot again within a few frames.
    #[test]
    fn a_kidnapped_robot_is_found_again_by_murea_but_not_by_the_ekf_alone() {
        let before = Pose2::new(-4.0, -1.0, std::f64::consts::PI);
        let after = Pose2::new(4.5, 0.0, 0.45); // the east net and its north corner in view
        assert!(narrow_frame(after, 0.0).sightings.iter().flatten().count() >= 2);
        let run = |localizer: Localizer| {
            let mut m = model().with_localizer(localizer);
            m.place(Framed::new(before));
            let mut t = 0.0;
            for _ in 0..10 {
                m.odometry(&exact_mice(Pose2::default()));
                m.camera(&narrow_frame(before, t));
                t += 0.1;
            }
            let mut found = None;
            for k in 0..30 {
                m.odometry(&exact_mice(Pose2::default()));
                m.camera(&narrow_frame(after, t));
                let p = m.pose().inner;
                let off = (p.x - after.x).hypot(p.y - after.y);
                if found.is_none()
                    && off < 0.1
                    && normalize_angle(p.theta - after.theta).abs() < 0.05
                {
                    found = Some(k);
                }
                t += 0.1;
            }
            (found, m.counts())
        };
        let (ekf, counts) = run(Localizer::Ekf);
        assert_eq!(ekf, None, "the EKF alone should stay lost here: {counts:?}");
        assert_eq!(counts.searches, 0);
        let (murea, counts) = run(Localizer::Murea);
        let k = murea.unwrap_or_else(|| panic!("MUREA never found it: {counts:?}"));
        assert!(k <= 3, "found after {k} frames");
        assert_eq!(counts.relocalized, 1, "{counts:?}");
        // The fuzzy grid: the old belief fades by the bias each frame, the new pose rises from
        // the floor; three frames in a row sure of it, and the filter moves.
        let (gm, counts) = run(Localizer::Gm);
        let k = gm.unwrap_or_else(|| panic!("GM never found it: {counts:?}"));
        assert!(k <= 8, "found after {k} frames");
        assert!(counts.relocalized >= 1, "{counts:?}");
    }

    /// Carried where it sees one net only, which its pose cannot explain and from which MUREA
    /// cannot tell where it is: after [`DOUBTED`] s it needs to localize (and turns, on a robot
    /// without a pan joint). A robot whose landmarks agree never does, and the need ends when
    /// a relocalization settles it.
    #[test]
    fn a_robot_that_sees_what_its_pose_cannot_explain_needs_to_localize() {
        let before = Pose2::new(-4.0, -1.0, std::f64::consts::PI);
        let one_net = Pose2::new(3.0, 0.0, 0.0);
        assert_eq!(narrow_frame(one_net, 0.0).sightings.iter().flatten().count(), 1);
        let mut m = model().with_localizer(Localizer::Murea);
        m.place(Framed::new(before));
        let mut t = 0.0;
        let mut step = |m: &mut WorldModel, at: Pose2, turn: f64| {
            m.odometry(&exact_mice(Pose2::new(0.0, 0.0, turn)));
            let w = m.camera(&narrow_frame(at, t));
            t += 0.1;
            w.needs_localization
        };
        assert!((0..10).all(|_| !step(&mut m, before, 0.0)), "its landmarks agree");
        // Doubted from the first frame after the carry (t = 1.0 s); needed from 1.5 s.
        let needs: Vec<bool> = (0..8).map(|_| step(&mut m, one_net, 0.0)).collect();
        assert_eq!(needs, [false, false, false, false, false, true, true, true]);
        assert_eq!(m.counts().relocalized, 0, "one net cannot place it");
        // It turns in place at 2 rad/s (crate::look_around's rate in mrt-robot): MUREA finds it
        // within one turn, and the need is met.
        let mut at = one_net;
        let settled = (0..32)
            .map(|_| {
                at.theta += 0.2;
                step(&mut m, at, 0.2)
            })
            .position(|n| !n);
        assert!(settled.is_some(), "{:?}", m.counts());
        assert!(m.counts().relocalized >= 1);
        let p = m.pose().inner;
        assert!((p.x - at.x).hypot(p.y - at.y) < 0.3, "{p:?} against {at:?}");
    }

    /// Nobody said where it starts: from a handful of frames it knows, wherever it stands.
    #[test]
    fn a_robot_never_placed_localizes_globally() {
        // Each with two landmarks in view: the west net and its north corner, the east net
        // and its south corner, the west net and its south corner.
        for truth in
            [Pose2::new(-4.0, 0.5, 2.8), Pose2::new(4.0, -0.5, -0.35), Pose2::new(-5.0, 1.0, -2.6)]
        {
            let mut m = model().with_localizer(Localizer::Murea);
            assert_eq!(m.localizer(), Localizer::Murea);
            let n = narrow_frame(truth, 0.0).sightings.iter().flatten().count();
            assert!(n >= 2, "{truth:?} sees {n}");
            for t in 0..5 {
                m.odometry(&exact_mice(Pose2::default()));
                m.camera(&narrow_frame(truth, f64::from(t) * 0.1));
            }
            let p = m.pose().inner;
            assert!((p.x - truth.x).hypot(p.y - truth.y) < 0.1, "{p:?} {:?}", m.counts());
            assert!(normalize_angle(p.theta - truth.theta).abs() < 0.05, "{p:?}");
        }
    }

    #[test]
    fn an_under_reading_mouse_is_repaired_and_broken_mice_give_way_to_the_wheels() {
        let mut m = model();
        m.place(Framed::new(Pose2::default()));
        // Sideways and forward (omni): x̄ ≠ 0, so a short mouse shows. The left mouse reads
        // 70 % of its motion: §4.2 scales it back exactly.
        let step = Pose2::new(0.1, 0.05, 0.02);
        let mut o = exact_mice(step);
        o.mice.x_left *= 0.7;
        o.mice.y_left *= 0.7;
        m.odometry(&o);
        let p = m.pose().inner;
        assert!((p.x - 0.1).abs() < 1e-9 && (p.y - 0.05).abs() < 1e-9, "{p:?}");
        assert_eq!(m.counts().reduced, 1);
        // Opposite x̄: no reduction possible → the wheels' motion is used.
        let mut o = exact_mice(step);
        o.mice.x_left = -o.mice.x_left;
        o.wheels = Displacement::new(0.2, 0.0, 0.0);
        m.odometry(&o);
        assert_eq!(m.counts().wheels, 1);
        let expected = p.compose(&Pose2::new(0.2, 0.0, 0.0));
        assert!(m.pose().inner.distance(&expected) < 1e-9, "{:?} {expected:?}", m.pose().inner);
        // A short mouse whose x̄ is almost 0 would be scaled by > 2: refused, wheels again.
        let mut o = exact_mice(Pose2::new(0.1, 0.001, 0.0));
        o.mice.x_left = 0.0002;
        o.mice.x_right = 0.0042;
        m.odometry(&o);
        assert_eq!(m.counts().wheels, 2);
        // NaN readings: the wheels too.
        let mut o = exact_mice(step);
        o.mice.y_right = f64::NAN;
        m.odometry(&o);
        assert_eq!(m.counts().wheels, 3);
        assert!(m.pose().inner.x.is_finite());
    }

    /// MAP on the object sensor's robots: a cyan robot 3 m ahead and a magenta one 2 m to
    /// the left of a magenta robot at (−2, 0) facing north, seen at their nearest points;
    /// after two frames both are anchored at their centres, an opponent and a teammate, in
    /// the team frame (attacking west: turned half round), nearest first.
    #[test]
    fn robots_seen_are_anchored_as_teammates_and_opponents_in_the_team_frame() {
        use mrt_msgs::{Marker, RobotClass, RobotSighting};
        let mut m = model().with_robot_radius(0.3);
        let at = Pose2::new(-2.0, 0.0, PI / 2.0);
        m.place(Framed::new(at));
        m.game(GameInfo { marker: Some(Marker::Magenta), ..playing(-1.0) });
        let robot = |distance: f64, bearing: f64, marker| RobotSighting {
            sighting: Sighting { distance, bearing },
            sigma: None,
            marker,
        };
        let mut f = frame(at, 1.0, &landmarks());
        // Their centres: (−2, 3) straight ahead and (−4, 0) on the left, 0.3 m beyond the
        // nearest points.
        f.robots = vec![robot(2.7, 0.0, Some(Marker::Cyan)), robot(1.7, PI / 2.0, None)];
        let w = m.camera(&f);
        assert!(w.robots.is_empty(), "one frame finds, it does not anchor");
        f.time = 1.1;
        f.robots[1].marker = Some(Marker::Magenta);
        let w = m.camera(&f);
        assert_eq!(w.robots.len(), 2, "{:?}", w.robots);
        let (mate, opponent) = (&w.robots[0], &w.robots[1]);
        assert_eq!((mate.class, opponent.class), (RobotClass::Teammate, RobotClass::Opponent));
        // Team frame attacking west: (x, y) → (−x, −y).
        let (mate_at, opponent_at) = (mate.at.inner, opponent.at.inner);
        assert!((mate_at.x - 4.0).abs() < 1e-3 && mate_at.y.abs() < 1e-3, "{mate:?}");
        assert!((opponent_at.x - 2.0).abs() < 1e-3 && (opponent_at.y + 3.0).abs() < 1e-3);
        assert!((opponent.rho - 3.0).abs() < 1e-3 && opponent.theta.abs() < 1e-6);
        assert_eq!((opponent.reliability, opponent.seen_ago), (1.0, 0.0));
        assert!(opponent.at_sigma > 0.0 && opponent.at_sigma < 0.2, "{}", opponent.at_sigma);
        assert_eq!(w.nearest_opponent(0.5).map(|r| r.id), Some(opponent.id));
        // Unseen for a second: still there, half as reliable.
        f.time = 2.1;
        f.robots.clear();
        let w = m.camera(&f);
        assert_eq!(w.robots.len(), 2);
        assert!(
            (w.robots[1].reliability - 0.5).abs() < 1e-9
                && (w.robots[1].seen_ago - 1.0).abs() < 1e-9
        );
        // The robot is put down elsewhere by hand: its anchors lay in the old pose's frame.
        m.place(Framed::new(Pose2::new(3.0, 3.0, 0.0)));
        f.time = 2.2;
        assert!(m.camera(&f).robots.is_empty());
    }

    /// The sonar ring keeps a robot the camera no longer sees anchored: its echo, a robot's
    /// radius short of its centre, is read with the next frame. Echoes of the wall and of the
    /// ball are not robots.
    #[test]
    fn a_robot_out_of_view_is_kept_by_its_sonar_echo() {
        use mrt_msgs::{RobotSighting, Sonar, SonarScan};
        let mut m = model();
        let at = Pose2::new(8.0, 0.0, 0.0);
        m.place(Framed::new(at));
        m.game(playing(1.0));
        // A robot 1.5 m ahead (centre), the ball 1 m to the left.
        let mut f = frame(at, 1.0, &[(lps::BALL, (8.0, 1.0))]);
        let foot = Sighting { distance: 1.25, bearing: 0.0 };
        f.robots = vec![RobotSighting { sighting: foot, sigma: None, marker: None }];
        m.camera(&f);
        f.time = 1.1;
        assert_eq!(m.camera(&f).robots.len(), 1);
        // Then only the sonars, for two seconds of frames without robot percepts: the robot's
        // echo straight ahead at 1.25 m, the ball's on the left at 0.89 m, and one from
        // beyond the east goal line (more than 0.3 m off the 18 m field).
        let scan = SonarScan {
            sonars: vec![
                Sonar::new(0.0, 1.25),
                Sonar::new(std::f64::consts::FRAC_PI_2, 0.89),
                Sonar::new(-0.3, 1.6), // (9.53, −0.47): beyond the goal line, a wall
            ],
        };
        for k in 1..=20 {
            m.sonars(&scan);
            f.time = 1.1 + 0.1 * f64::from(k);
            f.robots.clear();
            let w = m.camera(&f);
            assert_eq!(w.robots.len(), 1, "only the robot: {:?}", w.robots);
            assert_eq!(w.robots[0].reliability, 1.0, "heard at {}", f.time);
        }
        assert_eq!(m.robot_anchor_counts().echoes, 20);
        assert_eq!(m.robot_anchor_counts().created, 1);
    }

    #[test]
    fn the_snapshot_is_in_the_team_frame_and_unseen_objects_fade() {
        let mut m = model();
        let at = Pose2::new(-2.0, 0.0, std::f64::consts::FRAC_PI_2);
        m.place(Framed::new(at));
        m.odometry(&Odometry::default());
        let mut objects = landmarks();
        objects.push((lps::BALL, (0.0, 2.0)));
        // Attacking east: the team frame is the field frame.
        m.game(playing(1.0));
        let w = m.camera(&frame(at, 1.0, &objects));
        assert_eq!(w.game_state, GameState::Playing, "the game controller's state");
        let ball = w.lps[lps::BALL];
        assert!((ball.rho - 2.828427).abs() < 1e-5 && (ball.theta + PI / 4.0).abs() < 1e-9);
        assert_eq!((ball.reliability, ball.seen_ago), (1.0, 0.0));
        // The own net (west, (-9, 0)): 7 m on the left.
        let own = w.lps[lps::NET2];
        assert!((own.rho - 7.0).abs() < 1e-5 && (own.theta - PI / 2.0).abs() < 1e-9);
        let (me, ball) = (w.my_pos.pose.inner, w.global_ball.pose.inner);
        assert!((me.x + 2.0).abs() < 1e-9 && me.y.abs() < 1e-9);
        assert!(ball.x.abs() < 1e-9 && (ball.y - 2.0).abs() < 1e-9);
        // Attacking west: the same field turned half round; the opponent's net (NET1) is
        // the west net, 7 m on the left, and "landmark 0" (the opponent's left corner) is
        // the field's south-west corner.
        let mut m2 = model();
        m2.place(Framed::new(at));
        m2.game(playing(-1.0));
        let w = m2.camera(&frame(at, 1.0, &objects));
        assert!((w.lps[lps::NET1].rho - 7.0).abs() < 1e-5);
        assert!((w.lps[lps::NET1].theta - PI / 2.0).abs() < 1e-9);
        let sw = w.lps[lps::LANDMARK0];
        let (dx, dy) = (-9.0 - at.x, -6.0 - at.y);
        assert!((sw.rho - dx.hypot(dy)).abs() < 1e-5, "{sw:?}");
        let me = w.my_pos.pose.inner;
        assert!((me.x - 2.0).abs() < 1e-9, "{:?}", w.my_pos);
        assert!((me.theta + PI / 2.0).abs() < 1e-9, "north is the team's −y");
        assert!((w.global_ball.pose.inner.y + 2.0).abs() < 1e-9);
        // Nothing seen next cycle: memories stay where they were, fading; the robot moves
        // 1 m forward (north) by the mice, so the ball, 2 m north-east, is now 2.236 m away.
        m.odometry(&exact_mice(Pose2::new(1.0, 0.0, 0.0)));
        let w = m.camera(&frame(at, 1.1, &[]));
        let ball = w.lps[lps::BALL];
        assert!((ball.reliability - DECAY).abs() < 1e-12);
        assert!((ball.rho - 5f64.sqrt()).abs() < 1e-5, "{ball:?}");
        assert!((ball.seen_ago - 0.1).abs() < 1e-9);
    }

    /// The vision's posts carry their half's pattern only: a robot that knows where it is
    /// names each by the nearest landmark of that pattern and corrects its pose with it; a
    /// robot that does not know where it is names none.
    #[test]
    fn posts_are_named_by_where_the_robot_believes_it_is() {
        let map = FieldMap::default();
        let truth = Pose2::new(6.0, 3.0, 0.6);
        // Looking north-east: the NE corner post (3) and the half-way line's north end (7)
        // wear the east pattern; the robot believes it is 0.2 m and 0.03 rad off.
        let post = |k: usize, east: bool| {
            let at = map.object(k).unwrap();
            let f = frame(truth, 1.0, &[(k, (at.x, at.y))]);
            PostSighting {
                sighting: f.sightings[k].unwrap(),
                sigma: (0.05, 0.01),
                east,
                pixels: 40,
            }
        };
        let mut m = model();
        m.place(Framed::new(Pose2::new(6.2, 2.9, 0.63)));
        let p =
            Percepts { time: 1.0, posts: vec![post(3, true), post(7, true)], ..Default::default() };
        m.percepts(&p);
        assert_eq!(m.counts().posts_named, 2);
        assert_eq!(m.counts().corrections, 2);
        // Closer than the 0.22 m it was put down off.
        let e = m.pose().inner;
        assert!((e.x - truth.x).hypot(e.y - truth.y) < 0.2, "{e:?}");
        // The same sighting with the west pattern fits no west post: not named.
        let mut m = model();
        m.place(Framed::new(Pose2::new(6.2, 2.9, 0.63)));
        let p = Percepts { time: 1.0, posts: vec![post(3, false)], ..Default::default() };
        m.percepts(&p);
        assert_eq!(m.counts().posts_named, 0);
        // A robot that was never put down (10 m of uncertainty): every east post fits.
        let mut m = model();
        let p = Percepts { time: 1.0, posts: vec![post(3, true)], ..Default::default() };
        m.percepts(&p);
        assert_eq!((m.counts().posts_named, m.counts().corrections), (0, 0));
    }

    /// The ball's velocity from vision percepts is MAP's tracker's: a ball slowing by the
    /// carpet's friction, seen by a robot standing still, has its velocity within 0.15 m/s
    /// after a second; a kick is followed within three frames.
    #[test]
    fn a_rolling_ball_seen_by_vision_has_the_tracker_s_velocity() {
        let me = Pose2::new(-2.0, 1.0, 0.3);
        let mut m = model();
        m.place(Framed::new(me));
        let ball = |t: f64| {
            let v = 2.0 * (-BALL_DAMPING * t).exp();
            (2.0 * (1.0 - (-BALL_DAMPING * t).exp()) / BALL_DAMPING - 1.0, 2.0, v)
        };
        for k in 0..=10 {
            let t = 0.1 * f64::from(k);
            let (x, y, _) = ball(t);
            let f = frame(me, t, &[(lps::BALL, (x, y))]);
            let p = Percepts { time: t, sightings: f.sightings, ..Default::default() };
            m.percepts(&p);
        }
        let b = m.localization().ball.unwrap_or_default();
        let (vx, vy) = b.velocity.unwrap_or_default();
        assert!((vx - ball(1.0).2).abs() < 0.15 && vy.abs() < 0.15, "({vx}, {vy})");
        assert_eq!(m.ball_track_counts().restarts, 1);
        // Kicked back west at 4 m/s from where it was at 1.05 s.
        let (x0, y0, _) = ball(1.05);
        for k in 11..=13 {
            let t = 0.1 * f64::from(k);
            let f = frame(me, t, &[(lps::BALL, (x0 - 4.0 * (t - 1.05), y0))]);
            m.percepts(&Percepts { time: t, sightings: f.sightings, ..Default::default() });
        }
        // The manoeuvre model took the kick without a restart (the quiet model alone gated
        // it out twice and restarted): three frames later the velocity is the kick's.
        let (vx, vy) = m.localization().ball.and_then(|b| b.velocity).unwrap_or_default();
        assert!((vx + 4.0).abs() < 0.5 && vy.abs() < 0.3, "({vx}, {vy})");
        let restarts = m.ball_track_counts().restarts;
        assert!(restarts <= 2, "{:?}", m.ball_track_counts());
        // Put down by hand: the track, in the old pose's frame, starts again at once.
        m.place(Framed::new(me));
        let f = frame(me, 1.4, &[(lps::BALL, (x0 - 1.4, y0))]);
        m.percepts(&Percepts { time: 1.4, sightings: f.sightings, ..Default::default() });
        assert_eq!(m.ball_track_counts().restarts, restarts + 1, "{:?}", m.ball_track_counts());
    }

    /// The ball's track lies in the odometry's frame: the landmarks pulling a wrong pose
    /// 0.5 m and 0.15 rad back to the truth do not move a ball that lies still. (Tracked in
    /// the field frame, the pose's correction read as the ball rolling at 4.7 m/s after the
    /// first correction.)
    #[test]
    fn a_pose_correction_does_not_move_the_ball_s_track() {
        let truth = Pose2::new(3.0, -2.0, 2.0);
        let ball = (1.5, 0.0);
        let mut m = model();
        m.place(Framed::new(Pose2::new(3.4, -2.3, 2.15)));
        m.cov = Matrix3::from_diagonal(&Vector3::new(0.25, 0.25, 0.04));
        let mut objects = landmarks();
        objects.push((lps::BALL, ball));
        let mut fastest: f64 = 0.0;
        for t in 0..10 {
            m.odometry(&exact_mice(Pose2::default()));
            m.camera(&frame(truth, f64::from(t) * 0.1, &objects));
            if let Some((vx, vy)) = m.localization().ball.and_then(|b| b.velocity) {
                fastest = fastest.max(vx.hypot(vy));
            }
        }
        let p = m.pose().inner;
        assert!((p.x - truth.x).hypot(p.y - truth.y) < 0.01, "the pose is corrected: {p:?}");
        assert!(fastest < 0.05, "the ball seemed to roll at {fastest} m/s");
        assert_eq!(m.ball_track_counts().restarts, 1, "{:?}", m.ball_track_counts());
    }

    /// Field-line points seen from `truth`, in the robot frame: `n` points from `a` to `b`
    /// (field frame, m).
    fn line(truth: Pose2, a: (f64, f64), b: (f64, f64), n: usize) -> Vec<(f64, f64)> {
        let (s, c) = truth.theta.sin_cos();
        (0..n)
            .map(|i| {
                let f = i as f64 / (n - 1) as f64;
                let (x, y) = (a.0 + f * (b.0 - a.0) - truth.x, a.1 + f * (b.1 - a.1) - truth.y);
                (c * x + s * y, -s * x + c * y)
            })
            .collect()
    }

    /// The field lines correct the pose across them: points of the north touch line alone
    /// take out a 9 cm error in y and leave the x error, which they cannot see; with the
    /// east goal line beside them (the corner), in two frames, both errors go. Hand check
    /// of the first update: the nearest point, (7.56, 6) seen from (7.6, 5), is 1 m away
    /// almost straight along the line's normal, so its σ there is the range's, 3 % × 1 m +
    /// 1 cm = 4 cm: 2 × 16 = 32 cm² inflated, against the pose's 5² = 25 cm² across the line.
    /// That point alone takes out 25 / 57 = 44 % of the error; the eight, nearly all.
    #[test]
    fn field_lines_correct_the_pose_across_them_and_a_corner_fixes_it() {
        let truth = Pose2::new(7.6, 5.0, 0.3);
        let touch = line(truth, (7.0, 6.0), (8.3, 6.0), 8);
        let goal = line(truth, (9.0, 4.2), (9.0, 5.5), 8);
        // Off by 6 cm east and 9 cm south; the touch line only.
        let mut m = model();
        m.place(Framed::new(Pose2::new(truth.x + 0.06, truth.y - 0.09, truth.theta)));
        m.percepts(&Percepts { time: 0.1, line_points: touch.clone(), ..Default::default() });
        let e = m.pose().inner;
        assert_eq!(m.counts().line_corrections, 8);
        assert!((e.y - truth.y).abs() < 0.02, "y still {:.3} off", e.y - truth.y);
        assert!((e.x - truth.x - 0.06).abs() < 0.02, "x moved along the line: {e:?}");
        // Both lines: both coordinates.
        let mut m = model();
        m.place(Framed::new(Pose2::new(truth.x + 0.06, truth.y - 0.09, truth.theta)));
        let corner: Vec<(f64, f64)> = touch.iter().chain(&goal).copied().collect();
        for time in [0.1, 0.2] {
            m.percepts(&Percepts { time, line_points: corner.clone(), ..Default::default() });
        }
        let e = m.pose().inner;
        assert!((e.x - truth.x).hypot(e.y - truth.y) < 0.02, "{e:?}");
        assert!((e.theta - truth.theta).abs() < 0.01, "{e:?}");
    }

    /// The lines refine a pose the goals and posts confirmed: after a frame whose net
    /// disagrees with the pose (rejected), they correct nothing until a frame whose landmarks
    /// agree; a point that lies between two lines, or too far from its line, corrects nothing.
    #[test]
    fn field_lines_wait_for_the_landmarks_after_a_disagreement() {
        let truth = Pose2::new(7.6, 5.0, 0.3);
        let touch = line(truth, (7.0, 6.0), (8.3, 6.0), 8);
        let mut m = model();
        m.place(Framed::new(truth));
        // The frame at `time` with the east net seen at `net` and the touch line's points.
        let with_net = |time: f64, net: (f64, f64)| Percepts {
            time,
            sightings: frame(truth, time, &[(mrt_msgs::sighting::EAST_NET, net)]).sightings,
            line_points: touch.clone(),
            ..Default::default()
        };
        // The east net seen 3 m off where it is: rejected.
        m.percepts(&with_net(0.1, (9.0, 3.0)));
        assert_eq!((m.counts().rejected, m.counts().line_corrections), (1, 0));
        m.percepts(&Percepts { time: 0.2, line_points: touch.clone(), ..Default::default() });
        assert_eq!(m.counts().line_corrections, 0, "no landmark has agreed since");
        m.percepts(&with_net(0.3, (9.0, 0.0)));
        assert_eq!(m.counts().line_corrections, 8, "the net agreed");
        // Between the touch line and the goal line (the corner): no line is clear of the
        // other. 40 cm from the touch line at 0.6 m: gated (σ about 3 cm).
        let before = m.counts().line_corrections;
        let odd = [line(truth, (8.8, 5.8), (8.8, 5.8), 2), line(truth, (7.5, 5.6), (7.5, 5.6), 2)];
        m.percepts(&Percepts { time: 0.4, line_points: odd.concat(), ..Default::default() });
        assert_eq!(m.counts().line_corrections, before);
    }

    /// A correction whose step or covariance is not finite is refused and counted; the
    /// pose and its uncertainty stay as they were.
    #[test]
    fn a_correction_that_is_not_finite_is_refused_and_counted() {
        let mut m = model();
        m.place(Framed::new(Pose2::new(1.0, 2.0, 0.5)));
        let (pose, cov) = (m.pose, m.cov);
        let nan = Vector3::new(0.1, f64::NAN, 0.0);
        assert!(!m.commit(nan, Matrix3::identity()));
        assert!(!m.commit(Vector3::zeros(), Matrix3::identity() * f64::INFINITY));
        assert_eq!((m.pose, m.cov, m.counts().refused), (pose, cov, 2));
        assert!(m.commit(Vector3::new(0.1, 0.0, 0.0), cov));
        assert_eq!((m.pose.x, m.counts().refused), (1.1, 2));
    }

    /// Line points at the robot's centre carry no bearing: two of them, one a hair off it,
    /// leave the pose and its uncertainty finite (a case a property test once drew).
    #[test]
    fn line_points_at_the_robot_s_own_foot_leave_the_pose_and_its_sigma_finite() {
        let mut m = model();
        m.place(Framed::new(Pose2::new(-1.924532815054719, 0.49055413021987215, 0.0)));
        let points = vec![(-4.0e-151, 0.0), (0.0, 0.0)];
        m.percepts(&Percepts { time: 0.1, line_points: points, ..Default::default() });
        let e = m.pose().inner;
        assert!(e.x.is_finite() && e.y.is_finite() && e.theta.is_finite(), "{e:?}");
        let (sxy, st) = m.sigma();
        assert!(sxy.is_finite() && st.is_finite(), "σ {sxy}, {st}");
    }

    /// A coordinate of a line point: mostly near the robot, sometimes anything at all.
    fn coordinate() -> impl proptest::strategy::Strategy<Value = f64> {
        proptest::prop_oneof![3 => -5.0..5.0f64, 1 => proptest::num::f64::ANY]
    }

    proptest::proptest! {
        /// Any field-line points, finite or not, near or absurdly far, leave the pose finite
        /// and never panic (a malformed percept message is data, not a crash).
        #[test]
        fn any_line_points_leave_the_pose_finite(
            points in proptest::collection::vec((coordinate(), coordinate()), 0..40),
            x in -9.0..9.0f64, y in -6.0..6.0f64, theta in -3.2..3.2f64,
        ) {
            let mut m = model();
            m.place(Framed::new(Pose2::new(x, y, theta)));
            m.percepts(&Percepts { time: 0.1, line_points: points, ..Default::default() });
            let e = m.pose().inner;
            proptest::prop_assert!(e.x.is_finite() && e.y.is_finite() && e.theta.is_finite());
            let (sxy, st) = m.sigma();
            proptest::prop_assert!(sxy.is_finite() && st.is_finite());
        }
    }
}
