//! The gaze-control Member: the camera's pan joint turned to what the behaviors need.

use super::*;

/// The PAM's gaze control of one robot (ThinkingCap/TeamChaos report §2.1, [`mrt_world::gaze`]): each
/// cycle, the behaviors' latest perceptual needs (with `trackLandMarks`, the least recently seen
/// landmark or net) and the latest LPS choose the object to look at, and the camera's pan joint
/// is turned towards it. A joint that refuses is counted and
/// logged once; the robot plays on with its camera where it is.
pub(super) struct GazeControl {
    pub(super) robot: usize,
    pub(super) devices: SharedDevices,
    pub(super) gaze: Gaze,
    pub(super) period: f64,
    pub(super) needs: Vec<(usize, f64)>,
    pub(super) track_landmarks: bool,
    pub(super) lps: Vec<Lpo>,
    pub(super) refused: u64,
    pub(super) inputs: Inputs<GazeControl>,
}

impl GazeControl {
    /// What the gaze reads: the behaviors' needs, the LPS.
    pub(super) fn inputs() -> Inputs<GazeControl> {
        Inputs::<Self>::new()
            .on::<RobotCommand>(RequestType::Local, |g, c| {
                g.needs.clone_from(&c.needs);
                g.track_landmarks = c.track_landmarks;
            })
            .on::<WorldSnapshot>(RequestType::Local, |g, w| g.lps.clone_from(&w.lps))
    }
}

impl Member for GazeControl {
    fn name(&self) -> String {
        format!("gaze-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.subscribe(ctx);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.clone().drain(self, ctx)?;
        // The behaviors' needs stand until their next command; `trackLandMarks` adds one
        // landmark, the least recently seen, as needed as what they need most (this cycle).
        let mut needs = self.needs.clone();
        if self.track_landmarks {
            let need = needs.iter().map(|n| n.1).fold(0.0, f64::max);
            let need = if need > 0.0 { need } else { 1.0 };
            let slots: [usize; lps::COUNT - lps::NET1] = std::array::from_fn(|i| lps::NET1 + i);
            needs.extend(self.gaze.landmark_need(&slots, need, &self.lps));
        }
        let aim = self.gaze.step(&needs, &self.lps, self.period);
        if let Err(e) = lock(&self.devices)?.set_pan(aim.pan) {
            self.refused += 1;
            if self.refused == 1 {
                tracing::warn!(robot = self.robot, "gaze: {e} (further ones are counted)");
            }
        }
        Ok(())
    }
}
