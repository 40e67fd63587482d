//! Drawing a match: the field, trajectories, kicks and the score as SVG.

use crate::config::SimConfig;
use crate::game::{BeliefSample, MatchReport};
use crate::referee::Call;
use mrt_msgs::{BallBelief, RobotClass};
use std::fmt::Write as _;

/// The drawing's scale and origin: field metres to SVG pixels, a 40 px title band on top.
struct Canvas {
    hl: f64,
    hw: f64,
    border: f64,
    scale: f64,
}

impl Canvas {
    fn px(&self, x: f64) -> f64 {
        (x + self.hl + self.border) * self.scale
    }
    fn py(&self, y: f64) -> f64 {
        (self.hw + self.border - y) * self.scale + 40.0
    }

    /// The SVG's opening and the field (carpet, lines, goals, penalty areas) of `cfg`.
    fn field(cfg: &SimConfig) -> (Canvas, String) {
        let f = &cfg.field;
        let c = Canvas { hl: f.length / 2.0, hw: f.width / 2.0, border: f.border, scale: 50.0 };
        let (hl, hw, scale) = (c.hl, c.hw, c.scale);
        let (w, h) =
            ((f.length + 2.0 * c.border) * scale, (f.width + 2.0 * c.border) * scale + 40.0);
        let (px, py) = (|x| c.px(x), |y| c.py(y));
        let mut s = String::new();
        let _ = writeln!(
            s,
            r##"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" font-family="sans-serif">"##
        );
        let _ = writeln!(
            s,
            r##"<rect x="0" y="40" width="{w:.0}" height="{:.0}" fill="#2e7d32"/>"##,
            h - 40.0
        );
        let line = r##"stroke="white" stroke-width="2" fill="none""##;
        let _ = writeln!(
            s,
            r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" {line}/>"##,
            px(-hl),
            py(hw),
            f.length * scale,
            f.width * scale
        );
        let _ = writeln!(
            s,
            r##"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" {line}/>"##,
            px(0.0),
            py(hw),
            px(0.0),
            py(-hw)
        );
        let _ = writeln!(
            s,
            r##"<circle cx="{:.1}" cy="{:.1}" r="{:.1}" {line}/>"##,
            px(0.0),
            py(0.0),
            f.centre_circle_radius * scale
        );
        for (side, colour) in [(-1.0, "#1565c0"), (1.0, "#fdd835")] {
            let x = if side < 0.0 { px(-hl - f.goal_depth) } else { px(hl) };
            let _ = writeln!(
                s,
                r##"<rect x="{x:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="{colour}"/>"##,
                py(f.goal_width / 2.0),
                f.goal_depth * scale,
                f.goal_width * scale
            );
            let pa = if side < 0.0 { px(-hl) } else { px(hl - f.penalty_area_depth) };
            let _ = writeln!(
                s,
                r##"<rect x="{pa:.1}" y="{:.1}" width="{:.1}" height="{:.1}" {line}/>"##,
                py(f.penalty_area_width / 2.0),
                f.penalty_area_depth * scale,
                f.penalty_area_width * scale
            );
        }
        (c, s)
    }
}

impl MatchReport {
    /// The match as SVG: the field, every robot's and the ball's trajectory (frames must
    /// have been recorded), the kicks and the score; `names` are the teams' names.
    pub fn to_svg(&self, cfg: &SimConfig, names: (&str, &str)) -> String {
        let r = self;
        let (c, mut s) = Canvas::field(cfg);
        let (px, py) = (|x| c.px(x), |y| c.py(y));
        let n = cfg.rules.team_size;
        let robots = r.frames.first().map_or(0, |fr| fr.robots.len());
        for i in 0..robots {
            let colour = if i < n { "#e53935" } else { "#8e24aa" };
            let mut d = String::new();
            for (k, fr) in r.frames.iter().enumerate() {
                let (x, y, _) = fr.robots[i];
                let _ = write!(d, "{}{:.1},{:.1} ", if k == 0 { "M" } else { "L" }, px(x), py(y));
            }
            let _ = writeln!(
                s,
                r##"<path d="{d}" stroke="{colour}" stroke-width="1.2" fill="none" opacity="0.55"/>"##
            );
        }
        // The ball's path, broken where the referee moved it (kickoff, out, dropped ball).
        let mut d = String::new();
        let mut last: Option<(f64, f64)> = None;
        for fr in &r.frames {
            let jump = last.is_none_or(|(x, y)| (fr.ball.0 - x).hypot(fr.ball.1 - y) > 1.5);
            let _ = write!(
                d,
                "{}{:.1},{:.1} ",
                if jump { "M" } else { "L" },
                px(fr.ball.0),
                py(fr.ball.1)
            );
            last = Some(fr.ball);
        }
        let _ = writeln!(
            s,
            r##"<path d="{d}" stroke="white" stroke-width="1.5" fill="none" opacity="0.8"/>"##
        );
        for (_, robot, (x, y)) in &r.shots {
            let colour = if *robot < n { "#e53935" } else { "#8e24aa" };
            let _ = writeln!(
                s,
                r##"<circle cx="{:.1}" cy="{:.1}" r="4" fill="{colour}" stroke="black"/>"##,
                px(*x),
                py(*y)
            );
        }
        let goals = r.calls.iter().filter(|(_, c)| matches!(c, Call::Goal(_))).count();
        let _ = writeln!(
            s,
            r##"<text x="10" y="26" font-size="20">{} (home, red) {} : {} {} (away, purple) — seed {}, {} goals, {} shots (dots); white: the ball</text>"##,
            names.0,
            r.score.0,
            r.score.1,
            names.1,
            r.seed,
            goals,
            r.shots.len()
        );
        s.push_str("</svg>\n");
        s
    }
}

/// A polyline through `points`, broken where two in a row are more than `jump` m apart (a
/// robot carried, an estimate relocalized, a ball put back by the referee).
fn broken_path(c: &Canvas, points: impl IntoIterator<Item = (f64, f64)>, jump: f64) -> String {
    let mut d = String::new();
    let mut last: Option<(f64, f64)> = None;
    for (x, y) in points {
        let gap = last.is_none_or(|(lx, ly)| (x - lx).hypot(y - ly) > jump);
        let _ = write!(d, "{}{:.1},{:.1} ", if gap { "M" } else { "L" }, c.px(x), c.py(y));
        last = Some((x, y));
    }
    d
}

/// Seconds of roll a velocity arrow shows.
const ARROW_SECONDS: f64 = 0.5;

impl MatchReport {
    /// Robot `robot`'s belief over the match as SVG (frames must have been recorded): its
    /// estimated path (orange, dashed) over its true one (white), the ball where it believed
    /// it saw it (orange dots, with arrows for the velocity it estimated, half a second of roll,
    /// once a second) over the true ball (light blue), and the moments it was carried (a cross
    /// where it was put down, with how soon it found itself again). Only the simulated seconds
    /// `from ..= to` are drawn.
    pub fn belief_svg(&self, cfg: &SimConfig, robot: usize, (from, to): (f64, f64)) -> String {
        let (c, mut s) = Canvas::field(cfg);
        let _ = writeln!(
            s,
            r##"<defs><marker id="arrow" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="5" markerHeight="5" orient="auto"><path d="M0,0 L10,5 L0,10 z" fill="#ff9800"/></marker></defs>"##
        );
        let mine: Vec<&BeliefSample> = self
            .beliefs
            .iter()
            .filter(|b| b.robot == robot && b.time >= from && b.time <= to)
            .collect();
        let ball = broken_path(&c, mine.iter().map(|b| b.true_ball), 1.5);
        let _ = writeln!(
            s,
            r##"<path d="{ball}" stroke="#81d4fa" stroke-width="1.2" fill="none" opacity="0.8"/>"##
        );
        let truth = broken_path(&c, mine.iter().map(|b| (b.truth.x, b.truth.y)), 1.0);
        let _ = writeln!(
            s,
            r##"<path d="{truth}" stroke="white" stroke-width="2" fill="none" opacity="0.9"/>"##
        );
        let belief = broken_path(&c, mine.iter().map(|b| (b.estimate.x, b.estimate.y)), 1.0);
        let _ = writeln!(
            s,
            r##"<path d="{belief}" stroke="#ff9800" stroke-width="1.5" stroke-dasharray="5,3" fill="none"/>"##
        );
        let mut next_arrow = f64::NEG_INFINITY;
        for b in &mine {
            let Some(BallBelief { at, velocity, .. }) = b.ball else { continue };
            let (x, y) = (at.inner.x, at.inner.y);
            let _ = writeln!(
                s,
                r##"<circle cx="{:.1}" cy="{:.1}" r="1.8" fill="#ff9800"/>"##,
                c.px(x),
                c.py(y)
            );
            if let Some(v) = velocity.filter(|_| b.time >= next_arrow) {
                next_arrow = b.time + 1.0;
                let (vx, vy) = (v.inner.x, v.inner.y);
                let (tx, ty) = (x + vx * ARROW_SECONDS, y + vy * ARROW_SECONDS);
                let _ = writeln!(
                    s,
                    r##"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="#ff9800" stroke-width="1.5" marker-end="url(#arrow)"/>"##,
                    c.px(x),
                    c.py(y),
                    c.px(tx),
                    c.py(ty)
                );
            }
        }
        // Once a second: the other robots where they were (rings: green its teammates, red
        // its opponents) and where it anchored them (crosses in the colour of the class it
        // gave them, grey for a robot of unknown team).
        let mut next_robots = f64::NEG_INFINITY;
        for b in mine.iter().filter(|b| !b.others.is_empty()) {
            if b.time < next_robots {
                continue;
            }
            next_robots = b.time + 1.0;
            for &((x, y), mate) in &b.others {
                let colour = if mate { "#66bb6a" } else { "#ef5350" };
                let _ = writeln!(
                    s,
                    r##"<circle class="true-robot" cx="{:.1}" cy="{:.1}" r="5" fill="none" stroke="{colour}" stroke-width="1" opacity="0.6"/>"##,
                    c.px(x),
                    c.py(y)
                );
            }
            for &((x, y), class) in &b.anchors {
                let colour = match class {
                    RobotClass::Teammate => "#66bb6a",
                    RobotClass::Opponent => "#ef5350",
                    RobotClass::Robot => "#bdbdbd",
                };
                let _ = writeln!(
                    s,
                    r##"<path class="anchor" d="M{:.1},{:.1} l6,6 m0,-6 l-6,6" stroke="{colour}" stroke-width="1.5"/>"##,
                    c.px(x) - 3.0,
                    c.py(y) - 3.0
                );
            }
        }
        for k in self.kidnaps.iter().filter(|k| k.robot == robot && k.at >= from && k.at <= to) {
            let (x, y) = (c.px(k.to.x), c.py(k.to.y));
            let found =
                k.recovered_after.map_or("not found".to_string(), |t| format!("found {t:.1} s"));
            let _ = writeln!(
                s,
                r##"<path d="M{:.1},{:.1} l12,12 M{:.1},{:.1} l-12,12" stroke="#e53935" stroke-width="3"/>"##,
                x - 6.0,
                y - 6.0,
                x + 6.0,
                y - 6.0
            );
            // The label on the side of the cross towards the middle, so that it stays in the
            // picture.
            let (tx, anchor) = if k.to.x > 0.0 { (x - 9.0, "end") } else { (x + 9.0, "start") };
            let _ = writeln!(
                s,
                r##"<text x="{tx:.1}" y="{:.1}" font-size="13" fill="white" text-anchor="{anchor}">carried at {:.1} s, {found}</text>"##,
                y - 8.0,
                k.at
            );
        }
        let mut errors: Vec<f64> = mine
            .iter()
            .map(|b| (b.estimate.x - b.truth.x).hypot(b.estimate.y - b.truth.y))
            .collect();
        errors.sort_by(f64::total_cmp);
        let at = |q: f64| errors.get(((errors.len().max(1) - 1) as f64 * q) as usize).copied();
        let summary = match (at(0.5), at(0.95)) {
            (Some(m), Some(p)) => format!("position error median {m:.2} m, 95 % {p:.2} m"),
            _ => "no estimate recorded".to_string(),
        };
        let (first, last) = match (mine.first(), mine.last()) {
            (Some(a), Some(b)) => (a.time, b.time),
            _ => (from, to),
        };
        let _ = writeln!(
            s,
            r##"<text x="10" y="17" font-size="15">robot {robot}'s belief, seed {}, {first:.0} to {last:.0} s: {summary}</text>"##,
            self.seed
        );
        let _ = writeln!(
            s,
            r##"<text x="10" y="35" font-size="12">white: where it was · orange dashed: where it believed it was · orange dots, arrows: the ball it saw, its velocity (0.5 s) · blue: the ball · red ×: carried</text>"##
        );
        // The robots' legend at the bottom of the carpet, below the field.
        let _ = writeln!(
            s,
            r##"<text x="10" y="{:.0}" font-size="12" fill="white">each second, rings: the other robots (green: teammates, red: opponents) · crosses: where it anchored them, coloured by the team it gave them (grey: unknown)</text>"##,
            c.py(-(c.hw + c.border)) - 10.0
        );
        s.push_str("</svg>\n");
        s
    }
}

/// The indoor world's mission (`mrt sim --world indoor --plot`): the building, the path
/// points (numbered, green when reached), where the robot went (blue) and where it believed
/// it was once a second (orange dots), the doors that closed (red), the people's walks (grey),
/// and the cells its sonars found occupied at the end (red squares).
pub fn indoor(map: &mrt_plan::spike::PlanMap, r: &crate::indoor::IndoorReport) -> String {
    use mrt_robot::mission::MissionEvent;
    let scale = 50.0;
    let sheet = mrt_plan::spike::draw::Sheet::of(map, scale);
    let (w, h) = ((map.max.x - map.min.x) * scale, (map.max.y - map.min.y) * scale);
    let band = 44.0;
    let (x, y) = (|v: f64| sheet.x(v), |v: f64| sheet.y(v));
    let mut s = String::new();
    let _ = writeln!(
        s,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{:.0}" viewBox="0 0 {w:.0} {:.0}" font-family="sans-serif">"##,
        h + band,
        h + band
    );
    let _ = writeln!(s, r##"<rect width="{w:.0}" height="{:.0}" fill="#ffffff"/>"##, h + band);
    let _ = writeln!(
        s,
        r##"<text x="8" y="18" font-size="14">Roby, seed {}: {} of {} points in {:.1} s, {} re-plans, belief {:.2} m off at the end</text>"##,
        r.seed,
        r.reached(),
        r.points.len(),
        r.duration,
        r.replans(),
        r.final_error
    );
    let _ = writeln!(
        s,
        r##"<text x="8" y="36" font-size="11">blue: where it went · orange: where it believed it was · red: closed door, occupied cells · grey: a person's walk</text>"##
    );
    let _ = writeln!(s, r##"<g transform="translate(0 {band})">"##);
    let _ = writeln!(
        s,
        r##"<rect width="{w:.0}" height="{h:.0}" fill="#f4f4f0" stroke="#333333" stroke-width="4"/>"##
    );
    sheet.map(&mut s, map);
    for (a, b) in &r.closed_doors {
        let _ = writeln!(
            s,
            r##"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="#c0392b" stroke-width="5"/>"##,
            x(a.x),
            y(a.y),
            x(b.x),
            y(b.y)
        );
    }
    if let Some(last) = r.samples.last() {
        for p in &last.occupied {
            let side = mrt_robot::mission::ECHO_CELL * scale;
            let _ = writeln!(
                s,
                r##"<rect x="{:.1}" y="{:.1}" width="{side:.1}" height="{side:.1}" fill="#c0392b" fill-opacity="0.6"/>"##,
                x(p.x) - side / 2.0,
                y(p.y) - side / 2.0
            );
        }
    }
    let walks: Vec<(f64, f64)> =
        r.samples.iter().flat_map(|s| s.persons.iter().map(|(p, _)| (p.x, p.y))).collect();
    for (px, py) in walks.iter().step_by(3) {
        let _ = writeln!(
            s,
            r##"<circle cx="{:.1}" cy="{:.1}" r="3" fill="#9e9e9e"/>"##,
            x(*px),
            y(*py)
        );
    }
    let path: Vec<String> =
        r.trajectory.iter().map(|p| format!("{:.1},{:.1}", x(p.x), y(p.y))).collect();
    let _ = writeln!(
        s,
        r##"<polyline points="{}" fill="none" stroke="#1f4e9c" stroke-width="2" stroke-linejoin="round"/>"##,
        path.join(" ")
    );
    for b in &r.samples {
        let _ = writeln!(
            s,
            r##"<circle cx="{:.1}" cy="{:.1}" r="2.5" fill="#e67e22"/>"##,
            x(b.belief.x),
            y(b.belief.y)
        );
    }
    for (k, p) in r.points.iter().enumerate() {
        let reached = r
            .events
            .iter()
            .any(|e| matches!(e, MissionEvent::Reached { point, .. } if *point == k));
        let colour = if reached { "#27ae60" } else { "#8e44ad" };
        let _ = writeln!(
            s,
            r##"<circle cx="{:.1}" cy="{:.1}" r="12" fill="none" stroke="{colour}" stroke-width="3"/><text x="{:.1}" y="{:.1}" font-size="13" text-anchor="middle" fill="{colour}">{}</text>"##,
            x(p.x),
            y(p.y),
            x(p.x),
            y(p.y) + 5.0,
            k + 1
        );
    }
    s.push_str("</g>\n</svg>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bus::BusMatch;
    use mrt_robot::stacks::Chaser;

    /// A recorded one-a-side match of chasers, halves of `half` s, `kidnaps` carries a half.
    fn recorded(seed: u64, half: f64, kidnaps: u32) -> (SimConfig, MatchReport) {
        let mut cfg = SimConfig::oracle();
        cfg.rules.half_duration = half;
        cfg.rules.team_size = 1;
        cfg.rules.kidnaps = kidnaps;
        let chaser =
            || vec![Box::new(Chaser::default()) as Box<dyn mrt_robot::brain::Brain + Send>];
        let mut m = BusMatch::with_brains(&cfg, seed, chaser(), chaser()).unwrap();
        m.record_frames(true);
        let r = m.play(|_| {}).unwrap();
        (cfg, r)
    }

    #[test]
    fn the_drawing_shows_the_field_the_paths_and_the_score() {
        let (cfg, r) = recorded(2, 5.0, 0);
        let svg = r.to_svg(&cfg, ("red", "blue"));
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        // The field outline is 18 m × 12 m at 50 px/m: 900 × 600 px.
        assert!(svg.contains(r#"width="900.0" height="600.0""#), "{svg}");
        assert_eq!(svg.matches("<path").count(), 3, "two robots and the ball");
        assert!(svg.contains(&format!("red (home, red) {} : {} blue", r.score.0, r.score.1)));
    }

    #[test]
    fn a_robots_belief_is_drawn_over_the_truth_with_its_carries() {
        let (cfg, r) = recorded(3, 20.0, 1);
        assert!(r.beliefs.iter().any(|b| b.robot == 0) && r.beliefs.iter().any(|b| b.robot == 1));
        let carried = r.kidnaps.iter().filter(|k| k.robot == 0).count();
        assert!(carried >= 1, "{:?}", r.kidnaps);
        let svg = r.belief_svg(&cfg, 0, (0.0, f64::INFINITY));
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        let paths = svg.matches("<path d=\"M").count();
        assert_eq!(paths, 4 + carried, "arrowhead, ball, truth, belief, carries");
        assert_eq!(svg.matches("carried at").count(), carried);
        assert!(svg.contains("stroke-dasharray"), "the belief is dashed");
        assert!(
            svg.contains("robot 0's belief, seed 3, ") && svg.contains("position error median")
        );
        let seen = r.beliefs.iter().filter(|b| b.robot == 0 && b.ball.is_some()).count();
        assert_eq!(svg.matches("r=\"1.8\"").count(), seen, "one dot per sighting");
        // The other robot (an opponent: one a side) once a second, and where robot 0 anchored
        // it: a red cross, near the red ring.
        let rings = svg.matches("class=\"true-robot\"").count();
        assert!((35..=42).contains(&rings), "{rings} rings in 40 s");
        assert!(svg.matches("class=\"anchor\"").count() >= rings / 2, "{svg}");
        assert!(
            !svg.contains("class=\"anchor\" d=\"M0")
                && svg.contains("stroke=\"#ef5350\" stroke-width=\"1.5\"")
        );
        // A robot with no estimate gets the field and says so.
        assert!(r.belief_svg(&cfg, 9, (0.0, 1e9)).contains("no estimate recorded"));
        // A window: only its samples (none before the kickoff's first estimate).
        assert!(r.belief_svg(&cfg, 0, (-5.0, -1.0)).contains("no estimate recorded"));
        let early = r.belief_svg(&cfg, 0, (0.0, 5.0));
        assert!(early.matches("r=\"1.8\"").count() < seen);
    }
}
