//! The motor and kicker driver Member.

use super::*;

/// The motor and kicker driver of one robot: commands become duty cycles for its motor
/// driver (the processing side of the AIRBoard), kick requests fire the kicker.
pub(crate) struct Motor {
    pub(crate) devices: SharedDevices,
    pub(crate) robot: usize,
    pub(crate) base: Base,
}

impl Member for Motor {
    fn name(&self) -> String {
        format!("motor-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<MotorCommand>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut last = None;
        while let Some(m) = ctx.receive_msg() {
            last = Some(*m.get::<MotorCommand>()?);
        }
        if let Some(cmd) = last {
            let mut devices = lock(&self.devices)?;
            devices.set_duty(&self.base.duties(&cmd.twist))?;
            if cmd.kick {
                devices.kick()?;
            }
        }
        Ok(())
    }
}
