//! MUREA, multi-resolution evidence accumulation (MRT manual ch. 7): global localization as a
//! search over poses `(x, y, θ)` for the one that the most perceptions agree with.
//!
//! The manual gives MUREA's parameters (a map, the accuracy required, a timeout), its input
//! (sensor-agnostic *perceptions*) and its answer: the pose that accumulates the most
//! evidence. How MUREA searches is not written there; the search below is a design choice,
//! a best-first branch and bound:
//!
//! - **Evidence** of a pose: each perception whose residual `d` (range and bearing to the
//!   nearest map element of its [`Kind`], in tolerances) is below 1 counts its weight times
//!   `1 − d²`. The pose that the perceptions fit best wins, not merely one that they all
//!   tolerate: the tolerances are as wide as the sensor's errors.
//! - **Lines** ([`Perception::line`], e.g. a [`crate::hough`] line): a straight piece seen at
//!   a distance and a normal's bearing. Its residual against a map segment is `dρ² + dφ²` in
//!   tolerances, when the segment runs that way and overlaps the seen piece. A cell's bound
//!   asks only the direction (over the cell's headings) and the distance (over its box).
//! - **Evidence** of a cell `C` of poses, an upper bound of its poses': the summed weight of
//!   the perceptions that some pose in `C` may explain, i.e. some map element of the
//!   perception's kind lies where the perception puts it (range ± tolerance, bearing ±
//!   tolerance) from some pose of the cell. The test is conservative: the perceived point's
//!   region over the whole cell (the cell's `xy` box plus an annular sector) is bounded by a
//!   box. A smaller cell has a smaller region: `C' ⊂ C ⇒ E(C') ≤ E(C)`.
//! - **Search**: the area is tiled with root cells (about 1 m × 1 m × 64°), each evaluated and
//!   put on a max-heap. The best cell is taken off and split in two along every dimension
//!   still coarser than the accuracy, its children evaluated against the perceptions the
//!   parent explained only. A cell at the accuracy is scored at its centre and put back; the
//!   first scored cell taken off the heap is the best centre of the finest grid, since every
//!   other entry bounds its own cells by no more evidence.
//! - **Anytime**: a budget of cells (deterministic) and an optional wall-clock timeout stop
//!   the search early with the best cell so far, its size saying how uncertain it is.
//! - **Ambiguity**: after the best, the search goes on taking cells off the heap and reports
//!   other poses that explain nearly as much, far from the best: on a symmetric field without
//!   colour cues, the mirrored pose. Only cells that may hold such a pose are refined: one
//!   wholly near the best is dropped, and a child's evidence is abandoned as soon as the
//!   perceptions it misses put it below [`Murea::ambiguity`] of the best (docs/performance.md:
//!   35 → 9.3 ms for a global search of one frame).
//!
//! Angles in radians, lengths in metres, the field frame of [`FieldMap`].
//!
//! ```
//! use mrt_core::Pose2;
//! use mrt_world::field::FieldMap;
//! use mrt_world::murea::{Kind, Map, Murea, Perception};
//!
//! let murea = Murea::new(Map::field(&FieldMap::default(), true));
//! // From (2, 1) facing north, the east net is 7.07 m away at −98.1° (its bearing), the
//! // north-east corner post 8.60 m at −54.5°, the half-way line's north end 5.39 m at 21.8°.
//! let seen = [
//!     Perception::point(Kind::EAST_GOAL, 7.071, -1.7127),
//!     Perception::point(Kind::EAST_POST, 8.602, -0.9505),
//!     Perception::point(Kind::EAST_POST, 5.385, 0.3805),
//! ];
//! let fix = murea.localize(&seen, murea.whole_field());
//! assert!((fix.pose.x - 2.0).abs() < 0.1 && (fix.pose.y - 1.0).abs() < 0.1, "{fix:?}");
//! assert!((fix.pose.theta - std::f64::consts::FRAC_PI_2).abs() < 0.05);
//! assert!(fix.quality > 0.9, "rounded distances and bearings fit almost exactly");
//! ```

use crate::field::{FieldMap, Segment};
use mrt_core::{normalize_angle, Point2, Pose2};
use mrt_msgs::sighting::{EAST_NET, WEST_NET};
use mrt_msgs::FIELD_OBJECTS;
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::f64::consts::{PI, TAU};
use std::time::{Duration, Instant};

/// What kind of thing a map element or a perception is: what the sensor tells apart (a goal's
/// colour, a post's colour pattern, a white line). A perception is explained only by map
/// elements of its own kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Kind(pub u16);

impl Kind {
    /// A point of a white field line.
    pub const LINE: Kind = Kind(0);
    /// The east goal (its colour seen).
    pub const EAST_GOAL: Kind = Kind(1);
    /// The west goal.
    pub const WEST_GOAL: Kind = Kind(2);
    /// A landmark post wearing the east goal's colour outside ([`FieldMap::east_pattern`]).
    pub const EAST_POST: Kind = Kind(3);
    /// A landmark post wearing the west goal's colour outside.
    pub const WEST_POST: Kind = Kind(4);
    /// A goal whose colour is not known (a map without colour cues).
    pub const GOAL: Kind = Kind(5);
    /// A landmark post whose pattern is not known.
    pub const POST: Kind = Kind(6);
    /// A corner of the east goal on the floor ([`FieldMap::goal_corners`]): what a camera
    /// sees of a goal cut by the image's side.
    pub const EAST_CORNER: Kind = Kind(7);
    /// A corner of the west goal.
    pub const WEST_CORNER: Kind = Kind(8);
    /// A goal corner whose goal is not known.
    pub const CORNER: Kind = Kind(9);

    /// The kind of a corner of the east goal (`east`) or the west goal: its goal's colour
    /// when `coloured`.
    pub fn goal_corner(east: bool, coloured: bool) -> Kind {
        match (coloured, east) {
            (false, _) => Kind::CORNER,
            (true, true) => Kind::EAST_CORNER,
            (true, false) => Kind::WEST_CORNER,
        }
    }

    /// Whether this is the corner of a goal, of either colour or none.
    pub fn is_goal_corner(self) -> bool {
        matches!(self, Kind::EAST_CORNER | Kind::WEST_CORNER | Kind::CORNER)
    }

    /// The kind of field object `k` (camera sighting order, [`FieldMap::object`]): its goal
    /// colour or post pattern when `coloured`, else just goal or post; `None` for the ball and
    /// past the last landmark.
    pub fn of_object(field: &FieldMap, k: usize, coloured: bool) -> Option<Kind> {
        field.object(k)?;
        Some(match (k, coloured, field.east_pattern(k)) {
            (EAST_NET, true, _) => Kind::EAST_GOAL,
            (WEST_NET, true, _) => Kind::WEST_GOAL,
            (EAST_NET | WEST_NET, false, _) => Kind::GOAL,
            (_, true, Some(true)) => Kind::EAST_POST,
            (_, true, _) => Kind::WEST_POST,
            (_, false, _) => Kind::POST,
        })
    }
}

/// The map MUREA localizes on: typed points (goals, posts) and segments (lines), field frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Map {
    points: Vec<(Kind, Point2)>,
    segments: Vec<(Kind, Segment)>,
    /// Each segment's box `[x0, x1, y0, y1]`, in the same order: what the search asks first
    /// of every segment, millions of times a search.
    boxes: Vec<[f64; 4]>,
}

impl Map {
    /// An empty map.
    pub fn new() -> Map {
        Map::default()
    }

    /// The map with a point element of `kind` at `at`.
    pub fn point(mut self, kind: Kind, at: Point2) -> Map {
        self.points.push((kind, at));
        self
    }

    /// The point elements, with their kinds.
    pub fn points(&self) -> &[(Kind, Point2)] {
        &self.points
    }

    /// The map with a segment element of `kind`.
    pub fn segment(mut self, kind: Kind, segment: Segment) -> Map {
        self.segments.push((kind, segment));
        let (a, b) = (segment.a, segment.b);
        self.boxes.push([a.x.min(b.x), a.x.max(b.x), a.y.min(b.y), a.y.max(b.y)]);
        self
    }

    /// The soccer field: its two goals (the centres of their goal lines) and their corners
    /// on the floor, the landmark posts, and the lines with the centre circle (as 36 chords). `coloured`: goals and posts are
    /// told apart by colour (the ISocRob field); otherwise all goals are alike and all posts
    /// too, and the field is symmetric under a half turn.
    pub fn field(field: &FieldMap, coloured: bool) -> Map {
        let mut map = Map::new();
        for k in 1..FIELD_OBJECTS {
            if let (Some(at), Some(kind)) = (field.object(k), Kind::of_object(field, k, coloured)) {
                map = map.point(kind, at);
            }
        }
        for east in [true, false] {
            for at in field.goal_corners(east) {
                map = map.point(Kind::goal_corner(east, coloured), at);
            }
        }
        for s in field.lines() {
            map = map.segment(Kind::LINE, s);
        }
        let r = field.centre_circle_radius;
        let on_circle = |k: u32| {
            let a = f64::from(k) * TAU / 36.0;
            Point2::new(r * a.cos(), r * a.sin())
        };
        for k in 0..36 {
            map = map.segment(Kind::LINE, Segment { a: on_circle(k), b: on_circle(k + 1) });
        }
        map
    }

    /// The smallest box holding every element, `(min, max)`.
    fn bounds(&self) -> (Point2, Point2) {
        let ends = self.segments.iter().flat_map(|s| [s.1.a, s.1.b]);
        bounding_box(self.points.iter().map(|p| p.1).chain(ends))
    }

    /// Where a robot can stand, `(min, max)`: within the lines when the map has some (a
    /// goal's back corners lie beyond the goal line), else the points' box.
    fn area(&self) -> (Point2, Point2) {
        if self.segments.is_empty() {
            return self.bounds();
        }
        bounding_box(self.segments.iter().flat_map(|s| [s.1.a, s.1.b]))
    }

    /// Whether some element of `kind` meets the box `[x0, x1] × [y0, y1]`.
    fn meets(&self, kind: Kind, (x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> bool {
        let inside = |p: &Point2| p.x >= x0 && p.x <= x1 && p.y >= y0 && p.y <= y1;
        self.points.iter().any(|(k, p)| *k == kind && inside(p))
            || self.near(kind, (x0, x1), (y0, y1)).any(|s| clips(s, (x0, x1), (y0, y1)))
    }

    /// The segments of `kind` whose boxes meet the box `[x0, x1] × [y0, y1]`: every one
    /// that meets it, and some more.
    fn near(
        &self,
        kind: Kind,
        (x0, x1): (f64, f64),
        (y0, y1): (f64, f64),
    ) -> impl Iterator<Item = &Segment> {
        self.boxes.iter().zip(&self.segments).filter_map(move |(b, (k, s))| {
            (b[1] >= x0 && b[0] <= x1 && b[3] >= y0 && b[2] <= y1 && *k == kind).then_some(s)
        })
    }
}

/// Whether segment `s` meets the box (Liang–Barsky clipping).
fn clips(s: &Segment, (x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> bool {
    let d = s.b - s.a;
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for (p, q) in [(-d.x, s.a.x - x0), (d.x, x1 - s.a.x), (-d.y, s.a.y - y0), (d.y, y1 - s.a.y)] {
        if p == 0.0 {
            if q < 0.0 {
                return false;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    t0 <= t1
}

/// The two directions normal to segment `s`, rad.
fn normals(s: &Segment) -> [f64; 2] {
    let d = s.b - s.a;
    let along = d.y.atan2(d.x);
    [along + 0.5 * PI, along - 0.5 * PI]
}

/// One perception (MRT manual ch. 7: sensor-agnostic): something of a [`Kind`] seen at a
/// range and/or a bearing from the robot, each with its tolerance, and how much it counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Perception {
    /// What was seen.
    pub kind: Kind,
    /// Distance from the robot's centre, m (`None`: bearing only).
    pub range: Option<f64>,
    /// ± this much, m.
    pub range_tolerance: f64,
    /// Bearing in the robot's frame, rad, counter-clockwise (`None`: range only).
    pub bearing: Option<f64>,
    /// ± this much, rad.
    pub bearing_tolerance: f64,
    /// Its weight in the evidence, in (0, 1].
    pub weight: f64,
    /// `Some` for a straight piece of line ([`Perception::line`]): then `range` and `bearing`
    /// are its normal's (the foot of the perpendicular from the robot), and this is the seen
    /// piece, from and to, along the line's direction (the normal turned a quarter turn
    /// counter-clockwise), m from the foot.
    pub extent: Option<(f64, f64)>,
}

impl Perception {
    /// A point of `kind` at `range` and `bearing`, with tolerances of 5 % of the range (at least
    /// 5 cm) and 2°, weight 1.
    pub fn point(kind: Kind, range: f64, bearing: f64) -> Perception {
        Perception {
            kind,
            range: Some(range),
            range_tolerance: (0.05 * range).max(0.05),
            bearing: Some(bearing),
            bearing_tolerance: 2f64.to_radians(),
            weight: 1.0,
            extent: None,
        }
    }

    /// A straight piece of `kind` (a field line found by [`crate::hough`]): the foot of the
    /// perpendicular from the robot lies at `range` ≥ 0 and `bearing` (so the line's normal
    /// points that way), and the piece runs from `extent.0` to `extent.1` along the line,
    /// counted from the foot in the direction `bearing + π/2`. Tolerances 5 cm and 2°,
    /// weight 1. A map segment explains it when it runs the same way, lies at that distance
    /// and overlaps the seen piece; the centre circle's short chords rarely do.
    pub fn line(kind: Kind, range: f64, bearing: f64, extent: (f64, f64)) -> Perception {
        let extent = (extent.0.min(extent.1), extent.0.max(extent.1));
        Perception {
            range_tolerance: 0.05,
            extent: Some(extent),
            ..Perception::point(kind, range, bearing)
        }
    }

    /// Something of `kind` in the direction `bearing` (a camera without depth), ± 2°, weight 1.
    pub fn bearing_only(kind: Kind, bearing: f64) -> Perception {
        Perception { range: None, range_tolerance: 0.0, ..Perception::point(kind, 1.0, bearing) }
    }

    /// The same perception with other tolerances.
    pub fn tolerances(self, range: f64, bearing: f64) -> Perception {
        Perception { range_tolerance: range, bearing_tolerance: bearing, ..self }
    }

    /// The same perception with another weight.
    pub fn weighted(self, weight: f64) -> Perception {
        Perception { weight, ..self }
    }

    /// Whether the numbers make a perception (finite, tolerances ≥ 0, weight in (0, 1]).
    fn is_valid(&self) -> bool {
        let ok = |v: Option<f64>| v.is_none_or(f64::is_finite);
        let line = match self.extent {
            None => true,
            Some((a, b)) => {
                a.is_finite()
                    && b.is_finite()
                    && a <= b
                    && self.range.is_some_and(|r| r >= 0.0)
                    && self.bearing.is_some()
            }
        };
        line && ok(self.range)
            && ok(self.bearing)
            && self.range_tolerance.is_finite()
            && self.range_tolerance >= 0.0
            && self.bearing_tolerance.is_finite()
            && self.bearing_tolerance >= 0.0
            && self.weight > 0.0
            && self.weight <= 1.0
    }
}

/// A box of poses: `x`, `y` (m) and `theta` (rad) intervals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    /// `[x0, x1]`.
    pub x: (f64, f64),
    /// `[y0, y1]`.
    pub y: (f64, f64),
    /// `[θ0, θ1]` (not normalized: a cell may reach past π).
    pub theta: (f64, f64),
}

impl Cell {
    /// The pose at the cell's centre (heading normalized).
    pub fn centre(&self) -> Pose2 {
        let mid = |(a, b): (f64, f64)| 0.5 * (a + b);
        Pose2::new(mid(self.x), mid(self.y), normalize_angle(mid(self.theta)))
    }

    /// Whether the cell holds `pose` (its heading taken round the circle).
    pub fn contains(&self, pose: Pose2) -> bool {
        let within = |(a, b): (f64, f64), v: f64| v >= a && v <= b;
        let turns = (pose.theta - self.theta.0).div_euclid(TAU);
        within(self.x, pose.x)
            && within(self.y, pose.y)
            && within(self.theta, pose.theta - turns * TAU)
    }

    /// Its size `(x, y, θ)`.
    pub fn size(&self) -> (f64, f64, f64) {
        (self.x.1 - self.x.0, self.y.1 - self.y.0, self.theta.1 - self.theta.0)
    }
}

/// When to stop searching.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// At most this many cells evaluated (deterministic).
    pub cells: usize,
    /// At most this long (wall clock; `None`: no limit). A timeout makes the answer depend on
    /// the machine's speed; the cell budget does not.
    pub timeout: Option<Duration>,
}

/// MUREA's answer.
#[derive(Clone, Debug, PartialEq)]
pub struct Fix {
    /// The pose that accumulates the most evidence (the best cell's centre).
    pub pose: Pose2,
    /// Its evidence: each perception's weight times how well it fits (module doc); a cell's
    /// bound when the budget ran out before any cell reached the accuracy.
    pub evidence: f64,
    /// `evidence` over the summed weight of all perceptions, 0 to 1.
    pub quality: f64,
    /// The size `(x, y, θ)` of its cell: the accuracy asked for, or coarser when the budget ran
    /// out.
    pub cell: (f64, f64, f64),
    /// Other poses that explain nearly as much, far from `pose` and with poses between that
    /// explain much less (the mirrored pose on a symmetric field), with their evidence, best
    /// first.
    pub alternatives: Vec<(Pose2, f64)>,
    /// Whether the budget ran out: before the accuracy was reached (then `cell` is coarser), or
    /// before all the poses of the best evidence were compared (then `pose` may not fit best).
    pub timed_out: bool,
    /// Cells evaluated.
    pub cells: usize,
}

/// The indices of the perceptions that make sense ([`Perception::is_valid`]; at most 65 535)
/// and their summed weight.
fn usable(perceptions: &[Perception]) -> (Vec<u16>, f64) {
    let valid: Vec<u16> = (0..perceptions.len().min(usize::from(u16::MAX)))
        .filter(|&k| perceptions[k].is_valid())
        .filter_map(|k| u16::try_from(k).ok())
        .collect();
    let total = valid.iter().map(|&k| perceptions[usize::from(k)].weight).sum();
    (valid, total)
}

/// The perceptions of one search with what every cell and pose asks of them worked out once:
/// a cell's or a pose's angles are then sums, turned by the angle-addition formulas instead
/// of a `sin_cos` per perception and cell (it took a third of the search's time).
struct Seen<'a> {
    perceptions: &'a [Perception],
    prepared: Vec<Prepared>,
}

/// One perception's constants.
struct Prepared {
    /// `(sin, cos)` of its bearing less its tolerance, plus it, and itself (`(0, 1)`
    /// without a bearing).
    trig: [(f64, f64); 3],
    /// The radius of the largest disc round a seen point within its tolerances, m.
    disc: f64,
}

impl<'a> Seen<'a> {
    fn new(perceptions: &'a [Perception]) -> Seen<'a> {
        let prepared = perceptions
            .iter()
            .map(|p| {
                let b = p.bearing.unwrap_or(0.0);
                let tol = p.bearing_tolerance;
                let (tol_r, tol_b) = (p.range_tolerance.max(1e-6), tol.max(1e-6));
                let r = p.range.unwrap_or(0.0);
                Prepared {
                    trig: [(b - tol).sin_cos(), (b + tol).sin_cos(), b.sin_cos()],
                    disc: tol_r.min(r * tol_b.min(0.5 * PI).sin()).max(1e-6),
                }
            })
            .collect();
        Seen { perceptions, prepared }
    }
}

/// `(sin, cos)` of the sum of the angles `a` and `b` given as `(sin, cos)`.
fn turned((sa, ca): (f64, f64), (sb, cb): (f64, f64)) -> (f64, f64) {
    (sa * cb + ca * sb, ca * cb - sa * sb)
}

/// Two poses that both fit are two answers (an ambiguity) only when some pose between them
/// explains less than this fraction of the best's evidence...
const VALLEY: f64 = 0.5;
/// ... among this many less one evenly spaced between them.
const VALLEY_SAMPLES: u32 = 8;

/// The MUREA localizer: a map, the accuracy required, a budget (module doc).
#[derive(Clone, Debug)]
pub struct Murea {
    map: Map,
    /// The finest cell: `(x and y, θ)`, m and rad.
    pub accuracy: (f64, f64),
    /// When to stop.
    pub budget: Budget,
    /// Other poses are reported when they explain at least this fraction of the best's
    /// evidence...
    pub ambiguity: f64,
    /// ... and lie at least this far from it (m), or this far round (rad).
    pub apart: (f64, f64),
    /// The farthest a range-less perception can be, m (the map's diagonal).
    reach: f64,
}

/// A cell on the search's heap: ordered by evidence, then by depth (deeper first), then by
/// the order it was made in (earlier first), so that the search is deterministic.
struct Entry {
    evidence: f64,
    depth: u32,
    order: u64,
    cell: Cell,
    support: Vec<u16>,
    /// A leaf whose `evidence` is its centre's score, no longer a bound.
    scored: bool,
}

impl PartialEq for Entry {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        self.evidence
            .total_cmp(&other.evidence)
            .then(self.depth.cmp(&other.depth))
            .then(other.order.cmp(&self.order))
    }
}

/// The smallest box holding `points`, `(min, max)` (infinite bounds when there are none).
fn bounding_box(points: impl Iterator<Item = Point2>) -> (Point2, Point2) {
    let none = (
        Point2::new(f64::INFINITY, f64::INFINITY),
        Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
    );
    points.fold(none, |(lo, hi), p| {
        (Point2::new(lo.x.min(p.x), lo.y.min(p.y)), Point2::new(hi.x.max(p.x), hi.y.max(p.y)))
    })
}

impl Murea {
    /// MUREA on `map`, to 5 cm and 1° within 200 000 cells, no timeout (docs/performance.md:
    /// about 3.4 ms for a global search of one frame, 9.3 ms with the ambiguity search).
    pub fn new(map: Map) -> Murea {
        let (lo, hi) = map.bounds();
        let reach = if lo.x.is_finite() { (hi - lo).norm().max(1.0) } else { 1.0 };
        Murea {
            map,
            accuracy: (0.05, 1f64.to_radians()),
            budget: Budget { cells: 200_000, timeout: None },
            ambiguity: 0.9,
            apart: (1.0, 0.5),
            reach,
        }
    }

    /// The whole map's area (within its lines, where it has some), every heading: global
    /// localization.
    pub fn whole_field(&self) -> Cell {
        let (lo, hi) = self.map.area();
        if !lo.x.is_finite() {
            return Cell { x: (0.0, 0.0), y: (0.0, 0.0), theta: (-PI, PI) };
        }
        Cell { x: (lo.x, hi.x), y: (lo.y, hi.y), theta: (-PI, PI) }
    }

    /// The cells `prediction` ± `(xy, θ)`: tracking around the odometry's prediction.
    pub fn around(prediction: Pose2, xy: f64, theta: f64) -> Cell {
        Cell {
            x: (prediction.x - xy, prediction.x + xy),
            y: (prediction.y - xy, prediction.y + xy),
            theta: (prediction.theta - theta, prediction.theta + theta),
        }
    }

    /// The evidence of `cell` from `perceptions` (those of `among` only), and which of them
    /// it explains.
    /// `floor`: a cell whose evidence is certainly below it is not worth finishing (`None`);
    /// `weight`: the summed weight of `among`.
    fn evidence(
        &self,
        cell: &Cell,
        seen: &Seen,
        (among, weight): (&[u16], f64),
        floor: f64,
    ) -> Option<(f64, Vec<u16>)> {
        let mut support = Vec::with_capacity(among.len());
        let mut sum = 0.0;
        // What the cell may still reach; the margin keeps rounding from dropping a cell
        // that reaches `floor` exactly.
        let mut reachable = weight;
        let floor = floor - 1e-9 * weight;
        let headings = (cell.theta.0.sin_cos(), cell.theta.1.sin_cos());
        for &k in among {
            let p = &seen.perceptions[usize::from(k)];
            let explained = if p.extent.is_some() {
                self.some_segment_runs_along(cell, p)
            } else {
                let trig = &seen.prepared[usize::from(k)].trig;
                let (sx, sy) = self.sector(
                    cell.theta,
                    p,
                    (turned(headings.0, trig[0]), turned(headings.1, trig[1])),
                );
                let xs = (cell.x.0 + sx.0, cell.x.1 + sx.1);
                let ys = (cell.y.0 + sy.0, cell.y.1 + sy.1);
                self.map.meets(p.kind, xs, ys)
            };
            if explained {
                sum += p.weight;
                support.push(k);
            } else {
                reachable -= p.weight;
                if reachable < floor {
                    return None;
                }
            }
        }
        Some((sum, support))
    }

    /// Whether some map segment of line perception `p`'s kind runs the way `p` says from some
    /// pose of `cell`: its normal (either way round) within the bearing tolerance of `p`'s
    /// over the cell's headings, and its distance along that normal within the range
    /// tolerance over the cell's positions. The seen piece's overlap is left out: a bound
    /// may be loose, and [`Murea::score`] asks for it.
    fn some_segment_runs_along(&self, cell: &Cell, p: &Perception) -> bool {
        let (Some(range), Some(bearing)) = (p.range, p.bearing) else {
            return false;
        };
        let (a0, a1) = (
            cell.theta.0 + bearing - p.bearing_tolerance,
            cell.theta.1 + bearing + p.bearing_tolerance,
        );
        let (r0, r1) = (range - p.range_tolerance, range + p.range_tolerance);
        self.map.segments.iter().filter(|(kind, _)| *kind == p.kind).any(|(_, s)| {
            normals(s).into_iter().any(|psi| {
                let turns = ((a0 - psi) / TAU).ceil();
                if psi + turns * TAU > a1 {
                    return false;
                }
                // n·(a − pos) over the cell's box: n·pos is extreme at the box's corners.
                let (s_, c) = psi.sin_cos();
                let at = c * s.a.x + s_ * s.a.y;
                let xs = (c * cell.x.0, c * cell.x.1);
                let ys = (s_ * cell.y.0, s_ * cell.y.1);
                let lo = at - xs.0.max(xs.1) - ys.0.max(ys.1);
                let hi = at - xs.0.min(xs.1) - ys.0.min(ys.1);
                hi >= r0 && lo <= r1
            })
        })
    }

    /// The residual of line perception `p` against segment `s` from `pose`, squared, in
    /// tolerances (`dρ² + dφ²`), when the segment explains it (module doc), else `None`.
    fn line_residual(pose: Pose2, p: &Perception, s: &Segment) -> Option<f64> {
        let (Some(range), Some(bearing), Some((t0, t1))) = (p.range, p.bearing, p.extent) else {
            return None;
        };
        let tol_r = p.range_tolerance.max(1e-6);
        let tol_b = p.bearing_tolerance.max(1e-6);
        let normal = pose.theta + bearing;
        let (ns, nc) = normal.sin_cos();
        // The seen piece's ends in the field frame.
        let foot = Point2::new(pose.x + range * nc, pose.y + range * ns);
        let ends = [t0, t1].map(|t| Point2::new(foot.x - t * ns, foot.y + t * nc));
        normals(s)
            .into_iter()
            .filter_map(|psi| {
                let db = normalize_angle(psi - normal) / tol_b;
                let (s_, c) = psi.sin_cos();
                let dr = (c * (s.a.x - pose.x) + s_ * (s.a.y - pose.y) - range) / tol_r;
                if db.abs() >= 1.0 || dr.abs() >= 1.0 {
                    return None;
                }
                // The seen piece and the segment overlap along the segment (± the tolerance).
                let dir = s.b - s.a;
                let len = dir.norm().max(1e-9);
                let along = ends.map(|e| (e - s.a).dot(&dir) / len);
                let (lo, hi) = (along[0].min(along[1]), along[0].max(along[1]));
                (hi >= -tol_r && lo <= len + tol_r).then_some(dr * dr + db * db)
            })
            .fold(None, |best: Option<f64>, d| Some(best.map_or(d, |b| b.min(d))))
    }

    /// The box `(x, y)` bounding where perception `p` puts its object relative to the robot's
    /// position, over headings `theta`: an annular sector. `ends`: `(sin, cos)` of the
    /// sector's bounding directions, `θ0 + bearing − tolerance` and `θ1 + bearing +
    /// tolerance` (unused without a bearing).
    fn sector(
        &self,
        theta: (f64, f64),
        p: &Perception,
        ends: ((f64, f64), (f64, f64)),
    ) -> ((f64, f64), (f64, f64)) {
        let (r0, r1) = match p.range {
            Some(r) => ((r - p.range_tolerance).max(0.0), r + p.range_tolerance),
            None => (0.0, self.reach),
        };
        let (a0, a1) = match p.bearing {
            Some(b) => (theta.0 + b - p.bearing_tolerance, theta.1 + b + p.bearing_tolerance),
            None => (0.0, TAU),
        };
        let mut x = (f64::INFINITY, f64::NEG_INFINITY);
        let mut y = (f64::INFINITY, f64::NEG_INFINITY);
        let mut take = |(s, c): (f64, f64), r: f64| {
            x = (x.0.min(r * c), x.1.max(r * c));
            y = (y.0.min(r * s), y.1.max(r * s));
        };
        // (sin, cos) of 0, π/2, π, 3π/2.
        const AXES: [(f64, f64); 4] = [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0)];
        if a1 - a0 >= TAU {
            for axis in AXES {
                take(axis, r1);
            }
            return (x, y);
        }
        for sc in [ends.0, ends.1] {
            take(sc, r0);
            take(sc, r1);
        }
        // The axis directions within [a0, a1] reach farthest at the outer radius.
        let first = (a0 / (0.5 * PI)).ceil();
        let mut axis = first * 0.5 * PI;
        let mut k = first.rem_euclid(4.0) as usize;
        while axis <= a1 {
            take(AXES[k % 4], r1);
            axis += 0.5 * PI;
            k += 1;
        }
        (x, y)
    }

    /// Whether every pose of `cell` is near `pose`: within [`Murea::apart`] of it both in
    /// position and in heading (not another answer).
    fn wholly_near(&self, cell: &Cell, pose: Pose2) -> bool {
        let dx = (cell.x.0 - pose.x).abs().max((cell.x.1 - pose.x).abs());
        let dy = (cell.y.0 - pose.y).abs().max((cell.y.1 - pose.y).abs());
        let from = normalize_angle(cell.theta.0 - pose.theta);
        let to = from + (cell.theta.1 - cell.theta.0);
        dx.hypot(dy) < self.apart.0 && from > -self.apart.1 && to < self.apart.1
    }

    /// The root cells tiling `area`: each dimension in cells of the accuracy times a power of
    /// two (about 1 m and 64°), so that splitting them ends on the grid of the accuracy.
    fn roots(&self, area: &Cell) -> Vec<Cell> {
        let (axy, ath) = self.accuracy;
        let levels = |acc: f64, target: f64| (target / acc).log2().ceil().max(0.0) as u32;
        let (kxy, kth) = (levels(axy, 1.0), levels(ath, 1.1));
        let (sxy, sth) = (axy * f64::from(1u32 << kxy), ath * f64::from(1u32 << kth));
        let tiles = |(a, b): (f64, f64), s: f64| -> Vec<(f64, f64)> {
            let n = ((b - a) / s).ceil().max(1.0) as usize;
            (0..n).map(|i| (a + i as f64 * s, a + (i + 1) as f64 * s)).collect()
        };
        let mut roots = Vec::new();
        for x in tiles(area.x, sxy) {
            for y in tiles(area.y, sxy) {
                for theta in tiles(area.theta, sth) {
                    roots.push(Cell { x, y, theta });
                }
            }
        }
        roots
    }

    /// Whether `cell` is at the accuracy in every dimension.
    fn is_leaf(&self, cell: &Cell) -> bool {
        let (sx, sy, st) = cell.size();
        let fine = |s: f64, acc: f64| s <= acc * (1.0 + 1e-9);
        fine(sx, self.accuracy.0) && fine(sy, self.accuracy.0) && fine(st, self.accuracy.1)
    }

    /// `cell` split in two along every dimension coarser than the accuracy.
    fn split(&self, cell: &Cell) -> Vec<Cell> {
        let halves = |(a, b): (f64, f64), acc: f64| -> Vec<(f64, f64)> {
            if b - a <= acc * (1.0 + 1e-9) {
                vec![(a, b)]
            } else {
                let m = 0.5 * (a + b);
                vec![(a, m), (m, b)]
            }
        };
        let mut out = Vec::with_capacity(8);
        for x in halves(cell.x, self.accuracy.0) {
            for y in halves(cell.y, self.accuracy.0) {
                for theta in halves(cell.theta, self.accuracy.1) {
                    out.push(Cell { x, y, theta });
                }
            }
        }
        out
    }

    /// The evidence of one pose: each perception that `support` names counts `w·(1 − d²)`
    /// when its residual `d` (in tolerances: range and bearing to the nearest map point of its
    /// kind, the distance to the nearest segment for line points, distance and direction for
    /// lines) is below 1, nothing otherwise.
    /// A perception that counts here lies inside its conservative region of every cell that
    /// holds the pose, so a cell's evidence bounds this (the search's correctness rests on it).
    fn score(&self, pose: Pose2, seen: &Seen, support: &[u16]) -> f64 {
        let mut sum = 0.0;
        let heading = pose.theta.sin_cos();
        for &k in support {
            let p = &seen.perceptions[usize::from(k)];
            let tol_r = p.range_tolerance.max(1e-6);
            let tol_b = p.bearing_tolerance.max(1e-6);
            let mut best = f64::INFINITY;
            if p.extent.is_some() {
                for (_, seg) in self.map.segments.iter().filter(|(kind, _)| *kind == p.kind) {
                    if let Some(d) = Murea::line_residual(pose, p, seg) {
                        best = best.min(d);
                    }
                }
                sum += p.weight * (1.0 - best).max(0.0);
                continue;
            }
            for (_, at) in self.map.points.iter().filter(|(kind, _)| *kind == p.kind) {
                let (dx, dy) = (at.x - pose.x, at.y - pose.y);
                let dr = p.range.map_or(0.0, |r| (dx.hypot(dy) - r) / tol_r);
                let db = p
                    .bearing
                    .map_or(0.0, |b| normalize_angle(dy.atan2(dx) - pose.theta - b) / tol_b);
                if dr.abs() < 1.0 && db.abs() < 1.0 {
                    best = best.min(dr * dr + db * db);
                }
            }
            if let (Some(r), Some(_)) = (p.range, p.bearing) {
                let Prepared { trig, disc: tol } = seen.prepared[usize::from(k)];
                let (s, c) = turned(heading, trig[2]);
                let seen = Point2::new(pose.x + r * c, pose.y + r * s);
                // `tol`: the largest disc round the seen point within its tolerance sector.
                // A segment farther than a tolerance cannot count (its `off` ≥ 1).
                let around = ((seen.x - tol, seen.x + tol), (seen.y - tol, seen.y + tol));
                for seg in self.map.near(p.kind, around.0, around.1) {
                    best = best.min((seg.distance(seen) / tol).powi(2));
                }
            }
            sum += p.weight * (1.0 - best).max(0.0);
        }
        sum
    }

    /// How well `pose` explains `perceptions`: its evidence over their summed weight, 0 to 1
    /// (the [`Fix::quality`] that pose would have). Costs one pass over the map per
    /// perception: cheap enough to check a tracker's pose every frame.
    pub fn quality_at(&self, pose: Pose2, perceptions: &[Perception]) -> f64 {
        let (valid, total) = usable(perceptions);
        if total > 0.0 {
            self.score(pose, &Seen::new(perceptions), &valid) / total
        } else {
            0.0
        }
    }

    /// The pose in `area` that the perceptions fit best (module doc). Perceptions that are not
    /// numbers, or weigh nothing, are left out; with none left, the answer is the area's centre
    /// with quality 0.
    pub fn localize(&self, perceptions: &[Perception], area: Cell) -> Fix {
        let started = Instant::now();
        let (valid, total) = usable(perceptions);
        let seen = Seen::new(perceptions);
        let mut heap = BinaryHeap::new();
        let mut order = 0u64;
        let mut cells = 0usize;
        for cell in self.roots(&area) {
            let Some((evidence, support)) = self.evidence(&cell, &seen, (&valid, total), 0.0)
            else {
                continue;
            };
            cells += 1;
            heap.push(Entry { evidence, depth: 0, order, cell, support, scored: false });
            order += 1;
        }
        let out_of_budget = |cells: usize| {
            cells >= self.budget.cells
                || self.budget.timeout.is_some_and(|t| started.elapsed() >= t)
        };
        // Scored leaves taken off the heap, best first: the first is the optimum (every other
        // entry bounds its cells by no more); the search goes on for the ambiguous others.
        let mut found: Vec<(Pose2, f64)> = Vec::new();
        let mut coarse: Option<(Cell, f64)> = None;
        let mut cut = false;
        while let Some(mut entry) = heap.pop() {
            if let Some(&(_, top)) = found.first() {
                if entry.evidence < self.ambiguity * top || entry.evidence <= 0.0 {
                    break;
                }
            }
            if entry.scored {
                found.push((entry.cell.centre(), entry.evidence));
                continue;
            }
            // After the best, only poses far from it can be other answers: a cell wholly
            // near it holds none and is dropped without refining it to the accuracy.
            if found.first().is_some_and(|&(best, _)| self.wholly_near(&entry.cell, best)) {
                continue;
            }
            if self.is_leaf(&entry.cell) {
                entry.evidence = self.score(entry.cell.centre(), &seen, &entry.support);
                entry.scored = true;
                heap.push(entry);
                continue;
            }
            if out_of_budget(cells) {
                cut = true;
                if found.is_empty() {
                    coarse = Some((entry.cell, entry.evidence));
                }
                break;
            }
            // After the best, a cell below the ambiguity's share of it would never be taken
            // off the heap: its evidence is not worth finishing.
            let floor = found.first().map_or(0.0, |&(_, top)| self.ambiguity * top);
            for child in self.split(&entry.cell) {
                cells += 1;
                let among = (&entry.support[..], entry.evidence);
                let Some((evidence, support)) = self.evidence(&child, &seen, among, floor) else {
                    continue;
                };
                if evidence > 0.0 || entry.evidence <= 0.0 {
                    let depth = entry.depth + 1;
                    heap.push(Entry {
                        evidence,
                        depth,
                        order,
                        cell: child,
                        support,
                        scored: false,
                    });
                    order += 1;
                }
            }
        }
        let Some(&(pose, evidence)) = found.first() else {
            let (cell, evidence) = coarse.unwrap_or((area, 0.0));
            return Fix {
                pose: cell.centre(),
                evidence,
                quality: if total > 0.0 { evidence / total } else { 0.0 },
                cell: cell.size(),
                alternatives: Vec::new(),
                timed_out: true,
                cells,
            };
        };
        let far = |a: Pose2, b: Pose2| {
            (a.x - b.x).hypot(a.y - b.y) >= self.apart.0
                || normalize_angle(a.theta - b.theta).abs() >= self.apart.1
        };
        // A pose on the same ridge of evidence as the best is not another answer, only the
        // fix's imprecision (two far goals with metres of range tolerance fit a long strip
        // of poses): another answer lies beyond a valley.
        let valley = |q: Pose2| {
            (1..VALLEY_SAMPLES).any(|k| {
                let t = f64::from(k) / f64::from(VALLEY_SAMPLES);
                let between = Pose2::new(
                    pose.x + t * (q.x - pose.x),
                    pose.y + t * (q.y - pose.y),
                    pose.theta + t * normalize_angle(q.theta - pose.theta),
                );
                self.score(between, &seen, &valid) < VALLEY * evidence
            })
        };
        let mut alternatives: Vec<(Pose2, f64)> = Vec::new();
        for &(q, e) in &found[1..] {
            if far(q, pose) && alternatives.iter().all(|a| far(q, a.0)) && valley(q) {
                alternatives.push((q, e));
            }
        }
        Fix {
            pose,
            evidence,
            quality: if total > 0.0 { evidence / total } else { 0.0 },
            cell: (self.accuracy.0, self.accuracy.0, self.accuracy.1),
            alternatives,
            timed_out: cut,
            cells,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// What a robot at `pose` sees of the map's goals and posts (exact range and bearing), all round; not the goals' corners,
    /// which a camera reports only for a goal it cannot see whole.
    fn seen_from(map: &Map, pose: Pose2) -> Vec<Perception> {
        let corners = [Kind::EAST_CORNER, Kind::WEST_CORNER, Kind::CORNER];
        map.points
            .iter()
            .filter(|(kind, _)| !corners.contains(kind))
            .map(|&(kind, at)| {
                let (dx, dy) = (at.x - pose.x, at.y - pose.y);
                let bearing = normalize_angle(dy.atan2(dx) - pose.theta);
                Perception::point(kind, dx.hypot(dy), bearing)
            })
            .collect()
    }

    /// Line points seen from `pose`: `n` points of the map's segments within 6 m.
    fn line_points(map: &Map, pose: Pose2, n: usize) -> Vec<Perception> {
        let mut out = Vec::new();
        for (_, s) in &map.segments {
            for k in 0..8 {
                let p = s.a + (s.b - s.a) * (f64::from(k) + 0.5) / 8.0;
                let (dx, dy) = (p.x - pose.x, p.y - pose.y);
                if dx.hypot(dy) < 6.0 && out.len() < n {
                    let bearing = normalize_angle(dy.atan2(dx) - pose.theta);
                    out.push(Perception::point(Kind::LINE, dx.hypot(dy), bearing));
                }
            }
        }
        out
    }

    fn small_map() -> Map {
        Map::new()
            .point(Kind(1), Point2::new(1.5, 1.0))
            .point(Kind(2), Point2::new(-1.5, 0.5))
            .point(Kind(3), Point2::new(0.5, -1.2))
            .segment(Kind::LINE, Segment { a: Point2::new(-2.0, -1.5), b: Point2::new(2.0, -1.5) })
    }

    #[test]
    fn the_search_finds_the_best_cell_of_the_finest_grid_as_brute_force_does() {
        let mut murea = Murea::new(small_map());
        murea.accuracy = (0.1, 4f64.to_radians());
        let truth = Pose2::new(0.33, 0.21, 0.7);
        let mut seen = seen_from(&murea.map, truth);
        seen[1].range = Some(seen[1].range.unwrap_or(0.0) + 0.4); // one perception is off
        seen.push(Perception::point(Kind::LINE, 1.9, -1.3));
        let area = Cell { x: (-2.0, 2.0), y: (-1.5, 1.5), theta: (-PI, PI) };
        let fix = murea.localize(&seen, area);
        // Brute force: every cell of the finest grid that the roots split into.
        let all: Vec<u16> = (0..seen.len() as u16).collect();
        let mut leaves: Vec<Cell> = murea.roots(&area);
        while leaves.iter().any(|c| !murea.is_leaf(c)) {
            leaves = leaves.iter().flat_map(|c| murea.split(c)).collect();
        }
        let prepared = Seen::new(&seen);
        let scores: Vec<f64> =
            leaves.iter().map(|c| murea.score(c.centre(), &prepared, &all)).collect();
        let best = scores.iter().copied().fold(0.0, f64::max);
        assert_eq!(fix.evidence, best, "{fix:?}");
        assert!(fix.cells < leaves.len() / 10, "{} of {} cells", fix.cells, leaves.len());
        let argmax: Vec<Pose2> = leaves
            .iter()
            .zip(&scores)
            .filter(|(_, &s)| s == best)
            .map(|(c, _)| c.centre())
            .collect();
        assert!(argmax.contains(&fix.pose), "{:?} not among {} best cells", fix.pose, argmax.len());
    }

    #[test]
    fn an_msl_field_pose_is_found_with_a_third_of_the_perceptions_spurious() {
        let murea = Murea::new(Map::field(&FieldMap::default(), true));
        for truth in
            [Pose2::new(-3.2, 2.1, 2.5), Pose2::new(6.0, -4.0, -0.3), Pose2::new(0.4, 0.2, 1.6)]
        {
            let mut seen = seen_from(&murea.map, truth);
            seen.extend(line_points(&murea.map, truth, 8));
            // Noise of a third of the tolerances (1.7 % of the range, 0.7°: the vision survey's
            // medians), and 30 % spurious perceptions of every kind at made-up places.
            for (k, p) in seen.iter_mut().enumerate() {
                let wobble = [0.33, -0.33, 0.2, -0.1][k % 4];
                p.range = p.range.map(|r| r + wobble * p.range_tolerance);
                p.bearing = p.bearing.map(|b| b + wobble * p.bearing_tolerance);
            }
            let genuine = seen.len();
            for k in 0..genuine * 3 / 7 {
                let kind = [Kind::LINE, Kind::EAST_POST, Kind::WEST_GOAL][k % 3];
                seen.push(Perception::point(kind, 1.0 + 0.7 * k as f64, 0.9 * k as f64 - 2.0));
            }
            let fix = murea.localize(&seen, murea.whole_field());
            let err = (fix.pose.x - truth.x).hypot(fix.pose.y - truth.y);
            let turn = normalize_angle(fix.pose.theta - truth.theta).abs();
            assert!(err < 0.1 && turn < 2f64.to_radians(), "{truth:?}: {fix:?}");
            // A genuine perception off by a third of its tolerances counts 1 − 0.33² − 0.33².
            assert!(!fix.timed_out && fix.evidence >= 0.8 * genuine as f64, "{fix:?}");
        }
    }

    #[test]
    fn a_symmetric_field_gives_the_mirrored_pose_as_an_alternative_and_colour_breaks_it() {
        let truth = Pose2::new(-4.0, 1.5, 0.4);
        let mirror = Pose2::new(4.0, -1.5, normalize_angle(0.4 + PI));
        for coloured in [false, true] {
            let murea = Murea::new(Map::field(&FieldMap::default(), coloured));
            let seen = seen_from(&murea.map, truth);
            let fix = murea.localize(&seen, murea.whole_field());
            let near = |a: Pose2, b: Pose2| (a.x - b.x).hypot(a.y - b.y) < 0.1;
            assert!(near(fix.pose, truth) || (!coloured && near(fix.pose, mirror)), "{fix:?}");
            let other = if near(fix.pose, truth) { mirror } else { truth };
            let ambiguous = fix.alternatives.iter().any(|a| near(a.0, other));
            assert_eq!(ambiguous, !coloured, "coloured {coloured}: {:?}", fix.alternatives);
        }
    }

    /// Two far objects with a metre of range tolerance fit a strip of poses metres long: its
    /// ends are not two answers (otherwise the relocalizer refuses nearly every search of a
    /// goalkeeper looking up the field as "ambiguous").
    #[test]
    fn a_long_ridge_of_poses_that_fit_is_one_answer_not_an_ambiguity() {
        let mut murea = Murea::new(Map::field(&FieldMap::default(), true));
        murea.accuracy = (0.25, 4f64.to_radians());
        let truth = Pose2::new(-7.5, 0.5, 0.2);
        let far: Vec<Perception> = seen_from(&murea.map, truth)
            .into_iter()
            .filter(|p| {
                (p.kind == Kind::EAST_GOAL || p.kind == Kind::EAST_POST)
                    && p.range.unwrap_or(0.0) > 12.0
            })
            .map(|p| p.tolerances(0.1 * p.range.unwrap_or(0.0), 4f64.to_radians()))
            .collect();
        assert!(far.len() >= 2 && far.iter().all(|p| p.range_tolerance > 1.0), "{far:?}");
        let fix = murea.localize(&far, murea.whole_field());
        assert!((fix.pose.x - truth.x).hypot(fix.pose.y - truth.y) < 1.5, "{fix:?}");
        assert!(fix.alternatives.is_empty(), "{:?}", fix.alternatives);
        // The ridge is real: some pose a metre or more from the fix explains at least 90 % as
        // much (what was reported as another answer before).
        let q = fix.quality;
        let ridge = (-20..=20).flat_map(|i| (-20..=20).map(move |j| (i, j))).any(|(i, j)| {
            let (dx, dy) = (0.1 * f64::from(i), 0.1 * f64::from(j));
            dx.hypot(dy) >= 1.0
                && (-2..=2).any(|k| {
                    let at = Pose2::new(
                        fix.pose.x + dx,
                        fix.pose.y + dy,
                        fix.pose.theta + 0.02 * f64::from(k),
                    );
                    murea.quality_at(at, &far) >= murea.ambiguity * q
                })
        });
        assert!(ridge, "{fix:?}");
    }

    #[test]
    fn a_small_budget_returns_a_coarse_cell_near_the_truth() {
        let mut murea = Murea::new(Map::field(&FieldMap::default(), true));
        let truth = Pose2::new(2.0, -1.0, -2.0);
        let seen = seen_from(&murea.map, truth);
        let full = murea.localize(&seen, murea.whole_field());
        assert!(!full.timed_out && full.cells > 2000, "{full:?}");
        assert!((full.pose.x - truth.x).hypot(full.pose.y - truth.y) < 0.05, "{full:?}");
        // Stopped before any cell reached the accuracy: the best cell so far, as coarse as it
        // is (0.2 m, 8°), explains every perception and lies near the truth.
        murea.budget.cells = 600;
        let fix = murea.localize(&seen, murea.whole_field());
        assert!(fix.timed_out && fix.cell.0 > 0.1 && fix.evidence == 8.0, "{fix:?}");
        assert!((fix.pose.x - truth.x).hypot(fix.pose.y - truth.y) < 0.5, "{fix:?}");
        assert!(normalize_angle(fix.pose.theta - truth.theta).abs() < 0.2, "{fix:?}");
        // Stopped while comparing the poses of the best evidence: a leaf, flagged.
        murea.budget.cells = 1500;
        let fix = murea.localize(&seen, murea.whole_field());
        assert!(fix.timed_out && fix.cell.0 <= 0.05 && fix.evidence == 8.0, "{fix:?}");
    }

    #[test]
    fn the_search_is_deterministic_and_odd_input_is_harmless() {
        let murea = Murea::new(Map::field(&FieldMap::default(), true));
        let seen = seen_from(&murea.map, Pose2::new(1.0, 1.0, 1.0));
        let area = Murea::around(Pose2::new(1.2, 0.9, 1.1), 0.5, 0.3);
        assert_eq!(murea.localize(&seen, area), murea.localize(&seen, area));
        let mut odd = seen.clone();
        odd.push(Perception { range: Some(f64::NAN), ..seen[0] });
        odd.push(seen[1].weighted(0.0));
        odd.push(seen[2].tolerances(-1.0, 0.1));
        assert_eq!(murea.localize(&odd, area).pose, murea.localize(&seen, area).pose);
        let none = murea.localize(&[], area);
        assert_eq!(none.quality, 0.0);
        let empty = Murea::new(Map::new());
        assert_eq!(empty.localize(&seen, empty.whole_field()).evidence, 0.0);
    }

    proptest! {
        /// A cell's evidence bounds each of its children's and each of its poses' (the
        /// search's correctness rests on it).
        #[test]
        fn a_cell_bounds_the_evidence_of_its_children_and_poses(
            x in -9.0..9.0f64, y in -6.0..6.0f64, th in -3.2..3.2f64,
            sx in 0.1..4.0f64, sth in 0.02..2.0f64, at in (0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64),
            range in 0.3..12.0f64, bearing in -3.2..3.2f64, kind in 0u16..5, shape in 0u8..3,
            extent in (-6.0..6.0f64, 0.0..4.0f64),
        ) {
            let murea = Murea::new(Map::field(&FieldMap::default(), true));
            let p = match shape {
                0 => Perception::point(Kind(kind), range, bearing),
                1 => Perception::bearing_only(Kind(kind), bearing),
                _ => Perception::line(Kind::LINE, range, bearing, (extent.0, extent.0 + extent.1)),
            };
            let cell = Cell { x: (x, x + sx), y: (y, y + sx), theta: (th, th + sth) };
            let seen = [p];
            let seen = Seen::new(&seen);
            let bound = |cell: &Cell| murea.evidence(cell, &seen, (&[0], p.weight), 0.0).map_or(0.0, |e| e.0);
            let parent = bound(&cell);
            for child in murea.split(&cell) {
                prop_assert!(bound(&child) <= parent);
            }
            let pose = Pose2 { x: x + at.0 * sx, y: y + at.1 * sx, theta: th + at.2 * sth };
            prop_assert!(murea.score(pose, &seen, &[0]) <= parent);
        }
    }
}
