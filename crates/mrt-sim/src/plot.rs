//! Drawing a match: the field, trajectories, kicks and the score as SVG.

use crate::config::SimConfig;
use crate::game::MatchReport;
use crate::referee::Call;
use std::fmt::Write as _;

impl MatchReport {
    /// The match as SVG: the field, every robot's and the ball's trajectory (frames must
    /// have been recorded), the kicks and the score; `names` are the teams' names.
    pub fn to_svg(&self, cfg: &SimConfig, names: (&str, &str)) -> String {
        let r = self;
        let f = &cfg.field;
        let (hl, hw, b) = (f.length / 2.0, f.width / 2.0, f.border);
        let scale = 50.0; // px per m
        let (w, h) = ((f.length + 2.0 * b) * scale, (f.width + 2.0 * b) * scale + 40.0);
        let px = |x: f64| (x + hl + b) * scale;
        let py = |y: f64| (hw + b - y) * scale + 40.0;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bus::BusMatch;
    use mrt_robot::stacks::Chaser;

    #[test]
    fn the_drawing_shows_the_field_the_paths_and_the_score() {
        let mut cfg = SimConfig::oracle();
        cfg.rules.half_duration = 5.0;
        cfg.rules.team_size = 1;
        let mut m = BusMatch::with_brains(
            &cfg,
            2,
            vec![Box::new(Chaser::default())],
            vec![Box::new(Chaser::default())],
        )
        .unwrap();
        m.record_frames(true);
        let r = m.play(|_| {}).unwrap();
        let svg = r.to_svg(&cfg, ("red", "blue"));
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        // The field outline is 18 m × 12 m at 50 px/m: 900 × 600 px.
        assert!(svg.contains(r#"width="900.0" height="600.0""#), "{svg}");
        assert_eq!(svg.matches("<path").count(), 3, "two robots and the ball");
        assert!(svg.contains(&format!("red (home, red) {} : {} blue", r.score.0, r.score.1)));
    }
}
