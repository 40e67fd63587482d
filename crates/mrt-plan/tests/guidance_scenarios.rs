//! The guidance modes of ISocRob §3.2.3 driving the two MRT bases in closed loop: each step the
//! mode's twist goes through the base's `limit`, `inverse`, `ramp` (acceleration bound) and
//! `forward`, and `integrate` moves the robot exactly along the resulting arc for `dt`. The
//! invariants (never inside an obstacle, halted before the wall) are checked at every step.

use mrt_core::{angle_diff, Point2, Pose2};
use mrt_plan::guidance::{
    behind_ball, GuidanceCommand, Obstacle, PositionMode, PositionParams, PotentialField,
    PotentialParams, Sonar, VelocityGuard,
};
use mrt_plan::kinematics::{integrate, DiffDrive, Kinematics, Omni3, Twist};

const DT: f64 = 0.02;

/// Runs `steps` control cycles; `check` sees every pose. Returns the last pose and command.
fn run<K: Kinematics>(
    base: &K,
    start: Pose2,
    steps: usize,
    mut mode: impl FnMut(&Pose2) -> GuidanceCommand,
    mut check: impl FnMut(&Pose2),
) -> (Pose2, GuidanceCommand) {
    let mut pose = start;
    let mut wheels = base.inverse(&Twist::ZERO);
    let mut last = GuidanceCommand::default();
    for _ in 0..steps {
        last = mode(&pose);
        let target = base.inverse(&base.limit(&last.twist));
        wheels = base.ramp(&wheels, &target, DT);
        pose = integrate(pose, &base.forward(&wheels), DT);
        check(&pose);
    }
    (pose, last)
}

fn field_for<K: Kinematics>(base: &K) -> PotentialField {
    let position = PositionParams { steering: base.steering(), ..PositionParams::default() };
    match PotentialField::new(position, PotentialParams::default()) {
        Ok(f) => f,
        Err(e) => panic!("{e}"),
    }
}

/// Asserts the robot (radius `robot_radius`) never overlaps any obstacle.
fn outside(obstacles: &[Obstacle], robot_radius: f64) -> impl FnMut(&Pose2) + '_ {
    move |p: &Pose2| {
        for o in obstacles {
            let gap = (p.position() - o.center).norm() - o.radius - robot_radius;
            assert!(gap > 0.0, "robot at {p:?} inside {o:?} (gap {gap})");
        }
    }
}

/// A target straight past an obstacle on the line of travel: attraction and repulsion are
/// collinear there, the classic local minimum; the field must go around and arrive.
fn past_an_obstacle<K: Kinematics>(base: &K) -> Pose2 {
    let field = field_for(base);
    let obstacles = [Obstacle::new(2.0, 0.0, 0.25)]; // another robot
    let target = Pose2::new(4.0, 0.0, 0.0);
    let mut min_gap = f64::INFINITY;
    let (end, last) = run(
        base,
        Pose2::identity(),
        600, // 12 s; 4 m at ≤ 1.2 m/s plus the detour
        |p| field.command(p, &target, &obstacles),
        |p| {
            outside(&obstacles, 0.25)(p);
            min_gap = min_gap.min((p.position() - obstacles[0].center).norm() - 0.5);
        },
    );
    assert!(end.distance(&target) < 0.02, "ended at {end:?}");
    assert!(angle_diff(end.theta, target.theta).abs() < 0.03, "ended at {end:?}");
    assert!(last.done, "{last:?}");
    // It did pass close: the obstacle was in the way, not avoided by luck.
    assert!(min_gap < 0.5, "closest gap {min_gap}");
    end
}

#[test]
fn potential_field_reaches_a_target_past_an_obstacle_omni3() {
    past_an_obstacle(&Omni3::triskar());
}

#[test]
fn potential_field_reaches_a_target_past_an_obstacle_diff_drive() {
    past_an_obstacle(&DiffDrive::ianus3());
}

/// The ball between the robot and the spot behind it: the robot goes around the ball (a
/// repelling obstacle, ISocRob §3.2.3) to the spot on the line from the goal, facing the goal.
#[test]
fn potential_field_gets_behind_the_ball_without_touching_it() {
    let goal = Point2::new(6.0, 0.0);
    let ball = Obstacle::new(2.0, 0.3, 0.11); // MSL ball, radius 11 cm
                                              // 0.25 (robot) + 0.11 (ball) + 0.14 clearance.
    let target = match behind_ball(ball.center, goal, 0.5) {
        Ok(t) => t,
        Err(e) => panic!("{e}"),
    };
    // Behind: (2, 0.3) − 0.5·(4, −0.3)/|(4, −0.3)| = (2 − 0.498600, 0.3 + 0.037395).
    assert!((target.x - 1.501_400).abs() < 1e-6 && (target.y - 0.337_395).abs() < 1e-6);
    let obstacles = [ball];
    for (name, start) in
        [("goal side", Pose2::new(3.5, 0.0, 3.0)), ("beside", Pose2::new(2.0, 1.5, -1.0))]
    {
        let triskar = Omni3::triskar();
        let field = field_for(&triskar);
        let (end, _) = run(
            &triskar,
            start,
            800,
            |p| field.command(p, &target, &obstacles),
            outside(&obstacles, 0.25),
        );
        assert!(end.distance(&target) < 0.02, "{name}: ended at {end:?}");
        assert!(angle_diff(end.theta, target.theta).abs() < 0.03, "{name}: ended at {end:?}");

        let ianus = DiffDrive::ianus3();
        let field = field_for(&ianus);
        let (end, _) = run(
            &ianus,
            start,
            800,
            |p| field.command(p, &target, &obstacles),
            outside(&obstacles, 0.25),
        );
        assert!(end.distance(&target) < 0.02, "{name} (diff): ended at {end:?}");
        assert!(
            angle_diff(end.theta, target.theta).abs() < 0.03,
            "{name} (diff): ended at {end:?}"
        );
    }
}

/// Position mode reaches postures in all directions, forwards and (IANUS3) backwards.
#[test]
fn position_mode_reaches_postures() {
    let targets = [
        Pose2::new(1.0, 1.0, std::f64::consts::FRAC_PI_2),
        Pose2::new(-1.5, 0.2, 0.0),
        Pose2::new(0.3, -2.0, 3.0),
    ];
    for target in targets {
        let triskar = Omni3::triskar();
        let mode = PositionMode::default();
        let (end, last) =
            run(&triskar, Pose2::identity(), 500, |p| mode.command(p, &target), |_| {});
        assert!(end.distance(&target) < 0.02 && last.done, "{target:?}: {end:?}");
        assert!(angle_diff(end.theta, target.theta).abs() < 0.03);

        let ianus = DiffDrive::ianus3();
        let params = PositionParams { steering: ianus.steering(), ..PositionParams::default() };
        let mode = match PositionMode::new(params) {
            Ok(m) => m,
            Err(e) => panic!("{e}"),
        };
        let (end, last) = run(&ianus, Pose2::identity(), 500, |p| mode.command(p, &target), |_| {});
        assert!(end.distance(&target) < 0.02 && last.done, "diff {target:?}: {end:?}");
        assert!(angle_diff(end.theta, target.theta).abs() < 0.03);
    }
}

/// Sixteen sonars (ISocRob §2) seeing a wall `x = wall` from `pose`: a ray at field angle φ
/// with cos φ > 0 hits it at `(wall − x) / cos φ`; the sonars reach 5 m.
fn sonars_facing_wall(pose: &Pose2, wall: f64) -> Vec<Sonar> {
    (0..16)
        .map(|i| {
            let bearing = Sonar::ring_bearing(i, 16);
            let c = (pose.theta + bearing).cos();
            let range = if c > 1e-9 { (wall - pose.x) / c } else { f64::INFINITY };
            Sonar::new(bearing, if range < 5.0 { range } else { f64::INFINITY })
        })
        .collect()
}

/// Velocity mode: IANUS3 drives at 1 m/s toward a wall at x = 2 m; the guard (0.49 m, ±30°)
/// halts it. Without a ramp the robot moves 0.02 m per step (x = 0.02 k); sonar 0 reads
/// 2 − x, so the first blocked command is at x = 1.52 (the first x with 2 − x < 0.49, i.e.
/// x > 1.51), and the robot stays there. With the ramp (60 rad/s² = 3 m/s²) it accelerates
/// first, so the stop comes within one step of travel past x = 1.51 and it then brakes at
/// 3 m/s², which from 1 m/s takes 1/6 m.
#[test]
fn velocity_mode_halts_before_a_wall() {
    let guard = match VelocityGuard::new(0.49, std::f64::consts::FRAC_PI_6) {
        Ok(g) => g,
        Err(e) => panic!("{e}"),
    };
    let wall = 2.0;
    let reference = Twist::new(1.0, 0.0, 0.0);

    // Ideal base (no ramp): exact stop position by hand.
    let mut pose = Pose2::identity();
    let mut halted_at = None;
    for k in 0..200 {
        let cmd = guard.apply(&reference, &sonars_facing_wall(&pose, wall));
        if cmd.done && halted_at.is_none() {
            halted_at = Some(k);
        }
        pose = integrate(pose, &cmd.twist, DT);
    }
    assert_eq!(halted_at, Some(76), "x = 0.02·76 = 1.52");
    assert!((pose.x - 1.52).abs() < 1e-9, "{pose:?}");

    // IANUS3 with its acceleration limit: halts, never touches the wall (robot radius 0.25).
    let ianus = DiffDrive::ianus3();
    let (end, last) = run(
        &ianus,
        Pose2::identity(),
        400,
        |p| guard.apply(&reference, &sonars_facing_wall(p, wall)),
        |p| assert!(wall - p.x > 0.25, "hit the wall at {p:?}"),
    );
    assert!(last.done && last.twist == Twist::ZERO, "{last:?}");
    // Stopped between 1.51 − (one step) and 1.51 + 1/6 + (one step of travel).
    assert!(end.x > 1.49 && end.x < 1.51 + 1.0 / 6.0 + 0.02, "{end:?}");

    // Backing away from the wall is not halted.
    let back = Twist::new(-1.0, 0.0, 0.0);
    let near = Pose2::new(1.7, 0.0, 0.0);
    assert!(!guard.apply(&back, &sonars_facing_wall(&near, wall)).done);
    // Driving backwards into the wall (robot turned around) is.
    let turned = Pose2::new(1.7, 0.0, std::f64::consts::PI);
    assert!(guard.apply(&back, &sonars_facing_wall(&turned, wall)).done);
}
