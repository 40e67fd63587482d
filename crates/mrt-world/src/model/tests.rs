//! The world model's tests: localization, anchoring, the snapshot, the ball's track.

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
    assert!(m.pose().inner.x.abs() < 0.01 && m.pose().inner.y.abs() < 0.01, "{:?}", m.pose().inner);
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
            if found.is_none() && off < 0.1 && normalize_angle(p.theta - after.theta).abs() < 0.05 {
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
        (w.robots[1].reliability - 0.5).abs() < 1e-9 && (w.robots[1].seen_ago - 1.0).abs() < 1e-9
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
        PostSighting { sighting: f.sightings[k].unwrap(), sigma: (0.05, 0.01), east, pixels: 40 }
    };
    let mut m = model();
    m.place(Framed::new(Pose2::new(6.2, 2.9, 0.63)));
    let p = Percepts { time: 1.0, posts: vec![post(3, true), post(7, true)], ..Default::default() };
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
    let (vx, vy) = b.velocity.map_or((0.0, 0.0), |v| (v.inner.x, v.inner.y));
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
    let v = m.localization().ball.and_then(|b| b.velocity).unwrap_or_default().inner;
    let (vx, vy) = (v.x, v.y);
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
        if let Some(v) = m.localization().ball.and_then(|b| b.velocity) {
            fastest = fastest.max(v.inner.norm());
        }
    }
    let p = m.pose().inner;
    assert!((p.x - truth.x).hypot(p.y - truth.y) < 0.01, "the pose is corrected: {p:?}");
    assert!(fastest < 0.05, "the ball seemed to roll at {fastest} m/s");
    assert_eq!(m.ball_track_counts().restarts, 1, "{:?}", m.ball_track_counts());
}

/// Field-line points seen from `truth`, in the robot frame: `n` points from `a` to `b`
/// (field frame, m).
fn line(truth: Pose2, a: (f64, f64), b: (f64, f64), n: usize) -> Vec<Framed<Robot, Point2>> {
    let (s, c) = truth.theta.sin_cos();
    (0..n)
        .map(|i| {
            let f = i as f64 / (n - 1) as f64;
            let (x, y) = (a.0 + f * (b.0 - a.0) - truth.x, a.1 + f * (b.1 - a.1) - truth.y);
            Framed::new(Point2::new(c * x + s * y, -s * x + c * y))
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
    let corner: Vec<Framed<Robot, Point2>> = touch.iter().chain(&goal).copied().collect();
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
    let points = vec![Framed::new(Point2::new(-4.0e-151, 0.0)), Framed::new(Point2::origin())];
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
        let line_points = points.into_iter().map(|(x, y)| Framed::new(Point2::new(x, y))).collect();
        m.percepts(&Percepts { time: 0.1, line_points, ..Default::default() });
        let e = m.pose().inner;
        proptest::prop_assert!(e.x.is_finite() && e.y.is_finite() && e.theta.is_finite());
        let (sxy, st) = m.sigma();
        proptest::prop_assert!(sxy.is_finite() && st.is_finite());
    }
}
