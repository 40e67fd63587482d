//! Looking around with the body: what a robot whose camera cannot pan does when its world
//! model needs to localize ([`WorldSnapshot::needs_localization`](mrt_msgs::WorldSnapshot)).
//!
//! ThinkingCap's behaviors state a perceptual need for landmarks (`trackLandMarks`, ThinkingCap/TeamChaos report
//! §2.1) and the PAM turns the head to satisfy it ([`mrt_world::gaze`]). A robot with a fixed
//! camera has only its body to turn. When the world model doubts its pose (the goals and posts
//! it sees disagree with it: a robot carried by hand, the kidnapped robot of every RoboCup
//! match), guidance replaces the behaviors' command with a
//! turn in place, during play only, until the need is met or one whole turn is done. A turn
//! that did not meet the need is followed by [`REST`] seconds of the behaviors' own commands
//! before the next: a robot that sees nothing it knows (facing a wall) still plays.
//!
//! ```
//! use mrt_robot::look_around::{LookAround, TURN_RATE};
//!
//! let mut look = LookAround::default();
//! assert_eq!(look.step(0.0, true, true), Some(TURN_RATE), "in doubt during play: turn");
//! assert_eq!(look.step(0.5, false, true), None, "the need met: the behaviors drive again");
//! ```

use std::f64::consts::TAU;

/// How fast the robot turns to look around, rad/s (counter-clockwise).
pub const TURN_RATE: f64 = 2.0;
/// A look-around ends after one whole turn (s at [`TURN_RATE`]) ...
pub const TURN_TIME: f64 = TAU / TURN_RATE;
/// ... and the next may start this long after it, s.
pub const REST: f64 = 5.0;

/// The look-around of one robot (module doc): when it turns.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LookAround {
    /// When the current turn began, s.
    turning: Option<f64>,
    /// No turn starts before this, s.
    rest_until: f64,
}

impl LookAround {
    /// One cycle at `now` (s): whether the world model `needs` to localize and whether the
    /// game is being `played`. Returns the turning rate to command (rad/s), or `None` when the
    /// behaviors' command stands.
    pub fn step(&mut self, now: f64, needs: bool, played: bool) -> Option<f64> {
        if !needs || !played || !now.is_finite() {
            self.turning = None;
            return None;
        }
        let since = match self.turning {
            Some(t) => t,
            None if now >= self.rest_until => *self.turning.insert(now),
            None => return None,
        };
        if now - since >= TURN_TIME {
            self.turning = None;
            self.rest_until = now + REST;
            return None;
        }
        Some(TURN_RATE)
    }

    /// Whether a turn is under way.
    pub fn turning(&self) -> bool {
        self.turning.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steps of 0.1 s from `from` to `to` with the same need, the rates commanded.
    fn run(look: &mut LookAround, from: f64, to: f64, needs: bool) -> Vec<Option<f64>> {
        let n = ((to - from) / 0.1).round() as usize;
        (0..n).map(|i| look.step(from + 0.1 * i as f64, needs, true)).collect()
    }

    #[test]
    fn a_robot_in_doubt_turns_once_round_then_rests_then_turns_again() {
        let mut look = LookAround::default();
        let first = run(&mut look, 0.0, 10.0, true);
        let turning = first.iter().take_while(|r| r.is_some()).count();
        // 2π / 2 rad/s = 3.14 s: 32 steps of 0.1 s (0.0 ..= 3.1), then rest.
        assert_eq!(turning, 32);
        assert!(first[32..].iter().take(50).all(Option::is_none), "rests 5 s");
        // The rest ended at 3.2 + 5 = 8.2 s: step 82 turns again.
        assert_eq!(first[82], Some(TURN_RATE));
        assert!(first[81].is_none());
    }

    #[test]
    fn the_turn_stops_when_the_need_is_met_or_play_stops() {
        let mut look = LookAround::default();
        assert_eq!(look.step(0.0, true, true), Some(TURN_RATE));
        assert!(look.turning());
        assert_eq!(look.step(0.1, false, true), None);
        assert!(!look.turning());
        // A need met early leaves no rest: the next doubt turns at once.
        assert_eq!(look.step(0.2, true, true), Some(TURN_RATE));
        assert_eq!(look.step(0.3, true, false), None, "the referee stopped play");
        assert_eq!(look.step(f64::NAN, true, true), None, "no clock, no turn");
    }
}
