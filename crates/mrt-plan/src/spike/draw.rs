//! SVG of a SPIKE map, for the tools that draw on one (`mrt plan path --svg`, the indoor
//! world's `mrt sim --world indoor --plot`).

use super::map::{PlanMap, Shape};
use std::fmt::Write as _;

/// Map metres to SVG pixels: `scale` pixels a metre, north up, the map's top-left corner
/// at the origin.
#[derive(Clone, Copy, Debug)]
pub struct Sheet {
    /// The map's lower-left corner, m.
    pub min: mrt_core::Point2,
    /// Its upper edge, m.
    pub top: f64,
    /// Pixels a metre.
    pub scale: f64,
}

impl Sheet {
    /// The sheet of `map` at `scale` pixels a metre.
    pub fn of(map: &PlanMap, scale: f64) -> Sheet {
        Sheet { min: map.min, top: map.max.y, scale }
    }

    /// The pixel column of `x`.
    pub fn x(&self, x: f64) -> f64 {
        (x - self.min.x) * self.scale
    }

    /// The pixel row of `y`.
    pub fn y(&self, y: f64) -> f64 {
        (self.top - y) * self.scale
    }

    /// `shape` filled (or stroked, for a wall) in `colour`, appended to `out`.
    pub fn shape(&self, out: &mut String, shape: &Shape, colour: &str) {
        let (x, y) = (|v| self.x(v), |v| self.y(v));
        match shape {
            Shape::Disc { centre, radius } => {
                let _ = writeln!(
                    out,
                    r##"<circle cx="{:.2}" cy="{:.2}" r="{:.2}" fill="{colour}" fill-opacity="0.8"/>"##,
                    x(centre.x),
                    y(centre.y),
                    radius * self.scale
                );
            }
            Shape::Wall { a, b } => {
                let _ = writeln!(
                    out,
                    r##"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="{colour}" stroke-width="3"/>"##,
                    x(a.x),
                    y(a.y),
                    x(b.x),
                    y(b.y)
                );
            }
            Shape::Polygon(corners) => {
                let points: Vec<String> =
                    corners.iter().map(|p| format!("{:.2},{:.2}", x(p.x), y(p.y))).collect();
                let _ = writeln!(
                    out,
                    r##"<polygon points="{}" fill="{colour}" fill-opacity="0.8"/>"##,
                    points.join(" ")
                );
            }
        }
    }

    /// The map's obstacles (dark) and doors (dashed blue), appended to `out`.
    pub fn map(&self, out: &mut String, map: &PlanMap) {
        for s in &map.shapes {
            self.shape(out, s, "#333333");
        }
        for d in &map.doors {
            let _ = writeln!(
                out,
                r##"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="#2e86c1" stroke-width="2" stroke-dasharray="4 3"/>"##,
                self.x(d.a.x),
                self.y(d.a.y),
                self.x(d.b.x),
                self.y(d.b.y)
            );
        }
    }
}
