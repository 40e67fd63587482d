//! The DCDT Member that runs Mr. BRIAN (feature `member`, on by default): it receives
//! [`BrianInputs`] messages, runs one cycle per activation on the latest inputs, and publishes
//! the crisp [`BrianCommands`].
//!
//! The manual's Parser and Messenger (§10.3.10) are exactly this seam: sensors publish
//! `BrianInputs`, actuators subscribe to `BrianCommands`.

use crate::brian::Brian;
use mrt_dcdt::{Context, Member, MemberError, Message, MsgType, RequestType, RESERVED_TYPES_START};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Crisp inputs for Mr. BRIAN: `(name, value, reliability)`. Several messages between two cycles
/// merge; a later value of a name replaces an earlier one.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BrianInputs {
    /// The inputs.
    pub values: Vec<(String, f64, f64)>,
}

impl Message for BrianInputs {
    const TYPE: MsgType = MsgType(RESERVED_TYPES_START + 0x10);
    const NAME: &'static str = "BrianInputs";
}

/// The commands of one Mr. BRIAN cycle: action name → crisp value (absent actions are absent).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BrianCommands {
    /// The commands, sorted by name.
    pub commands: BTreeMap<String, f64>,
}

impl Message for BrianCommands {
    const TYPE: MsgType = MsgType(RESERVED_TYPES_START + 0x11);
    const NAME: &'static str = "BrianCommands";
}

/// Runs a [`Brian`] on the bus. Activate it periodically (one cycle per period, on the inputs
/// received since the last one) or on-message (one cycle per batch of inputs).
pub struct BrianMember {
    brian: Brian,
    pending: BTreeMap<String, (f64, f64)>,
    name: String,
}

impl BrianMember {
    /// A Member around a loaded engine.
    pub fn new(brian: Brian, name: impl Into<String>) -> Self {
        Self { brian, pending: BTreeMap::new(), name: name.into() }
    }
}

impl Member for BrianMember {
    fn name(&self) -> String {
        self.name.clone()
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<BrianInputs>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            for (name, v, r) in &m.get::<BrianInputs>()?.values {
                self.pending.insert(name.clone(), (*v, *r));
            }
        }
        let inputs: Vec<(&str, f64, f64)> =
            self.pending.iter().map(|(k, (v, r))| (k.as_str(), *v, *r)).collect();
        let commands = self.brian.run(&inputs).to_map();
        self.pending.clear();
        ctx.publish(BrianCommands { commands });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_core::SimClock;
    use mrt_dcdt::{Activation, SteppedExecutor};
    use std::sync::{Arc, Mutex};
    use std::time::Duration;

    struct Sensor;
    impl Member for Sensor {
        fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            let d = if ctx.cycle() == 0 { 5.0 } else { 50.0 };
            ctx.publish(BrianInputs { values: vec![("D".into(), d, 1.0)] });
            Ok(())
        }
    }

    struct Motor(Arc<Mutex<Vec<Option<f64>>>>);
    impl Member for Motor {
        fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            ctx.subscribe_to::<BrianCommands>(RequestType::All);
            Ok(())
        }
        fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            while let Some(m) = ctx.receive_msg() {
                self.0
                    .lock()
                    .map_err(|_| "poisoned")?
                    .push(m.get::<BrianCommands>()?.commands.get("Speed").copied());
            }
            Ok(())
        }
    }

    #[test]
    fn sensor_to_brian_to_motor_on_the_bus() {
        let dir = std::env::temp_dir().join(format!("mrt-brian-member-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("b")).unwrap();
        for (f, t) in [
            ("shape_ctof.txt", "(Dist (TOL (NEAR 10 20)) (TOR (FAR 10 20)))"),
            ("ctof.txt", "(D Dist)"),
            ("Predicate.ini", "Near = (D D NEAR);\nFar = (D D FAR);"),
            ("Cando.ini", "Go = (OR (P Near) (P Far));"),
            ("want.txt", "Go = (OR (P Near) (P Far));"),
            ("behavior.txt", "(level 1 Go b/Go.rul)"),
            ("b/Go.rul", "(Near) => (Speed SLOW);\n(Far) => (Speed FAST);"),
            ("s_shape.txt", "(SPEED (SNG (SLOW 10)) (SNG (FAST 100)))"),
            ("s_ftoc.txt", "(Speed SPEED)"),
        ] {
            std::fs::write(dir.join(f), t).unwrap();
        }
        let brian = Brian::from_dir(&dir).unwrap();
        let seen = Arc::new(Mutex::new(Vec::new()));
        let mut exec = SteppedExecutor::new(SimClock::new(), Duration::from_millis(1));
        let mut robot = exec.agora_builder(1).build().unwrap();
        let ids = [
            robot.add_member(Sensor, Activation::Periodic(Duration::from_millis(10))),
            robot.add_member(BrianMember::new(brian, "brian"), Activation::OnMessage),
            robot.add_member(Motor(seen.clone()), Activation::OnMessage),
        ];
        for id in ids {
            robot.activate_member(id).unwrap();
        }
        exec.add_agora(robot).unwrap();
        exec.run_for(Duration::from_millis(20));
        exec.finish();
        assert_eq!(*seen.lock().unwrap(), vec![Some(10.0), Some(100.0)]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
