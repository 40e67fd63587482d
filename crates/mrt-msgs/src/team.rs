//! What teammates tell each other (ISocRob-2000 report §3.1, ThinkingCap report §2.3): each
//! robot's own pose, ball and the robots it sees, every cycle.

use crate::robot::{Estimate, RobotClass, WorldSnapshot};
use mrt_core::frames::{Framed, Team};
use mrt_core::Point2;
use serde::{Deserialize, Serialize};

/// What a robot tells its teammates every cycle (team frame, m): its own pose and its own
/// sighting of the ball (never what it heard from others, so stale news does not circulate).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MateReport {
    /// The robot's player number.
    pub id: u32,
    /// Whether it keeps goal.
    pub keeper: bool,
    /// Where it believes it is.
    pub pose: Estimate,
    /// Where it believes the ball is (quality 0 when it has no idea).
    pub ball: Estimate,
    /// One standard deviation of `ball`'s position, m (0: not known; the team then reads it
    /// from the quality).
    #[serde(default)]
    pub ball_sigma: f64,
    /// The robots it sees this frame (MAP's team level: a teammate is an intelligent sensor
    /// whose anchors the others fuse, MRT manual ch. 8).
    #[serde(default)]
    pub robots: Vec<SharedRobot>,
    /// Its part in the team's ball booking (TeamChaos' distributed mutual exclusion, ThinkingCap/TeamChaos
    /// report §3.3; `mrt_team::booking`).
    #[serde(default)]
    pub booking: BookingReport,
    /// The role it plays (`getRole`: `goalkeeper`, `attacker`, `supporter`, `defender`;
    /// `mrt_team::roles`), so that every teammate allocates from the same data.
    #[serde(default)]
    pub role: String,
    /// Its part in SCARE's allocation (MRT manual ch. 11; `mrt_team::scare`).
    #[serde(default)]
    pub scare: ScareReport,
}

/// What a robot tells its teammates for SCARE's allocation (`mrt_team::scare`): every robot
/// allocates from these, so all that heard the same reports agree.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ScareReport {
    /// The fingerprint of its activity table (`Activities::fingerprint`): attitudes are read
    /// slot by slot only from a robot that runs the same table.
    pub table: u32,
    /// Its attitude for each (activity, functionality) slot of the table, `0..=1`.
    pub attitudes: Vec<f32>,
    /// Its rating of each activity's opportunity, `0..=1` (the team uses one robot's: the
    /// lowest-numbered heard).
    pub opportunity: Vec<f32>,
    /// What it does now: activity and functionality indices in the table.
    pub doing: Option<(u16, u8)>,
}

/// What a robot tells its teammates about the ball booking (`mrt_team::booking`): whether it
/// wants the ball, whose claim it supports, and the latest report it heard from each of them.
/// Times are the sender's own clock, s.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct BookingReport {
    /// When it sent this report.
    pub stamp: f64,
    /// When it began wanting the ball (`bookBall`), while it does.
    pub claim: Option<f64>,
    /// The claim it supports: the claimant's number and its claim's time.
    pub grant: Option<(u32, f64)>,
    /// For each teammate heard: its number and the stamp of its latest report heard.
    pub echo: Vec<(u32, f64)>,
}

/// A robot a teammate anchored and sees this frame (team frame, m).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SharedRobot {
    /// Teammate, opponent or unknown, as the teammate classified it (one team, one meaning).
    pub class: RobotClass,
    /// Its centre, m.
    #[cfg_attr(feature = "schema", schemars(with = "[f64; 2]"))]
    pub at: Framed<Team, Point2>,
    /// One standard deviation of its place, m.
    pub at_sigma: f64,
}

impl MateReport {
    /// The report of robot `id` on its world snapshot (before the team's reports are merged
    /// into it: the robots it sees itself), with no ball uncertainty ([`MateReport::with_ball_sigma`] adds it).
    pub fn of(id: u32, keeper: bool, w: &WorldSnapshot) -> MateReport {
        let robots = w
            .robots
            .iter()
            .filter(|r| r.seen_ago <= 0.0)
            .map(|r| SharedRobot { class: r.class, at: r.at, at_sigma: r.at_sigma })
            .collect();
        MateReport {
            id,
            keeper,
            pose: w.my_pos,
            ball: w.global_ball,
            ball_sigma: 0.0,
            robots,
            booking: BookingReport::default(),
            role: String::new(),
            scare: ScareReport::default(),
        }
    }

    /// The same report with the ball's standard deviation, m.
    pub fn with_ball_sigma(self, ball_sigma: f64) -> MateReport {
        MateReport { ball_sigma, ..self }
    }
}
