//! # mrt-plan: kinematics, guidance and the SPIKE planner
//!
//! The acting end of an MRT robot as a plain library (no bus, no Lua): SPIKE, the path planner
//! of the MRT manual's ch. 9 ([`spike`], docs/planning.md), and from a wanted velocity
//! to wheel speeds for the two MRT bases (MRT manual ch. 12: IANUS3, Triskar; the AIRBoard of
//! ch. 5 takes one set point per motor), and the three guidance modes of the ISocRob Guidance µAgent (ISocRob-2000 report
//! §3.2.3): velocity with a sonar stop, go-to-posture, and potential fields around obstacles,
//! including "behind the ball" targets.
//!
//! ```
//! use mrt_core::Pose2;
//! use mrt_plan::kinematics::{integrate, DiffDrive, Kinematics, Twist};
//!
//! // IANUS3 asked for 2 m/s while turning at 1 rad/s: the right wheel would need
//! // (2 + 0.2) / 0.05 = 44 rad/s > 24, so the whole twist is scaled by 24/44 (curvature kept).
//! let ianus = DiffDrive::ianus3();
//! let twist = ianus.limit(&Twist::new(2.0, 0.0, 1.0));
//! assert!((twist.vx - 12.0 / 11.0).abs() < 1e-9 && (twist.omega - 6.0 / 11.0).abs() < 1e-9);
//! let wheels = ianus.inverse(&twist); // rad/s, [left, right]
//! assert!(wheels.right() > wheels.left());
//!
//! // 20 ms of that motion: an arc of circle, integrated exactly.
//! let after = integrate(Pose2::identity(), &twist, 0.02);
//! assert!((after.theta - 0.02 * twist.omega).abs() < 1e-12);
//! ```
//!
//! Start with [`kinematics::Kinematics`] and [`kinematics::integrate`] (exact dead reckoning
//! over one period; `mrt-sim` moves its robots with rapier2d and uses the kinematics to turn
//! commands into wheel duty cycles and back) and [`guidance::PotentialField`]. The two-mice
//! odometry that complements the kinematics is `mrt-perception`'s.
//!
//! | seed name | Rust |
//! |---|---|
//! | IANUS3 base, two central wheels, 1.2 m/s (manual §12.5) | [`kinematics::DiffDrive`], [`kinematics::DiffDriveParams::IANUS3`] |
//! | Triskar base, three omni wheels at 120° (manual §12.6) | [`kinematics::Omni3`], [`kinematics::Omni3Params::TRISKAR`] |
//! | AIRBoard set points, PWM (manual ch. 5) | [`kinematics::WheelSpeeds`], [`kinematics::duty_cycle`] |
//! | arc of circumference per sampling period (manual §4.1) | [`kinematics::integrate`] |
//! | velocity mode, halted by the sonars (ISocRob §3.2.3) | [`guidance::VelocityGuard`], [`guidance::Sonar`] |
//! | position mode | [`guidance::PositionMode`] |
//! | the Guidance µAgent: the mode a command asks for, sonar echoes, ball echoes told apart | [`guidance::Guidance`] |
//! | SPIKE, multi-resolution path planning with doors and moving objects (manual ch. 9) | [`spike::Spike`], [`spike::PlanMap`], [`spike::Plan`] |
//! | potential field mode, ball as a repelling obstacle | [`guidance::PotentialField`], [`guidance::Obstacle`], [`guidance::behind_ball`], [`guidance::sonar_obstacles`] |
//!
//! No feature flags. Errors: [`PlanError`].
#![deny(missing_docs)]

mod error;
pub mod guidance;
pub mod kinematics;
pub mod spike;

pub use error::PlanError;
