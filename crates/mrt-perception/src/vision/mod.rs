//! Colour vision (ISocRob seed `003` §3.2.1, the vision µAgent): pixels classified by a colour
//! lookup table built from HSV thresholds ([`colors`]). Blobs, the ball, goals, lines and open
//! space build on it (issue 19).

pub mod blobs;
pub mod colors;
pub mod goals;
