//! The standard robot messages: what a robot's world model publishes and what its behaviors
//! answer, so that sensors, world models, behaviors (Lua, fuzzy) and motor drivers of different
//! authors plug together on one bus. The types themselves live in [`mrt_core::robot`].

use crate::msg::{Message, RESERVED_TYPES_START};
use mrt_core::robot::{RobotCommand, WorldSnapshot};
use mrt_core::MsgType;

impl Message for WorldSnapshot {
    const TYPE: MsgType = MsgType(RESERVED_TYPES_START + 0x20);
    const NAME: &'static str = "WorldSnapshot";
}

impl Message for RobotCommand {
    const TYPE: MsgType = MsgType(RESERVED_TYPES_START + 0x21);
    const NAME: &'static str = "RobotCommand";
}
