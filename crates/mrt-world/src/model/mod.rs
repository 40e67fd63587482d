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
//! - **LPS** (ThinkingCap/TeamChaos report §3, the perceptual anchors): each object keeps the field position
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
use mrt_core::frames::{Attack, Field, Framed, Robot};
use mrt_core::{normalize_angle, Point2, Pose2, Time, Vec2};
use mrt_msgs::robot::{lps, AnchoredRobot, Estimate, Lpo, WorldSnapshot};
use mrt_msgs::{
    sighting, BallBelief, CameraFrame, GameInfo, Localization, Odometry, Percepts, PostSighting,
    RobotSighting, Sighting, Sonar, SonarScan, FIELD_OBJECTS,
};
use mrt_perception::mice::{Displacement, MiceOdometry};
use nalgebra::{Matrix2, Matrix2x3, Matrix3, Rotation2, Vector2, Vector3};
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
    /// The ball's velocity (m/s) when the last frame saw the ball.
    ball_velocity: Option<Framed<Field, Vec2>>,
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

    /// The sonar ring's reading (ISocRob-2000 report §2): kept for the next frame's anchoring,
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
    /// ThinkingCap's behaviors state with `trackLandMarks` (ThinkingCap/TeamChaos report §2.1), stated by the
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
            at: m.at,
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

    /// One camera frame: the nets and landmarks correct the pose, every sighting refreshes the
    /// LPS memory, the ball's tracker gives its velocity, and the snapshot is built. Call after
    /// this cycle's [`WorldModel::odometry`].
    pub fn camera(&mut self, frame: &CameraFrame) -> WorldSnapshot {
        let none = [None; FIELD_OBJECTS];
        let perceived = self.global().then(|| {
            relocalize::perceptions(&self.map, self.noise, FrameSeen::of(&frame.sightings))
        });
        let velocity =
            frame.sightings[sighting::BALL].map(|z| self.track_ball(frame.time, &z, None));
        self.observe(frame, &none, &frame.robots, frame.pan, perceived, &[], velocity)
    }

    /// [`WorldModel::camera`] with each sighting's own standard deviations, where known, the
    /// frame's perceptions for the relocalizer and the ball tracker's velocity (odometry frame,
    /// [`WorldModel::track_ball`]).
    #[allow(clippy::too_many_arguments)]
    fn observe(
        &mut self,
        frame: &CameraFrame,
        sigmas: &[Option<(f64, f64)>; FIELD_OBJECTS],
        robots: &[RobotSighting],
        pan: Option<f64>,
        mut perceived: Option<Vec<Perception>>,
        line_points: &[Framed<Robot, Point2>],
        ball_velocity: Option<Vec2>,
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
        // From the odometry's frame into the field's: turned by the corrected heading's
        // difference from the odometry's.
        let turn = Rotation2::new(self.pose.theta - self.odom.theta);
        self.ball_velocity = ball_velocity.map(|v| Framed::new(turn * v));
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
        let velocity = p.sightings[sighting::BALL]
            .map(|z| self.track_ball(p.time, &z, p.sigmas[sighting::BALL]));
        self.observe(&frame, &sigmas, &p.robots, p.pan, perceived, &p.line_points, velocity)
    }

    /// MAP's tracker fed with one sighting of the ball; returns the ball's velocity in the
    /// odometry's frame. The track lies in the odometry's frame ([`WorldModel::odom`]), not the
    /// field's: there a correction of the pose (a few centimetres, a degree, every frame that
    /// sees a landmark) would move every sighting after it and read as the ball's motion. The
    /// sighting's covariance is the camera's alone; odometry over a few frames errs far less.
    /// The place stays the sighting's in the field frame (the track lags behind kicks and a
    /// relocalized pose: 0.33 m mean error against 0.20 m).
    fn track_ball(&mut self, time: f64, z: &Sighting, sigma: Option<(f64, f64)>) -> Vec2 {
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
        Vec2::new(vx, vy)
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
}

mod ekf;
mod snapshot;

#[cfg(test)]
mod tests;
