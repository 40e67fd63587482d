//! What `mrt sim` prints after one match: the score and each team's line, what the robots
//! believed against the truth, and what went wrong on the way (robots not found after a
//! kidnap, faults).

use mrt_sim::game::{MatchReport, TeamStats};
use mrt_sim::metrics::Metrics;
use mrt_sim::referee::{Call, Team};

/// The score, each team's line, its robots' team beliefs and the goals' times.
pub(super) fn score(report: &MatchReport, (h, a): (&str, &str)) {
    outln!("{h} (home) {} : {} {a} (away)   seed {}", report.score.0, report.score.1, report.seed);
    for line in team_lines(&[h, a], &report.stats) {
        outln!("{line}");
    }
    for (i, name) in [(0, h), (1, a)] {
        let s = &report.stats[i];
        if s.booked_cycles > 0 {
            outln!(
                "  {name:<8} ball booked in {} robot cycles, by two robots at once in {}",
                s.booked_cycles,
                s.booking_conflicts
            );
        }
        // What the robots believed is watched in one process only (not with --distributed).
        if s.attacker_cycles > 0 {
            outln!(
                "  {name:<8} attacker (getRole) in {} robot cycles, two at once in {}",
                s.attacker_cycles,
                s.attacker_conflicts
            );
        }
        if s.ball_job_cycles > 0 {
            outln!(
                "  {name:<8} SCARE job on the ball in {} robot cycles, two at once in {}",
                s.ball_job_cycles,
                s.ball_job_conflicts
            );
        }
    }
    for (t, call) in &report.calls {
        if let Call::Goal(team) = call {
            let who = if *team == Team::Home { h } else { a };
            outln!("  goal {who:<8} at {:>3}:{:02}", (*t as u64) / 60, (*t as u64) % 60);
        }
    }
}

/// How far the robots' estimates were from the truth: their poses, the ball, the other
/// robots; relocalizations and kidnaps.
pub(super) fn estimates(m: &Metrics) {
    let l = &m.localization;
    if let (Some(pm), Some(p95), Some(hm), Some(h95)) =
        (l.median_m, l.p95_m, l.heading_median_deg, l.heading_p95_deg)
    {
        outln!(
            "  localization error (the robots' own estimates against the truth): position {pm:.2} m median, {p95:.2} m p95; heading {hm:.1}° median, {h95:.1}° p95"
        );
    }
    if let (Some(mean), Some(p95)) = (m.ball.mean_m, m.ball.p95_m) {
        let velocity = m
            .ball
            .velocity_mean_mps
            .map_or(String::new(), |v| format!("; velocity {v:.2} m/s mean"));
        outln!("  ball error while seen: {mean:.2} m mean, {p95:.2} m p95{velocity}");
    }
    let r = &m.robots;
    if let (Some(median), Some(p95)) = (r.median_m, r.p95_m) {
        outln!(
            "  other robots anchored while seen: {median:.2} m median, {p95:.2} m p95; team right {}, wrong {}, unknown {}; {} phantoms",
            r.class_right,
            r.class_wrong,
            r.class_unknown,
            r.phantoms
        );
    }
    if let (Some(median), Some(p95)) = (r.remembered_median_m, r.remembered_p95_m) {
        outln!(
            "  other robots remembered unseen (reliability ≥ 0.3): {median:.2} m median, {p95:.2} m p95; {} phantoms of {}",
            r.remembered_phantoms,
            r.remembered_samples
        );
    }
    if m.localization.relocalized > 0 {
        outln!(
            "  relocalized {} times, {} of them falsely (> 1 m from the truth)",
            m.localization.relocalized,
            m.localization.falsely_relocalized
        );
    }
    if m.kidnap.count > 0 {
        outln!(
            "  kidnapped {} times, found again {} times{}",
            m.kidnap.count,
            m.kidnap.recovered,
            m.kidnap
                .median_recovery_s
                .map_or(String::new(), |t| format!(" (median {t:.1} s after the carry)"))
        );
    }
}

/// The kidnapped robots not found again and the robots that faulted, each with its team
/// (robots `0 .. team_size` are home's).
pub(super) fn incidents(report: &MatchReport, team_size: usize, (h, a): (&str, &str)) {
    let n = team_size;
    let clock = |t: f64| format!("{}:{:04.1}", (t / 60.0).floor() as u64, t % 60.0);
    for k in report.kidnaps.iter().filter(|k| k.recovered_after.is_none()) {
        let (team, i) = if k.robot < n { (h, k.robot) } else { (a, k.robot - n) };
        outln!(
            "  robot {} ({team} #{i}) carried at {} to ({:.2}, {:.2}) m facing {:.0}°: not found again",
            k.robot,
            clock(k.at),
            k.to.x,
            k.to.y,
            k.to.theta.to_degrees()
        );
    }
    for f in &report.faults {
        let (team, k) = if f.robot < n { (h, f.robot) } else { (a, f.robot - n) };
        let from = f
            .first_at
            .map_or(String::new(), |t| format!(" from {}:{:02}", (t as u64) / 60, (t as u64) % 60));
        outln!(
            "  robot {} ({team} #{k}) faulted {} times{from} (stood still meanwhile): {}",
            f.robot,
            f.count,
            mrt_core::printable(&f.message)
        );
    }
}

/// A match's line for each team named (home's, then away's, if it played): goals, shots (on
/// target) and the team's share of the cycles in which one of its robots was the closest to
/// the ball.
pub(crate) fn team_lines(names: &[&str], stats: &[TeamStats; 2]) -> Vec<String> {
    let total = (stats[0].possession_cycles + stats[1].possession_cycles).max(1) as f64;
    names
        .iter()
        .zip(stats)
        .map(|(name, s)| {
            format!(
                "  {name:<8} goals {:>2}  shots {:>3} ({:>3} on target)  possession {:>5.1} %",
                s.goals,
                s.shots,
                s.shots_on_target,
                100.0 * s.possession_cycles as f64 / total
            )
        })
        .collect()
}
