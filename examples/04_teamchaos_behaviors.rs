//! # 04 — TeamChaos behaviors: the Attacker HFSM, the goalkeeper, and a hot reload
//!
//! What you learn: how ThinkingCap (TeamChaos, ThinkingCap/TeamChaos report) runs a robot's behaviors written in
//! Lua: a hierarchical state machine (`behaviors/teamchaos/attacker.hfsm.lua`) chooses a
//! low-level behavior each cycle with `chaos.setBehavior`, and fuzzy rules (`go2ball.lua`,
//! `dokick.lua`, ...) blended by context give the velocities, the kick and the perceptual
//! needs. The Attacker plays against a tiny scripted world where the ball sits 4 m away on the
//! left: it faces the ball, walks to it, enters the `Score` meta-state, aligns the ball with
//! the opponent's net and kicks.
//!
//! Half-way, the example **edits `go2ball.lua` on disk** (slow instead of fast) and the robot
//! asks for a slower walk from the next cycle on, without a restart; then it saves a **broken** version,
//! which is rejected with `file:line: message` while the robot keeps walking. Finally the
//! goalkeeper (a hierarchy of 12 fuzzy behaviors) meets three situations.
//!
//! Run: `cargo run -p mrt-examples --example 04_teamchaos_behaviors`. The behaviors are
//! copied to a temporary directory first, so the edits never touch the repository.

#![allow(clippy::print_stdout)] // examples talk to the user

use anyhow::{Context as _, Result};
use mrt_core::frames::{setpoints_of, Framed};
use mrt_core::{Pose2, Time, Twist};
use mrt_msgs::robot::{lps, Estimate, Lpo, WorldSnapshot};
use mrt_script::{Sandbox, ThinkingCap};
use std::path::{Path, PathBuf};

/// The TeamChaos behaviors shipped with MRT.
pub fn behaviors_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../behaviors/teamchaos")
}

/// One Attacker cycle, as printed.
#[derive(Clone, Debug)]
pub struct Step {
    /// The HFSM's active path.
    pub path: String,
    /// The behavior that ran.
    pub behavior: String,
    /// Linear velocity asked for, mm/s.
    pub vlin: f64,
    /// Rotational velocity asked for, deg/s.
    pub vrot: f64,
    /// The kick asked for.
    pub kick: Option<i64>,
    /// Reloads and errors reported this cycle.
    pub events: Vec<String>,
}

/// What the example saw.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The Attacker's cycles.
    pub attacker: Vec<Step>,
    /// The goalkeeper's command per situation.
    pub goalkeeper: Vec<KeeperMove>,
}

/// What the goalkeeper did in one situation.
#[derive(Clone, Debug)]
pub struct KeeperMove {
    /// The situation.
    pub situation: &'static str,
    /// Linear velocity, mm/s.
    pub vlin: f64,
    /// Rotational velocity, deg/s.
    pub vrot: f64,
    /// Lateral velocity (left positive), mm/s.
    pub vlat: f64,
    /// Whether it looks for landmarks.
    pub track_landmarks: bool,
    /// The posture it asked guidance for, if any (team frame: m, m, rad).
    pub target: Option<Pose2>,
}

/// The scripted world: the robot at the origin facing +x, the ball at `ball`, the opponent's
/// net 4.5 m beyond the ball on the same line.
struct Field {
    robot: Pose2,
    ball: (f64, f64),
}

impl Field {
    fn snapshot(&self, time: Time) -> WorldSnapshot {
        let mut w = WorldSnapshot { time, ..Default::default() };
        let seen = |x: f64, y: f64| {
            let (dx, dy) = (x - self.robot.x, y - self.robot.y);
            let theta = mrt_core::normalize_angle(dy.atan2(dx) - self.robot.theta);
            Lpo { rho: dx.hypot(dy), theta, reliability: 0.9, seen_ago: 0.0 }
        };
        w.lps[lps::BALL] = seen(self.ball.0, self.ball.1);
        w.lps[lps::NET1] = seen(self.ball.0 + 4.5, self.ball.1);
        w.my_pos = Estimate { pose: Framed::new(self.robot), quality: 0.9 };
        w
    }

    /// Moves the robot as commanded for `dt` seconds (forward, sideways to the left, turning),
    /// at most at a Middle Size base's top speeds (1.2 m/s, 4 rad/s), as guidance would; a
    /// kick sends the ball 5 m on.
    fn advance(&mut self, twist: Twist, kick: Option<i64>, dt: f64) {
        let (top, top_turn) = (1.2, 4.0);
        let speed = twist.vx.hypot(twist.vy);
        let slow = if speed > top { top / speed } else { 1.0 };
        let (vx, vy, omega) =
            (twist.vx * slow, twist.vy * slow, twist.omega.clamp(-top_turn, top_turn));
        let theta = self.robot.theta + omega * dt;
        let (c, s) = (theta.cos(), theta.sin());
        let (x, y) = (self.robot.x + (vx * c - vy * s) * dt, self.robot.y + (vx * s + vy * c) * dt);
        self.robot = Pose2::new(x, y, theta);
        if kick.is_some() {
            self.ball.0 += 5.0;
        }
    }
}

fn copy_behaviors(to: &Path) -> Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(behaviors_dir())? {
        let path = entry?.path();
        if path.extension().is_some_and(|e| e == "lua") {
            let name = path.file_name().context("a file name")?;
            std::fs::copy(&path, to.join(name))?;
        }
    }
    Ok(())
}

/// Runs the example in a scratch copy of the behaviors at `scratch`.
pub fn run(scratch: &Path, verbose: bool) -> Result<Outcome> {
    copy_behaviors(scratch)?;
    let sandbox = Sandbox::default();
    let mut attacker = ThinkingCap::with_hfsm(scratch, scratch.join("attacker.hfsm.lua"), sandbox)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut field = Field { robot: Pose2::new(0.0, 0.0, 0.0), ball: (3.2, 2.4) };
    let go2ball = scratch.join("go2ball.lua");
    let original = std::fs::read_to_string(&go2ball)?;
    let mut steps = Vec::new();
    if verbose {
        println!(
            "Attacker (attacker.hfsm.lua), 100 ms cycles, printed on changes and every 1 s:\n"
        );
        println!(
            "{:>5}  {:<28} {:<10} {:>7} {:>7} {:>7}  kick",
            "t ms", "path", "behavior", "vlin", "vlat", "vrot"
        );
    }
    for k in 0..150u64 {
        let mut events = Vec::new();
        // Hot reload, as a reload request on the bus (or the file watcher) triggers it: the
        // edited file is compiled and swapped in at this cycle boundary.
        let edit = match k {
            15 => Some(original.replace("\"go\", \"FAST\")", "\"go\", \"SLOW\")")),
            20 => Some(format!("{original}\nrule(ballAhead(), \"go\"  -- an unfinished edit\n")),
            _ => None,
        };
        if let Some(text) = edit {
            std::fs::write(&go2ball, text)?;
            bump_mtime(&go2ball, k)?;
            let (done, errors) = attacker.reload_changed();
            events.extend(done.iter().map(|d| format!("reloaded {d}")));
            events.extend(errors.iter().map(|e| format!("rejected: {e}")));
        }
        let c = attacker.cycle(field.snapshot(Time::from_millis(k * 100)));
        events.extend(c.errors.iter().map(ToString::to_string));
        let cmd = &c.command;
        // The set-points in the behaviors' own units, as the script wrote them.
        let (vlin, vlat, vrot) = setpoints_of(cmd.twist);
        field.advance(cmd.twist, cmd.kick, 0.1);
        let step = Step {
            path: c.path.clone(),
            behavior: c.behavior.clone().unwrap_or_default(),
            vlin,
            vrot,
            kick: cmd.kick,
            events,
        };
        let changed = steps.last().is_none_or(|p: &Step| p.path != step.path);
        if verbose
            && (changed
                || k % 10 == 0
                || (12..24).contains(&k)
                || step.kick.is_some()
                || !step.events.is_empty())
        {
            let kick = step.kick.map_or(String::new(), |k| format!("{k}"));
            println!(
                "{:>5}  {:<28} {:<10} {:>7.1} {:>7.1} {:>7.1}  {kick}",
                k * 100,
                step.path,
                step.behavior,
                step.vlin,
                vlat,
                step.vrot
            );
            for e in &step.events {
                println!("       ^ {e}");
            }
        }
        let kicked = step.kick.is_some();
        steps.push(step);
        if kicked {
            break;
        }
    }
    std::fs::write(&go2ball, original)?; // put the shipped version back
    let goalkeeper = run_goalkeeper(scratch, verbose)?;
    Ok(Outcome { attacker: steps, goalkeeper })
}

/// Gives a rewritten file a distinct modification time, so that a reload sees the change even
/// on file systems with coarse timestamps.
fn bump_mtime(path: &Path, k: u64) -> Result<()> {
    let t = std::time::SystemTime::now() + std::time::Duration::from_secs(k);
    std::fs::File::options().write(true).open(path)?.set_modified(t)?;
    Ok(())
}

fn run_goalkeeper(dir: &Path, verbose: bool) -> Result<Vec<KeeperMove>> {
    let mut gk = ThinkingCap::with_behavior(dir, "goalkeeper", Sandbox::default())
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let at = |x: f64, y: f64| Framed::new(Pose2::new(x, y, 0.0));
    let home = Estimate { pose: at(-8.7, 0.0), quality: 0.9 };
    let lost = WorldSnapshot { my_pos: home, ..Default::default() };
    let mut in_net = lost.clone();
    in_net.my_pos.pose = at(-9.2, 0.0);
    in_net.lps[lps::BALL] = Lpo { rho: 3.0, theta: 0.0, reliability: 0.9, seen_ago: 0.0 };
    // The ball 2.9 m out at y = 0.3, the keeper 0.6 m to its left on its line (0.4 m out of
    // the goal line): it asks guidance for the spot level with the ball, (−8.6, 0.3).
    let mut cut = lost.clone();
    let theta = (-0.6f64).atan2(2.9);
    cut.lps[lps::BALL] = Lpo { rho: 2.961, theta, reliability: 0.9, seen_ago: 0.0 };
    cut.global_ball = Estimate { pose: at(-5.7, 0.3), quality: 0.9 };
    cut.my_pos.pose = at(-8.6, 0.9);
    let mut out = Vec::new();
    if verbose {
        println!("\nGoalkeeper (goalkeeper.lua and its 11 sub-behaviors):\n");
    }
    for (name, world) in [
        ("ball lost", lost),
        ("inside its own net", in_net),
        ("ball coming, keeper off the line", cut),
    ] {
        let c = gk.cycle(world);
        if let Some(e) = c.errors.first() {
            anyhow::bail!("goalkeeper, {name}: {e}");
        }
        let m = &c.command;
        let (vlin, vlat, vrot) = setpoints_of(m.twist);
        let target = m.target.map(|t| t.pose.inner);
        if verbose {
            let to = target.map_or(String::new(), |t| {
                format!("  to ({:.2}, {:.2}) m facing {:.2} rad", t.x, t.y, t.theta)
            });
            println!(
                "  {name:<34} vlin {vlin:>6.1}  vrot {vrot:>6.1}  vlat {vlat:>6.1}  landmarks {}{to}",
                m.track_landmarks
            );
        }
        out.push(KeeperMove {
            situation: name,
            vlin,
            vrot,
            vlat,
            track_landmarks: m.track_landmarks,
            target,
        });
    }
    Ok(out)
}

/// Runs the example and prints it.
pub fn main() -> Result<()> {
    let scratch = std::env::temp_dir().join(format!("mrt-example-04-{}", std::process::id()));
    let result = run(&scratch, true);
    let _ = std::fs::remove_dir_all(&scratch);
    let outcome = result?;
    let kicks = outcome.attacker.iter().filter(|s| s.kick.is_some()).count();
    println!("\nThe attacker kicked {kicks} time(s) in {} cycles.", outcome.attacker.len());
    Ok(())
}
