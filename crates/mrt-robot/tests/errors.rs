//! What each error of the robot program says: the kind of trouble as its variant, the value
//! to change in its message.

#![allow(clippy::unwrap_used)]

use mrt_robot::spec::Stack;
use mrt_robot::stacks::send_brain;
use mrt_robot::RobotError;

#[test]
fn each_error_says_where_the_trouble_is() {
    let e = Stack::parse("lego").unwrap_err();
    assert!(matches!(&e, RobotError::UnknownStack(name) if name == "lego"), "{e:?}");
    assert_eq!(e.to_string(), "unknown team stack 'lego' (chaos, milan, isocrob, chaser)");
    let e = mrt_robot::base::Base::parse("legs").unwrap_err();
    assert!(matches!(e, RobotError::UnknownBase(_)), "{e:?}");
    let mut file = mrt_robot::config::RobotFile::default();
    file.body.radius = -1.0;
    let e = file.config().unwrap_err();
    assert!(matches!(e, RobotError::Config(_)), "{e:?}");
    assert_eq!(e.to_string(), "body.radius must be a finite number > 0, not -1");
    file.body.radius = 0.25;
    file.body.base = "legs".into();
    let e = file.config().unwrap_err();
    assert_eq!(e.to_string(), "body.base must be differential or omni, not legs");
    let e = send_brain(Stack::Isocrob, false).err();
    assert!(matches!(e, Some(RobotError::StackWiring(_))), "{e:?}");
}
