//! The pitch's book of what the robots believed, against the truth: their own poses and the
//! ball's ([`LocalizationErrors`]), the other robots they anchored ([`RobotErrors`]) and the
//! team beliefs two robots should not hold at once ([`TeamStats`]: the ball booking, the
//! attacker, SCARE's job on the ball). The robots never read it; the match report does.

use super::{BeliefSample, Pitch, FALSELY_RELOCALIZED, PHANTOM, RECOVERED};
#[cfg(doc)]
use super::{LocalizationErrors, RobotErrors, TeamStats};
use crate::referee::Team;
use mrt_core::frames::Attack;
use mrt_core::normalize_angle;
use mrt_msgs::{AnchoredRobot, Localization, RobotClass, WorldSnapshot};
use mrt_world::team::SHARED_ID;

impl Pitch {
    /// Books robot `i`'s own estimates (its pose, and the ball's when it sees it) against the
    /// truth now, and notes when a kidnapped robot is found again.
    pub fn book_estimate(&mut self, i: usize, estimate: &Localization) {
        let Some(truth) = self.world.robot(i) else { return };
        let p = estimate.pose.inner;
        let seen = estimate.ball.filter(|b| b.seen_ago <= 0.0);
        if self.record {
            self.beliefs.push(BeliefSample {
                robot: i,
                time: self.world.time(),
                estimate: p,
                truth,
                ball: seen,
                true_ball: self.world.ball(),
                anchors: Vec::new(),
                others: Vec::new(),
            });
        }
        let l = &mut self.localization;
        let off = (p.x - truth.x).hypot(p.y - truth.y);
        l.position.push(off);
        l.heading.push(normalize_angle(p.theta - truth.theta).abs());
        if let Some(ball) = seen {
            let (bx, by) = self.world.ball();
            l.ball.push((ball.at.inner.x - bx).hypot(ball.at.inner.y - by));
            if let Some(v) = ball.velocity {
                let (tx, ty) = self.world.ball_velocity();
                l.ball_velocity.push((v.inner.x - tx).hypot(v.inner.y - ty));
            }
        }
        if l.seen_relocalized.len() <= i {
            l.seen_relocalized.resize(i + 1, 0);
        }
        let fixes = estimate.counts.relocalized.saturating_sub(l.seen_relocalized[i]);
        l.seen_relocalized[i] = estimate.counts.relocalized;
        l.relocalized += fixes;
        if off > FALSELY_RELOCALIZED {
            l.falsely_relocalized += fixes;
        }
        let now = self.world.time();
        if let Some(k) = self.kidnaps.iter_mut().rev().find(|k| k.robot == i) {
            if k.recovered_after.is_none() && now > k.at && off < RECOVERED {
                k.recovered_after = Some(now - k.at);
            }
        }
    }

    /// Books robot `i`'s beliefs of this cycle that it holds the ball booking, that it is
    /// the attacker, and that SCARE gave it a job that plays the ball, and whether a teammate
    /// believed so in the same cycle ([`TeamStats::booking_conflicts`],
    /// [`TeamStats::attacker_conflicts`], [`TeamStats::ball_job_conflicts`]).
    pub fn book_team_beliefs(&mut self, i: usize, held: bool, attacker: bool, ball_job: bool) {
        let now = self.world.time();
        let team = self.referee.team_of(i);
        let referee = &self.referee;
        // Marks robot `i` in `at` for this cycle; whether a teammate was marked in it too.
        let mark = |at: &mut Vec<f64>| {
            let slot = at.get_mut(i)?;
            *slot = now;
            Some((0..at.len()).any(|k| k != i && referee.team_of(k) == team && at[k] == now))
        };
        let stats = &mut self.stats[team.index()];
        if held {
            if let Some(mate) = mark(&mut self.booked_at) {
                stats.booked_cycles += 1;
                stats.booking_conflicts += u64::from(mate);
            }
        }
        if attacker {
            if let Some(mate) = mark(&mut self.attacker_at) {
                stats.attacker_cycles += 1;
                stats.attacker_conflicts += u64::from(mate);
            }
        }
        if ball_job {
            if let Some(mate) = mark(&mut self.ball_job_at) {
                stats.ball_job_cycles += 1;
                stats.ball_job_conflicts += u64::from(mate);
            }
        }
    }

    /// Books the robots robot `i`'s world snapshot anchored (team frame) against where
    /// the other robots are now ([`RobotErrors`]); anchors not seen in this frame are left out.
    pub fn book_robots(&mut self, i: usize, robots: &[AnchoredRobot]) {
        let mine = self.referee.team_of(i);
        let attack = self.referee.attack_direction(mine);
        let others: Vec<((f64, f64), Team)> = (0..self.world.robot_count())
            .filter(|&k| k != i)
            .filter_map(|k| self.world.robot(k).map(|p| ((p.x, p.y), self.referee.team_of(k))))
            .collect();
        // Kept with the robot's belief of this cycle, for drawing (its `Localization` came
        // first in the cycle).
        let now = self.world.time();
        let sample = self
            .beliefs
            .iter_mut()
            .rev()
            .take_while(|b| b.time >= now)
            .find(|b| b.robot == i)
            .filter(|_| self.record);
        let field = |r: &AnchoredRobot| {
            let p = r.at.to_field(Attack::from_direction(attack)).inner;
            (p.x, p.y)
        };
        if let Some(b) = sample {
            b.anchors =
                robots.iter().filter(|r| r.seen_ago <= 0.0).map(|r| (field(r), r.class)).collect();
            b.others = others.iter().map(|&(at, team)| (at, team == mine)).collect();
        }
        let e = &mut self.localization.robots;
        let nearest = |(x, y): (f64, f64)| {
            others
                .iter()
                .map(|&((ox, oy), team)| ((ox - x).powi(2) + (oy - y).powi(2), team))
                .min_by(|a, b| a.0.total_cmp(&b.0))
        };
        let remembered = |r: &&AnchoredRobot| {
            r.seen_ago > 0.0 && r.reliability >= WorldSnapshot::ANCHORED && r.id & SHARED_ID == 0
        };
        for r in robots.iter().filter(remembered) {
            let Some((d2, _)) = nearest(field(r)) else { continue };
            let d = d2.sqrt();
            e.remembered.push(d);
            e.remembered_phantoms += u64::from(d > PHANTOM);
        }
        for r in robots.iter().filter(|r| r.seen_ago <= 0.0) {
            // The team frame turned back into the field's (half a turn when attacking west).
            let Some((d2, team)) = nearest(field(r)) else { continue };
            let d = d2.sqrt();
            e.position.push(d);
            if d > PHANTOM {
                e.phantoms += 1;
                continue;
            }
            let truth = if team == mine { RobotClass::Teammate } else { RobotClass::Opponent };
            match r.class {
                RobotClass::Robot => e.class_unknown += 1,
                c if c == truth => e.class_right += 1,
                _ => e.class_wrong += 1,
            }
        }
    }
}
