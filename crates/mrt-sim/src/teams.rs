//! The teams: which behavior stack drives which robot.
//!
//! - **Chaos**: TeamChaos' Lua stack (`behaviors/teamchaos`): the goalkeeper hierarchy of fuzzy
//!   behaviors for robot 0, the `player.hfsm.lua` machine (the seed's Attacker inside a game
//!   loop) for the field players. The files are compiled into the binary, so a match needs no
//!   setup; `--behaviors DIR` runs edited copies instead.
//! - **Chaser**: the hand-written baseline player ([`crate::game::Chaser`]).
//!
//! TeamChaos tuned its behaviors for AIBO walking speeds (about 0.3 m/s); on a Middle Size
//! League base the Chaos brain scales the behaviors' set-points, as the seed's Commander
//! Module turned set-points into a walking style for its own body.

use crate::game::{Brain, Chaser};
use mrt_core::robot::{RobotCommand, WorldSnapshot};
use mrt_script::{Sandbox, ThinkingCap};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// A behavior stack.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stack {
    /// TeamChaos: Lua HFSM and fuzzy HBM behaviors.
    Chaos,
    /// The hand-written baseline.
    Chaser,
}

impl Stack {
    /// Parses `chaos` or `chaser`.
    pub fn parse(s: &str) -> Result<Stack, String> {
        match s {
            "chaos" => Ok(Stack::Chaos),
            "chaser" => Ok(Stack::Chaser),
            other => Err(format!("unknown team stack '{other}' (chaos, chaser)")),
        }
    }

    /// The name.
    pub fn name(self) -> &'static str {
        match self {
            Stack::Chaos => "chaos",
            Stack::Chaser => "chaser",
        }
    }
}

/// The TeamChaos behavior files, compiled in.
const TEAMCHAOS: &[(&str, &str)] = &[
    ("alignbnet1.lua", include_str!("../../../behaviors/teamchaos/alignbnet1.lua")),
    ("attacker.hfsm.lua", include_str!("../../../behaviors/teamchaos/attacker.hfsm.lua")),
    ("dokick.lua", include_str!("../../../behaviors/teamchaos/dokick.lua")),
    ("faceball.lua", include_str!("../../../behaviors/teamchaos/faceball.lua")),
    ("gkclearb.lua", include_str!("../../../behaviors/teamchaos/gkclearb.lua")),
    ("gkcutb.lua", include_str!("../../../behaviors/teamchaos/gkcutb.lua")),
    ("gkkeeparea.lua", include_str!("../../../behaviors/teamchaos/gkkeeparea.lua")),
    ("gkkeepbarea.lua", include_str!("../../../behaviors/teamchaos/gkkeepbarea.lua")),
    ("gkkeepout.lua", include_str!("../../../behaviors/teamchaos/gkkeepout.lua")),
    ("gklocalize.lua", include_str!("../../../behaviors/teamchaos/gklocalize.lua")),
    ("gkscanobj.lua", include_str!("../../../behaviors/teamchaos/gkscanobj.lua")),
    ("gktracklms.lua", include_str!("../../../behaviors/teamchaos/gktracklms.lua")),
    ("go2ball.lua", include_str!("../../../behaviors/teamchaos/go2ball.lua")),
    ("goalkeeper.lua", include_str!("../../../behaviors/teamchaos/goalkeeper.lua")),
    ("hbm.lua", include_str!("../../../behaviors/teamchaos/hbm.lua")),
    ("lookball.lua", include_str!("../../../behaviors/teamchaos/lookball.lua")),
    ("player.hfsm.lua", include_str!("../../../behaviors/teamchaos/player.hfsm.lua")),
    ("stand.lua", include_str!("../../../behaviors/teamchaos/stand.lua")),
    ("trackbnet1.lua", include_str!("../../../behaviors/teamchaos/trackbnet1.lua")),
];

/// Linear set-points are multiplied by this on a Middle Size League base.
pub const CHAOS_LINEAR_SCALE: f64 = 4.0;
/// Turning set-points are multiplied by this.
pub const CHAOS_TURN_SCALE: f64 = 2.0;

/// Writes the compiled-in TeamChaos files to a directory of this process (once) and returns it.
pub fn embedded_teamchaos() -> Result<PathBuf, String> {
    static DIR: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("mrt-teamchaos-{}", std::process::id()));
        std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        for (name, text) in TEAMCHAOS {
            std::fs::write(dir.join(name), text).map_err(|e| format!("{name}: {e}"))?;
        }
        Ok(dir)
    })
    .clone()
}

/// A robot driven by ThinkingCap.
pub struct ChaosBrain {
    cap: ThinkingCap,
    /// The base's radius, mm: TeamChaos measured distances from an AIBO's head, so on a round
    /// base the brain measures LPS distances from the robot's edge.
    edge: f64,
}

impl ChaosBrain {
    /// The goalkeeper (`goalkeeper.lua`) or a field player (`player.hfsm.lua`) of `dir`.
    pub fn new(dir: &Path, keeper: bool, robot_radius_m: f64) -> Result<ChaosBrain, String> {
        let sandbox = Sandbox::default();
        let cap = if keeper {
            ThinkingCap::with_behavior(dir, "goalkeeper", sandbox)
        } else {
            ThinkingCap::with_hfsm(dir, dir.join("player.hfsm.lua"), sandbox)
        };
        Ok(ChaosBrain { cap: cap.map_err(|e| e.to_string())?, edge: robot_radius_m * 1000.0 })
    }
}

impl Brain for ChaosBrain {
    fn cycle(&mut self, world: &WorldSnapshot) -> RobotCommand {
        let mut seen = world.clone();
        for o in &mut seen.lps {
            o.rho = (o.rho - self.edge).max(0.0);
        }
        let c = self.cap.cycle(seen);
        for e in &c.errors {
            tracing::warn!("chaos robot: {e}");
        }
        let mut cmd = c.command;
        cmd.vlin *= CHAOS_LINEAR_SCALE;
        cmd.vlat *= CHAOS_LINEAR_SCALE;
        cmd.vrot *= CHAOS_TURN_SCALE;
        cmd
    }
}

/// The brains of one team of `size` robots (robot 0 keeps goal). `behaviors` overrides the
/// compiled-in TeamChaos files.
pub fn team(
    stack: Stack,
    size: usize,
    robot_radius_m: f64,
    behaviors: Option<&Path>,
) -> Result<Vec<Box<dyn Brain>>, String> {
    match stack {
        Stack::Chaser => {
            Ok((0..size).map(|i| Box::new(Chaser { keeper: i == 0 }) as Box<dyn Brain>).collect())
        }
        Stack::Chaos => {
            let dir = match behaviors {
                Some(d) => d.to_path_buf(),
                None => embedded_teamchaos()?,
            };
            (0..size)
                .map(|i| {
                    ChaosBrain::new(&dir, i == 0, robot_radius_m)
                        .map(|b| Box::new(b) as Box<dyn Brain>)
                })
                .collect()
        }
    }
}
