//! # mrt-msgs: MRT's standard messages
//!
//! The MRT manual builds a robot out of sensing, reasoning and acting modules that talk over
//! one bus (§2.1). This crate is the one catalogue of what they say to each other, so that
//! drivers, world models, behaviors (Lua, fuzzy, Rust) and motor drivers written by different
//! people plug together: every standard message's Rust type, with its [`Message`] id taken
//! from one table ([`ids`]). It depends on `mrt-core` and `serde` only: a tool that reads
//! recordings or a driver for a new robot needs no bus, no engine and no simulator.
//!
//! | message | from → to | seed |
//! |---|---|---|
//! | [`Odometry`] (mice readings, wheels, placement) | odometry driver → world model | manual ch. 4 |
//! | [`CameraFrame`] (sightings of ball, nets, landmarks) | camera driver → world model | ISocRob-2000 report §3.2.1 |
//! | [`SonarScan`] of [`Sonar`]s | sonar driver → guidance | ISocRob-2000 report §2, §3.2.3 |
//! | [`GameInfo`] | game controller → world model | ThinkingCap/TeamChaos report §3.3 (`getCurrentState`) |
//! | [`MateReport`] | world model → teammates' world models | ISocRob-2000 report §3.1 |
//! | [`Localization`] (pose, uncertainty, [`FilterCounts`]) | world model → monitors, recorders | ThinkingCap/TeamChaos report §4.1 |
//! | [`WorldSnapshot`] | world model → behaviors, guidance | ThinkingCap/TeamChaos report §3.3 (LPS, GS) |
//! | [`RobotCommand`] | behaviors → guidance | ThinkingCap/TeamChaos report §3.3 |
//! | [`MotorCommand`] | guidance → motor and kicker driver | ISocRob-2000 report §3.2.3 |
//! | [`PlanRequest`], [`PlannedPath`] | guidance (or SCARE) ↔ planner | manual ch. 9 (SPIKE) |
//! | [`BehaviorStatus`], [`ReloadRequest`], [`BehaviorPush`], [`BehaviorPushReply`] | behavior Member ↔ monitors, editors | ThinkingCap/TeamChaos report §3.2 |
//! | [`HfsmStructure`] (the machine's states and transitions) | HFSM Member → monitors | ThinkingCap/TeamChaos report §4.1, §5.1 |
//!
//! Three standard messages live with their engine and take their id from [`ids`] too: the
//! blackboard's `BbUpdate` (`mrt-blackboard`), the bus's XML `SelfDescribing` message
//! (`mrt-dcdt`, feature `describe`) and `mrt-net`'s probes.
//!
//! ```
//! use mrt_msgs::{ids, Message, MateReport, WorldSnapshot};
//!
//! let w = WorldSnapshot::default();
//! let report = MateReport::of(2, false, &w);
//! assert_eq!(MateReport::TYPE, ids::MATE_REPORT);
//! assert_eq!(ids::name_of(MateReport::TYPE), Some(MateReport::NAME));
//! assert_eq!(report.ball.quality, 0.0, "nothing seen yet");
//! ```
#![deny(missing_docs)]

mod acting;
mod behavior;
mod fault;
pub mod ids;
mod localization;
pub mod robot;
mod sensing;
mod team;

#[cfg(test)]
mod describe_tests;

pub use acting::{MotorCommand, PlanRequest, PlannedPath};
pub use behavior::{
    BehaviorPush, BehaviorPushReply, BehaviorStatus, HfsmMachine, HfsmState, HfsmStructure,
    HfsmTransition, ReloadRequest,
};
pub use fault::MemberFault;
pub use localization::{BallBelief, FilterCounts, Localization};
pub use mrt_core::{Message, MsgType};
pub use robot::{
    lps, AnchoredRobot, Estimate, Field, GameState, Lpo, Mate, RobotClass, RobotCommand, ScareJob,
    Target, WorldSnapshot,
};
pub use sensing::sighting;
pub use sensing::{
    CameraFrame, DetectionKind, Displacement, GameInfo, Image, ImageDetection, ImageDetections,
    Marker, MiceReadings, Odometry, Percepts, PostSighting, RobotSighting, Sighting, Sonar,
    SonarScan, FIELD_OBJECTS,
};
pub use team::{BookingReport, MateReport, ScareReport, SharedRobot};

/// Declares the [`Message`] impls of the catalogue, each with its id from [`ids`] and its name
/// as the table gives it.
macro_rules! messages {
    ($($ty:ty => $id:ident),* $(,)?) => {
        $(impl Message for $ty {
            const TYPE: MsgType = ids::$id;
            const NAME: &'static str = stringify!($ty);
        })*

        /// The catalogue's types as `(id, name)`, for the table test.
        #[cfg(test)]
        const CATALOGUE: &[(MsgType, &str)] = &[$((ids::$id, stringify!($ty))),*];

        /// Visits every type of the catalogue, for the tests that must cover them all: a type
        /// added here without samples ([`describe_tests::Samples`]) fails to compile.
        #[cfg(test)]
        fn visit_catalogue(visitor: &mut impl describe_tests::Visitor) {
            $(visitor.visit::<$ty>();)*
        }
    };
}

messages! {
    WorldSnapshot => WORLD_SNAPSHOT,
    RobotCommand => ROBOT_COMMAND,
    BehaviorStatus => BEHAVIOR_STATUS,
    ReloadRequest => RELOAD_REQUEST,
    BehaviorPush => BEHAVIOR_PUSH,
    BehaviorPushReply => BEHAVIOR_PUSH_REPLY,
    HfsmStructure => HFSM_STRUCTURE,
    MateReport => MATE_REPORT,
    SonarScan => SONAR_SCAN,
    MotorCommand => MOTOR_COMMAND,
    Odometry => ODOMETRY,
    CameraFrame => CAMERA_FRAME,
    GameInfo => GAME_INFO,
    Localization => LOCALIZATION,
    Percepts => PERCEPTS,
    PlanRequest => PLAN_REQUEST,
    PlannedPath => PLANNED_PATH,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every type of the catalogue has the id and the name the table gives it, and so does the
    /// bus's self-describing message.
    #[test]
    fn the_catalogue_agrees_with_the_table() {
        for (ty, name) in CATALOGUE {
            assert_eq!(ids::name_of(*ty), Some(*name), "{ty}");
        }
        use mrt_dcdt::describe::SelfDescribing;
        assert_eq!(CATALOGUE.len() + 6, ids::TABLE.len(), "SelfDescribing, BbUpdate, 4 probes");
        assert_eq!(SelfDescribing::TYPE, ids::SELF_DESCRIBING);
        assert_eq!(ids::name_of(SelfDescribing::TYPE), Some(SelfDescribing::NAME));
    }

    /// A framed pose is its pose on the wire: typing the frames changed no byte, and a field
    /// frame pose reads back as one.
    #[test]
    fn framed_fields_are_their_values_on_the_wire() {
        use mrt_core::frames::{Field, Framed};
        use mrt_core::Pose2;
        let pose = Pose2::new(-1.5, 2.0, 0.25);
        let framed: Framed<Field, Pose2> = Framed::new(pose);
        assert_eq!(serde_json::to_string(&framed).unwrap(), serde_json::to_string(&pose).unwrap());
        let g = GameInfo {
            state: GameState::Ready,
            attack: -1.0,
            kickoff_pose: Some(framed),
            marker: Some(Marker::Cyan),
        };
        let back: GameInfo = serde_json::from_str(&serde_json::to_string(&g).unwrap()).unwrap();
        assert_eq!(back, g);
    }

    /// A sonar without an echo (an infinite range) is `null` in JSON, which has no infinity,
    /// and reads back as no echo; the bus's binary form keeps the number.
    #[test]
    fn a_sonar_without_an_echo_survives_json_and_the_wire() {
        let scan = SonarScan { sonars: vec![Sonar::new(0.0, f64::INFINITY), Sonar::new(1.0, 2.5)] };
        let json = serde_json::to_string(&scan).unwrap();
        assert!(json.contains(r#""range":null"#), "{json}");
        let back: SonarScan = serde_json::from_str(&json).unwrap();
        assert_eq!(back, scan);
        let bytes = postcard::to_stdvec(&scan).unwrap();
        let back: SonarScan = postcard::from_bytes(&bytes).unwrap();
        assert_eq!(back, scan);
    }
}
