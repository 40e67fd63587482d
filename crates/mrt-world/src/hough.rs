//! ISocRob's self-localization from the field lines (ISocRob-2000 report §3.2.1, the vision
//! µAgent's "self" mode, whose steps the report names without their details): the white
//! points a camera found on the floor (robot frame) vote in a **Hough** transform for
//! straight lines, `ρ = x·cos φ + y·sin φ`; the strongest lines are matched
//! **combinatorially** to the field model, whose lines all run along the field's axes: a
//! detected line's direction gives the heading up to a quarter turn, and its distance, put
//! against each model line of its family, one coordinate of the robot. Every combination is
//! scored by how many of the points fall on the field's lines (the centre circle included)
//! from that pose.
//!
//! The field is symmetric under a half turn about the centre spot: a pose and its twin
//! (`(−x, −y, θ + π)`) explain the same lines, and both are returned with the same score.
//! The goal colour breaks the tie ([`HoughPose::facing`]: which goal the robot sees where),
//! or the pose the robot believed ([`nearest`]).
//!
//! Design choices, where the report is silent: 1° × 5 cm cells; after a line is taken,
//! its points leave the vote, so a second line is not the first one's neighbour cell; a line
//! needs [`HoughParams::min_votes`] points; a point is on a line within
//! [`HoughParams::tolerance`].
//!
//! ```
//! use mrt_core::{Point2, Pose2};
//! use mrt_world::field::FieldMap;
//! use mrt_world::hough::{hough_lines, self_localize, HoughParams};
//!
//! // A robot at (-6, 1.5) facing west-north-west sees the west goal line, the
//! // front of the west penalty area and its north side: points every 10 cm within 4 m, in
//! // its own frame.
//! let (truth, map) = (Pose2::new(-6.0, 1.5, 2.6), FieldMap::default());
//! let mut seen = Vec::new();
//! for seg in map.lines() {
//!     let n = (seg.length() / 0.1) as usize;
//!     for k in 0..=n {
//!         let field = seg.a + (seg.b - seg.a) * (k as f64 / n as f64);
//!         let (dx, dy) = (field.x - truth.x, field.y - truth.y);
//!         let (sin, cos) = truth.theta.sin_cos();
//!         if dx.hypot(dy) <= 4.0 {
//!             seen.push(Point2::new(cos * dx + sin * dy, -sin * dx + cos * dy));
//!         }
//!     }
//! }
//! let params = HoughParams::default();
//! let lines = hough_lines(&seen, &params);
//! assert!(lines.len() >= 3, "{lines:?}");
//! let poses = self_localize(&map, &seen, &lines, &params);
//! // The truth and its half-turn twin explain every point.
//! let best = poses[0].pose;
//! let twin = Pose2::new(-best.x, -best.y, best.theta + std::f64::consts::PI);
//! assert!(poses.iter().take(2).any(|p| (p.pose.x - truth.x).hypot(p.pose.y - truth.y) < 0.05));
//! assert!(poses.iter().take(2).any(|p| (p.pose.x - twin.x).hypot(p.pose.y - twin.y) < 0.05));
//! ```

use crate::field::{FieldMap, Segment};
use crate::murea::{Kind, Perception};
use mrt_core::{normalize_angle, Point2, Pose2};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// The Hough transform's and the matching's settings (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoughParams {
    /// Angle of a cell, rad.
    pub angle_step: f64,
    /// Distance of a cell, m.
    pub rho_step: f64,
    /// Points a line needs.
    pub min_votes: usize,
    /// Lines taken at most.
    pub max_lines: usize,
    /// How far a point may lie from a line (detected or of the field) and be on it, m.
    pub tolerance: f64,
}

impl Default for HoughParams {
    fn default() -> Self {
        HoughParams {
            angle_step: 1f64.to_radians(),
            rho_step: 0.05,
            min_votes: 6,
            max_lines: 6,
            tolerance: 0.08,
        }
    }
}

/// A straight line of points: `x·cos φ + y·sin φ = ρ` (robot frame), `φ` in `[0, π)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoughLine {
    /// The direction of its normal, rad.
    pub phi: f64,
    /// Its signed distance from the robot along the normal, m.
    pub rho: f64,
    /// The points on it.
    pub votes: usize,
    /// Where its points lie along it, from and to, m from the foot of the perpendicular from
    /// the robot, in the direction `φ + π/2`.
    pub extent: (f64, f64),
}

impl HoughLine {
    /// The line as a MUREA perception ([`Perception::line`], kind [`Kind::LINE`]): its normal
    /// turned to point from the robot to the line, with the tolerances of the Hough cell it
    /// was found in: `params.tolerance` (at least a cell) across, two cells' angle.
    pub fn perception(&self, params: &HoughParams) -> Perception {
        let (range, bearing, extent) = if self.rho >= 0.0 {
            (self.rho, self.phi, self.extent)
        } else {
            // The normal turned a half turn: the line's direction turns too.
            (-self.rho, self.phi - PI, (-self.extent.1, -self.extent.0))
        };
        Perception::line(Kind::LINE, range, normalize_angle(bearing), extent)
            .tolerances(params.tolerance.max(params.rho_step), (2.0 * params.angle_step).max(1e-3))
    }
}

/// The line through `points` that fits them best (least squares across it: the normal is the
/// direction of their least spread), as `(φ, ρ)` with `φ` in `[0, π)`, the way round nearest
/// the Hough cell's `cell_phi`: the cell's 1° steps alone leave up to half a degree of error.
fn fit(points: &[Point2], cell_phi: f64) -> (f64, f64) {
    let n = points.len().max(1) as f64;
    let mean = points.iter().fold(Point2::origin(), |m, p| m + p.coords / n);
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in points {
        let d = p - mean;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    // The spread's major axis is at ½·atan2(2sxy, sxx − syy); the normal is a quarter turn on.
    let mut phi = 0.5 * (2.0 * sxy).atan2(sxx - syy) + FRAC_PI_2;
    if !phi.is_finite() || sxx + syy <= 0.0 {
        phi = cell_phi;
    }
    phi += ((cell_phi - phi) / PI).round() * PI;
    let rho = mean.x * phi.cos() + mean.y * phi.sin();
    if phi < 0.0 {
        (phi + PI, -rho)
    } else if phi >= PI {
        (phi - PI, -rho)
    } else {
        (phi, rho)
    }
}

/// Two points of one piece of line lie at most this far apart along it, m: a stray point
/// that happens to lie on the line's extension does not stretch the piece.
const PIECE_GAP: f64 = 0.5;

/// The line of the points on a Hough cell's line (`cell_phi`): the longest run of them along
/// it without a gap wider than [`PIECE_GAP`], fitted by least squares, and the run's extent.
fn piece(points: &[Point2], cell_phi: f64) -> (f64, f64, (f64, f64)) {
    let (s, c) = cell_phi.sin_cos();
    let mut along: Vec<(f64, Point2)> = points.iter().map(|p| (p.y * c - p.x * s, *p)).collect();
    along.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best = (0, 0);
    let mut start = 0;
    for k in 1..=along.len() {
        if k == along.len() || along[k].0 - along[k - 1].0 > PIECE_GAP {
            if k - start > best.1 - best.0 {
                best = (start, k);
            }
            start = k;
        }
    }
    let run: Vec<Point2> = along[best.0..best.1].iter().map(|a| a.1).collect();
    let (phi, rho) = fit(&run, cell_phi);
    let (s, c) = phi.sin_cos();
    let extent = run
        .iter()
        .map(|p| p.y * c - p.x * s)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| (lo.min(t), hi.max(t)));
    (phi, rho, extent)
}

/// The strongest lines through `points` (robot frame, m), strongest first: the Hough cell
/// with the most votes, refined to its points' mean distance; its points then leave the vote
/// and the next line is sought, until a line would have fewer than `min_votes` points.
pub fn hough_lines(points: &[Point2], params: &HoughParams) -> Vec<HoughLine> {
    let finite: Vec<Point2> =
        points.iter().copied().filter(|p| p.x.is_finite() && p.y.is_finite()).collect();
    if finite.is_empty()
        || !(params.angle_step > 0.0 && params.rho_step > 0.0 && params.tolerance > 0.0)
    {
        return Vec::new();
    }
    let reach = finite.iter().map(|p| p.coords.norm()).fold(0.0, f64::max) + params.rho_step;
    let angles = ((PI / params.angle_step).ceil() as usize).clamp(1, 3600);
    let rhos = ((2.0 * reach / params.rho_step).ceil() as usize + 1).min(100_000);
    let trig: Vec<(f64, f64)> =
        (0..angles).map(|k| (k as f64 * PI / angles as f64).sin_cos()).collect();
    let mut left = finite;
    let mut lines = Vec::new();
    let mut votes = vec![0u32; angles * rhos];
    while lines.len() < params.max_lines && left.len() >= params.min_votes {
        votes.iter_mut().for_each(|v| *v = 0);
        for p in &left {
            for (k, (s, c)) in trig.iter().enumerate() {
                let rho = p.x * c + p.y * s;
                let bin = ((rho + reach) / params.rho_step).round() as usize;
                if let Some(v) = votes.get_mut(k * rhos + bin.min(rhos - 1)) {
                    *v += 1;
                }
            }
        }
        let Some((best, _)) = votes.iter().enumerate().max_by_key(|(i, v)| (**v, usize::MAX - i))
        else {
            break;
        };
        let (k, bin) = (best / rhos, best % rhos);
        let (s, c) = trig[k];
        let rho0 = bin as f64 * params.rho_step - reach;
        let on = |p: &Point2| (p.x * c + p.y * s - rho0).abs() <= params.tolerance;
        let inliers: Vec<Point2> = left.iter().copied().filter(on).collect();
        if inliers.len() < params.min_votes {
            break;
        }
        let (phi, rho, extent) = piece(&inliers, k as f64 * PI / angles as f64);
        lines.push(HoughLine { phi, rho, votes: inliers.len(), extent });
        left.retain(|p| !on(p));
    }
    lines
}

/// A pose found by [`self_localize`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoughPose {
    /// The robot's pose, field frame.
    pub pose: Pose2,
    /// How many of the points lie on a field line from there.
    pub explained: usize,
}

impl HoughPose {
    /// How well the pose agrees with seeing the east (yellow) goal's centre at `bearing`
    /// (robot frame, rad): the cosine of the angle between where it is seen and where that
    /// pose would see it, 1 at best. Of a pose and its half-turn twin, the one facing the
    /// goal seen is the right one (ISocRob-2000 report §3.2.1: goal colour breaks the symmetry).
    pub fn facing(&self, map: &FieldMap, bearing: f64) -> f64 {
        let p = self.pose;
        let expected = (0.0 - p.y).atan2(map.half_length() - p.x) - p.theta;
        (expected - bearing).cos()
    }
}

/// The candidate nearest to `belief` (field frame): of twins that explain the lines equally
/// well, the one the robot's own estimate points at.
pub fn nearest(poses: &[HoughPose], belief: Pose2) -> Option<HoughPose> {
    let best = poses.first()?.explained;
    let heading = |a: f64, b: f64| (a - b + PI).rem_euclid(TAU) - PI;
    poses.iter().filter(|p| p.explained == best).copied().min_by(|a, b| {
        let d = |p: &HoughPose| {
            (p.pose.x - belief.x).hypot(p.pose.y - belief.y)
                + heading(p.pose.theta, belief.theta).abs()
        };
        d(a).total_cmp(&d(b))
    })
}

/// The poses (field frame) from which the `lines` found in `points` (robot frame) are the
/// field's lines, best first (module doc); a pose and its half-turn twin come with the same
/// score. Empty when the lines do not fix both coordinates: lines of both directions are
/// needed (one direction fixes one coordinate and the heading).
pub fn self_localize(
    map: &FieldMap,
    points: &[Point2],
    lines: &[HoughLine],
    params: &HoughParams,
) -> Vec<HoughPose> {
    let Some(first) = lines.first() else { return Vec::new() };
    let (hl, hw) = (map.half_length(), map.half_width());
    let front = hl - map.penalty_area_depth;
    let pw = map.penalty_area_width / 2.0;
    // Model lines: x = c (the goal lines, the penalty areas' fronts, the half-way line) and
    // y = c (the side lines, the penalty areas' sides).
    let across = [-hl, -front, 0.0, front, hl];
    let along = [-hw, -pw, pw, hw];
    let segments = map.lines();
    let ring = map.centre_circle_radius;
    let mut found: Vec<HoughPose> = Vec::new();
    for quarter in 0..4 {
        // The strongest line is one of the field's: its normal, turned into the field, lies
        // along an axis. The other lines that agree (modulo a quarter turn) refine it.
        let theta = quarter as f64 * FRAC_PI_2 - first.phi;
        let mut xs = Vec::new();
        let mut ys = Vec::new();
        for l in lines {
            let normal = l.phi + theta;
            let off = (normal / FRAC_PI_2).round();
            if (normal - off * FRAC_PI_2).abs() > 3.0 * params.angle_step {
                continue;
            }
            // The line's field normal is s·x̂ (off even) or s·ŷ (off odd): points p on it
            // have s·p = ρ + s·t, so a model line at c puts the robot at t = c − s·ρ.
            let s = if (off as i64).rem_euclid(4) < 2 { 1.0 } else { -1.0 };
            if (off as i64).rem_euclid(2) == 0 {
                xs.extend(across.iter().map(|c| c - s * l.rho));
            } else {
                ys.extend(along.iter().map(|c| c - s * l.rho));
            }
        }
        for &x in &xs {
            for &y in &ys {
                let pose = Pose2::new(x, y, theta.rem_euclid(TAU));
                let explained = explained(points, pose, &segments, ring, params.tolerance);
                found.push(HoughPose { pose, explained });
            }
        }
    }
    found.sort_by(|a, b| {
        b.explained
            .cmp(&a.explained)
            .then(a.pose.x.total_cmp(&b.pose.x))
            .then(a.pose.y.total_cmp(&b.pose.y))
    });
    // One of each place: candidates within the tolerance of a better one are the same.
    let mut unique: Vec<HoughPose> = Vec::new();
    for p in found {
        let same = |q: &HoughPose| {
            (q.pose.x - p.pose.x).hypot(q.pose.y - p.pose.y) < 2.0 * params.tolerance
                && ((q.pose.theta - p.pose.theta + PI).rem_euclid(TAU) - PI).abs() < 0.1
        };
        if p.explained > 0 && !unique.iter().any(same) {
            unique.push(p);
        }
    }
    unique
}

/// How many of `points` (robot frame) lie within `tolerance` of a field line or the centre
/// circle when the robot stands at `pose`.
fn explained(
    points: &[Point2],
    pose: Pose2,
    segments: &[Segment],
    ring: f64,
    tolerance: f64,
) -> usize {
    let (s, c) = pose.theta.sin_cos();
    points
        .iter()
        .filter(|q| {
            let p = Point2::new(pose.x + c * q.x - s * q.y, pose.y + s * q.x + c * q.y);
            (ring > 0.0 && (p.coords.norm() - ring).abs() <= tolerance)
                || segments.iter().any(|seg| seg.distance(p) <= tolerance)
        })
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The field's line points within `reach` of `pose`, every 10 cm, in the robot frame,
    /// with Gaussian-ish noise of `noise` m, and `outliers` random points besides.
    fn seen(pose: Pose2, reach: f64, noise: f64, outliers: usize, seed: u64) -> Vec<Point2> {
        let map = FieldMap::default();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut field = Vec::new();
        for seg in map.lines() {
            let n = (seg.length() / 0.1).ceil() as usize;
            for k in 0..=n {
                field.push(seg.a + (seg.b - seg.a) * (k as f64 / n as f64));
            }
        }
        for k in 0..126 {
            let a = TAU * k as f64 / 126.0;
            field.push(Point2::new(2.0 * a.cos(), 2.0 * a.sin()));
        }
        let (s, c) = pose.theta.sin_cos();
        let mut out: Vec<Point2> = field
            .into_iter()
            .filter(|p| (p.x - pose.x).hypot(p.y - pose.y) <= reach)
            .map(|p| {
                let (dx, dy) = (p.x - pose.x, p.y - pose.y);
                let jitter = |rng: &mut rand_chacha::ChaCha8Rng| {
                    (rng.random::<f64>() + rng.random::<f64>() + rng.random::<f64>() - 1.5)
                        * noise
                        * 2.0
                };
                Point2::new(c * dx + s * dy + jitter(&mut rng), -s * dx + c * dy + jitter(&mut rng))
            })
            .collect();
        for _ in 0..outliers {
            out.push(Point2::new(rng.random_range(-reach..reach), rng.random_range(-reach..reach)));
        }
        out
    }

    fn close(a: Pose2, b: Pose2) -> bool {
        (a.x - b.x).hypot(a.y - b.y) < 0.1
            && ((a.theta - b.theta + PI).rem_euclid(TAU) - PI).abs() < 0.03
    }

    fn twin(p: Pose2) -> Pose2 {
        Pose2::new(-p.x, -p.y, (p.theta + PI).rem_euclid(TAU))
    }

    /// Field-line points from known poses, with noise and 30 % outliers, give the pose up to
    /// the half-turn symmetry (the truth and its twin, both best), and the goal seen (or the
    /// pose believed) picks the truth.
    #[test]
    fn the_pose_is_found_up_to_the_symmetry_and_the_goal_picks_it() {
        let map = FieldMap::default();
        let params = HoughParams::default();
        let truths = [
            Pose2::new(-5.0, 2.0, 0.5),
            Pose2::new(6.5, -4.0, 2.0),
            Pose2::new(-7.5, -5.0, -1.2),
            Pose2::new(3.0, 5.0, 3.0),
        ];
        for (i, truth) in truths.into_iter().enumerate() {
            let mut points = seen(truth, 4.0, 0.02, 0, i as u64);
            let real = points.len();
            points.extend(
                seen(truth, 4.0, 0.0, real * 3 / 10, 100 + i as u64).into_iter().skip(real),
            );
            let lines = hough_lines(&points, &params);
            assert!(lines.len() >= 2, "{truth:?}: {lines:?}");
            let poses = self_localize(&map, &points, &lines, &params);
            assert!(poses.len() >= 2, "{truth:?}");
            let (a, b) = (poses[0], poses[1]);
            assert_eq!(a.explained, b.explained, "twins explain the same points");
            assert!(
                (close(a.pose, truth) && close(b.pose, twin(truth)))
                    || (close(b.pose, truth) && close(a.pose, twin(truth))),
                "{truth:?}: {a:?} {b:?}"
            );
            assert!(a.explained * 10 >= real * 8, "{truth:?}: {} of {real}", a.explained);
            // The east goal's centre, where the truth sees it.
            let bearing = (0.0 - truth.y).atan2(9.0 - truth.x) - truth.theta;
            let picked = if a.facing(&map, bearing) > b.facing(&map, bearing) { a } else { b };
            assert!(close(picked.pose, truth), "{truth:?}: {picked:?}");
            let believed = Pose2::new(truth.x + 0.5, truth.y - 0.3, truth.theta + 0.2);
            assert!(close(nearest(&poses, believed).unwrap().pose, truth), "{truth:?}");
        }
    }

    #[test]
    fn one_direction_of_lines_or_none_fixes_no_pose() {
        let map = FieldMap::default();
        let params = HoughParams::default();
        assert!(hough_lines(&[], &params).is_empty());
        assert!(self_localize(&map, &[], &[], &params).is_empty());
        // Only the north side line: the heading, one coordinate, not the other.
        let points: Vec<Point2> =
            (0..30).map(|k| Point2::new(-1.5 + 0.1 * k as f64, 2.0)).collect();
        let lines = hough_lines(&points, &params);
        assert_eq!(lines.len(), 1);
        assert!(self_localize(&map, &points, &lines, &params).is_empty());
        // Non-finite points are left out, not a panic.
        let odd = [Point2::new(f64::NAN, 1.0), Point2::new(f64::INFINITY, 0.0)];
        assert!(hough_lines(&odd, &params).is_empty());
    }

    #[test]
    fn the_same_points_give_the_same_poses() {
        let map = FieldMap::default();
        let params = HoughParams::default();
        let points = seen(Pose2::new(1.0, -3.0, 0.7), 4.0, 0.02, 10, 9);
        let run = || {
            let lines = hough_lines(&points, &params);
            self_localize(&map, &points, &lines, &params)
        };
        assert_eq!(run(), run());
    }

    /// The Hough lines as MUREA's percept source. From the same noisy points
    /// with 30 % outliers, the lines (a handful of perceptions instead of a hundred points)
    /// put MUREA on the truth or its half-turn twin, both explaining every line; one goal
    /// sighting settles it. The lines' own numbers: each lies where a field line does.
    #[test]
    fn hough_lines_are_murea_perceptions_and_a_goal_breaks_their_symmetry() {
        use crate::murea::{Map, Murea};
        let field = FieldMap::default();
        let params = HoughParams::default();
        let murea = Murea::new(Map::field(&field, true));
        let truths =
            [Pose2::new(-5.0, 2.0, 0.5), Pose2::new(6.5, -4.0, 2.0), Pose2::new(-7.5, -5.0, -1.2)];
        for (i, truth) in truths.into_iter().enumerate() {
            let mut points = seen(truth, 4.0, 0.02, 0, i as u64);
            let real = points.len();
            points.extend(
                seen(truth, 4.0, 0.0, real * 3 / 10, 100 + i as u64).into_iter().skip(real),
            );
            let lines: Vec<Perception> =
                hough_lines(&points, &params).iter().map(|l| l.perception(&params)).collect();
            assert!(lines.len() >= 2, "{truth:?}: {lines:?}");
            // Every line the truth explains (each is a piece of a field line), by hand: the
            // truth's quality is the lines' weight less their residuals.
            // Lines alone fit many poses (any two crossing field lines): the truth is among
            // the best, and it explains every straight line it sees.
            let fix = murea.localize(&lines, murea.whole_field());
            let truth_evidence = murea.quality_at(truth, &lines) * lines.len() as f64;
            eprintln!(
                "{truth:?}: truth {truth_evidence} fix {} of {} lines, {} cells",
                fix.evidence,
                lines.len(),
                fix.cells
            );
            assert!(truth_evidence >= 0.8 * fix.evidence, "{truth:?}: {truth_evidence} {fix:?}");
            // The east goal where the truth sees it: the twin sees the west one there.
            let (dx, dy) = (9.0 - truth.x, 0.0 - truth.y);
            let goal = Perception::point(
                Kind::EAST_GOAL,
                dx.hypot(dy),
                normalize_angle(dy.atan2(dx) - truth.theta),
            );
            let mut with_goal = lines.clone();
            with_goal.push(goal);
            let fix = murea.localize(&with_goal, murea.whole_field());
            assert!(close(fix.pose, truth), "{truth:?}: {fix:?}");
            assert!(murea.quality_at(twin(truth), &with_goal) < fix.quality, "{fix:?}");
        }
    }

    #[test]
    fn a_line_with_a_negative_distance_turns_into_a_perception_facing_it() {
        let params = HoughParams::default();
        // The line y = −2 in the robot frame: φ = π/2, ρ = −2; its points from x = 1 to 3.
        let points: Vec<Point2> =
            (0..21).map(|k| Point2::new(1.0 + 0.1 * k as f64, -2.0)).collect();
        let lines = hough_lines(&points, &params);
        assert_eq!(lines.len(), 1, "{lines:?}");
        let l = lines[0];
        assert!((l.phi - FRAC_PI_2).abs() < 1e-9 && (l.rho + 2.0).abs() < 1e-9, "{l:?}");
        // Along (−sin φ, cos φ) = (−1, 0): x = 1..3 is t = −3..−1.
        assert!((l.extent.0 + 3.0).abs() < 1e-9 && (l.extent.1 + 1.0).abs() < 1e-9, "{l:?}");
        let p = l.perception(&params);
        // Turned: the foot 2 m away at −90°, the direction now (1, 0), so t = 1..3.
        assert!((p.range.unwrap_or(0.0) - 2.0).abs() < 1e-9);
        assert!((p.bearing.unwrap_or(0.0) + FRAC_PI_2).abs() < 1e-9, "{p:?}");
        assert_eq!(p.extent.map(|(a, b)| ((a * 1e6).round(), (b * 1e6).round())), Some((1e6, 3e6)));
    }
}
