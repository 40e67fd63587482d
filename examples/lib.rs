//! MRT's numbered examples, also usable as a library so that `mrt demo` runs exactly the
//! example code. Run one with `cargo run -p mrt-examples --example 01_hello_agora`.
#![allow(clippy::print_stdout)]

#[path = "06_anchoring_robots.rs"]
pub mod anchoring_robots;
#[path = "08_coordinating_with_scare.rs"]
pub mod coordinating_with_scare;
#[path = "03_fuzzy_controller.rs"]
pub mod fuzzy_controller;
#[path = "01_hello_agora.rs"]
pub mod hello_agora;
#[path = "07_planning_a_path.rs"]
pub mod planning_a_path;
#[path = "05_robot_on_its_own_devices.rs"]
pub mod robot_on_its_own_devices;
#[path = "04_teamchaos_behaviors.rs"]
pub mod teamchaos_behaviors;
#[path = "02_two_agoras.rs"]
pub mod two_agoras;

#[cfg(test)]
mod tests {
    /// Example 08: every robot computes the same allocation; with the opponent in front of
    /// the ball robots 2 and 3 run the passage, the keeper keeps goal, robot 4 defends;
    /// without it robot 2 brings the ball.
    #[test]
    fn coordinating_with_scare_gives_every_robot_the_same_allocation() {
        use super::coordinating_with_scare::run;
        let (views, job) = run(&[(-0.2, 0.0)], false);
        assert!(views.windows(2).all(|w| w[0] == w[1]), "{views:?}");
        let expect =
            |v: &[(u32, &str)]| v.iter().map(|(r, a)| (*r, a.to_string())).collect::<Vec<_>>();
        assert_eq!(
            views[0],
            expect(&[(1, "Goalie"), (2, "PassageToMate"), (3, "PassageToMate"), (4, "Defense")])
        );
        assert_eq!(job, "PassageToMate (passer), sub-task ReachBall");
        let (views, job) = run(&[], false);
        assert!(views.windows(2).all(|w| w[0] == w[1]), "{views:?}");
        assert_eq!(views[0][1], (2, "BringBall".to_string()));
        // Robot 2 stands 0.5 m behind the ball on the line to the net: ReachBall is done.
        assert_eq!(job, "BringBall, sub-task Shoot");
    }

    /// Example 07: the door is taken when the building is empty, a visitor in the doorway
    /// blocks the first path and leaves no other, and a visitor on the path in the right
    /// room blocks it and is gone round (0.25 + 0.3 + 0.1 m from the visitor's centre).
    #[test]
    fn planning_a_path_takes_the_door_unless_someone_stands_in_it() {
        let out = super::planning_a_path::run(false).unwrap();
        let empty = out[0].plan.as_ref().unwrap();
        // The door's gap is x = 0, y from 0.55 to 1.45: the path crosses x = 0 inside it.
        let crossing = empty.waypoints.windows(2).find_map(|w| {
            let t = (0.0 - w[0].x) / (w[1].x - w[0].x);
            (0.0..=1.0).contains(&t).then(|| w[0].y + t * (w[1].y - w[0].y))
        });
        assert!(crossing.is_some_and(|y| (0.55..=1.45).contains(&y)), "{crossing:?}");
        assert!(!out[0].first_blocked);
        assert!(out[1].first_blocked && out[1].plan.is_err(), "the doorway is shut");
        let round = out[2].plan.as_ref().unwrap();
        assert!(out[2].first_blocked && round.length > empty.length);
        let visitor = mrt_core::Point2::new(2.7, -1.7);
        let gap = round
            .waypoints
            .windows(2)
            .map(|w| mrt_plan::spike::Shape::Wall { a: w[0], b: w[1] }.distance(visitor))
            .fold(f64::INFINITY, f64::min);
        assert!(gap >= 0.65 - 1e-9, "{gap}");
    }

    use mrt_dcdt::ExitReason;
    use std::time::Duration;

    #[test]
    fn hello_agora_delivers_every_greeting_and_shuts_down() {
        let report = super::hello_agora::run(5, Duration::from_millis(1), false).unwrap();
        assert_eq!(report.exit, ExitReason::Shutdown);
        let names: Vec<_> = report.members.iter().map(|m| (m.name.as_str(), m.cycles)).collect();
        assert_eq!(names[0], ("Greeter", 5));
        assert_eq!(names[1].0, "Listener");
        assert!(names[1].1 >= 1 && names[1].1 <= 5);
    }

    /// MAP in the world model: the crossing robots keep their identities and their teams, the
    /// hidden opponent is kept (fading) and found again, and the free way to the net opens
    /// once both have passed.
    #[test]
    fn two_crossing_robots_keep_their_identities_and_teams() {
        use mrt_msgs::RobotClass;
        let moments = super::anchoring_robots::run(false).unwrap();
        let at = |t: f64| moments.iter().find(|m| (m.time - t).abs() < 1e-9).unwrap();
        // From 0.5 s on, one anchor per team, always the same identities.
        let ids = |t: f64, class| -> Vec<u32> {
            at(t).robots.iter().filter(|r| r.class == class).map(|r| r.id).collect()
        };
        let (mate, opponent) = (ids(0.5, RobotClass::Teammate), ids(0.5, RobotClass::Opponent));
        assert_eq!((mate.len(), opponent.len()), (1, 1), "{:?}", at(0.5).robots);
        for t in [1.0, 2.0, 3.0, 4.0] {
            assert_eq!(ids(t, RobotClass::Teammate), mate, "t = {t}");
            assert_eq!(ids(t, RobotClass::Opponent), opponent, "t = {t}: {:?}", at(t).robots);
        }
        // Hidden from 1.5 s: at 2.0 s unseen for 0.6 s, reliability 0.5^0.6 ≈ 0.66, predicted
        // near where it is (x −0.1, y 0 m).
        let hidden = at(2.0).robots.iter().find(|r| r.class == RobotClass::Opponent).unwrap();
        assert!((hidden.reliability - 0.5f64.powf(0.6)).abs() < 1e-6, "{hidden:?}");
        let hidden_at = hidden.at.inner;
        assert!((hidden_at.x + 0.1).abs() < 0.15 && hidden_at.y.abs() < 0.3, "{hidden:?}");
        // At the end the teammate is 2 m north, the opponent 2 m south, both seen.
        let end = &at(4.0).robots;
        let mate = end.iter().find(|r| r.class == RobotClass::Teammate).unwrap();
        assert!((mate.at.inner.y - 2.0).abs() < 0.1 && mate.reliability == 1.0);
        // Straight ahead is blocked while they cross, and free at the start and the end.
        assert_eq!(at(0.0).free_direction, Some(0.0));
        assert_ne!(at(2.0).free_direction, Some(0.0));
        assert_eq!(at(4.0).free_direction, Some(0.0));
    }

    /// The robot program runs on a team's own `Devices` with no simulator: the baseline walks
    /// from 2 m to the ball and kicks it.
    #[test]
    fn the_robot_program_runs_on_its_own_devices_and_kicks() {
        let out = super::robot_on_its_own_devices::run(40, false).unwrap();
        assert!(out.distances[0] > 1.8, "{:?}", out.distances);
        // `kicks` counts cycles from 1; `distances[k - 1]` is measured after cycle k.
        let first = *out.kicks.first().unwrap();
        assert!(first > 2 && first < 30, "{:?}", out.kicks);
        let before = out.distances[first - 2];
        assert!(before < 0.6, "walked up to the ball: {before} m before the kick");
        assert!(out.distances[first - 1] > 2.0, "and kicked it away: {:?}", out.distances);
    }

    #[test]
    fn two_agoras_separates_local_and_remote() {
        let seen = super::two_agoras::run(Duration::from_millis(100), false).unwrap();
        // Robot 1's own-sightings listener hears only robot 1 (every 20 ms: 0..=80 -> 5);
        // its teammate listener hears only robot 2 (every 30 ms: 0..=90 -> 4).
        assert_eq!(seen.own, vec![1; 5]);
        assert_eq!(seen.teammates, vec![2; 4]);
    }

    #[test]
    fn teamchaos_attacker_scores_and_hot_reload_applies_at_the_next_cycle() {
        use super::teamchaos_behaviors::run;
        let scratch =
            std::env::temp_dir().join(format!("mrt-example-04-test-{}", std::process::id()));
        let out = run(&scratch, false).unwrap();
        std::fs::remove_dir_all(&scratch).unwrap();
        let a = &out.attacker;
        let paths: Vec<&str> = a.iter().map(|s| s.path.as_str()).collect();
        // The ball starts on the left: face it, walk to it, score with a kick at the end.
        assert_eq!(paths[0], "Attacker/FaceBall");
        assert!(a[0].vrot > 0.0, "ball on the left: turn left");
        let first_walk = paths.iter().position(|p| *p == "Attacker/GoToBall").unwrap();
        assert!(paths.iter().skip(first_walk).any(|p| p.starts_with("Attacker/Score/")));
        let last = a.last().unwrap();
        assert_eq!((last.path.as_str(), last.kick), ("Attacker/Score/DoKick", Some(1)));
        // Cycle 15: go2ball edited (FAST -> SLOW) and reloaded; the walk slows down at once.
        assert_eq!(a[15].events, ["reloaded go2ball"]);
        // Walking on FAST the robot asks for 2.9 m/s; the SLOW version for 2.3 at once
        // (Mamdani centroids of FAST or SLOW clipped at ballAhead, against a little STAY; the
        // team's labels are the seed's scaled to a Middle Size robot, docs/teams.md; the base
        // drives either at its top speed).
        assert!(a[14].vlin > 2700.0 && a[15].vlin < 2400.0, "{} -> {}", a[14].vlin, a[15].vlin);
        assert!(a[15..20].iter().all(|s| s.behavior == "go2ball" && s.vlin < 2400.0));
        // Cycle 20: a broken edit is rejected with file:line, and the robot keeps going.
        assert_eq!(a[20].events.len(), 1);
        let rejected = &a[20].events[0];
        assert!(
            rejected.starts_with("rejected: ") && rejected.contains("go2ball.lua:"),
            "{rejected}"
        );
        assert!(a[21..].iter().all(|s| s.events.is_empty()));
        assert!(a[21].vlin > 0.0, "still walking with the last good go2ball");
        // The goalkeeper: scanning for a lost ball, leaving its net, stepping onto the line.
        let gk = &out.goalkeeper;
        assert!(gk[0].vrot != 0.0 && gk[0].track_landmarks, "ball lost: turns to look for it");
        assert!(gk[1].vlin > 0.0, "inside its net: moves out");
        let spot = gk[2].target.expect("off the line: it asks guidance for its spot");
        assert!((spot.x + 8.6).abs() < 1e-9 && (spot.y - 0.3).abs() < 1e-9, "{spot:?}");
    }

    #[test]
    fn fuzzy_controller_steers_sensibly() {
        use super::fuzzy_controller::{config_dir, run, situations};
        let outcomes = run(&config_dir(), false).unwrap();
        assert_eq!(outcomes.len(), situations().len());
        let cmd = |situation: &str, action: &str| -> f64 {
            let o = outcomes.iter().find(|o| o.situation == situation).unwrap();
            *o.commands.get(action).unwrap_or_else(|| panic!("{situation}: no {action}"))
        };
        // Angular distance in degrees, in [0, 180].
        let apart = |a: f64, b: f64| {
            let d = (a - b).rem_euclid(360.0);
            d.min(360.0 - d)
        };

        // Far target straight ahead: FAST (75 cm/s), straight on.
        assert!((cmd("target far ahead", "SpeedModule") - 75.0).abs() < 1e-9);
        assert!(apart(cmd("target far ahead", "SpeedAngle"), 0.0) < 1e-9);

        // Near target on the left (80°): slower, and to the left.
        let near = "target near, to the left";
        assert!(cmd(near, "SpeedModule") < cmd("target far ahead", "SpeedModule"));
        assert!(apart(cmd(near, "SpeedAngle"), 80.0) <= 15.0);

        // Obstacle 50 cm ahead (10°) on the way to the target: AvoidObstacle (level 2) deletes
        // the heading proposed by GoToTarget and turns away, and slows down.
        let obstacle = "obstacle ahead while going to the target";
        let heading = cmd(obstacle, "SpeedAngle");
        assert!(apart(heading, 10.0) >= 60.0, "still heading for the obstacle: {heading}");
        assert!(apart(heading, cmd("target far ahead", "SpeedAngle")) >= 60.0);
        assert!(cmd(obstacle, "SpeedModule") < cmd("target far ahead", "SpeedModule") / 2.0);
        let o = outcomes.iter().find(|o| o.situation == obstacle).unwrap();
        assert!(o
            .behaviors
            .iter()
            .any(|b| b.name == "AvoidObstacle" && b.level == 2 && b.ran.is_some()));

        // Battery almost empty: GoToTarget cannot pursue a far target (CANDO), GoToHome wants
        // to go home (WANT): the robot heads home (200°), away from the target (0°).
        let battery = "battery almost empty";
        let heading = cmd(battery, "SpeedAngle");
        assert!(apart(heading, 200.0) <= 30.0, "not heading home: {heading}");
        assert!(apart(heading, 0.0) >= 90.0);
        let o = outcomes.iter().find(|o| o.situation == battery).unwrap();
        assert!(o.behaviors.iter().any(|b| b.name == "GoToTarget" && b.ran.is_none()));
        assert!(o
            .behaviors
            .iter()
            .any(|b| b.name == "GoToHome" && b.ran.is_some_and(|(_, w)| w > 0.49)));
    }
}
