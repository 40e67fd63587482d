//! What the acting side receives (MRT manual §2.1: acting modules; ISocRob seed `003` §3.2.3:
//! guidance between the behaviors and the motors).

use crate::robot::RobotCommand;
use serde::{Deserialize, Serialize};

/// What guidance asks of the motor and kicker driver: the velocities to drive (mm/s, deg/s,
/// the units of the behaviors' [`RobotCommand`]) and the kick.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MotorCommand(pub RobotCommand);
