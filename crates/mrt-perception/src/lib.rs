//! # mrt-perception: what a robot makes of its sensors
//!
//! The processing side of the MRT manual's sensing modules (§2.1: drivers apart from
//! processing): readings come in as the standard messages of `mrt-msgs` (from a real robot's
//! drivers or from the simulator's), and what they mean comes out: the dead-reckoning
//! sensor made of two optical mice (manual ch. 4), with the manual's formula typos fixed and
//! its error detection and reduction (§4.2), the camera models
//! ([`camera`]: a pinhole camera on a pan joint with radial distortion, ISocRob's
//! omnidirectional mirror, the ball's floor point and apparent size, with the report's typos
//! fixed), colour vision on camera images ([`vision`]: ISocRob-2000 report §3.2.1's lookup table,
//! ball, goals, lines and obstacles, and the vision µAgent that turns an image into percepts),
//! and where images come from ([`source`]: the camera driver trait and a player of image
//! files). A plain library: no bus, no simulator.
//!
//! ```
//! use mrt_perception::mice::MiceOdometry;
//!
//! // Mice 0.2 m apart, 0.1 mm tolerance on the x̄_r = x̄_l check. The robot moves 20 mm
//! // forward and 5 mm to the left while turning by 0.03 rad: the mice read that motion
//! // (the manual's forward model) and give it back.
//! let mice = MiceOdometry::new(0.2, 1e-4)?;
//! let readings = mice.readings_for(0.02, 0.005, 0.03);
//! let d = mice.displacement(&readings)?;
//! assert!((d.dx - 0.02).abs() < 1e-12 && (d.dy - 0.005).abs() < 1e-12);
//! assert!((d.dtheta - 0.03).abs() < 1e-12);
//! # Ok::<(), mrt_perception::PerceptionError>(())
//! ```
//!
//! | seed name | Rust |
//! |---|---|
//! | mice readings `x̄_l, ȳ_l, x̄_r, ȳ_r` (manual §4.1) | [`mice::MiceReadings`] (a message field, from `mrt-msgs`) |
//! | eq. (4.1), (4.2) and the mid-point of the mice | [`mice::MiceOdometry::displacement`], [`mice::MiceArcs`] |
//! | eq. (4.3)–(4.5) | [`mice::update_pose`] |
//! | `x̄_r = x̄_l` error detection, error reduction (manual §4.2) | [`mice::MiceOdometry::check`], [`mice::MiceOdometry::reduce`] |
//! | calibration: `D`, `σ_r`, `σ_l`, `δ`, resolutions, positions (manual §4.2), general mounting | [`mice_calibration::calibrate`], [`mice_calibration::MiceMounting`], its log [`mice_calibration::log`] |
//! | front camera, inverse projection eqs (7)–(9) (ISocRob-2000 report §3.2.1) | [`camera::Pinhole`] (with a pan joint) |
//! | "up" camera, mirror (ISocRob-2000 report §2.2) | [`camera::Omni`], its file [`camera::OmniFile`]; either model's file [`camera::CameraModel`] |
//! | the µAgent's "up" mode: the ball all around (ISocRob-2000 report §3.2.1) | [`vision::up::find_ball_up`] |
//! | ball correction and expected size, eqs (10)–(11) | [`camera::ball_floor_point`], [`camera::ball_diameter_px`] |
//! | the vision µAgent (ISocRob-2000 report §3.2.1) | [`vision::agent::VisionAgent`] |
//! | a camera driver (manual ch. 12, ISocRob §2.2) | [`source::ImageSource`], [`source::ImageSequence`] |
//!
//! The manual's mice equations have typos; [`mice`] lists each one with the corrected formula,
//! and a test pins each fix. Errors: [`PerceptionError`].
#![deny(missing_docs)]

pub mod camera;
mod error;
pub mod mice;
pub mod mice_calibration;
pub mod source;
#[cfg(all(feature = "v4l2", target_os = "linux"))]
pub mod v4l2;
pub mod vision;

pub use error::PerceptionError;
