//! # mrt-fuzzy: fuzzy sets and the Mr. BRIAN behavior engine
//!
//! Mr. BRIAN (Multilevel Ruling BRIAN Reacts by Inferential ActioNs, MRT manual chapter 10)
//! turns crisp sensor data into fuzzy predicates, lets behaviors propose fuzzy actions through
//! rules, composes them by CANDO/WANT conditions in a hierarchy, and defuzzifies the result into
//! crisp commands.
//!
//! The fuzzy core (sets of §10.4.1 as [`FuzzySet`], the (value, reliability) datum and its
//! operators as [`FuzzyValue`], shapes, fuzzification and singleton defuzzification in
//! [`shapes`]) is shared with ThinkingCap's HBM behaviors. The engine is [`brian::Brian`]: it
//! loads a configuration directory of the manual's files and runs one cycle in well under a
//! microsecond (see `docs/performance.md`).
//!
//! ```
//! use mrt_fuzzy::shapes::{defuzzify, parse_shapes};
//! use std::path::Path;
//!
//! let shapes = parse_shapes(
//!     "(Distance (TRA (NEAREST 0 0.1 40 60)) (TRA (NEAR 40 60 100 120)) (TOR (FAR 100 120)))",
//!     Path::new("shape_ctof.txt"),
//! )?;
//! let near: Vec<_> = shapes[0].fuzzify(45.0, 1.0).filter(|(_, v)| !v.is_dropped()).collect();
//! assert_eq!(near.len(), 2); // NEAREST 0.75 and NEAR 0.25; FAR 0 is dropped
//!
//! // Formula 10.6: VERY_FAST(100) 0.8, FAST(75) 0.6, SLOW(25) 0.9 -> 64.13 cm/s.
//! let speed = defuzzify([(100.0, 0.8), (75.0, 0.6), (25.0, 0.9)], false);
//! assert!((speed.unwrap() - 64.1304).abs() < 1e-4);
//! # Ok::<(), mrt_fuzzy::BrianError>(())
//! ```
//!
//! | seed name (MRT manual ch. 10) | Rust |
//! |---|---|
//! | TRI, TOL, TOR, DIV, TRA, REC, SNG | [`FuzzySet`] |
//! | fuzzy datum `<name, label, value, reliability>` | [`FuzzyValue`] |
//! | `shape_ctof.txt`, `s_shape.txt` | [`shapes::parse_shapes`], [`shapes::Shape`] |
//! | `ctof.txt`, `s_ftoc.txt` | [`shapes::parse_associations`] |
//! | default (singleton) defuzzification, formula 10.6 | [`shapes::defuzzify`] |
//! | barycenter defuzzification (TRI, DIV, TRA, REC outputs), formula 10.7 | [`shapes::barycenter`] |
//! | weighted composition (10.3) or the best behavior's actions (10.5) | [`brian::Composition`], `composition` in `engine.txt` |
//! | `behavior` written in code / `can_do_filter` | [`brian::CodeBehavior`] (`code:<name>` in `behavior.txt`), [`brian::CandoFilter`] |
//! | the original C++ engine's reading of reliability | [`brian::Semantics`], `semantics` in `engine.txt` |
//! | `Predicate.ini`, `PredicateActions.ini`, `Cando.ini`, `want.txt` | [`expr`] grammar, resolved by [`brian::Brian`] |
//! | `behavior.txt`, `*.rul` rules with `&DEL` | [`brian::Brian::from_dir`] |
//! | `weight_composer` (mult, max, min) / `float_composer` (max, average, min) | [`brian::WeightComposer`], [`brian::Composer`], `engine.txt` ([`engine`]) |
//! | `threshold_filter` (0.49) | [`brian::Brian::set_threshold`], `engine.txt` ([`engine`]) |
//! | Parser and Messenger (§10.3.10) on the bus | [`member::BrianMember`], [`member::BrianInputs`], [`member::BrianCommands`] (feature `member`) |
//! | ThinkingCap HBM rules and Context-Dependent Blending (ThinkingCap/TeamChaos report §4.1) | [`hbm::Blender`], [`hbm::ControlVariable`], Mamdani [`hbm::centroid`] |
//! | the checker of §10.4.7 | `mrt brian check DIR` (errors: [`BrianError`]) |
#![deny(missing_docs)]

pub mod brian;
mod compose;
pub mod engine;
mod error;
pub mod expr;
pub mod hbm;
pub mod lexer;
#[cfg(feature = "member")]
pub mod member;
mod set;
pub mod shapes;
mod span;

pub use error::BrianError;
pub use set::{FuzzySet, FuzzyValue};
