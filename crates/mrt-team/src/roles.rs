//! The roles a team agrees on (ThinkingCap report §3.3: `getRole`, "implemented with a
//! dynamic role allocation method", Agüero et al. 2006a, not retrieved; figure 8's roles).
//!
//! Every robot runs [`allocate`] on the same shared data, so every robot that heard the same
//! reports gets the same answer. The data are each teammate's pose and the role it said it
//! plays, from its latest report, and the team ball.
//!
//! - The goalkeeper is the goalkeeper.
//! - The field players are ranked by their distance to the ball. The one that says it is the
//!   attacker counts [`ROLE_HOLD`] nearer, so roles do not swap back and forth when two
//!   robots are about as far. Ties go to the lower number.
//! - The first is the attacker, the second the supporter, and the others defenders.
//! - Without a ball known, everyone keeps the role it said it plays (a field player new to
//!   the game defends).
//!
//! A robot that has lost contact with its team sees only itself and takes the attacker's
//! role: it plays for itself alone, as SCARE's robots do.
//!
//! ```
//! use mrt_team::roles::{allocate, Player, Role};
//!
//! let players = [
//!     Player { id: 1, at: (-8.5, 0.0), keeper: true, said: Role::Goalkeeper },
//!     Player { id: 2, at: (-1.0, 0.3), keeper: false, said: Role::Defender },
//!     Player { id: 3, at: (-3.0, 0.0), keeper: false, said: Role::Attacker },
//!     Player { id: 4, at: (-6.0, 0.0), keeper: false, said: Role::Supporter },
//! ];
//! let roles = allocate(&players, Some((-1.2, 0.0)));
//! assert_eq!(roles, vec![(1, Role::Goalkeeper), (2, Role::Attacker), (3, Role::Supporter), (4, Role::Defender)]);
//! ```

/// A role in the team (ThinkingCap report, figure 8).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Role {
    /// Keeps goal.
    Goalkeeper,
    /// Goes for the ball.
    Attacker,
    /// Follows the attacker, ready to take over.
    Supporter,
    /// Stays between the ball and its own goal.
    Defender,
}

impl Role {
    /// The role's name, as `getRole().name` gives it.
    pub fn name(self) -> &'static str {
        match self {
            Role::Goalkeeper => "goalkeeper",
            Role::Attacker => "attacker",
            Role::Supporter => "supporter",
            Role::Defender => "defender",
        }
    }

    /// The role of a name ([`Role::name`]); `None` for any other text.
    pub fn from_name(name: &str) -> Option<Role> {
        [Role::Goalkeeper, Role::Attacker, Role::Supporter, Role::Defender]
            .into_iter()
            .find(|r| r.name() == name)
    }
}

/// How much nearer the ball the robot that says it is the attacker counts, m.
pub const ROLE_HOLD: f64 = 0.4;

/// One robot as the allocation sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Player {
    /// Its number.
    pub id: u32,
    /// Where it is (team frame, m).
    pub at: (f64, f64),
    /// Whether it keeps goal.
    pub keeper: bool,
    /// The role it said it plays.
    pub said: Role,
}

/// Every player's role (module doc), in the order of `players`.
pub fn allocate(players: &[Player], ball: Option<(f64, f64)>) -> Vec<(u32, Role)> {
    let Some((bx, by)) = ball.filter(|b| b.0.is_finite() && b.1.is_finite()) else {
        return players
            .iter()
            .map(|p| match (p.keeper, p.said) {
                (true, _) => (p.id, Role::Goalkeeper),
                (false, Role::Goalkeeper) => (p.id, Role::Defender),
                (false, said) => (p.id, said),
            })
            .collect();
    };
    let cost = |p: &Player| {
        let d = (p.at.0 - bx).hypot(p.at.1 - by);
        let d = if d.is_finite() { d } else { f64::MAX };
        if p.said == Role::Attacker {
            d - ROLE_HOLD
        } else {
            d
        }
    };
    let mut field: Vec<&Player> = players.iter().filter(|p| !p.keeper).collect();
    field.sort_by(|a, b| cost(a).total_cmp(&cost(b)).then(a.id.cmp(&b.id)));
    players
        .iter()
        .map(|p| {
            if p.keeper {
                return (p.id, Role::Goalkeeper);
            }
            let rank = field.iter().position(|q| q.id == p.id).unwrap_or(usize::MAX);
            let role = match rank {
                0 => Role::Attacker,
                1 => Role::Supporter,
                _ => Role::Defender,
            };
            (p.id, role)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(id: u32, x: f64, y: f64, said: Role) -> Player {
        Player { id, at: (x, y), keeper: false, said }
    }

    #[test]
    fn the_attacker_keeps_its_role_until_another_is_nearer_by_the_hold() {
        // Ball at the origin; robot 2 attacks from 1 m, robot 3 comes to 0.7 m.
        let near = [p(2, 1.0, 0.0, Role::Attacker), p(3, 0.0, 0.7, Role::Supporter)];
        assert_eq!(
            allocate(&near, Some((0.0, 0.0))),
            vec![(2, Role::Attacker), (3, Role::Supporter)]
        );
        // At 0.55 m it is 0.45 m nearer: more than the hold.
        let nearer = [p(2, 1.0, 0.0, Role::Attacker), p(3, 0.0, 0.55, Role::Supporter)];
        assert_eq!(
            allocate(&nearer, Some((0.0, 0.0))),
            vec![(2, Role::Supporter), (3, Role::Attacker)]
        );
    }

    #[test]
    fn every_robot_computes_the_same_roles_whatever_order_it_lists_them_in() {
        let team = [
            Player { id: 1, at: (-8.5, 0.0), keeper: true, said: Role::Goalkeeper },
            p(2, 0.1, 0.0, Role::Defender),
            p(3, -0.1, 0.0, Role::Defender),
            p(4, 3.0, 0.0, Role::Defender),
        ];
        let ball = Some((0.0, 0.0));
        let mut reversed = team;
        reversed.reverse();
        let mut a = allocate(&team, ball);
        let mut b = allocate(&reversed, ball);
        a.sort();
        b.sort();
        assert_eq!(a, b);
        // 2 and 3 are as far: the lower number attacks.
        assert!(a.contains(&(2, Role::Attacker)) && a.contains(&(3, Role::Supporter)));
        assert!(a.contains(&(1, Role::Goalkeeper)) && a.contains(&(4, Role::Defender)));
    }

    #[test]
    fn without_a_ball_roles_stand_and_alone_a_robot_attacks() {
        let team = [p(2, 0.0, 0.0, Role::Supporter), p(3, 0.0, 0.0, Role::Goalkeeper)];
        assert_eq!(allocate(&team, None), vec![(2, Role::Supporter), (3, Role::Defender)]);
        assert_eq!(
            allocate(&[p(5, 0.0, 0.0, Role::Defender)], Some((9.0, 9.0))),
            vec![(5, Role::Attacker)]
        );
        assert_eq!(allocate(&team, Some((f64::NAN, 0.0))), allocate(&team, None));
        for r in [Role::Goalkeeper, Role::Attacker, Role::Supporter, Role::Defender] {
            assert_eq!(Role::from_name(r.name()), Some(r));
        }
        assert_eq!(Role::from_name("striker"), None);
    }
}
