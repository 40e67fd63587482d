//! MRT's numbered examples, also usable as a library so that `mrt demo` runs exactly the
//! example code. Run one with `cargo run -p mrt-examples --example 01_hello_agora`.
#![allow(clippy::print_stdout)]

#[path = "03_fuzzy_controller.rs"]
pub mod fuzzy_controller;
#[path = "01_hello_agora.rs"]
pub mod hello_agora;
#[path = "02_two_agoras.rs"]
pub mod two_agoras;

#[cfg(test)]
mod tests {
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

    #[test]
    fn two_agoras_separates_local_and_remote() {
        let seen = super::two_agoras::run(Duration::from_millis(100), false).unwrap();
        // Robot 1's own-sightings listener hears only robot 1 (every 20 ms: 0..=80 -> 5);
        // its teammate listener hears only robot 2 (every 30 ms: 0..=90 -> 4).
        assert_eq!(seen.own, vec![1; 5]);
        assert_eq!(seen.teammates, vec![2; 4]);
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
