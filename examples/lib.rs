//! MRT's numbered examples, also usable as a library so that `mrt demo` runs exactly the
//! example code. Run one with `cargo run -p mrt-examples --example 01_hello_agora`.
#![allow(clippy::print_stdout)]

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
}
