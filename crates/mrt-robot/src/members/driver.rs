//! The driver Member: one device reading a cycle.

use super::*;

/// A driver Member (MRT manual §2.1: drivers apart from processing): each cycle it reads one
/// of the robot's devices and publishes what it read. The odometry, camera, game-controller and
/// sonar drivers are this one Member with a different reading.
pub(crate) struct Driver<M> {
    /// `odometry`, `camera`, `sonars`: the Member is named `<kind>-<robot>`.
    pub(crate) kind: &'static str,
    pub(crate) robot: usize,
    pub(crate) devices: SharedDevices,
    pub(crate) read: fn(&mut dyn Devices) -> Result<M, DeviceError>,
}

impl<M: Message> Member for Driver<M> {
    fn name(&self) -> String {
        format!("{}-{}", self.kind, self.robot)
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let reading = (self.read)(&mut *lock(&self.devices)?)?;
        ctx.publish(reading);
        Ok(())
    }
}
