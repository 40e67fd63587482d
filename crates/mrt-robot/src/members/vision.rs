//! The vision Member: the camera's images into percepts.

use super::*;

/// The vision µAgent of one robot (ISocRob-2000 report §3.2.1): the camera's latest image into
/// [`Percepts`]. An image the camera's geometry does not fit is counted, logged once, and
/// dropped.
pub(super) struct Vision {
    pub(super) robot: usize,
    pub(super) agent: VisionAgent,
    pub(super) refused: u64,
    /// The latest frame with an image, not yet seen.
    pub(super) latest: Option<MsgRef>,
    pub(super) inputs: Inputs<Vision>,
}

impl Vision {
    /// The vision µAgent of robot `robot`.
    pub(super) fn new(robot: usize, agent: VisionAgent) -> Vision {
        let inputs =
            Inputs::new().on_msg::<CameraFrame>(RequestType::Local, |v: &mut Vision, m| {
                if m.get::<CameraFrame>().is_ok_and(|f| f.image.is_some()) {
                    v.latest = Some(m.clone());
                }
            });
        Vision { robot, agent, refused: 0, latest: None, inputs }
    }
}

impl Member for Vision {
    fn name(&self) -> String {
        format!("vision-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.subscribe(ctx);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.clone().drain(self, ctx)?;
        let Some(m) = self.latest.take() else { return Ok(()) };
        let frame = m.get::<CameraFrame>()?;
        let Some(image) = &frame.image else { return Ok(()) };
        // Where the pan joint was when the frame was taken (the gaze control turns it), or,
        // for a camera without a joint, where its camera file puts it.
        let pan = frame.pan.unwrap_or(self.agent.camera().pan);
        match self.agent.see_with_up(image, frame.up_image.as_ref(), frame.time, pan) {
            Ok(p) => {
                ctx.publish(p);
            }
            Err(e) => {
                self.refused += 1;
                if self.refused == 1 {
                    tracing::warn!(robot = self.robot, "vision: {e} (further ones are counted)");
                }
            }
        }
        Ok(())
    }
}
