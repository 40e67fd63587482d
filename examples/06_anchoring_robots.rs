//! # 06 — Anchoring the other robots: MAP in the world model
//!
//! What you learn: how a robot's world model (`mrt_world::WorldModel`) turns the camera's robot
//! percepts into anchored robots that behaviors read (MRT manual ch. 8, MAP; TeamChaos'
//! perceptual anchoring, ThinkingCap report §2.1). The marker band a percept shows makes it a teammate or
//! an opponent. Association keeps each robot's identity when two robots cross. An anchor
//! predicted through an occlusion keeps its identity and fades while unseen. The snapshot then
//! answers a behavior's questions: the nearest opponent and a free direction to the net.
//!
//! The robot stands at (−2, 0) on the field, facing the opponent's (east) net, and sees two
//! robots walk across its view: a magenta teammate going north and a cyan opponent going
//! south. They pass each other 2 m ahead of it. For one second in the middle the opponent is
//! hidden. Every frame is exact (no noise), so the numbers are the model's, not the sensor's.
//!
//! Run: `cargo run -p mrt-examples --example 06_anchoring_robots`.

#![allow(clippy::print_stdout)] // examples talk to the user

use mrt_core::frames::Framed;
use mrt_core::{normalize_angle, Pose2};
use mrt_msgs::{
    AnchoredRobot, CameraFrame, GameInfo, GameState, Marker, RobotSighting, Sighting, WorldSnapshot,
};
use mrt_perception::mice::MiceOdometry;
use mrt_world::{FieldMap, WorldModel};

/// Where the robot stands, and the other robots' radius (m).
const ME: (f64, f64, f64) = (-2.0, 0.0, 0.0);
const RADIUS: f64 = 0.25;

/// The two robots at `t` (s): the teammate walks north along x = 0.1, the opponent south along
/// x = −0.1 (field frame, m), 1 m/s each, crossing at t = 2 s.
fn walkers(t: f64) -> [(f64, f64, Marker); 2] {
    [(0.1, -2.0 + t, Marker::Magenta), (-0.1, 2.0 - t, Marker::Cyan)]
}

/// What the camera reports at `t`: each robot's nearest point and its marker (the opponent is
/// hidden between 1.5 and 2.5 s).
fn frame(t: f64) -> CameraFrame {
    let mut f = CameraFrame { time: t, ..Default::default() };
    for (k, (x, y, marker)) in walkers(t).into_iter().enumerate() {
        if k == 1 && (1.5..2.5).contains(&t) {
            continue;
        }
        let (dx, dy) = (x - ME.0, y - ME.1);
        let bearing = normalize_angle(dy.atan2(dx) - ME.2);
        f.robots.push(RobotSighting {
            sighting: Sighting { distance: dx.hypot(dy) - RADIUS, bearing },
            sigma: None,
            marker: Some(marker),
        });
    }
    f
}

/// One line of what the robot believes at a moment.
#[derive(Clone, Debug)]
pub struct Moment {
    /// Simulated time, s.
    pub time: f64,
    /// The anchored robots of the snapshot, nearest first.
    pub robots: Vec<AnchoredRobot>,
    /// The bearing of a free way towards the net (rad), if any.
    pub free_direction: Option<f64>,
}

/// Runs 4 s of frames at 10 Hz; returns a moment every half second. `print` shows them.
pub fn run(print: bool) -> Result<Vec<Moment>, String> {
    let mice = MiceOdometry::new(0.2, 0.003).map_err(|e| e.to_string())?;
    let mut model =
        WorldModel::new(FieldMap::default(), mice, 0.03, 0.02).with_robot_radius(RADIUS);
    model.place(Framed::new(Pose2::new(ME.0, ME.1, ME.2)));
    // The game controller says: playing, attacking east, our colour is magenta.
    model.game(GameInfo {
        state: GameState::Playing,
        attack: 1.0,
        kickoff_pose: None,
        marker: Some(Marker::Magenta),
    });
    let mut moments = Vec::new();
    for k in 0..=40 {
        let t = 0.1 * f64::from(k);
        let w: WorldSnapshot = model.camera(&frame(t));
        if k % 5 != 0 {
            continue;
        }
        // A behavior's questions: the way to the net (straight ahead here), 2 m long, 1 m
        // wide.
        let free = w.free_direction(
            0.0,
            WorldSnapshot::FREE_REACH,
            WorldSnapshot::FREE_CLEARANCE,
            WorldSnapshot::ANCHORED,
        );
        if print {
            println!(
                "t = {t:.1} s: free way to the net at {}",
                match free {
                    Some(b) => format!("{:+.0}°", b.to_degrees()),
                    None => "none".to_string(),
                }
            );
            for r in &w.robots {
                println!(
                    "    anchor {} {:<8} at ({:+.2}, {:+.2}) m, {:+.1} m/s north, reliability {:.2}{}",
                    r.id,
                    r.class.name(),
                    r.at.inner.x,
                    r.at.inner.y,
                    r.velocity.inner.y,
                    r.reliability,
                    if r.seen_ago > 0.0 { format!(", unseen for {:.1} s", r.seen_ago) } else { String::new() }
                );
            }
        }
        moments.push(Moment { time: t, robots: w.robots.clone(), free_direction: free });
    }
    Ok(moments)
}

/// Entry point of the example.
pub fn main() -> Result<(), String> {
    println!(
        "A robot at (-2, 0) facing east; a magenta teammate and a cyan opponent cross 2 m ahead.\n"
    );
    run(true)?;
    Ok(())
}
