//! GM, ThinkingCap's fuzzy grid self-localization (ThinkingCap/TeamChaos report §2.1: "Self-localization in the
//! GM is based on fuzzy logic (Buschka et al., 2000), (Herrero-Pérez et al., 2004)").
//!
//! The report names the method only; the method below is recalled from those papers, not
//! checked against their text, and the details marked *design* are this module's choices.
//!
//! - **State**: a 2½-D possibility grid. Each `(x, y)` cell of [`GmParams::cell`] metres holds a
//!   fuzzy set over the heading, sampled in [`GmParams::headings`] bins: how possible it is that
//!   the robot stands in the cell facing that way (1: fully, 0: not at all).
//! - **Predict** (odometry): every heading slice moves by the motion turned into the field frame
//!   by its own heading, and the headings by the turn; motion is accumulated per slice and
//!   applied in whole cells and bins (*design*: a cell is larger than a cycle's motion). Each
//!   cell travelled and each bin turned, the grid is *dilated*: a cell becomes at least
//!   [`GmParams::dilation`] times its neighbours' possibility, so that the support grows with
//!   the odometry's uncertainty.
//! - **Observe** (each perception, MUREA's sensor-agnostic [`Perception`]s of goals and posts):
//!   the possibility of a pose is the fuzzy AND (minimum) of a range trapezoid `μρ(|L − p|)`
//!   and a bearing trapezoid `μφ(atan2(L − p) − θ − φ)` of the landmark `L`; a post whose name
//!   is not known (several posts wear its colours) takes the best candidate (maximum). The
//!   trapezoids' cores are the cell's and the bin's own size, their slopes the perception's
//!   tolerances.
//! - **Fuse**: `G ← G · (b + (1 − b) μz)`: the product t-norm with a bias `b`
//!   ([`GmParams::bias`]), so that a false sighting lowers the true pose by `b` instead of
//!   erasing it. The grid is then scaled to height 1 and floored at [`GmParams::floor`] (every
//!   pose stays a little possible: a robot carried elsewhere is found again within a few
//!   frames). The height before scaling measures how consistent the frame was with the belief:
//!   when the best pose explains less than [`GmParams::consistency`] of a frame of two
//!   perceptions or more (geometric mean over them), the belief is reset to "anywhere" and the
//!   frame applied to it.
//! - **Estimate**: the `α`-cut ([`GmParams::alpha`]) of the cells near the best one gives the
//!   position (centre of gravity) and its spread; their heading sets the heading (circular
//!   mean). A second mode as high elsewhere makes the estimate [`GmEstimate::ambiguous`]: the
//!   half-turn twin of a symmetric field.
//!
//! A Markov grid filter in which fuzzy t-norms replace Bayes' rule: multi-modal for free, fixed
//! time and memory. Lengths in metres, angles in radians, the field frame.
//!
//! ```
//! use mrt_core::Pose2;
//! use mrt_world::field::FieldMap;
//! use mrt_world::gm::FuzzyGrid;
//! use mrt_world::murea::{Kind, Perception};
//!
//! let mut gm = FuzzyGrid::field(&FieldMap::default());
//! // From (2, 1) facing north: the east net 7.07 m at −98.1°, the north-east corner post
//! // 8.60 m at −54.5°, the half-way line's north post 5.39 m at 21.8° (MUREA's example).
//! gm.observe(&[
//!     Perception::point(Kind::EAST_GOAL, 7.071, -1.7127).tolerances(0.3, 0.05),
//!     Perception::point(Kind::EAST_POST, 8.602, -0.9505).tolerances(0.3, 0.05),
//!     Perception::point(Kind::EAST_POST, 5.385, 0.3805).tolerances(0.3, 0.05),
//! ]);
//! let e = gm.estimate();
//! assert!((e.pose.x - 2.0).abs() < 0.25 && (e.pose.y - 1.0).abs() < 0.25, "{e:?}");
//! assert!((e.pose.theta - std::f64::consts::FRAC_PI_2).abs() < 0.15);
//! assert!(!e.ambiguous);
//! ```

use crate::field::FieldMap;
use crate::murea::{Kind, Map, Perception};
use mrt_core::{normalize_angle, Point2, Pose2};
use std::f64::consts::{PI, TAU};

/// The grid's settings (*design* values, sized for the 18 m × 12 m field).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GmParams {
    /// Side of a position cell, m.
    pub cell: f64,
    /// Heading bins per turn.
    pub headings: usize,
    /// The fusion's bias `b` in `(0, 1)`: what a pose keeps of its possibility when a
    /// perception does not fit it.
    pub bias: f64,
    /// The least possibility a pose keeps after a frame, in `[0, 1)`.
    pub floor: f64,
    /// Dilation per cell travelled or bin turned, in `(0, 1)`: a pose becomes at least this
    /// times its neighbours' possibility.
    pub dilation: f64,
    /// The `α`-cut of the estimate, in `(0, 1]`.
    pub alpha: f64,
    /// Below this geometric mean of the best pose's fit per perception, the frame contradicts
    /// the belief: it is reset.
    pub consistency: f64,
    /// Margin of the grid beyond the field's lines, m (robots drive there).
    pub margin: f64,
}

impl Default for GmParams {
    fn default() -> Self {
        GmParams {
            cell: 0.25,
            headings: 32,
            bias: 0.1,
            floor: 0.02,
            dilation: 0.8,
            alpha: 0.7,
            consistency: 0.35,
            margin: 0.6,
        }
    }
}

/// The grid's belief summed up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GmEstimate {
    /// Centre of gravity of the best mode's `α`-cut, with its heading.
    pub pose: Pose2,
    /// Spread of the position in the `α`-cut (root mean square of x and y, with the cell's own
    /// size), m.
    pub sigma_xy: f64,
    /// Spread of the heading, rad.
    pub sigma_theta: f64,
    /// Another mode, more than 1.5 m away, is nearly as possible (at least 0.9 of the best).
    pub ambiguous: bool,
    /// The highest possibility more than 1.5 m from the best cell, relative to the best: how
    /// much the next other answer is worth, 0 to 1.
    pub second: f64,
}

/// What the grid did, counted since it started.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GmCounts {
    /// Perceptions fused.
    pub perceptions: u64,
    /// Frames that contradicted the belief (reset to "anywhere").
    pub resets: u64,
    /// Heading slices moved by whole cells.
    pub shifts: u64,
}

/// The fuzzy position grid (module doc).
#[derive(Clone, Debug)]
pub struct FuzzyGrid {
    params: GmParams,
    /// The lower-left corner of cell `(0, 0)`.
    origin: Point2,
    nx: usize,
    ny: usize,
    /// Possibility of cell `(ix, iy)` at heading bin `k`: `mu[(iy * nx + ix) * headings + k]`.
    mu: Vec<f32>,
    /// The fit of the current perception, same layout (zero outside `fit_perception`).
    fit: Vec<f32>,
    /// Per heading bin: motion not yet applied to its slice, field frame, m.
    pending: Vec<(f64, f64)>,
    /// Turn not yet applied, rad.
    turn: f64,
    /// Distance driven since the last dilation, m.
    driven: f64,
    /// The landmarks a perception may be of, by kind (goals and posts).
    points: Vec<(Kind, Point2)>,
    /// Per landmark, per cell: its distance (m) and direction (rad, field frame) from the
    /// cell's centre. The grid and the map do not move: computed once.
    sight: Vec<Vec<(f32, f32)>>,
    counts: GmCounts,
}

/// A trapezoid of height 1 on `[0, core]` falling to 0 at `core + slope` (`slope ≥ 0`).
#[inline]
fn trapezoid(d: f64, core: f64, slope: f64) -> f64 {
    if d <= core {
        1.0
    } else if slope <= 0.0 {
        0.0
    } else {
        (1.0 - (d - core) / slope).max(0.0)
    }
}

impl FuzzyGrid {
    /// A grid covering `map`'s points within `(min, max)`, believing the robot may be anywhere.
    pub fn new(map: &Map, (min, max): (Point2, Point2), params: GmParams) -> FuzzyGrid {
        let params = GmParams {
            cell: if params.cell.is_finite() && params.cell > 0.01 { params.cell } else { 0.2 },
            headings: params.headings.clamp(4, 360),
            ..params
        };
        let extent = |lo: f64, hi: f64| {
            let n = ((hi - lo) / params.cell).ceil();
            if n.is_finite() && n >= 1.0 {
                (n as usize).min(4000)
            } else {
                1
            }
        };
        let (nx, ny) = (extent(min.x, max.x), extent(min.y, max.y));
        let size = nx * ny * params.headings;
        let centre = |ix: usize, iy: usize| {
            Point2::new(
                min.x + (ix as f64 + 0.5) * params.cell,
                min.y + (iy as f64 + 0.5) * params.cell,
            )
        };
        let sight = map
            .points()
            .iter()
            .map(|(_, at)| {
                (0..nx * ny)
                    .map(|c| {
                        let to = at - centre(c % nx, c / nx);
                        (to.norm() as f32, to.y.atan2(to.x) as f32)
                    })
                    .collect()
            })
            .collect();
        FuzzyGrid {
            params,
            origin: min,
            nx,
            ny,
            mu: vec![1.0; size],
            fit: vec![0.0; size],
            pending: vec![(0.0, 0.0); params.headings],
            turn: 0.0,
            driven: 0.0,
            points: map.points().to_vec(),
            sight,
            counts: GmCounts::default(),
        }
    }

    /// The grid for `field` with the default parameters: goals and posts told apart by
    /// colour, the field and its margin covered.
    pub fn field(field: &FieldMap) -> FuzzyGrid {
        let params = GmParams::default();
        let (hx, hy) = (field.length / 2.0 + params.margin, field.width / 2.0 + params.margin);
        FuzzyGrid::new(
            &Map::field(field, true),
            (Point2::new(-hx, -hy), Point2::new(hx, hy)),
            params,
        )
    }

    /// The parameters in use.
    pub fn params(&self) -> GmParams {
        self.params
    }

    /// What the grid did so far.
    pub fn counts(&self) -> GmCounts {
        self.counts
    }

    /// Cells along x and y, and heading bins.
    pub fn shape(&self) -> (usize, usize, usize) {
        (self.nx, self.ny, self.params.headings)
    }

    fn bin_width(&self) -> f64 {
        TAU / self.params.headings as f64
    }

    /// The heading at the centre of bin `k`.
    fn heading(&self, k: usize) -> f64 {
        -PI + (k as f64 + 0.5) * self.bin_width()
    }

    /// The bin of heading `theta`.
    fn bin(&self, theta: f64) -> usize {
        let k = ((normalize_angle(theta) + PI) / self.bin_width()).floor();
        (k.max(0.0) as usize).min(self.params.headings - 1)
    }

    /// The centre of cell `(ix, iy)`.
    fn centre(&self, ix: usize, iy: usize) -> Point2 {
        let c = self.params.cell;
        Point2::new(self.origin.x + (ix as f64 + 0.5) * c, self.origin.y + (iy as f64 + 0.5) * c)
    }

    /// The possibility of `pose` (its cell and bin); 0 outside the grid.
    pub fn possibility(&self, pose: Pose2) -> f64 {
        let c = self.params.cell;
        let (fx, fy) = ((pose.x - self.origin.x) / c, (pose.y - self.origin.y) / c);
        if !(fx >= 0.0 && fy >= 0.0 && (fx as usize) < self.nx && (fy as usize) < self.ny) {
            return 0.0;
        }
        let i = ((fy as usize) * self.nx + fx as usize) * self.params.headings;
        f64::from(self.mu[i + self.bin(pose.theta)])
    }

    /// Believes the robot may be anywhere.
    pub fn forget(&mut self) {
        self.mu.fill(1.0);
    }

    /// Believes the robot is at `pose`, give or take a cell and a bin (put down by hand).
    pub fn place(&mut self, pose: Pose2) {
        let floor = self.params.floor as f32;
        let (cell, bin) = (self.params.cell, self.bin_width());
        let h = self.params.headings;
        for iy in 0..self.ny {
            for ix in 0..self.nx {
                let p = self.centre(ix, iy);
                let near = trapezoid((p - pose.position()).norm(), cell, cell);
                for k in 0..h {
                    let turn = normalize_angle(self.heading(k) - pose.theta).abs();
                    let v = near.min(trapezoid(turn, bin, bin)) as f32;
                    self.mu[(iy * self.nx + ix) * h + k] = v.max(floor);
                }
            }
        }
        self.pending.fill((0.0, 0.0));
        self.turn = 0.0;
        self.driven = 0.0;
    }

    /// Odometry: the robot moved by `d` in its own frame since the last call.
    pub fn predict(&mut self, d: Pose2) {
        if !(d.x.is_finite() && d.y.is_finite() && d.theta.is_finite()) {
            return;
        }
        let cell = self.params.cell;
        for k in 0..self.params.headings {
            let (s, c) = self.heading(k).sin_cos();
            let p = &mut self.pending[k];
            p.0 += c * d.x - s * d.y;
            p.1 += s * d.x + c * d.y;
            let (sx, sy) = ((p.0 / cell).round(), (p.1 / cell).round());
            if sx != 0.0 || sy != 0.0 {
                p.0 -= sx * cell;
                p.1 -= sy * cell;
                self.shift_slice(k, sx as isize, sy as isize);
            }
        }
        self.turn += d.theta;
        let bin = self.bin_width();
        while self.turn.abs() >= bin / 2.0 {
            let step = if self.turn > 0.0 { 1 } else { -1 };
            self.roll(step);
            self.turn -= f64::from(step) * bin;
            self.dilate_headings();
        }
        self.driven += d.x.hypot(d.y);
        while self.driven >= cell {
            self.driven -= cell;
            self.dilate_cells();
            self.dilate_headings();
        }
    }

    /// Moves heading slice `k` by `(sx, sy)` cells; cells coming in from outside get the floor.
    fn shift_slice(&mut self, k: usize, sx: isize, sy: isize) {
        self.counts.shifts += 1;
        let (nx, ny, h) = (self.nx as isize, self.ny as isize, self.params.headings);
        let floor = self.params.floor as f32;
        // Walk against the motion so that a value is read before it is overwritten.
        for jy in 0..ny {
            let iy = if sy > 0 { ny - 1 - jy } else { jy };
            for jx in 0..nx {
                let ix = if sx > 0 { nx - 1 - jx } else { jx };
                let (fx, fy) = (ix - sx, iy - sy);
                let v = if (0..nx).contains(&fx) && (0..ny).contains(&fy) {
                    self.mu[((fy * nx + fx) as usize) * h + k]
                } else {
                    floor
                };
                self.mu[((iy * nx + ix) as usize) * h + k] = v;
            }
        }
    }

    /// Turns every cell's heading set by one bin (`step` = ±1), with the slices' pending motion.
    fn roll(&mut self, step: i32) {
        let h = self.params.headings;
        for cell in self.mu.chunks_exact_mut(h) {
            if step > 0 {
                cell.rotate_right(1);
            } else {
                cell.rotate_left(1);
            }
        }
        if step > 0 {
            self.pending.rotate_right(1);
        } else {
            self.pending.rotate_left(1);
        }
    }

    /// Fuzzy dilation in position: each cell at least `dilation` × its 8 neighbours, per bin.
    /// The 3 × 3 maximum is taken separably, along x into `fit`, then along y back into `mu`,
    /// a whole heading set (contiguous) at a time.
    fn dilate_cells(&mut self) {
        let (nx, h) = (self.nx, self.params.headings);
        let keep = self.params.dilation as f32;
        let row = nx * h;
        for (src, dst) in self.mu.chunks_exact(row).zip(self.fit.chunks_exact_mut(row)) {
            for ix in 0..nx {
                let out = &mut dst[ix * h..(ix + 1) * h];
                out.copy_from_slice(&src[ix * h..(ix + 1) * h]);
                for n in [ix.wrapping_sub(1), ix + 1] {
                    if n < nx {
                        for (o, v) in out.iter_mut().zip(&src[n * h..(n + 1) * h]) {
                            *o = o.max(*v);
                        }
                    }
                }
            }
        }
        for iy in 0..self.ny {
            for n in [iy.wrapping_sub(1), iy, iy + 1] {
                if n >= self.ny {
                    continue;
                }
                let (near, mine) = (n * row, iy * row);
                for (m, f) in self.mu[mine..mine + row].iter_mut().zip(&self.fit[near..near + row])
                {
                    *m = m.max(keep * f);
                }
            }
        }
        self.fit.fill(0.0);
    }

    /// Fuzzy dilation in heading: each bin at least `dilation` × its two neighbours.
    fn dilate_headings(&mut self) {
        let h = self.params.headings;
        let keep = self.params.dilation as f32;
        let mut before = vec![0f32; h + 2];
        for cell in self.mu.chunks_exact_mut(h) {
            // `before` is the cell's set with its ends wrapped round: [last, 0, 1, ..., last, 0].
            before[1..=h].copy_from_slice(cell);
            before[0] = cell[h - 1];
            before[h + 1] = cell[0];
            for (k, m) in cell.iter_mut().enumerate() {
                let near = before[k].max(before[k + 2]);
                *m = m.max(keep * near);
            }
        }
    }

    /// Fills `fit` with how well each pose explains `p` (0 where no landmark of its kind fits),
    /// noting the poses it set in `touched`. Returns `false` when `p` says nothing the grid
    /// can use.
    fn fit_perception(&mut self, p: &Perception, touched: &mut Vec<usize>) -> bool {
        let Some(bearing) = p.bearing.filter(|b| b.is_finite()) else {
            return false;
        };
        let range = p.range.filter(|r| r.is_finite() && *r >= 0.0);
        let (cell, bin, h) = (self.params.cell, self.bin_width(), self.params.headings);
        let half_diagonal = cell * std::f64::consts::FRAC_1_SQRT_2;
        let range_slope =
            if p.range_tolerance.is_finite() { p.range_tolerance.max(0.0) } else { 0.0 };
        let bearing_slope =
            if p.bearing_tolerance.is_finite() { p.bearing_tolerance.clamp(0.0, PI) } else { 0.0 };
        let inv_bin = 1.0 / bin;
        let mut any = false;
        for (&(kind, landmark), sight) in self.points.iter().zip(&self.sight) {
            if kind != p.kind {
                continue;
            }
            any = true;
            // Only the cells of the annulus `range ± (half diagonal + slope)` can fit.
            let (inner, outer) = match range {
                Some(r) => {
                    let w = half_diagonal + range_slope;
                    ((r - w).max(0.0), r + w)
                }
                None => (0.0, f64::INFINITY),
            };
            let (lo_y, hi_y) = (landmark.y - outer, landmark.y + outer);
            for iy in 0..self.ny {
                let cy = self.origin.y + (iy as f64 + 0.5) * cell;
                if cy < lo_y || cy > hi_y {
                    continue;
                }
                let dy = landmark.y - cy;
                let reach_x = (outer * outer - dy * dy).max(0.0).sqrt();
                let first = ((landmark.x - reach_x - self.origin.x) / cell - 0.5).ceil().max(0.0);
                let last = ((landmark.x + reach_x - self.origin.x) / cell - 0.5).floor();
                if !(first.is_finite() && last.is_finite()) || last < first {
                    continue;
                }
                let (first, last) = (first as usize, (last as usize).min(self.nx - 1));
                for ix in first..=last {
                    let (d, direction) = sight[iy * self.nx + ix];
                    let d = f64::from(d);
                    if d < inner {
                        continue;
                    }
                    let mu_range = match range {
                        Some(r) => trapezoid((d - r).abs(), half_diagonal, range_slope),
                        None => 1.0,
                    };
                    if mu_range <= 0.0 {
                        continue;
                    }
                    // The heading the robot must have for the landmark to be at `bearing`,
                    // unsure by half a bin and by the cell's own size seen from the landmark.
                    let facing = normalize_angle(f64::from(direction) - bearing);
                    let core = bin / 2.0 + half_diagonal / d.max(cell);
                    let reach = ((core + bearing_slope) * inv_bin).ceil() as isize;
                    let centre = (((facing + PI) * inv_bin) as usize).min(h - 1);
                    // The offset of bin `centre + step` from `facing` is `first + step · bin`.
                    let first = self.heading(centre) - facing;
                    let base = (iy * self.nx + ix) * h;
                    for step in -reach..=reach {
                        let k = (centre as isize + step).rem_euclid(h as isize) as usize;
                        let off = (first + step as f64 * bin).abs();
                        let v = mu_range.min(trapezoid(off, core, bearing_slope)) as f32;
                        let f = &mut self.fit[base + k];
                        if v > *f {
                            if *f == 0.0 {
                                touched.push(base + k);
                            }
                            *f = v;
                        }
                    }
                }
            }
        }
        any
    }

    /// Fuses the current `fit` of the `touched` poses into the belief and clears it; returns
    /// the belief's new height. The belief is kept unscaled between [`FuzzyGrid::observe`]'s
    /// normalizations: a pose no landmark fits keeps its value (instead of losing `b`), one that
    /// fits gains `1 + (1 − b) f / b` (instead of `b + (1 − b) f`), the same ratios.
    fn fuse(&mut self, touched: &[usize], height: f32) -> f32 {
        let b = self.params.bias as f32;
        let gain = (1.0 - b) / b;
        let mut best = height;
        for &i in touched {
            let m = &mut self.mu[i];
            *m *= 1.0 + gain * self.fit[i];
            self.fit[i] = 0.0;
            if *m > best {
                best = *m;
            }
        }
        best
    }

    /// Scales the belief to height 1 (from `best`) and floors it.
    fn normalize(&mut self, best: f32) {
        let floor = self.params.floor as f32;
        let scale = if best > 0.0 && best.is_finite() { 1.0 / best } else { 0.0 };
        for m in &mut self.mu {
            *m = (*m * scale).max(floor);
        }
    }

    /// One frame's perceptions (goals and posts; other kinds and non-finite numbers are
    /// ignored). Returns whether the frame was consistent with the belief (`false`: reset).
    pub fn observe(&mut self, perceptions: &[Perception]) -> bool {
        let (used, best, log_scale) = self.fuse_all(perceptions);
        if used == 0 {
            return true;
        }
        // The best pose's fit per perception (geometric mean): 1 when it explains them all,
        // `b` when it explains none. (`best` is unscaled: its true height is `best · bⁿ`.)
        let b = self.params.bias;
        let fit = ((log_scale + f64::from(best).ln()) / used as f64 + b.ln()).exp();
        let consistent = fit >= self.params.consistency;
        // One perception alone may be a false sighting: it never resets the belief.
        if consistent || used < 2 {
            self.normalize(best);
            return true;
        }
        self.counts.resets += 1;
        self.forget();
        let (_, best, _) = self.fuse_all(perceptions);
        self.normalize(best);
        false
    }

    /// Fuses every usable perception; returns how many, the belief's unscaled height (it was
    /// 1 before) and the log of the scale already taken out of it (many perceptions would
    /// overflow an `f32` otherwise).
    fn fuse_all(&mut self, perceptions: &[Perception]) -> (usize, f32, f64) {
        let (mut used, mut best, mut log_scale) = (0, 1f32, 0.0);
        let mut touched = Vec::new();
        for p in perceptions {
            touched.clear();
            if self.fit_perception(p, &mut touched) {
                best = self.fuse(&touched, best);
                used += 1;
                self.counts.perceptions += 1;
            }
            if best > 1e12 {
                self.mu.iter_mut().for_each(|m| *m /= best);
                log_scale += f64::from(best).ln();
                best = 1.0;
            }
        }
        (used, best, log_scale)
    }

    /// The belief summed up (module doc).
    pub fn estimate(&self) -> GmEstimate {
        let h = self.params.headings;
        let cell_best: Vec<f32> =
            self.mu.chunks_exact(h).map(|c| c.iter().copied().fold(0f32, f32::max)).collect();
        let (top, height) =
            cell_best
                .iter()
                .enumerate()
                .fold((0, 0f32), |(bi, bv), (i, &v)| if v > bv { (i, v) } else { (bi, bv) });
        let at = |i: usize| self.centre(i % self.nx, i / self.nx);
        let top_at = at(top);
        let cut = height * self.params.alpha as f32;
        let (mut w, mut sx, mut sy, mut sxx, mut syy) = (0.0, 0.0, 0.0, 0.0, 0.0);
        let (mut hs, mut hc, mut hw) = (0.0, 0.0, 0.0);
        let mut second = 0f32;
        for (i, &m) in cell_best.iter().enumerate() {
            let p = at(i);
            let far = (p - top_at).norm();
            if far > 1.5 {
                second = second.max(m);
                continue;
            }
            if m < cut {
                continue;
            }
            if far > 0.75 {
                continue;
            }
            let m = f64::from(m);
            w += m;
            sx += m * p.x;
            sy += m * p.y;
            sxx += m * p.x * p.x;
            syy += m * p.y * p.y;
            for (k, &v) in self.mu[i * h..(i + 1) * h].iter().enumerate() {
                if v >= cut {
                    let (s, c) = self.heading(k).sin_cos();
                    hs += f64::from(v) * s;
                    hc += f64::from(v) * c;
                    hw += f64::from(v);
                }
            }
        }
        let cell = self.params.cell;
        let (x, y) = if w > 0.0 { (sx / w, sy / w) } else { (top_at.x, top_at.y) };
        let var = if w > 0.0 { (sxx / w - x * x + syy / w - y * y) / 2.0 } else { 0.0 };
        let sigma_xy = (var.max(0.0) + cell * cell / 12.0).sqrt();
        // The heading weights' mean resultant length R: σ = √(−2 ln R).
        let resultant = if hw > 0.0 { (hs.hypot(hc) / hw).min(1.0) } else { 0.0 };
        let bin = self.bin_width();
        let sigma_theta = ((-2.0 * resultant.max(1e-12).ln()).max(0.0) + bin * bin / 12.0).sqrt();
        GmEstimate {
            pose: Pose2::new(x, y, normalize_angle(hs.atan2(hc))),
            sigma_xy,
            sigma_theta,
            ambiguous: second >= 0.9 * height,
            second: if height > 0.0 { f64::from(second / height) } else { 0.0 },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_msgs::sighting::EAST_NET;
    use proptest::prelude::*;
    use std::f64::consts::FRAC_PI_2;

    /// Range and bearing of `at` from `pose`.
    fn seen_from(pose: Pose2, at: Point2) -> (f64, f64) {
        let to = at - pose.position();
        (to.norm(), normalize_angle(to.y.atan2(to.x) - pose.theta))
    }

    fn perceive(pose: Pose2, kind: Kind, at: Point2) -> Perception {
        let (r, b) = seen_from(pose, at);
        Perception::point(kind, r, b).tolerances(0.06 * r + 0.05, 0.05)
    }

    /// The colour-coded field's goals and posts as (kind, place).
    fn landmarks() -> Vec<(Kind, Point2)> {
        Map::field(&FieldMap::default(), true).points().to_vec()
    }

    /// What a robot at `pose` sees: every goal and post within `reach` m in front (±60°).
    fn frame(pose: Pose2, reach: f64) -> Vec<Perception> {
        landmarks()
            .into_iter()
            .filter(|(_, at)| {
                let (r, b) = seen_from(pose, *at);
                r < reach && b.abs() < 60f64.to_radians()
            })
            .map(|(kind, at)| perceive(pose, kind, at))
            .collect()
    }

    fn east_net() -> Point2 {
        FieldMap::default().object(EAST_NET).unwrap()
    }

    #[test]
    fn one_landmark_gives_a_ring_of_poses_each_facing_it_the_same_way() {
        let mut gm = FuzzyGrid::field(&FieldMap::default());
        // The east net 5 m away, 30° to the left.
        let (r, b) = (5.0, 30f64.to_radians());
        gm.observe(&[Perception::point(Kind::EAST_GOAL, r, b).tolerances(0.2, 0.05)]);
        let net = east_net();
        for k in 0..8 {
            // Standing 5 m from the net on a ring (west half), facing so that it is at 30°.
            let a = PI * 0.6 + f64::from(k) * 0.1 * PI;
            let at = net + nalgebra::Vector2::new(r * a.cos(), r * a.sin());
            let facing = normalize_angle(a + PI - b);
            let on = gm.possibility(Pose2::new(at.x, at.y, facing));
            assert!(on > 0.9, "on the ring at {a:.2} rad: {on}");
            let turned = gm.possibility(Pose2::new(at.x, at.y, facing + 0.5));
            assert!(turned <= 0.11, "the same place facing 29° away: {turned}");
        }
        let off = gm.possibility(Pose2::new(net.x - 7.0, net.y, 0.5));
        assert!(off <= 0.11, "2 m off the ring: {off}");
    }

    #[test]
    fn two_landmarks_give_one_pose_within_a_cell() {
        let truth = Pose2::new(-3.0, 2.0, -0.3);
        let mut gm = FuzzyGrid::field(&FieldMap::default());
        let net = east_net();
        // The post seen most across from the net (two landmarks in a line fix little).
        let across = |at: Point2| {
            let (_, a) = seen_from(truth, at);
            let (_, n) = seen_from(truth, net);
            normalize_angle(a - n).abs().min(PI - normalize_angle(a - n).abs())
        };
        let post = landmarks()
            .into_iter()
            .filter(|(k, _)| *k == Kind::EAST_POST || *k == Kind::WEST_POST)
            .max_by(|a, b| across(a.1).total_cmp(&across(b.1)))
            .unwrap();
        gm.observe(&[perceive(truth, Kind::EAST_GOAL, net), perceive(truth, post.0, post.1)]);
        let e = gm.estimate();
        assert!((e.pose.position() - truth.position()).norm() < gm.params().cell, "{e:?}");
        assert!(normalize_angle(e.pose.theta - truth.theta).abs() < 0.1, "{e:?}");
        assert!(!e.ambiguous && e.sigma_xy < 0.5, "{e:?}");
    }

    #[test]
    fn a_symmetric_pair_of_landmarks_leaves_two_modes() {
        // Two goals alike (no colours), a robot on the half-way line seeing both: facing north
        // at (0, −3) or facing south at (0, 3) sees the same.
        let field = FieldMap::default();
        let map = Map::field(&field, false);
        let mut gm = FuzzyGrid::new(
            &map,
            (Point2::new(-9.6, -6.6), Point2::new(9.6, 6.6)),
            GmParams::default(),
        );
        let truth = Pose2::new(0.0, -3.0, FRAC_PI_2);
        let goals: Vec<_> =
            map.points().iter().filter(|(k, _)| *k == Kind::GOAL).copied().collect();
        assert_eq!(goals.len(), 2);
        let seen: Vec<_> = goals.iter().map(|(k, at)| perceive(truth, *k, *at)).collect();
        gm.observe(&seen);
        let twin = Pose2::new(0.0, 3.0, -FRAC_PI_2);
        assert!(gm.possibility(truth) > 0.9 && gm.possibility(twin) > 0.9);
        assert!(gm.estimate().ambiguous);
    }

    #[test]
    fn dilation_grows_the_support_and_lowers_no_pose() {
        let mut gm = FuzzyGrid::field(&FieldMap::default());
        gm.place(Pose2::new(1.0, 1.0, 0.0));
        let support = |g: &FuzzyGrid| g.mu.iter().filter(|&&v| v > 0.5).count();
        let mut last = support(&gm);
        for _ in 0..10 {
            let before = gm.mu.clone();
            gm.dilate_cells();
            gm.dilate_headings();
            assert!(gm.mu.iter().zip(&before).all(|(a, b)| a >= b));
            let now = support(&gm);
            assert!(now >= last);
            last = now;
        }
        assert!(last > 9, "the 3 × 3 neighbourhood and more: {last}");
    }

    #[test]
    fn odometry_moves_the_belief_with_the_robot() {
        let mut gm = FuzzyGrid::field(&FieldMap::default());
        let start = Pose2::new(-2.0, 0.0, FRAC_PI_2);
        gm.place(start);
        // 2 m forward (north), then a quarter turn to the left, in 2 cm steps.
        for _ in 0..100 {
            gm.predict(Pose2::new(0.02, 0.0, 0.0));
        }
        for _ in 0..50 {
            gm.predict(Pose2::new(0.0, 0.0, FRAC_PI_2 / 50.0));
        }
        let e = gm.estimate();
        assert!((e.pose.position() - Point2::new(-2.0, 2.0)).norm() < 0.25, "{e:?}");
        assert!(normalize_angle(e.pose.theta - PI).abs() < 0.15, "{e:?}");
        assert!(e.sigma_xy > 0.1, "the odometry's uncertainty widened the belief: {e:?}");
    }

    #[test]
    fn a_false_sighting_does_not_empty_the_grid() {
        let truth = Pose2::new(2.0, -1.0, 0.2);
        let mut gm = FuzzyGrid::field(&FieldMap::default());
        for _ in 0..3 {
            gm.observe(&frame(truth, 12.0));
        }
        // The east net reported 20 m away behind the robot: no pose explains it.
        let consistent = gm.observe(&[Perception::point(Kind::EAST_GOAL, 20.0, PI)]);
        assert!(consistent, "one perception at b = 0.1 is what the bias is for");
        assert!(gm.mu.iter().all(|v| v.is_finite() && *v >= 0.0 && *v <= 1.0));
        let e = gm.estimate();
        assert!((e.pose.position() - truth.position()).norm() < 0.3, "{e:?}");
    }

    #[test]
    fn a_carried_robot_is_found_again_within_a_few_frames() {
        let mut gm = FuzzyGrid::field(&FieldMap::default());
        let here = Pose2::new(3.0, 2.0, 0.0);
        for _ in 0..3 {
            gm.observe(&frame(here, 12.0));
        }
        assert!((gm.estimate().pose.position() - here.position()).norm() < 0.3);
        // Carried to the west half, facing east, without a word.
        let there = Pose2::new(-4.0, -2.0, 0.1);
        let mut found = None;
        for n in 1..=6 {
            gm.observe(&frame(there, 12.0));
            let e = gm.estimate();
            if (e.pose.position() - there.position()).norm() < 0.3 {
                found = Some(n);
                break;
            }
        }
        assert!(found.is_some_and(|n| n <= 4), "frames to find it again: {found:?}");
    }

    #[test]
    fn the_same_inputs_give_the_same_belief() {
        let run = || {
            let mut gm = FuzzyGrid::field(&FieldMap::default());
            let mut pose = Pose2::new(-1.0, 0.5, 0.3);
            for _ in 0..20 {
                gm.predict(Pose2::new(0.05, 0.0, 0.02));
                pose = pose.compose(&Pose2::new(0.05, 0.0, 0.02));
                gm.observe(&frame(pose, 10.0));
            }
            (gm.estimate(), gm.mu)
        };
        assert_eq!(run(), run());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// Any perceptions, garbage included, keep the belief a possibility distribution of
        /// height 1.
        #[test]
        fn any_perceptions_keep_the_grid_normal(
            seen in prop::collection::vec(
                (0u16..8, prop::num::f64::ANY, prop::num::f64::ANY, 0.0..2.0f64, 0.0..1.0f64),
                0..4,
            ),
            motion in (-0.5..0.5f64, -0.5..0.5f64, -1.0..1.0f64),
        ) {
            let mut gm = FuzzyGrid::field(&FieldMap::default());
            let seen: Vec<Perception> = seen
                .into_iter()
                .map(|(k, r, b, rt, bt)| Perception::point(Kind(k), r, b).tolerances(rt, bt))
                .collect();
            gm.observe(&seen);
            gm.predict(Pose2::new(motion.0, motion.1, motion.2));
            gm.observe(&seen);
            prop_assert!(gm.mu.iter().all(|v| v.is_finite() && *v >= 0.0 && *v <= 1.0));
            let top = gm.mu.iter().copied().fold(0f32, f32::max);
            prop_assert!(top > 0.99);
            let e = gm.estimate();
            prop_assert!(e.pose.x.is_finite() && e.pose.y.is_finite() && e.sigma_xy.is_finite());
        }
    }
}
