//! SPIKE, *Spike Plans In Known Environments* (MRT manual ch. 9): a fast trajectory planner on
//! a geometric map of fixed objects, over a multi-resolution grid.
//!
//! The manual gives what SPIKE takes and gives: a description of the environment, a start
//! and a goal in, a trajectory (a sequence of poses) out, with the robot's size, the required
//! accuracy, a safety distance and the plan's resolution as options; doors and passages small
//! with respect to the grid are handled, and moving objects when the robot detects them. How
//! it does it is not written down; this is the research notes' reconstruction (`MODULES.md`
//! §4, design choices tagged \[DES\] there) on the classical multi-resolution cell
//! decomposition (Kambhampati and Davis, 1986):
//!
//! 1. **Configuration space.** The robot is a disc: its centre must keep `robot_radius +
//!    safety` from every obstacle and from the map's edge. In a [`Door`]'s region the safety
//!    shrinks so that a door a little wider than the robot is passable, and one narrower is
//!    not.
//! 2. **Quadtree.** A square cell is *free* when its centre is at least the clearance plus
//!    half its diagonal from every obstacle (then all of it is), *blocked* when it is at most
//!    the clearance less half its diagonal (all of it is inside), else *mixed* and split in
//!    four. A mixed cell at the accuracy is blocked: a path never comes nearer than asked.
//!    The tree is built **lazily**: a cell is split only when the search looks into it, so
//!    open space stays in big cells and only the obstacles' edges that the search meets are
//!    refined to the accuracy. Narrow passages appear at the fine levels.
//! 3. **Search.** Weighted A* over the free leaves, from the leaf of the start to the leaf of
//!    the goal, neighbours across shared sides; a cell is reached where the straight way to
//!    the goal crosses the side it is entered by, and costs are the distances between these
//!    points.
//! 4. **Path.** The cells found make a channel of boxes; the shortest path inside it (the
//!    *funnel* algorithm over the sides crossed) is the plan's corners, then pulled tight
//!    where a straight line between two corners crosses free cells only (the search may have
//!    gone by cells that a straighter way does not need). It is collision-free by
//!    construction: every point of a free cell keeps the clearance.
//! 5. **Trajectory.** Poses every `resolution` metres along the corners, headed along the
//!    path.
//!
//! Moving objects (other robots from the world model) are discs given to
//! [`Spike::plan_among`]; re-planning builds a new lazy tree, so nothing is to be repaired
//! by hand, and [`Plan::is_blocked_by`] says when the old path must be given up.
//!
//! Lengths in metres, the map's frame (the soccer field's: origin at the centre spot).
//!
//! ```
//! use mrt_core::Point2;
//! use mrt_plan::spike::{PlanMap, Shape, Spike, SpikeParams};
//!
//! // A 10 m × 6 m room with a pillar of 1 m radius in the middle.
//! let map = PlanMap::new(Point2::new(-5.0, -3.0), Point2::new(5.0, 3.0))?
//!     .with(Shape::Disc { centre: Point2::new(0.0, 0.0), radius: 1.0 });
//! let spike = Spike::new(map, SpikeParams::default())?;
//! let plan = spike.plan(Point2::new(-4.0, 0.0), Point2::new(4.0, 0.0))?;
//! // Round the pillar at robot radius 0.25 m + safety 0.1 m: a little longer than 8 m.
//! assert!(plan.length > 8.2 && plan.length < 8.7, "{}", plan.length);
//! assert!(plan.waypoints.len() >= 3);
//! # Ok::<(), mrt_plan::PlanError>(())
//! ```

use crate::error::{positive, PlanError};
use mrt_core::{Point2, Pose2};
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::f64::consts::{FRAC_1_SQRT_2, TAU};

/// An obstacle of the map (MRT manual ch. 9: "a geometrical representation of fixed
/// objects"), or a moving object inserted for one plan.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A round object: a pillar, a robot, a person.
    Disc {
        /// Its centre.
        centre: Point2,
        /// Its radius, m.
        radius: f64,
    },
    /// A thin wall from `a` to `b`.
    Wall {
        /// One end.
        a: Point2,
        /// The other end.
        b: Point2,
    },
    /// A filled polygon (furniture, a goal's box), its corners in order; concave allowed.
    Polygon(Vec<Point2>),
}

impl Shape {
    /// How far `p` lies from the shape, m; negative inside a disc or a polygon.
    pub fn distance(&self, p: Point2) -> f64 {
        match self {
            Shape::Disc { centre, radius } => (p - centre).norm() - radius,
            Shape::Wall { a, b } => segment_distance(p, *a, *b),
            Shape::Polygon(corners) => {
                let Some(&last) = corners.last() else {
                    return f64::INFINITY;
                };
                let mut d = f64::INFINITY;
                let mut inside = false;
                let mut prev = last;
                for &c in corners {
                    d = d.min(segment_distance(p, prev, c));
                    // Even-odd rule: count the edges a ray to +x crosses.
                    if (c.y > p.y) != (prev.y > p.y)
                        && p.x < prev.x + (p.y - prev.y) * (c.x - prev.x) / (c.y - prev.y)
                    {
                        inside = !inside;
                    }
                    prev = c;
                }
                if inside {
                    -d
                } else {
                    d
                }
            }
        }
    }

    /// How near the segment `a`–`b` comes to the shape, m (0 when it touches or crosses it).
    pub fn segment_distance(&self, a: Point2, b: Point2) -> f64 {
        match self {
            Shape::Disc { centre, radius } => (segment_distance(*centre, a, b) - radius).max(0.0),
            Shape::Wall { a: p, b: q } => segments_distance(a, b, *p, *q),
            Shape::Polygon(corners) => {
                if self.distance(a) <= 0.0 {
                    return 0.0;
                }
                let Some(&last) = corners.last() else {
                    return f64::INFINITY;
                };
                let mut prev = last;
                let mut d = f64::INFINITY;
                for &c in corners {
                    d = d.min(segments_distance(a, b, prev, c));
                    prev = c;
                }
                d
            }
        }
    }

    /// Whether every number is within [`MAX_COORD`] (so finite, and far from overflowing the
    /// geometry) and a disc's radius is not negative.
    fn is_valid(&self) -> bool {
        let ok = |p: &Point2| p.x.abs() <= MAX_COORD && p.y.abs() <= MAX_COORD;
        match self {
            Shape::Disc { centre, radius } => ok(centre) && (0.0..=MAX_COORD).contains(radius),
            Shape::Wall { a, b } => ok(a) && ok(b),
            Shape::Polygon(corners) => corners.iter().all(ok),
        }
    }
}

/// The largest coordinate or radius a map or a moving object may have, m: a thousand
/// kilometres, well inside what the geometry computes without overflow.
pub const MAX_COORD: f64 = 1e6;

/// The most poses in a trajectory ([`Plan::poses`]): a path longer than this many times the
/// resolution gets its poses farther apart.
pub const MAX_POSES: usize = 100_000;

/// The largest map file [`PlanMap::from_toml`] reads, bytes: some 20 000 obstacles, and a bound
/// on what parsing it allocates.
pub const MAX_MAP_BYTES: usize = 1 << 20;

/// How far `p` lies from the segment `a`–`b`.
fn segment_distance(p: Point2, a: Point2, b: Point2) -> f64 {
    let d = b - a;
    let t = ((p - a).dot(&d) / d.norm_squared().max(1e-18)).clamp(0.0, 1.0);
    (p - (a + d * t)).norm()
}

/// The side of `c` from the line `a`→`b`: positive on the left (counter-clockwise).
fn cross(a: Point2, b: Point2, c: Point2) -> f64 {
    let (u, v) = (b - a, c - a);
    u.x * v.y - u.y * v.x
}

/// How near the segments `a`–`b` and `p`–`q` come, 0 when they cross.
fn segments_distance(a: Point2, b: Point2, p: Point2, q: Point2) -> f64 {
    let (d1, d2) = (cross(a, b, p), cross(a, b, q));
    let (d3, d4) = (cross(p, q, a), cross(p, q, b));
    if ((d1 > 0.0) != (d2 > 0.0)) && ((d3 > 0.0) != (d4 > 0.0)) {
        return 0.0;
    }
    segment_distance(a, p, q)
        .min(segment_distance(b, p, q))
        .min(segment_distance(p, a, b))
        .min(segment_distance(q, a, b))
}

/// A door (research notes §4 step 4): the gap between two jambs `a` and `b`. Within its
/// region (closer to the gap than the robot's radius plus the safety) the safety distance
/// shrinks to what the door's width leaves, so a door is passable when it is wider than the
/// robot by a few times the accuracy, and not when it is narrower.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Door {
    /// One jamb.
    pub a: Point2,
    /// The other jamb.
    pub b: Point2,
}

/// The environment SPIKE plans in: the area the robot may be in, the fixed obstacles, and the
/// doors.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanMap {
    /// The area's lower-left corner.
    pub min: Point2,
    /// Its upper-right corner. The area's edge is a wall.
    pub max: Point2,
    /// The fixed obstacles.
    pub shapes: Vec<Shape>,
    /// The doors.
    pub doors: Vec<Door>,
}

impl PlanMap {
    /// An empty area from `min` to `max`.
    ///
    /// # Errors
    /// [`PlanError::InvalidParameter`] when a corner is not finite or `max` is not above and
    /// right of `min`.
    pub fn new(min: Point2, max: Point2) -> Result<PlanMap, PlanError> {
        for (name, v) in [("min.x", min.x), ("min.y", min.y), ("max.x", max.x), ("max.y", max.y)] {
            if !v.is_finite() || v.abs() > MAX_COORD {
                return Err(PlanError::InvalidParameter {
                    name,
                    value: v,
                    expected: "a finite value within ±1 000 000 m",
                });
            }
        }
        positive("max.x - min.x", max.x - min.x)?;
        positive("max.y - min.y", max.y - min.y)?;
        Ok(PlanMap { min, max, shapes: Vec::new(), doors: Vec::new() })
    }

    /// The map with one more obstacle.
    pub fn with(mut self, shape: Shape) -> PlanMap {
        self.shapes.push(shape);
        self
    }

    /// The map with one more door.
    pub fn with_door(mut self, door: Door) -> PlanMap {
        self.doors.push(door);
        self
    }

    /// A soccer field of `length` × `width` between its lines, origin at the centre spot, as
    /// MRT's simulator builds it: a 1 m border inside the walls, and each goal a box 2 m wide
    /// and 0.6 m deep behind its goal line (its back and sides are obstacles, its mouth is
    /// open).
    ///
    /// # Errors
    /// [`PlanError::InvalidParameter`] when a size is not finite and positive.
    pub fn soccer_field(length: f64, width: f64) -> Result<PlanMap, PlanError> {
        let (hl, hw) = (positive("length", length)? / 2.0, positive("width", width)? / 2.0);
        let border = 1.0;
        let (gw, gd) = (1.0, 0.6);
        let mut map = PlanMap::new(
            Point2::new(-hl - border, -hw - border),
            Point2::new(hl + border, hw + border),
        )?;
        for side in [-1.0, 1.0] {
            let (line, back) = (side * hl, side * (hl + gd));
            map = map
                .with(Shape::Wall { a: Point2::new(back, -gw), b: Point2::new(back, gw) })
                .with(Shape::Wall { a: Point2::new(line, gw), b: Point2::new(back, gw) })
                .with(Shape::Wall { a: Point2::new(line, -gw), b: Point2::new(back, -gw) });
        }
        Ok(map)
    }

    /// How far `p` lies from the nearest obstacle or the area's edge, m; negative inside an
    /// obstacle or outside the area.
    pub fn clearance(&self, p: Point2) -> f64 {
        let edge =
            (p.x - self.min.x).min(self.max.x - p.x).min(p.y - self.min.y).min(self.max.y - p.y);
        self.shapes.iter().fold(edge, |d, s| d.min(s.distance(p)))
    }
}

/// A map file (docs/planning.md): `[area]` or `[field]`, then any number of `[[disc]]`,
/// `[[wall]]`, `[[polygon]]` and `[[door]]` tables.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct MapFile {
    area: Option<AreaTable>,
    field: Option<FieldTable>,
    #[serde(default)]
    disc: Vec<DiscTable>,
    #[serde(default)]
    wall: Vec<SegmentTable>,
    #[serde(default)]
    polygon: Vec<PolygonTable>,
    #[serde(default)]
    door: Vec<SegmentTable>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct AreaTable {
    min: [f64; 2],
    max: [f64; 2],
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct FieldTable {
    length: f64,
    width: f64,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct DiscTable {
    centre: [f64; 2],
    radius: f64,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct SegmentTable {
    from: [f64; 2],
    to: [f64; 2],
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct PolygonTable {
    corners: Vec<[f64; 2]>,
}

impl PlanMap {
    /// Parses a map file (TOML, docs/planning.md); `file` names it in errors, with the line
    /// and column of a syntax error.
    ///
    /// ```
    /// let text = "[area]\nmin = [0, 0]\nmax = [6, 4]\n\n[[disc]]\ncentre = [3, 2]\nradius = 0.5\n";
    /// let map = mrt_plan::spike::PlanMap::from_toml(text, "room.toml")?;
    /// assert_eq!(map.shapes.len(), 1);
    /// let bad = mrt_plan::spike::PlanMap::from_toml("[area]\nmin = [0, 0]\nmax = 4\n", "bad.toml");
    /// assert!(bad.unwrap_err().to_string().starts_with("bad.toml:3:7: "));
    /// # Ok::<(), mrt_core::FileError>(())
    /// ```
    ///
    /// # Errors
    /// [`mrt_core::FileError::Parse`] for malformed TOML or an unknown key,
    /// [`mrt_core::FileError::Invalid`] for an area and a field both or neither, a size that
    /// is not positive, a number that is not finite or beyond [`MAX_COORD`], a polygon of
    /// fewer than 3 corners, or a file longer than [`MAX_MAP_BYTES`].
    pub fn from_toml(text: &str, file: &str) -> Result<PlanMap, mrt_core::FileError> {
        if text.len() > MAX_MAP_BYTES {
            return Err(mrt_core::FileError::Invalid {
                file: file.to_string(),
                message: format!(
                    "{} bytes: a map file may have at most {MAX_MAP_BYTES}",
                    text.len()
                ),
            });
        }
        let parsed: MapFile = toml::from_str(text).map_err(|e| {
            mrt_core::FileError::parse(file, text, e.span().map(|s| s.start), e.message())
        })?;
        let invalid =
            |message: String| mrt_core::FileError::Invalid { file: file.to_string(), message };
        let point = |[x, y]: [f64; 2]| Point2::new(x, y);
        let mut map = match (parsed.area, parsed.field) {
            (Some(a), None) => PlanMap::new(point(a.min), point(a.max)),
            (None, Some(f)) => PlanMap::soccer_field(f.length, f.width),
            _ => return Err(invalid("give either [area] or [field], not both or neither".into())),
        }
        .map_err(|e| invalid(e.to_string()))?;
        for d in parsed.disc {
            map = map.with(Shape::Disc { centre: point(d.centre), radius: d.radius });
        }
        for w in parsed.wall {
            map = map.with(Shape::Wall { a: point(w.from), b: point(w.to) });
        }
        for (k, p) in parsed.polygon.into_iter().enumerate() {
            if p.corners.len() < 3 {
                return Err(invalid(format!(
                    "polygon {}: {} corners, at least 3 needed",
                    k + 1,
                    p.corners.len()
                )));
            }
            map = map.with(Shape::Polygon(p.corners.into_iter().map(point).collect()));
        }
        for d in parsed.door {
            map = map.with_door(Door { a: point(d.from), b: point(d.to) });
        }
        if let Some(k) = map.shapes.iter().position(|s| !s.is_valid()) {
            return Err(invalid(format!(
                "obstacle {}: a number is not finite or beyond ±{MAX_COORD} m, or a radius is negative",
                k + 1
            )));
        }
        let near = |p: &Point2| p.x.abs() <= MAX_COORD && p.y.abs() <= MAX_COORD;
        if map.doors.iter().any(|d| !near(&d.a) || !near(&d.b)) {
            return Err(invalid(format!("a door's jamb is not finite or beyond ±{MAX_COORD} m")));
        }
        Ok(map)
    }

    /// Reads a map file ([`PlanMap::from_toml`]).
    ///
    /// # Errors
    /// [`mrt_core::FileError::Io`] when the file cannot be read, else as
    /// [`PlanMap::from_toml`].
    pub fn from_file(path: impl AsRef<std::path::Path>) -> Result<PlanMap, mrt_core::FileError> {
        let (text, file) = mrt_core::FileError::read(path.as_ref())?;
        PlanMap::from_toml(&text, &file)
    }
}

/// SPIKE's options (MRT manual ch. 9: "robot size, the required accuracy, and a safety
/// distance from obstacles", and "the resolution of the plan").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpikeParams {
    /// The robot's radius, m.
    pub robot_radius: f64,
    /// How far it keeps from obstacles besides, m.
    pub safety: f64,
    /// The smallest cell, m, from 1 mm to 1 m: a path never comes nearer an obstacle than
    /// asked, and may keep up to this much more.
    pub accuracy: f64,
    /// The trajectory's poses are at most this far apart, m (at least the accuracy; see
    /// [`MAX_POSES`]).
    pub resolution: f64,
}

impl Default for SpikeParams {
    /// An MRT soccer robot (0.25 m), 0.1 m safety, 1 cm accuracy, a pose every 0.25 m.
    fn default() -> Self {
        SpikeParams { robot_radius: 0.25, safety: 0.1, accuracy: 0.01, resolution: 0.25 }
    }
}

/// What a cell of the decomposition is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellState {
    /// Every point of it keeps the clearance.
    Free,
    /// Some point of it does not, and it is at the accuracy or wholly inside an obstacle.
    Blocked,
    /// Neither yet: it is split when the search looks into it.
    Mixed,
}

/// A square cell of the decomposition.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    /// Its lower-left corner, x.
    pub x: f64,
    /// Its lower-left corner, y.
    pub y: f64,
    /// Its side, m.
    pub size: f64,
    /// What it is.
    pub state: CellState,
}

/// SPIKE's answer.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The path's corners, from the start to the goal.
    pub waypoints: Vec<Point2>,
    /// The trajectory: poses along the corners at most `resolution` apart, each headed along
    /// the path, the last at the goal.
    pub poses: Vec<Pose2>,
    /// The path's length, m.
    pub length: f64,
    /// Whether the start (`.0`) or the goal (`.1`) lay too near an obstacle and the path
    /// begins or ends at the nearest point that does not.
    pub snapped: (bool, bool),
    /// Cells made while planning (the lazy tree's size).
    pub cells: usize,
    /// Cells the search expanded.
    pub expanded: usize,
}

impl Plan {
    /// Whether some `moving` obstacle comes nearer the path than `clearance` (the robot's
    /// radius and safety): then the path must be planned again.
    pub fn is_blocked_by(&self, moving: &[Shape], clearance: f64) -> bool {
        self.waypoints.windows(2).any(|w| {
            moving.iter().any(|s| s.is_valid() && s.segment_distance(w[0], w[1]) < clearance)
        })
    }
}

/// The SPIKE planner: a map and its options (module doc).
#[derive(Clone, Debug)]
pub struct Spike {
    map: PlanMap,
    params: SpikeParams,
}

/// The search's heuristic weight (weighted A*): the distance left counts this much more than
/// the way so far. At 1 the search is plain A* and expands every cell that could lie on a
/// shorter channel: 3065 cells for a path across the 18 × 12 m field among 7 robots, 0.96 ms.
/// At 1.1 it expands 1028 (0.28 ms), and the path, pulled tight afterwards, was 0.3 % longer
/// (docs/performance.md, "SPIKE"; 3000 random cases of the property test stayed within 5 %
/// of the shortest path).
const GREED: f64 = 1.1;

/// The most cells one plan may make (about 30 MB): a map far larger than its accuracy (a
/// kilometre at 1 cm with a wall across) is refused instead of filling the memory.
pub const MAX_CELLS: usize = 500_000;

/// How far the search looks round a start or goal that is too near an obstacle, in
/// clearances.
const SNAP_REACH: f64 = 2.0;

impl Spike {
    /// SPIKE on `map` with `params`.
    ///
    /// # Errors
    /// [`PlanError::InvalidParameter`] for a non-positive or non-finite radius, a negative
    /// safety, an accuracy outside 1 mm to 1 m, a resolution below the accuracy, or a map
    /// shape that is not finite or beyond [`MAX_COORD`].
    pub fn new(map: PlanMap, params: SpikeParams) -> Result<Spike, PlanError> {
        positive("robot_radius", params.robot_radius)?;
        positive("accuracy", params.accuracy)?;
        positive("resolution", params.resolution)?;
        if !(params.safety.is_finite() && params.safety >= 0.0) {
            return Err(PlanError::InvalidParameter {
                name: "safety",
                value: params.safety,
                expected: "a finite value ≥ 0",
            });
        }
        if !(0.001..=1.0).contains(&params.accuracy) {
            return Err(PlanError::InvalidParameter {
                name: "accuracy",
                value: params.accuracy,
                expected: "from 1 mm to 1 m",
            });
        }
        if params.resolution < params.accuracy {
            return Err(PlanError::InvalidParameter {
                name: "resolution",
                value: params.resolution,
                expected: "at least the accuracy",
            });
        }
        if map.shapes.iter().any(|s| !s.is_valid()) {
            return Err(PlanError::InvalidParameter {
                name: "map shape",
                value: f64::NAN,
                expected: "finite corners and a radius ≥ 0",
            });
        }
        Ok(Spike { map, params })
    }

    /// The map.
    pub fn map(&self) -> &PlanMap {
        &self.map
    }

    /// The options.
    pub fn params(&self) -> &SpikeParams {
        &self.params
    }

    /// The clearance every point of a path keeps: robot radius plus safety.
    pub fn clearance(&self) -> f64 {
        self.params.robot_radius + self.params.safety
    }

    /// A path from `from` to `to` among the map's obstacles.
    ///
    /// # Errors
    /// See [`Spike::plan_among`].
    pub fn plan(&self, from: Point2, to: Point2) -> Result<Plan, PlanError> {
        self.plan_among(from, to, &[])
    }

    /// A path from `from` to `to` among the map's obstacles and the `moving` ones (module
    /// doc). A start or goal too near an obstacle is moved to the nearest point that is not
    /// (within twice the clearance; [`Plan::snapped`]). Invalid moving shapes are left out.
    ///
    /// # Errors
    /// [`PlanError::NonFiniteInput`] for a start or goal that is not finite;
    /// [`PlanError::NoPath`] when the start or goal is shut in, or nothing connects them;
    /// [`PlanError::TooManyCells`] when the plan would need more than [`MAX_CELLS`] cells.
    pub fn plan_among(
        &self,
        from: Point2,
        to: Point2,
        moving: &[Shape],
    ) -> Result<Plan, PlanError> {
        self.plan_drawn(from, to, moving).map(|(plan, _)| plan)
    }

    /// [`Spike::plan_among`], and the cells of the decomposition it made (for drawing).
    ///
    /// # Errors
    /// See [`Spike::plan_among`].
    pub fn plan_drawn(
        &self,
        from: Point2,
        to: Point2,
        moving: &[Shape],
    ) -> Result<(Plan, Vec<Cell>), PlanError> {
        for (name, v) in [("from.x", from.x), ("from.y", from.y), ("to.x", to.x), ("to.y", to.y)] {
            if !v.is_finite() {
                return Err(PlanError::NonFiniteInput { name });
            }
        }
        let moving: Vec<&Shape> = moving.iter().filter(|s| s.is_valid()).collect();
        let mut tree = Tree::new(self, &moving);
        let start = tree.snap(from);
        let goal = tree.snap(to);
        if tree.full {
            return Err(PlanError::TooManyCells { cells: MAX_CELLS });
        }
        let start = start.ok_or(PlanError::NoPath { reason: "the start is shut in" })?;
        let goal = goal.ok_or(PlanError::NoPath { reason: "the goal is shut in" })?;
        let (chain, expanded) = tree.search((start.1, start.0), (goal.1, goal.0))?;
        let corners = funnel(&tree.portals(&chain, start.0, goal.0));
        let mut waypoints = tree.pull_tight(&corners);
        if start.0 != from {
            waypoints.insert(0, from);
        }
        waypoints.dedup();
        if tree.full {
            return Err(PlanError::TooManyCells { cells: MAX_CELLS });
        }
        let length = waypoints.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        let poses = trajectory(&waypoints, self.params.resolution);
        let plan = Plan {
            waypoints,
            poses,
            length,
            snapped: (start.0 != from, goal.0 != to),
            cells: tree.nodes.len(),
            expanded,
        };
        Ok((plan, tree.leaves()))
    }
}

/// A node of the lazy quadtree: its cell, the index of its first child (the four are
/// consecutive; 0: none, the root is no one's child) and its parent's.
#[derive(Clone, Copy, Debug)]
struct Node {
    cell: Cell,
    children: u32,
    /// Its parent (the root's is itself).
    parent: u32,
    /// Once split: the obstacles near enough to matter to its children, a range of
    /// [`Tree::near`].
    near: (u32, u32),
}

/// The quadtree of one plan, grown as the search looks into it.
struct Tree<'a> {
    spike: &'a Spike,
    moving: &'a [&'a Shape],
    nodes: Vec<Node>,
    /// Lists of obstacles (see [`Tree::obstacle_distance`]) for the split nodes.
    near: Vec<u32>,
    /// Far less than the smallest cell: a point this far past a side lies in the neighbour.
    nudge: f64,
    /// Whether a split was refused at [`MAX_CELLS`].
    full: bool,
}

/// A cell on the search's heap, by its `f = g + h`, smallest first, then by index.
#[derive(Clone, Copy, PartialEq)]
struct Open {
    f: f64,
    node: u32,
}

impl Eq for Open {}
impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        other.f.total_cmp(&self.f).then(other.node.cmp(&self.node))
    }
}

impl<'a> Tree<'a> {
    fn new(spike: &'a Spike, moving: &'a [&'a Shape]) -> Tree<'a> {
        let map = &spike.map;
        let side = (map.max.x - map.min.x).max(map.max.y - map.min.y);
        let all = 4 + map.shapes.len() + moving.len();
        let mut tree = Tree {
            spike,
            moving,
            nodes: Vec::with_capacity(4096),
            near: (0..u32::try_from(all).unwrap_or(u32::MAX)).collect(),
            nudge: spike.params.accuracy / 16.0,
            full: false,
        };
        let root = tree.classify(map.min.x, map.min.y, side, (0, tree.near.len() as u32));
        tree.nodes.push(Node { cell: root, children: 0, parent: 0, near: (0, 0) });
        tree
    }

    /// How far `p` lies from obstacle `k`: the area's four edges first, then the map's
    /// shapes, then the moving ones.
    fn obstacle_distance(&self, k: u32, p: Point2) -> f64 {
        let map = &self.spike.map;
        let k = k as usize;
        match k {
            0 => p.x - map.min.x,
            1 => map.max.x - p.x,
            2 => p.y - map.min.y,
            3 => map.max.y - p.y,
            _ => match map.shapes.get(k - 4) {
                Some(shape) => shape.distance(p),
                None => self
                    .moving
                    .get(k - 4 - map.shapes.len())
                    .map_or(f64::INFINITY, |s| s.distance(p)),
            },
        }
    }

    /// The clearance a cell must keep: the robot's radius and safety, less in a door's region
    /// (the door's half width less two cells, but never less than the radius and a cell).
    fn required(&self, centre: Point2, half_diagonal: f64) -> f64 {
        let p = &self.spike.params;
        let full = p.robot_radius + p.safety;
        self.spike
            .map
            .doors
            .iter()
            .filter(|d| segment_distance(centre, d.a, d.b) + half_diagonal <= full)
            .map(|d| {
                let half = 0.5 * (d.b - d.a).norm() - 2.0 * p.accuracy;
                half.min(full).max(p.robot_radius + p.accuracy)
            })
            .fold(full, f64::min)
    }

    /// The cell of side `size` at `(x, y)`, classified against the obstacles `near` (a
    /// range of [`Tree::near`]; the others are too far to change its state).
    fn classify(&self, x: f64, y: f64, size: f64, (from, to): (u32, u32)) -> Cell {
        let centre = Point2::new(x + 0.5 * size, y + 0.5 * size);
        let h = size * FRAC_1_SQRT_2;
        let d = self.near[from as usize..to as usize]
            .iter()
            .fold(f64::INFINITY, |d, &k| d.min(self.obstacle_distance(k, centre)));
        let need = self.required(centre, h);
        let state = if d - h >= need {
            CellState::Free
        } else if d + h < need || size <= self.spike.params.accuracy {
            CellState::Blocked
        } else {
            CellState::Mixed
        };
        Cell { x, y, size, state }
    }

    /// Splits mixed node `at` in four: the obstacles that can matter to its children are
    /// those of its parent's within the clearance and twice its half diagonal of its centre
    /// (one farther keeps every point of every child free of it), and the children are
    /// classified against them. Returns the first child.
    fn split(&mut self, at: usize) -> Option<u32> {
        if self.nodes.len() + 4 > MAX_CELLS {
            self.full = true;
            return None;
        }
        let node = self.nodes[at];
        let c = node.cell;
        let (centre, h) =
            (Point2::new(c.x + 0.5 * c.size, c.y + 0.5 * c.size), c.size * FRAC_1_SQRT_2);
        let reach = self.spike.clearance() + 2.0 * h;
        // The root's parent list is every obstacle, the first entries of `near`.
        let all = 4 + self.spike.map.shapes.len() + self.moving.len();
        let (from, to) = if at == 0 {
            (0, u32::try_from(all).ok()?)
        } else {
            self.nodes[node.parent as usize].near
        };
        let start = u32::try_from(self.near.len()).ok()?;
        for i in from as usize..to as usize {
            let k = self.near[i];
            if self.obstacle_distance(k, centre) < reach {
                self.near.push(k);
            }
        }
        let near = (start, u32::try_from(self.near.len()).ok()?);
        let first = u32::try_from(self.nodes.len()).ok()?;
        let parent = u32::try_from(at).ok()?;
        let half = 0.5 * c.size;
        for (dx, dy) in [(0.0, 0.0), (half, 0.0), (0.0, half), (half, half)] {
            let cell = self.classify(c.x + dx, c.y + dy, half, near);
            self.nodes.push(Node { cell, children: 0, parent, near: (0, 0) });
        }
        self.nodes[at].children = first;
        self.nodes[at].near = near;
        Some(first)
    }

    /// The leaf holding `p`, splitting mixed cells on the way; `None` outside the root.
    fn leaf_at(&mut self, p: Point2) -> Option<u32> {
        self.leaf_near(0, p)
    }

    /// [`Tree::leaf_at`], looked for from node `from` up: up to the first ancestor that
    /// holds `p`, then down. A neighbour's leaf is usually a few levels away, the root a dozen.
    fn leaf_near(&mut self, from: u32, p: Point2) -> Option<u32> {
        let holds = |c: &Cell| p.x >= c.x && p.x < c.x + c.size && p.y >= c.y && p.y < c.y + c.size;
        let mut at = from as usize;
        while !holds(&self.nodes.get(at)?.cell) {
            if at == 0 {
                return None;
            }
            at = self.nodes[at].parent as usize;
        }
        loop {
            let node = self.nodes[at];
            if node.cell.state != CellState::Mixed {
                return u32::try_from(at).ok();
            }
            let half = 0.5 * node.cell.size;
            let first = if node.children == 0 { self.split(at)? } else { node.children };
            let right = usize::from(p.x >= node.cell.x + half);
            let up = usize::from(p.y >= node.cell.y + half);
            at = first as usize + right + 2 * up;
        }
    }

    /// The free leaves across each side of leaf `n`.
    fn neighbours(&mut self, n: u32, out: &mut Vec<u32>) {
        out.clear();
        let c = self.nodes[n as usize].cell;
        let (x1, y1) = (c.x + c.size, c.y + c.size);
        let e = self.nudge;
        // Along each side, from one end: the leaf just past it, then on from that leaf's end.
        for side in 0..4 {
            let mut t = if side < 2 { c.y } else { c.x };
            let end = t + c.size;
            while t < end - e {
                let probe = match side {
                    0 => Point2::new(x1 + e, t + e),
                    1 => Point2::new(c.x - e, t + e),
                    2 => Point2::new(t + e, y1 + e),
                    _ => Point2::new(t + e, c.y - e),
                };
                let Some(leaf) = self.leaf_near(n, probe) else {
                    break;
                };
                let cell = self.nodes[leaf as usize].cell;
                if cell.state == CellState::Free {
                    out.push(leaf);
                }
                t = if side < 2 { cell.y + cell.size } else { cell.x + cell.size };
            }
        }
    }

    /// `p` and its free leaf, or the nearest point round it (rings a cell apart, out to
    /// [`SNAP_REACH`] clearances) whose leaf is free.
    fn snap(&mut self, p: Point2) -> Option<(Point2, u32)> {
        let free = |tree: &mut Tree, q: Point2| {
            tree.leaf_at(q).filter(|&n| tree.nodes[n as usize].cell.state == CellState::Free)
        };
        if let Some(n) = free(self, p) {
            return Some((p, n));
        }
        // At most 64 rings, a cell apart when the cells allow.
        let reach = SNAP_REACH * self.spike.clearance();
        let step = self.spike.params.accuracy.max(reach / 64.0);
        let mut r = step;
        while r <= reach {
            let around = ((TAU * r / step).ceil() as usize).clamp(8, 4096);
            for k in 0..around {
                let a = TAU * k as f64 / around as f64;
                let q = Point2::new(p.x + r * a.cos(), p.y + r * a.sin());
                if let Some(n) = free(self, q) {
                    return Some((q, n));
                }
            }
            r += step;
        }
        None
    }

    /// A* from leaf `start` (at `from`) to leaf `goal` (at `to`): the leaves in order, and
    /// how many were expanded. A leaf is reached at a point of the side it is entered by: where
    /// the straight line from the previous point to the goal crosses that side, or the side's
    /// nearest end. Costs are the distances between these points, so a big cell costs what
    /// crossing it does, not the way to its centre and out.
    fn search(
        &mut self,
        (start, from): (u32, Point2),
        (goal, to): (u32, Point2),
    ) -> Result<(Vec<u32>, usize), PlanError> {
        let mut g: Vec<f64> = Vec::new();
        let mut parent: Vec<u32> = Vec::new();
        let mut entry: Vec<Point2> = Vec::new();
        let mut closed: Vec<bool> = Vec::new();
        let grow = |g: &mut Vec<f64>,
                    parent: &mut Vec<u32>,
                    entry: &mut Vec<Point2>,
                    closed: &mut Vec<bool>,
                    n: usize| {
            if g.len() < n {
                g.resize(n, f64::INFINITY);
                parent.resize(n, u32::MAX);
                entry.resize(n, Point2::origin());
                closed.resize(n, false);
            }
        };
        grow(&mut g, &mut parent, &mut entry, &mut closed, self.nodes.len());
        g[start as usize] = 0.0;
        entry[start as usize] = from;
        let mut open = BinaryHeap::new();
        open.push(Open { f: (from - to).norm(), node: start });
        let mut around = Vec::new();
        let mut expanded = 0;
        while let Some(Open { node, .. }) = open.pop() {
            if closed[node as usize] {
                continue;
            }
            closed[node as usize] = true;
            expanded += 1;
            if node == goal {
                let mut chain = vec![goal];
                while let Some(&last) = chain.last() {
                    let up = parent[last as usize];
                    if up == u32::MAX {
                        break;
                    }
                    chain.push(up);
                }
                chain.reverse();
                return Ok((chain, expanded));
            }
            self.neighbours(node, &mut around);
            if self.full {
                return Err(PlanError::TooManyCells { cells: MAX_CELLS });
            }
            grow(&mut g, &mut parent, &mut entry, &mut closed, self.nodes.len());
            let here = entry[node as usize];
            let cell = self.nodes[node as usize].cell;
            for &m in &around {
                if closed[m as usize] {
                    continue;
                }
                let (a, b) = shared_side(&cell, &self.nodes[m as usize].cell, self.nudge);
                let at = crossing(here, to, a, b);
                let cost = g[node as usize] + (at - here).norm();
                if cost < g[m as usize] {
                    g[m as usize] = cost;
                    parent[m as usize] = node;
                    entry[m as usize] = at;
                    open.push(Open { f: cost + GREED * (to - at).norm(), node: m });
                }
            }
        }
        Err(PlanError::NoPath { reason: "no free passage joins the start and the goal" })
    }

    /// The sides crossed from leaf to leaf along `chain`, between the start's and the goal's
    /// points.
    fn portals(&self, chain: &[u32], from: Point2, to: Point2) -> Vec<(Point2, Point2)> {
        let mut out = vec![(from, from)];
        for w in chain.windows(2) {
            let (a, b) = (self.nodes[w[0] as usize].cell, self.nodes[w[1] as usize].cell);
            out.push(shared_side(&a, &b, self.nudge));
        }
        out.push((to, to));
        out
    }

    /// Whether every point of the segment `a`–`b` lies in a free cell: the cells along it
    /// are walked from `a`, each entered a little past where the last one is left.
    fn visible(&mut self, a: Point2, b: Point2) -> bool {
        let d = b - a;
        let length = d.norm();
        if length <= self.nudge {
            return true;
        }
        let step = self.nudge / length;
        let mut t = 0.0;
        let mut leaf = 0;
        while t < 1.0 {
            let Some(next) = self.leaf_near(leaf, a + d * (t + step).min(1.0)) else {
                return false;
            };
            leaf = next;
            let c = self.nodes[leaf as usize].cell;
            if c.state != CellState::Free {
                return false;
            }
            // Where the segment leaves the cell's box (slab method, the farthest exit).
            let exit = |p: f64, v: f64, lo: f64, hi: f64| {
                if v > 0.0 {
                    (hi - p) / v
                } else if v < 0.0 {
                    (lo - p) / v
                } else {
                    f64::INFINITY
                }
            };
            let out = exit(a.x, d.x, c.x, c.x + c.size).min(exit(a.y, d.y, c.y, c.y + c.size));
            t = out.max(t + step);
        }
        true
    }

    /// `corners` pulled tight: from each kept corner, straight on to the farthest later one
    /// in sight ([`Tree::visible`]). The funnel's path is the shortest through the cells the
    /// search went by; this lets it leave them where other free cells allow.
    fn pull_tight(&mut self, corners: &[Point2]) -> Vec<Point2> {
        let Some(&first) = corners.first() else {
            return Vec::new();
        };
        let mut out = vec![first];
        let mut i = 0;
        while i + 1 < corners.len() {
            let j = (i + 2..corners.len())
                .rev()
                .find(|&j| self.visible(corners[i], corners[j]))
                .unwrap_or(i + 1);
            out.push(corners[j]);
            i = j;
        }
        out
    }

    /// The leaves made (every node without children).
    fn leaves(&self) -> Vec<Cell> {
        self.nodes.iter().filter(|n| n.children == 0).map(|n| n.cell).collect()
    }
}

/// The side that neighbouring cells `a` and `b` share, as its (left, right) ends seen going
/// from `a` into `b`; `e`: how far apart two coordinates may be and be the same.
fn shared_side(a: &Cell, b: &Cell, e: f64) -> (Point2, Point2) {
    let (ylo, yhi) = (a.y.max(b.y), (a.y + a.size).min(b.y + b.size));
    let (xlo, xhi) = (a.x.max(b.x), (a.x + a.size).min(b.x + b.size));
    if (a.x + a.size - b.x).abs() < e {
        (Point2::new(b.x, yhi), Point2::new(b.x, ylo)) // east
    } else if (b.x + b.size - a.x).abs() < e {
        (Point2::new(a.x, ylo), Point2::new(a.x, yhi)) // west
    } else if (a.y + a.size - b.y).abs() < e {
        (Point2::new(xlo, b.y), Point2::new(xhi, b.y)) // north
    } else {
        (Point2::new(xhi, a.y), Point2::new(xlo, a.y)) // south
    }
}

/// Where the way from `here` to `to` crosses the side `a`–`b` (axis-aligned): the crossing of
/// the straight line, or, when the line misses the side, the side's end nearest to it.
fn crossing(here: Point2, to: Point2, a: Point2, b: Point2) -> Point2 {
    let d = to - here;
    let side = b - a;
    let denom = d.x * side.y - d.y * side.x;
    let t = if denom.abs() > 1e-12 {
        // here + s·d = a + t·side.
        ((a.x - here.x) * d.y - (a.y - here.y) * d.x) / denom
    } else {
        // Parallel: the point of the side nearest `here`.
        (here - a).dot(&side) / side.norm_squared().max(1e-18)
    };
    a + side * t.clamp(0.0, 1.0)
}

/// The shortest path through a channel of portals (each `(left, right)` as seen going
/// forward, the first and last a single point): the funnel algorithm. The funnel from the
/// current apex is narrowed portal by portal; when one side would cross the other, that side's
/// point becomes a corner and the new apex.
fn funnel(portals: &[(Point2, Point2)]) -> Vec<Point2> {
    let Some(&(start, _)) = portals.first() else {
        return Vec::new();
    };
    let mut path = vec![start];
    let (mut apex, mut left, mut right) = (start, start, start);
    let (mut left_at, mut right_at) = (0, 0);
    let mut i = 1;
    // Every restart moves the apex at least one portal on; this bounds a degenerate case.
    let mut guard = portals.len() * portals.len() + 16;
    while i < portals.len() && guard > 0 {
        guard -= 1;
        let (l, r) = portals[i];
        // The right side: narrow it if `r` lies left of it (or on it).
        if cross(apex, right, r) >= 0.0 {
            if apex == right || cross(apex, left, r) < 0.0 {
                right = r;
                right_at = i;
            } else {
                // `r` crosses over the left side: the left point is a corner, the new apex.
                path.push(left);
                (apex, right, right_at) = (left, left, left_at);
                i = left_at + 1;
                continue;
            }
        }
        // The left side, the same way round.
        if cross(apex, left, l) <= 0.0 {
            if apex == left || cross(apex, right, l) > 0.0 {
                left = l;
                left_at = i;
            } else {
                path.push(right);
                (apex, left, left_at) = (right, right, right_at);
                i = right_at + 1;
                continue;
            }
        }
        i += 1;
    }
    if let Some(&(goal, _)) = portals.last() {
        path.push(goal);
    }
    path.dedup();
    path
}

/// Poses along `corners` at most `resolution` apart, each headed along its segment; the last
/// at the last corner, headed as the last segment.
fn trajectory(corners: &[Point2], resolution: f64) -> Vec<Pose2> {
    // At most MAX_POSES poses: a longer path gets them farther apart.
    let length: f64 = corners.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    let resolution = resolution.max(length / MAX_POSES as f64);
    let mut poses = Vec::new();
    for w in corners.windows(2) {
        let d = w[1] - w[0];
        let heading = d.y.atan2(d.x);
        let steps = ((d.norm() / resolution).ceil() as usize).clamp(1, 1_000_000);
        for k in 0..steps {
            let p = w[0] + d * (k as f64 / steps as f64);
            poses.push(Pose2::new(p.x, p.y, heading));
        }
    }
    if let Some(&end) = corners.last() {
        let heading = poses.last().map_or(0.0, |p| p.theta);
        poses.push(Pose2::new(end.x, end.y, heading));
    }
    poses
}
