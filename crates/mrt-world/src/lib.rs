//! # mrt-world: what a robot knows about the world
//!
//! The reasoning side of an MRT robot that turns percepts into knowledge (MRT manual §2.1;
//! ThinkingCap/TeamChaos report §2.1, perceptual anchoring; ISocRob-2000 report §3.1, the world
//! state): one [`field::FieldMap`] (lines, goals, landmarks) that the simulator's truth and
//! the robot's localization both read; the [`model::WorldModel`], an extended Kalman filter on
//! the robot's pose predicted by the two-mice odometry and corrected by the landmarks the
//! camera saw, with the local perceptual space (LPS) of anchors whose reliability decays when
//! they go unseen; the PAM's camera control, [`gaze::Gaze`], which turns the camera's pan joint
//! to the object the behaviors need most (ThinkingCap/TeamChaos report §2.1); and the team side,
//! [`team::merge_team`]. It reads the standard messages of `mrt-msgs` only (never a
//! simulator), so the same world model runs on a real robot.
//!
//! ```
//! use mrt_core::frames::Framed;
//! use mrt_core::Pose2;
//! use mrt_msgs::{sighting, CameraFrame, GameInfo, GameState, Sighting, lps};
//! use mrt_perception::mice::MiceOdometry;
//! use mrt_world::{field::FieldMap, model::WorldModel};
//!
//! let map = FieldMap::default();
//! let mut model = WorldModel::new(map, MiceOdometry::new(0.2, 1e-3)?, 0.03, 0.02);
//! // Put down on the centre spot, facing east (a field-frame pose, as its type says).
//! model.place(Framed::new(Pose2::new(0.0, 0.0, 0.0)));
//! // The camera sees the east net 9 m straight ahead and the ball 2 m to the front left.
//! model.game(GameInfo { state: GameState::Playing, attack: 1.0, kickoff_pose: None, marker: None });
//! let mut frame = CameraFrame::default();
//! frame.sightings[mrt_msgs::sighting::EAST_NET] = Some(Sighting { distance: 9.0, bearing: 0.0 });
//! frame.sightings[sighting::BALL] = Some(Sighting { distance: 2.0, bearing: 0.5 });
//! let w = model.camera(&frame);
//! assert!((w.lps[lps::BALL].rho - 2.0).abs() < 1e-9, "LPS distances are in metres");
//! assert_eq!(w.lps[lps::BALL].reliability, 1.0);
//! assert!(w.my_pos.quality > 0.8);
//! assert_eq!(w.game_state, GameState::Playing);
//! # Ok::<(), mrt_perception::PerceptionError>(())
//! ```
#![deny(missing_docs)]

pub mod anchor;
pub mod field;
pub mod gaze;
pub mod gm;
pub mod hough;
pub mod model;
pub mod murea;
pub mod relocalize;
pub mod team;
pub mod track;

pub use field::FieldMap;
pub use model::WorldModel;
pub use team::merge_team;
