//! The field map: the one description of the soccer field that both the simulator's truth and
//! the robot's localization read (lines, goals, landmarks), in the field frame: metres from the
//! centre spot, x towards the east goal, y to the north side line.
//!
//! The landmarks are the objects the camera tells apart by colour (ISocRob-2000 report
//! §3.2.1: the two goals, the corner posts, the posts at the ends of the half-way line), in the
//! order of the camera's sightings ([`mrt_msgs::sighting`]): after the ball, the east and the
//! west net, then the four corners (NE, SE, NW, SW) and the north and south ends of the
//! half-way line. This table exists once: the simulator computes what a camera
//! sees from it, and the world model corrects its pose with it.

use mrt_core::{Point2, Vec2};
use mrt_msgs::sighting::{
    EAST_NET, NE_CORNER, NORTH_HALFWAY, NW_CORNER, SE_CORNER, SOUTH_HALFWAY, SW_CORNER, WEST_NET,
};
use mrt_msgs::{Field, FIELD_OBJECTS};
use serde::{Deserialize, Serialize};

/// A straight field line, from `a` to `b` (m, field frame).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// One end.
    pub a: Point2,
    /// The other end.
    pub b: Point2,
}

impl Segment {
    fn new(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
        Segment { a: Point2::new(ax, ay), b: Point2::new(bx, by) }
    }

    /// Its length, m.
    pub fn length(&self) -> f64 {
        (self.b - self.a).norm()
    }

    /// How far the point `p` lies from it, m.
    pub fn distance(&self, p: Point2) -> f64 {
        let d = self.b - self.a;
        let t = ((p - self.a).dot(&d) / d.norm_squared().max(1e-12)).clamp(0.0, 1.0);
        (p - (self.a + d * t)).norm()
    }
}

/// The field as a map (Middle Size League proportions by default), in metres.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FieldMap {
    /// Length between the goal lines.
    pub length: f64,
    /// Width between the side lines.
    pub width: f64,
    /// Free space between the lines and the walls around the field.
    pub border: f64,
    /// Inner width of a goal.
    pub goal_width: f64,
    /// Depth of a goal behind its goal line, to the inner face of its back.
    pub goal_depth: f64,
    /// Thickness of a goal's sides and back: a goal's corners on the floor, as a camera sees
    /// them from outside, are the outer faces' ([`FieldMap::goal_corners`]).
    pub goal_wall: f64,
    /// Depth of the penalty area from the goal line.
    pub penalty_area_depth: f64,
    /// Width of the penalty area.
    pub penalty_area_width: f64,
    /// Radius of the centre circle.
    pub centre_circle_radius: f64,
}

impl Default for FieldMap {
    /// The Middle Size League field of the seeds' time: 18 m × 12 m inside walls 1 m beyond
    /// the lines, goals 2 m wide and 0.6 m deep with 5 cm sides, penalty areas 2.25 m × 6.5 m,
    /// centre circle of 2 m.
    fn default() -> Self {
        FieldMap {
            length: 18.0,
            width: 12.0,
            border: 1.0,
            goal_width: 2.0,
            goal_depth: 0.6,
            goal_wall: 0.05,
            penalty_area_depth: 2.25,
            penalty_area_width: 6.5,
            centre_circle_radius: 2.0,
        }
    }
}

impl FieldMap {
    /// From the centre spot to a goal line, m.
    pub fn half_length(&self) -> f64 {
        self.length / 2.0
    }

    /// From the centre line to a side line, m.
    pub fn half_width(&self) -> f64 {
        self.width / 2.0
    }

    /// Where camera object `k` stands on the field ([`FIELD_OBJECTS`] order, module doc);
    /// `None` for the ball (index 0), which is not on the map, and past the last object.
    pub fn object(&self, k: usize) -> Option<Point2> {
        let (hl, hw) = (self.half_length(), self.half_width());
        let at = match k {
            EAST_NET => (hl, 0.0),
            WEST_NET => (-hl, 0.0),
            NE_CORNER => (hl, hw),
            SE_CORNER => (hl, -hw),
            NW_CORNER => (-hl, hw),
            SW_CORNER => (-hl, -hw),
            NORTH_HALFWAY => (0.0, hw),
            SOUTH_HALFWAY => (0.0, -hw),
            _ => return None,
        };
        Some(Point2::new(at.0, at.1))
    }

    /// The four corners on the floor of the east goal (`east`) or the west goal, at the outer
    /// faces of its sides: the two in front (the uprights) and the two at the back. A camera
    /// that sees a goal cut by the image's side sees one of them
    /// (`mrt_msgs::Percepts::goal_corners`) and cannot tell which.
    pub fn goal_corners(&self, east: bool) -> [Point2; 4] {
        let side = if east { 1.0 } else { -1.0 };
        let (front, back) = (
            side * self.half_length(),
            side * (self.half_length() + self.goal_depth + self.goal_wall),
        );
        let y = self.goal_width / 2.0 + self.goal_wall;
        [Point2::new(front, y), Point2::new(front, -y), Point2::new(back, y), Point2::new(back, -y)]
    }

    /// Whether landmark post `k` wears the east goal's colour in its outer bands and the west
    /// goal's in the middle one (ISocRob-2000 report §3.2.1: the landmarks are told apart by
    /// colour). The posts of the east half do, and, a choice of this map, those at the ends
    /// of the half-way line; the west half's wear the colours the other way round. A camera
    /// tells the pattern, not which post of its pattern it sees. `None` for the ball, the
    /// nets and past the last object.
    pub fn east_pattern(&self, k: usize) -> Option<bool> {
        if k <= WEST_NET {
            return None;
        }
        self.object(k).map(|p| p.x >= 0.0)
    }

    /// The field lines: the boundary (two touch lines, two goal lines), the half-way line and
    /// the three lines of each penalty area. The centre circle is [`FieldMap::centre_circle_radius`]
    /// around the origin.
    pub fn lines(&self) -> [Segment; FIELD_LINES] {
        let (hl, hw) = (self.half_length(), self.half_width());
        let (pd, pw) = (self.penalty_area_depth, self.penalty_area_width / 2.0);
        let area = |side: f64| {
            let (line, front) = (side * hl, side * (hl - pd));
            [
                Segment::new(front, -pw, front, pw),
                Segment::new(line, pw, front, pw),
                Segment::new(line, -pw, front, -pw),
            ]
        };
        let ([e0, e1, e2], [w0, w1, w2]) = (area(1.0), area(-1.0));
        [
            Segment::new(-hl, hw, hl, hw),
            Segment::new(-hl, -hw, hl, -hw),
            Segment::new(hl, -hw, hl, hw),
            Segment::new(-hl, -hw, -hl, hw),
            Segment::new(0.0, -hw, 0.0, hw),
            e0,
            e1,
            e2,
            w0,
            w1,
            w2,
        ]
    }

    /// The field line that a point `p` seen on the floor (field frame, m) lies on, when only
    /// one line can explain it: the nearest line (a straight one it lies beside, within
    /// [`LINE_END_SLACK`] of its ends, or the centre circle), when the next one is farther
    /// by at least `clearance` (m). The tracker corrects its pose with such points
    /// ([`crate::model::WorldModel`]).
    pub fn line_fit(&self, p: Point2, clearance: f64) -> Option<LineFit> {
        let straight = self.lines().into_iter().filter_map(|s| {
            let d = s.b - s.a;
            let len = d.norm();
            let u = d / len.max(1e-12);
            let along = (p - s.a).dot(&u);
            if along < -LINE_END_SLACK || along > len + LINE_END_SLACK {
                return None;
            }
            let normal = Vec2::new(-u.y, u.x);
            Some(LineFit { normal, residual: (p - s.a).dot(&normal) })
        });
        let r = p.coords.norm();
        let circle = (r > 1e-6)
            .then(|| LineFit { normal: p.coords / r, residual: r - self.centre_circle_radius });
        let (mut best, mut second): (Option<LineFit>, f64) = (None, f64::INFINITY);
        for fit in straight.chain(circle) {
            let d = fit.residual.abs();
            match best {
                Some(b) if d >= b.residual.abs() => second = second.min(d),
                _ => {
                    if let Some(b) = best {
                        second = b.residual.abs();
                    }
                    best = Some(fit);
                }
            }
        }
        best.filter(|b| second - b.residual.abs() >= clearance)
    }

    /// The field as behaviors read it in their [`mrt_msgs::WorldSnapshot`]: half sizes, m.
    pub fn snapshot(&self) -> Field {
        Field {
            half_length: self.length / 2.0,
            half_width: self.width / 2.0,
            goal_half_width: self.goal_width / 2.0,
            penalty_area_depth: self.penalty_area_depth,
        }
    }
}

/// How many straight lines the field has ([`FieldMap::lines`]).
pub const FIELD_LINES: usize = 11;

/// A floor point beside a straight field line counts as on it up to this far beyond its
/// ends, m (a line's end is where another meets it, or a corner).
pub const LINE_END_SLACK: f64 = 0.1;

/// How a point lies against the field line it was matched to ([`FieldMap::line_fit`]): the
/// line's unit normal (for the centre circle, pointing away from its centre) and the point's
/// signed distance along it from the line, m. The point lies on the line at residual 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineFit {
    /// The line's unit normal at the point.
    pub normal: Vec2,
    /// The point's signed distance from the line along `normal`, m.
    pub residual: f64,
}

/// How many fixed objects the map holds (every camera object but the ball).
pub const MAP_OBJECTS: usize = FIELD_OBJECTS - 1;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_posts_wear_the_pattern_of_their_half() {
        let map = FieldMap::default();
        let east: Vec<Option<bool>> = (0..=FIELD_OBJECTS).map(|k| map.east_pattern(k)).collect();
        let (y, n) = (Some(true), Some(false));
        // ball, nets; NE, SE, NW, SW, the half-way line's N and S ends; past the end.
        assert_eq!(east, [None, None, None, y, y, n, n, y, y, None]);
    }

    #[test]
    fn the_landmarks_of_the_default_field() {
        let map = FieldMap::default();
        let at: Vec<(f64, f64)> =
            (1..FIELD_OBJECTS).map(|k| map.object(k).map(|p| (p.x, p.y)).unwrap()).collect();
        assert_eq!(
            at,
            [
                (9.0, 0.0),
                (-9.0, 0.0),
                (9.0, 6.0),
                (9.0, -6.0),
                (-9.0, 6.0),
                (-9.0, -6.0),
                (0.0, 6.0),
                (0.0, -6.0)
            ]
        );
        assert_eq!(map.object(0), None, "the ball is not on the map");
        assert_eq!(map.object(FIELD_OBJECTS), None);
        assert_eq!(MAP_OBJECTS, at.len());
    }

    #[test]
    fn the_lines_of_the_default_field() {
        let map = FieldMap::default();
        let lines = map.lines();
        assert_eq!(lines.len(), 11);
        // Boundary 2 × 18 + 2 × 12, half-way 12, two penalty areas 2 × (6.5 + 2 × 2.25).
        let total: f64 = lines.iter().map(Segment::length).sum();
        assert!((total - (60.0 + 12.0 + 22.0)).abs() < 1e-12, "{total}");
        // Every line lies on the field.
        assert!(lines.iter().all(|s| [s.a, s.b]
            .iter()
            .all(|p| p.x.abs() <= 9.0 + 1e-12 && p.y.abs() <= 6.0 + 1e-12)));
    }

    #[test]
    fn a_floor_point_is_matched_to_the_one_line_it_lies_beside() {
        let map = FieldMap::default();
        // 4 cm north of the north touch line, half-way between the corner and the middle (the
        // normal's sign follows the segment's direction; the residual along it is +4 cm north).
        let fit = map.line_fit(Point2::new(4.5, 6.04), 0.5).unwrap();
        assert!((fit.normal.y.abs() - 1.0).abs() < 1e-12 && fit.normal.x.abs() < 1e-12);
        assert!((fit.residual * fit.normal.y - 0.04).abs() < 1e-12, "{fit:?}");
        // On the centre circle, 3 cm outside it, 45° round: the normal points outwards.
        let p = Point2::new(2.03 * 0.5f64.sqrt(), 2.03 * 0.5f64.sqrt());
        let fit = map.line_fit(p, 0.5).unwrap();
        assert!(
            (fit.residual - 0.03).abs() < 1e-12 && (fit.normal.x - 0.5f64.sqrt()).abs() < 1e-12
        );
        // Beside the half-way line inside the centre circle, 5 cm from the line and 1.95 m
        // from the circle: the line.
        let fit = map.line_fit(Point2::new(0.05, 0.0), 0.5).unwrap();
        assert!(
            (fit.residual.abs() - 0.05).abs() < 1e-12 && (fit.normal.x.abs() - 1.0).abs() < 1e-12
        );
        // Where the half-way line crosses the circle both fit: no answer.
        assert_eq!(map.line_fit(Point2::new(0.02, 1.99), 0.5), None);
        // In a corner both lines fit: no answer.
        assert_eq!(map.line_fit(Point2::new(9.0, 6.0), 0.5), None, "the corner");
        // Far from every line, the nearest still counts when it is clear of the next: at
        // (4.5, 3) the penalty area's front line (x = 6.75) is 2.25 m away, the north touch
        // line 3 m, the centre circle 3.41 m, the half-way line 4.5 m.
        let fit = map.line_fit(Point2::new(4.5, 3.0), 0.5).unwrap();
        assert!((fit.residual.abs() - 2.25).abs() < 1e-12, "{fit:?}");
        // Beyond a line's end by more than the slack, the line is not a candidate: 0.5 m past
        // the end of the penalty area's north line (y = 3.25 from x = 6.75 to 9) at x = 6.25,
        // 1 cm off it, the nearest candidate is another line.
        let fit = map.line_fit(Point2::new(6.25, 3.26), 0.0).unwrap();
        assert!(fit.residual.abs() > 0.4, "{fit:?}");
    }

    #[test]
    fn the_snapshot_field_is_the_maps_in_half_sizes() {
        let f = FieldMap::default().snapshot();
        assert_eq!(
            (f.half_length, f.half_width, f.goal_half_width, f.penalty_area_depth),
            (9.0, 6.0, 1.0, 2.25)
        );
        assert_eq!(f, Field::default(), "the snapshot's default field is the map's");
    }
}
