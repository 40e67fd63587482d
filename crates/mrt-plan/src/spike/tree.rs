//! SPIKE's lazy quadtree, its search, and the path through the cells it found (module doc of
//! [`super`]).

use super::map::{cross, segment_distance, Shape};
use super::{Cell, CellState, PlanError, Spike, GREED, MAX_CELLS, SNAP_REACH};
use mrt_core::Point2;
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::f64::consts::{FRAC_1_SQRT_2, TAU};

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
pub(super) struct Tree<'a> {
    spike: &'a Spike,
    moving: &'a [&'a Shape],
    nodes: Vec<Node>,
    /// Lists of obstacles (see [`Tree::obstacle_distance`]) for the split nodes.
    near: Vec<u32>,
    /// Far less than the smallest cell: a point this far past a side lies in the neighbour.
    nudge: f64,
    /// Whether a split was refused at [`MAX_CELLS`].
    pub(super) full: bool,
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
    pub(super) fn new(spike: &'a Spike, moving: &'a [&'a Shape]) -> Tree<'a> {
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
    pub(super) fn snap(&mut self, p: Point2) -> Option<(Point2, u32)> {
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
    pub(super) fn search(
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
    pub(super) fn portals(&self, chain: &[u32], from: Point2, to: Point2) -> Vec<(Point2, Point2)> {
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
    pub(super) fn pull_tight(&mut self, corners: &[Point2]) -> Vec<Point2> {
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

    /// How many cells were made.
    pub(super) fn cells(&self) -> usize {
        self.nodes.len()
    }

    /// The leaves made (every node without children).
    pub(super) fn leaves(&self) -> Vec<Cell> {
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
pub(super) fn funnel(portals: &[(Point2, Point2)]) -> Vec<Point2> {
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
