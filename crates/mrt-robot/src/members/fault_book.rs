//! The fault book Member: a robot's script errors booked against it.

use super::*;

/// Books a robot's script errors (its behavior Member's `BehaviorStatus`) against the robot,
/// as a referee's assistant would note a robot that stopped.
pub(super) struct FaultBook {
    pub(super) devices: SharedDevices,
    pub(super) robot: usize,
}

impl Member for FaultBook {
    fn name(&self) -> String {
        format!("faults-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<BehaviorStatus>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            if let Some(e) = m.get::<BehaviorStatus>()?.errors.first() {
                lock(&self.devices)?.fault(e)?;
            }
        }
        Ok(())
    }
}
