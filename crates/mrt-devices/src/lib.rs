//! # mrt-devices: the device protocol
//!
//! What a world (a simulator in any language, or the bridge to a real robot's boards) sends
//! each robot every step, and what the robot answers: UTF-8 JSON in SI units over zenoh keys
//! that name the world and the robot, lock-step by default (docs/devices.md specifies it all;
//! the JSON Schemas of [`schemas`] are published in `schemas/devices/1/`). This crate holds the
//! messages ([`messages`]), the keys ([`Keys`]), the robot's rules for what it takes
//! ([`Gate`]) and the world's side for a world written in Rust ([`world`]); the robot that
//! runs on them is `mrt_robot::world`, the transport `mrt robot`'s.
//!
//! ```
//! use mrt_devices::{Admitted, Gate, Keys};
//! use std::time::Instant;
//!
//! let keys = Keys::new("stub", "home-1")?;
//! assert_eq!(keys.sense(), "mrt/devices/1/stub/home-1/sense");
//! let mut gate = Gate::new("stub", "home-1", 2);
//! let sense = br#"{"protocol": 1, "world": "stub", "run": "r1", "robot": "home-1",
//!     "step": 0, "time": 0.0, "odometry": {"wheels": [0.1, 0.1]},
//!     "game": {"state": "playing", "attack": 1}}"#;
//! let Ok(Admitted::Step(readings)) = gate.admit(sense, Instant::now()) else { panic!() };
//! assert_eq!(readings.wheel_turns, Some(vec![0.1, 0.1]));
//! assert!(gate.admit(b"{not json", Instant::now()).is_err());
//! assert_eq!(gate.dropped().malformed, 1);
//! # Ok::<(), mrt_devices::Refusal>(())
//! ```
#![deny(missing_docs)]

mod gate;
pub mod messages;
pub mod world;

pub use gate::{
    image, is_name, Admitted, Gate, Readings, Refusal, MAX_IMAGE_SIDE, MAX_MESSAGE, MAX_TIME_STEP,
    RUN_SILENCE,
};
pub use messages::{Act, Bye, Dropped, End, Sense, PROTOCOL};

/// The zenoh keys of one robot of one world (docs/devices.md, "Keys").
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Keys {
    world: String,
    robot: String,
}

impl Keys {
    /// The keys of robot `robot` in world `world` (names of 1–64 of `a–z 0–9 - _`).
    pub fn new(world: &str, robot: &str) -> Result<Keys, Refusal> {
        for name in [world, robot] {
            if !is_name(name) {
                return Err(Refusal::Malformed(format!(
                    "{:?} is not a name (1-64 of a-z 0-9 - _)",
                    name.escape_debug().to_string()
                )));
            }
        }
        Ok(Keys { world: world.into(), robot: robot.into() })
    }

    /// The world's name.
    pub fn world(&self) -> &str {
        &self.world
    }

    /// The robot's name.
    pub fn robot(&self) -> &str {
        &self.robot
    }

    fn robot_key(&self, last: &str) -> String {
        format!("mrt/devices/{PROTOCOL}/{}/{}/{last}", self.world, self.robot)
    }

    /// World → robot: one step's readings.
    pub fn sense(&self) -> String {
        self.robot_key("sense")
    }

    /// Robot → world: the answer.
    pub fn act(&self) -> String {
        self.robot_key("act")
    }

    /// Robot → world: the last word.
    pub fn bye(&self) -> String {
        self.robot_key("bye")
    }

    /// The robot's liveliness token.
    pub fn alive(&self) -> String {
        self.robot_key("alive")
    }

    /// World → all its robots: the match is over.
    pub fn end(&self) -> String {
        format!("mrt/devices/{PROTOCOL}/{}/end", self.world)
    }

    /// The world's liveliness token ([`world_alive`]).
    pub fn world_alive(&self) -> String {
        world_alive(&self.world)
    }
}

/// The liveliness token world `world` holds while it runs: a robot that saw it and sees it go
/// ends at once (its world is gone) instead of waiting out its silence.
pub fn world_alive(world: &str) -> String {
    format!("mrt/devices/{PROTOCOL}/{world}/alive")
}

/// The JSON Schema of each message, by file name (`sense.schema.json`, …): what
/// `schemas/devices/1/` holds.
pub fn schemas() -> Vec<(&'static str, serde_json::Value)> {
    fn one<T: schemars::JsonSchema>() -> serde_json::Value {
        serde_json::to_value(schemars::schema_for!(T)).unwrap_or_default()
    }
    vec![
        ("sense.schema.json", one::<Sense>()),
        ("act.schema.json", one::<Act>()),
        ("end.schema.json", one::<End>()),
        ("bye.schema.json", one::<Bye>()),
    ]
}
