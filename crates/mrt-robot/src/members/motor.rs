//! The motor and kicker driver Member.

use super::*;

/// The motor and kicker driver of one robot: commands become duty cycles for its motor
/// driver (the processing side of the AIRBoard), kick requests fire the kicker.
pub(crate) struct Motor {
    pub(crate) devices: SharedDevices,
    pub(crate) robot: usize,
    pub(crate) base: Base,
    /// The latest command, not yet applied.
    pub(crate) command: Option<MotorCommand>,
    pub(crate) inputs: Inputs<Motor>,
}

impl Motor {
    /// The motor driver of robot `robot` on `devices`, driving `base`.
    pub(crate) fn new(devices: SharedDevices, robot: usize, base: Base) -> Motor {
        let inputs = Inputs::new()
            .on::<MotorCommand>(RequestType::Local, |m: &mut Motor, c| m.command = Some(*c));
        Motor { devices, robot, base, command: None, inputs }
    }
}

impl Member for Motor {
    fn name(&self) -> String {
        format!("motor-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.subscribe(ctx);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.clone().drain(self, ctx)?;
        if let Some(cmd) = self.command.take() {
            let mut devices = lock(&self.devices)?;
            devices.set_duty(&self.base.duties(&cmd.twist))?;
            if cmd.kick {
                devices.kick()?;
            }
        }
        Ok(())
    }
}
