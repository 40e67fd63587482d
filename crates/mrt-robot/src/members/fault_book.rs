//! The fault book Member: a robot's script errors booked against it.

use super::*;

/// Books a robot's script errors (its behavior Member's `BehaviorStatus`) against the robot,
/// as a referee's assistant would note a robot that stopped.
pub(super) struct FaultBook {
    pub(super) devices: SharedDevices,
    pub(super) robot: usize,
    /// Script errors received, not yet booked (the first of each status).
    pub(super) errors: Vec<String>,
    pub(super) inputs: Inputs<FaultBook>,
}

impl FaultBook {
    /// The fault book of robot `robot` on `devices`.
    pub(super) fn new(devices: SharedDevices, robot: usize) -> FaultBook {
        let inputs =
            Inputs::new().on::<BehaviorStatus>(RequestType::Local, |f: &mut FaultBook, s| {
                f.errors.extend(s.errors.first().cloned());
            });
        FaultBook { devices, robot, errors: Vec::new(), inputs }
    }
}

impl Member for FaultBook {
    fn name(&self) -> String {
        format!("faults-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.subscribe(ctx);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.clone().drain(self, ctx)?;
        for e in std::mem::take(&mut self.errors) {
            lock(&self.devices)?.fault(&e)?;
        }
        Ok(())
    }
}
