//! SPIKE, *Spike Plans In Known Environments* (MRT manual ch. 9): a fast trajectory planner on
//! a geometric map of fixed objects, over a multi-resolution grid.
//!
//! The manual gives what SPIKE takes and gives: a description of the environment, a start
//! and a goal in, a trajectory (a sequence of poses) out, with the robot's size, the required
//! accuracy, a safety distance and the plan's resolution as options; doors and passages small
//! with respect to the grid are handled, and moving objects when the robot detects them. How
//! it does it is not written down; what follows is a reconstruction, its details design
//! choices, on the classical multi-resolution cell decomposition (Kambhampati and Davis,
//! 1986):
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

pub mod draw;
mod map;
mod tree;

pub use map::{Door, PlanMap, Shape, MAX_COORD, MAX_DOORS, MAX_MAP_BYTES};

use crate::error::{positive, PlanError};
use mrt_core::{Point2, Pose2};
use tree::{funnel, Tree};

/// The most poses in a trajectory ([`Plan::poses`]): a path longer than this many times the
/// resolution gets its poses farther apart.
pub const MAX_POSES: usize = 100_000;

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
            moving
                .iter()
                .filter_map(Shape::bounded)
                .any(|s| s.segment_distance(w[0], w[1]) < clearance)
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
        let moving: Vec<Shape> = moving.iter().filter_map(Shape::bounded).collect();
        let moving: Vec<&Shape> = moving.iter().collect();
        let mut tree = Tree::new(self, &moving);
        let start = tree.snap(from);
        let goal = tree.snap(to);
        if tree.full {
            return Err(PlanError::TooManyCells { cells: MAX_CELLS });
        }
        let (min, max) = (self.map.min, self.map.max);
        let inside = |p: Point2| (min.x..=max.x).contains(&p.x) && (min.y..=max.y).contains(&p.y);
        let why = |p: Point2, shut: &'static str, outside: &'static str| PlanError::NoPath {
            reason: if inside(p) { shut } else { outside },
        };
        let start = start
            .ok_or_else(|| why(from, "the start is shut in", "the start is outside the map"))?;
        let goal =
            goal.ok_or_else(|| why(to, "the goal is shut in", "the goal is outside the map"))?;
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
            cells: tree.cells(),
            expanded,
        };
        Ok((plan, tree.leaves()))
    }
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
