//! Colour vision (ISocRob-2000 report §3.2.1, the vision µAgent): pixels classified by a colour
//! lookup table built from HSV thresholds ([`colors`]), each image white-balanced to the
//! carpet first ([`balance`]); blobs and the ball ([`blobs`]), goals
//! with their nearest point and open space ([`goals`]), field-line points ([`lines`]) and the
//! landmark posts ([`posts`]) build on it; [`agent`] puts them together into the µAgent: one
//! image in, the percepts out; [`up`] is the µAgent's up mode, the ball in an omnidirectional
//! camera's image; [`calibrate`] helps a person tune the thresholds.

pub mod agent;
pub mod balance;
pub mod blobs;
pub mod calibrate;
pub mod colors;
pub mod goals;
pub mod lines;
pub mod posts;
pub mod up;
