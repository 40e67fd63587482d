//! An HFSM drawn as SVG, with a layout of our own that stays linear in the machine's size.
//!
//! Each machine is a panel, the root first; inside it the states stand in columns by their
//! distance (in transitions) from the initial state, read left to right as the dot drawing
//! (`rankdir=LR`); within a column, states are ordered by where their predecessors stand (one
//! barycentre pass, which removes most crossings of a state machine's usual shape). Forward
//! transitions are curves between columns, the others arcs below, self-loops small loops
//! above; a meta-state's dashed arrow points at the panel of the machine it runs.

use super::{Hfsm, StateKind};
use std::collections::VecDeque;
use std::fmt::Write as _;

const FONT: f64 = 11.0;
/// Width of one character of the labels (Helvetica at `FONT` px, on average).
const CHAR: f64 = 6.4;
const NODE_H: f64 = 26.0;
const ROW_GAP: f64 = 18.0;
const COL_GAP: f64 = 90.0;
const PAD: f64 = 24.0;
const TITLE_H: f64 = 26.0;
/// Vertical room of one backward transition's arc and label.
const LANE: f64 = 14.0;

struct Placed {
    x: f64,
    y: f64,
    w: f64,
}

fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            c if c.is_control() => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// Labels longer than this are cut in drawings (the dot output keeps them whole).
const MAX_LABEL: usize = 48;

fn short(s: &str) -> String {
    match s.char_indices().nth(MAX_LABEL) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s.to_string(),
    }
}

impl Hfsm {
    /// The machine as a standalone SVG drawing.
    pub fn to_svg(&self) -> String {
        let mut body = String::new();
        let mut panel_y = PAD;
        let mut width: f64 = 0.0;
        // The root first, then the others in file order.
        let order: Vec<usize> = std::iter::once(self.root)
            .chain((0..self.machines.len()).filter(|&m| m != self.root))
            .collect();
        // Where each machine's initial state was drawn, for the meta-states' arrows.
        let mut panel_top = vec![0.0; self.machines.len()];
        let mut metas: Vec<(f64, f64, usize)> = Vec::new();
        for &mi in &order {
            let m = &self.machines[mi];
            let n = m.states.len();
            let labels: Vec<String> = m
                .states
                .iter()
                .map(|s| match s.kind {
                    StateKind::Meta(inner) => {
                        short(&format!("{} [{}]", s.name, self.machines[inner].name))
                    }
                    StateKind::Code(_) => short(&s.name),
                })
                .collect();
            // Columns: breadth-first distance from the initial state.
            let mut out_edges = vec![Vec::new(); n];
            let mut in_edges = vec![Vec::new(); n];
            for t in &m.transitions {
                out_edges[t.from].push(t.to);
                in_edges[t.to].push(t.from);
            }
            let mut rank = vec![usize::MAX; n];
            let mut queue = VecDeque::from([m.initial]);
            rank[m.initial] = 0;
            let mut found = vec![m.initial];
            while let Some(s) = queue.pop_front() {
                for &t in &out_edges[s] {
                    if rank[t] == usize::MAX {
                        rank[t] = rank[s] + 1;
                        found.push(t);
                        queue.push_back(t);
                    }
                }
            }
            let reached = rank.iter().filter(|r| **r != usize::MAX).map(|r| r + 1).max();
            let unreached = reached.unwrap_or(0);
            for (s, r) in rank.iter_mut().enumerate() {
                if *r == usize::MAX {
                    *r = unreached;
                    found.push(s);
                }
            }
            let ranks = rank.iter().max().map_or(0, |r| r + 1);
            let mut columns: Vec<Vec<usize>> = vec![Vec::new(); ranks];
            for &s in &found {
                columns[rank[s]].push(s);
            }
            // One barycentre pass: order each column by its predecessors' rows.
            let mut row = vec![0.0; n];
            for col in &mut columns {
                let key = |s: &usize| {
                    let preds: Vec<f64> = in_edges[*s]
                        .iter()
                        .filter(|p| rank[**p] < rank[*s])
                        .map(|p| row[*p])
                        .collect();
                    if preds.is_empty() {
                        f64::MAX
                    } else {
                        preds.iter().sum::<f64>() / preds.len() as f64
                    }
                };
                let mut keyed: Vec<(f64, usize)> = col.iter().map(|s| (key(s), *s)).collect();
                keyed.sort_by(|a, b| a.0.total_cmp(&b.0));
                *col = keyed.into_iter().map(|(_, s)| s).collect();
                for (i, s) in col.iter().enumerate() {
                    row[*s] = i as f64;
                }
            }
            // Positions.
            let top = panel_y + TITLE_H;
            let mut placed: Vec<Placed> =
                (0..n).map(|_| Placed { x: 0.0, y: 0.0, w: 0.0 }).collect();
            let mut x = PAD + 30.0;
            let mut tallest: f64 = 0.0;
            for col in &columns {
                let w = col
                    .iter()
                    .map(|s| labels[*s].chars().count() as f64 * CHAR + 20.0)
                    .fold(60.0, f64::max);
                for (i, s) in col.iter().enumerate() {
                    let y = top + i as f64 * (NODE_H + ROW_GAP);
                    placed[*s] = Placed { x, y, w };
                }
                tallest = tallest.max(col.len() as f64 * (NODE_H + ROW_GAP));
                x += w + COL_GAP;
            }
            // Backward transitions arc under the states, each one lane lower than the last so
            // that their labels do not overlap.
            let backward = m
                .transitions
                .iter()
                .filter(|t| t.from != t.to && rank[t.to] <= rank[t.from])
                .count();
            let panel_h = TITLE_H + tallest + 2.0 * ROW_GAP + 16.0 + LANE * backward as f64;
            let panel_w = x - COL_GAP + 30.0;
            width = width.max(panel_w + PAD);
            panel_top[mi] = top;
            let root = if mi == self.root { " (root)" } else { "" };
            let _ = writeln!(
                body,
                r##"<g class="machine"><rect x="{PAD}" y="{panel_y}" width="{:.1}" height="{panel_h:.1}" rx="8" fill="#f7f7fb" stroke="#9aa"/><text x="{:.1}" y="{:.1}" font-weight="bold">{}</text>"##,
                panel_w - PAD,
                PAD + 10.0,
                panel_y + 17.0,
                esc(&format!("{}{root}", m.name))
            );
            // The entry point.
            let init = &placed[m.initial];
            let _ = writeln!(
                body,
                r##"<circle cx="{:.1}" cy="{:.1}" r="4" fill="#333"/><path d="M{:.1},{:.1} L{:.1},{:.1}" stroke="#333" marker-end="url(#arrow)"/>"##,
                init.x - 22.0,
                init.y + NODE_H / 2.0,
                init.x - 18.0,
                init.y + NODE_H / 2.0,
                init.x - 2.0,
                init.y + NODE_H / 2.0
            );
            // Transitions first, so the states are drawn over them.
            let bottom = top + tallest;
            let mut lane = 0;
            for t in &m.transitions {
                let (a, b) = (&placed[t.from], &placed[t.to]);
                let label = esc(&short(&format!("{} [{}]", t.name, t.priority)));
                let (path, lx, ly) = if t.from == t.to {
                    let (cx, cy) = (a.x + a.w / 2.0, a.y);
                    (
                        format!(
                            "M{:.1},{cy:.1} C{:.1},{:.1} {:.1},{:.1} {:.1},{cy:.1}",
                            cx - 8.0,
                            cx - 20.0,
                            cy - 24.0,
                            cx + 20.0,
                            cy - 24.0,
                            cx + 8.0
                        ),
                        cx,
                        cy - 20.0,
                    )
                } else if rank[t.to] > rank[t.from] {
                    let (x1, y1) = (a.x + a.w, a.y + NODE_H / 2.0);
                    let (x2, y2) = (b.x, b.y + NODE_H / 2.0);
                    let mid = (x1 + x2) / 2.0;
                    (
                        format!(
                            "M{x1:.1},{y1:.1} C{mid:.1},{y1:.1} {mid:.1},{y2:.1} {x2:.1},{y2:.1}"
                        ),
                        mid,
                        (y1 + y2) / 2.0 - 3.0,
                    )
                } else {
                    // Backwards or within a column: an arc under the states, in a lane of
                    // its own; the label under the arc's lowest point.
                    let (x1, y1) = (a.x + a.w / 2.0 - 6.0, a.y + NODE_H);
                    let (x2, y2) = (b.x + b.w / 2.0 + 6.0, b.y + NODE_H);
                    lane += 1;
                    let low = bottom + LANE * (4.0 * lane as f64) / 3.0;
                    let apex = (y1 + y2) / 8.0 + 0.75 * low;
                    (
                        format!(
                            "M{x1:.1},{y1:.1} C{x1:.1},{low:.1} {x2:.1},{low:.1} {x2:.1},{y2:.1}"
                        ),
                        (x1 + x2) / 2.0,
                        apex + 10.0,
                    )
                };
                let _ = writeln!(
                    body,
                    r##"<g class="transition"><title>{}</title><path d="{path}" fill="none" stroke="#557" marker-end="url(#arrow)"/><text x="{lx:.1}" y="{ly:.1}" font-size="9" text-anchor="middle" fill="#335">{label}</text></g>"##,
                    esc(&format!(
                        "{} -> {}: {}",
                        m.states[t.from].name, m.states[t.to].name, t.shown
                    ))
                );
            }
            for (s, state) in m.states.iter().enumerate() {
                let p = &placed[s];
                let (fill, dash) = match state.kind {
                    StateKind::Meta(inner) => {
                        metas.push((p.x + p.w / 2.0, p.y + NODE_H, inner));
                        ("#e8eefc", r#" stroke-dasharray="4 2""#)
                    }
                    StateKind::Code(_) => ("#ffffff", ""),
                };
                let _ = writeln!(
                    body,
                    r##"<g class="state"><rect x="{:.1}" y="{:.1}" width="{:.1}" height="{NODE_H}" rx="6" fill="{fill}" stroke="#333"{dash}/><text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text></g>"##,
                    p.x,
                    p.y,
                    p.w,
                    p.x + p.w / 2.0,
                    p.y + NODE_H / 2.0 + 4.0,
                    esc(&labels[s])
                );
            }
            body.push_str("</g>\n");
            panel_y += panel_h + PAD;
        }
        // Meta-states point at the machine they run.
        for (x, y, inner) in metas {
            let to = panel_top[inner] - TITLE_H + 4.0;
            let _ = writeln!(
                body,
                r##"<path d="M{x:.1},{y:.1} L{x:.1},{to:.1}" fill="none" stroke="#88a" stroke-dasharray="5 3" marker-end="url(#open)"/>"##
            );
        }
        format!(
            r##"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{panel_y:.0}" viewBox="0 0 {width:.1} {panel_y:.1}" font-family="Helvetica, Arial, sans-serif" font-size="{FONT}">
<defs><marker id="arrow" viewBox="0 0 10 10" refX="10" refY="5" markerWidth="7" markerHeight="7" orient="auto"><path d="M0,0 L10,5 L0,10 z" fill="#557"/></marker><marker id="open" viewBox="0 0 10 10" refX="10" refY="5" markerWidth="8" markerHeight="8" orient="auto"><path d="M0,0 L10,5 L0,10" fill="none" stroke="#88a"/></marker></defs>
<rect width="100%" height="100%" fill="white"/>
{body}</svg>
"##
        )
    }
}
