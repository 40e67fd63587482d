//! The field map: the one description of the soccer field that both the simulator's truth and
//! the robot's localization read (lines, goals, landmarks), in the field frame: metres from the
//! centre spot, x towards the east goal, y to the north side line.
//!
//! The landmarks are the objects the camera tells apart by colour (ISocRob seed `003`
//! §3.2.1: the two goals, the corner posts, the posts at the ends of the half-way line), in the
//! order of the camera's sightings ([`mrt_msgs::CameraFrame::sightings`]): after the ball,
//! [`EAST_NET`], [`WEST_NET`], then the four corners (NE, SE, NW, SW) and the north and south
//! ends of the half-way line. This table exists once: the simulator computes what a camera
//! sees from it, and the world model corrects its pose with it.

use mrt_core::Point2;
use mrt_msgs::{Field, FIELD_OBJECTS};
use serde::{Deserialize, Serialize};

/// Camera sighting index of the east net (the centre of its goal line).
pub const EAST_NET: usize = 1;
/// Camera sighting index of the west net.
pub const WEST_NET: usize = 2;

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
    /// Inner width of a goal.
    pub goal_width: f64,
    /// Depth of the penalty area from the goal line.
    pub penalty_area_depth: f64,
    /// Width of the penalty area.
    pub penalty_area_width: f64,
    /// Radius of the centre circle.
    pub centre_circle_radius: f64,
}

impl Default for FieldMap {
    /// The Middle Size League field of the seeds' time: 18 m × 12 m, goals 2 m wide, penalty
    /// areas 2.25 m × 6.5 m, centre circle of 2 m.
    fn default() -> Self {
        FieldMap {
            length: 18.0,
            width: 12.0,
            goal_width: 2.0,
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
            3 => (hl, hw),
            4 => (hl, -hw),
            5 => (-hl, hw),
            6 => (-hl, -hw),
            7 => (0.0, hw),
            8 => (0.0, -hw),
            _ => return None,
        };
        Some(Point2::new(at.0, at.1))
    }

    /// Whether landmark post `k` wears the east goal's colour in its outer bands and the west
    /// goal's in the middle one (ISocRob seed `003` §3.2.1: the landmarks are told apart by
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
    pub fn lines(&self) -> Vec<Segment> {
        let (hl, hw) = (self.half_length(), self.half_width());
        let (pd, pw) = (self.penalty_area_depth, self.penalty_area_width / 2.0);
        let mut lines = vec![
            Segment::new(-hl, hw, hl, hw),
            Segment::new(-hl, -hw, hl, -hw),
            Segment::new(hl, -hw, hl, hw),
            Segment::new(-hl, -hw, -hl, hw),
            Segment::new(0.0, -hw, 0.0, hw),
        ];
        for side in [1.0, -1.0] {
            let (line, front) = (side * hl, side * (hl - pd));
            lines.push(Segment::new(front, -pw, front, pw));
            lines.push(Segment::new(line, pw, front, pw));
            lines.push(Segment::new(line, -pw, front, -pw));
        }
        lines
    }

    /// The field as behaviors read it in their [`mrt_msgs::WorldSnapshot`]: half sizes in
    /// millimetres (the unit of TeamChaos' `getField`, seed `001` §3.3).
    pub fn snapshot(&self) -> Field {
        Field {
            half_length: self.length * 500.0,
            half_width: self.width * 500.0,
            goal_half_width: self.goal_width * 500.0,
            penalty_area_depth: self.penalty_area_depth * 1000.0,
        }
    }
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
    fn the_snapshot_field_is_in_millimetres() {
        let f = FieldMap::default().snapshot();
        assert_eq!(
            (f.half_length, f.half_width, f.goal_half_width, f.penalty_area_depth),
            (9000.0, 6000.0, 1000.0, 2250.0)
        );
        assert_eq!(f, Field::default(), "the snapshot's default field is the map's");
    }
}
