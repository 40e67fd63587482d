//! The one table of MRT's message type ids.
//!
//! Every standard message's [`MsgType`] is defined here and nowhere else; the types that carry
//! them (in this crate, and the few that live with their engine: the blackboard's `BbUpdate`,
//! the bus's `SelfDescribing`, `mrt-net`'s probe messages) take their id from this table. All
//! Agoras of a community must agree on the ids (MRT manual §3.2): a change here breaks the wire
//! with every robot built before it, so the test below pins every value.

use mrt_core::{MsgType, RESERVED_TYPES_START};

const fn reserved(offset: u32) -> MsgType {
    MsgType(RESERVED_TYPES_START + offset)
}

/// The XML self-describing message (manual §3.2; `mrt_dcdt::describe::SelfDescribing`).
pub const SELF_DESCRIBING: MsgType = reserved(0x01);
/// [`crate::WorldSnapshot`]: what the behaviors read each cycle.
pub const WORLD_SNAPSHOT: MsgType = reserved(0x20);
/// [`crate::RobotCommand`]: what the behaviors ask for each cycle.
pub const ROBOT_COMMAND: MsgType = reserved(0x21);
/// [`crate::BehaviorStatus`]: what a behavior Member did in its last cycle.
pub const BEHAVIOR_STATUS: MsgType = reserved(0x30);
/// [`crate::ReloadRequest`]: reload the edited behaviors at the next cycle boundary.
pub const RELOAD_REQUEST: MsgType = reserved(0x31);
/// [`crate::BehaviorPush`]: an edited behavior file for a running robot.
pub const BEHAVIOR_PUSH: MsgType = reserved(0x32);
/// [`crate::BehaviorPushReply`]: the robot's answer to a behavior push.
pub const BEHAVIOR_PUSH_REPLY: MsgType = reserved(0x33);
/// [`crate::HfsmStructure`]: the states and transitions of a behavior Member's HFSM.
pub const HFSM_STRUCTURE: MsgType = reserved(0x34);
/// [`crate::MateReport`]: a robot's pose and ball, told to its teammates.
pub const MATE_REPORT: MsgType = reserved(0x40);
/// [`crate::SonarScan`]: one reading of the sonar ring.
pub const SONAR_SCAN: MsgType = reserved(0x41);
/// [`crate::MotorCommand`]: what guidance asks of the motor and kicker driver.
pub const MOTOR_COMMAND: MsgType = reserved(0x42);
/// [`crate::Odometry`]: the mice and wheels since the last reading.
pub const ODOMETRY: MsgType = reserved(0x43);
/// [`crate::CameraFrame`]: what the camera (object sensor) saw.
pub const CAMERA_FRAME: MsgType = reserved(0x44);
// 0x45–0x48 carried a simulator's device frames over the bus before the device protocol
// (docs/devices.md) replaced them: retired, never to be given to another type.
/// [`crate::GameInfo`]: the game controller's news.
pub const GAME_INFO: MsgType = reserved(0x49);
/// [`crate::Localization`]: the world model's own pose estimate, for monitors.
pub const LOCALIZATION: MsgType = reserved(0x4A);
/// [`crate::Percepts`]: what the vision µAgent found in a camera image.
pub const PERCEPTS: MsgType = reserved(0x4B);
/// [`crate::PlanRequest`]: guidance (or SCARE) → planner.
pub const PLAN_REQUEST: MsgType = reserved(0x4C);
/// [`crate::PlannedPath`]: planner → guidance, monitors.
pub const PLANNED_PATH: MsgType = reserved(0x4D);
/// The blackboard's `BbUpdate` (ISocRob-2000 report §3.1; `mrt_blackboard::proxy`).
pub const BB_UPDATE: MsgType = reserved(0x50);
/// `mrt-net`'s probe: a ping (for `mrt-net-node` and the network tests).
pub const NET_PING: MsgType = MsgType(0x4E45_5401);
/// `mrt-net`'s probe: a timed probe.
pub const NET_PROBE: MsgType = MsgType(0x4E45_5402);
/// `mrt-net`'s probe: the echo of a probe.
pub const NET_ECHO: MsgType = MsgType(0x4E45_5403);
/// `mrt-net`'s probe: a flood of bytes.
pub const NET_FLOOD: MsgType = MsgType(0x4E45_5404);

/// Every id of the table with its message's name, in id order.
pub const TABLE: &[(MsgType, &str)] = &[
    (SELF_DESCRIBING, "SelfDescribing"),
    (WORLD_SNAPSHOT, "WorldSnapshot"),
    (ROBOT_COMMAND, "RobotCommand"),
    (BEHAVIOR_STATUS, "BehaviorStatus"),
    (RELOAD_REQUEST, "ReloadRequest"),
    (BEHAVIOR_PUSH, "BehaviorPush"),
    (BEHAVIOR_PUSH_REPLY, "BehaviorPushReply"),
    (HFSM_STRUCTURE, "HfsmStructure"),
    (MATE_REPORT, "MateReport"),
    (SONAR_SCAN, "SonarScan"),
    (MOTOR_COMMAND, "MotorCommand"),
    (ODOMETRY, "Odometry"),
    (CAMERA_FRAME, "CameraFrame"),
    (GAME_INFO, "GameInfo"),
    (LOCALIZATION, "Localization"),
    (PERCEPTS, "Percepts"),
    (PLAN_REQUEST, "PlanRequest"),
    (PLANNED_PATH, "PlannedPath"),
    (BB_UPDATE, "BbUpdate"),
    (NET_PING, "Ping"),
    (NET_PROBE, "Probe"),
    (NET_ECHO, "Echo"),
    (NET_FLOOD, "Flood"),
];

/// The name of a standard message type, if it is one.
pub fn name_of(ty: MsgType) -> Option<&'static str> {
    TABLE.iter().find(|(t, _)| *t == ty).map(|(_, n)| *n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    #[test]
    fn ids_and_names_are_unique() {
        let ids: BTreeSet<u32> = TABLE.iter().map(|(t, _)| t.0).collect();
        let names: BTreeSet<&str> = TABLE.iter().map(|(_, n)| *n).collect();
        assert_eq!(ids.len(), TABLE.len(), "an id is used twice");
        assert_eq!(names.len(), TABLE.len(), "a name is used twice");
        assert!(TABLE.windows(2).all(|w| w[0].0 .0 < w[1].0 .0 || w[0].0 .0 >= 0xFFFF_0000));
    }

    /// The wire values, written out: changing one breaks every robot built before.
    #[test]
    fn ids_are_stable() {
        let pinned: Vec<(u32, &str)> = vec![
            (0xFFFF_0001, "SelfDescribing"),
            (0xFFFF_0020, "WorldSnapshot"),
            (0xFFFF_0021, "RobotCommand"),
            (0xFFFF_0030, "BehaviorStatus"),
            (0xFFFF_0031, "ReloadRequest"),
            (0xFFFF_0032, "BehaviorPush"),
            (0xFFFF_0033, "BehaviorPushReply"),
            (0xFFFF_0034, "HfsmStructure"),
            (0xFFFF_0040, "MateReport"),
            (0xFFFF_0041, "SonarScan"),
            (0xFFFF_0042, "MotorCommand"),
            (0xFFFF_0043, "Odometry"),
            (0xFFFF_0044, "CameraFrame"),
            (0xFFFF_0049, "GameInfo"),
            (0xFFFF_004A, "Localization"),
            (0xFFFF_004B, "Percepts"),
            (0xFFFF_004C, "PlanRequest"),
            (0xFFFF_004D, "PlannedPath"),
            (0xFFFF_0050, "BbUpdate"),
            (0x4E45_5401, "Ping"),
            (0x4E45_5402, "Probe"),
            (0x4E45_5403, "Echo"),
            (0x4E45_5404, "Flood"),
        ];
        let table: Vec<(u32, &str)> = TABLE.iter().map(|(t, n)| (t.0, *n)).collect();
        assert_eq!(table, pinned);
        assert_eq!(name_of(MATE_REPORT), Some("MateReport"));
        assert_eq!(name_of(MsgType(7)), None);
    }
}
