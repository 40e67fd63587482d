//! What each error of the simulator says: the kind of trouble as its variant, the value to
//! change in its message, the error it came from as its source.

#![allow(clippy::unwrap_used)]

use mrt_sim::config::SimConfig;
use mrt_sim::game::Pitch;
use mrt_sim::SimError;

#[test]
fn each_error_says_where_the_trouble_is() {
    let mut cfg = SimConfig::oracle();
    cfg.body.radius = 0.6;
    let e = cfg.validate().unwrap_err();
    assert!(matches!(e, SimError::Config(_)), "{e:?}");
    assert!(e.to_string().starts_with("body.radius must be at most 0.575 m"), "{e}");
    let cfg = SimConfig::oracle();
    let e = Pitch::new(&cfg, 1, 3, 0).err();
    assert!(matches!(&e, Some(SimError::Match(m)) if m.contains("each team needs 4")), "{e:?}");
    let mut cfg = SimConfig::oracle();
    cfg.body.base = "legs".into();
    let e = cfg.robot().unwrap_err();
    assert!(matches!(e, SimError::Robot(mrt_robot::RobotError::Config(_))), "{e:?}");
    let source = std::error::Error::source(&e).map(|s| s.to_string());
    assert_eq!(source, None, "a robot file's value is its own message");
    assert_eq!(e.to_string(), "body.base must be differential or omni, not legs");
}
