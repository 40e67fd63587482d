//! Goals: their nearest point and the open space for a shot (ISocRob-2000 report §3.2.1,
//! eqs 16–18).
//!
//! With `u(i, j) = 1` where pixel (column i, row j) has the goal's colour: the column counts
//! `p_h(i) = Σ_j u(i, j)` (eq. 16) and the row counts `p_v(j) = Σ_i u(i, j)` (eq. 17).
//! - **Nearest point.** The report prints `y_n = argmin_y {p_v(y) | p_v(y) > T_p}`, which taken
//!   literally picks the row with the *fewest* goal pixels; what is meant is the extreme
//!   row: the goal row closest to the bottom of the image, the last row whose count passes
//!   the noise threshold `T_p`.
//! - **Open space** (eq. 18): `x_o = argmax_x Σ_k p_h(k)·h(x − k)` with `h(n) = 1` for
//!   `|n| ≤ T_o`: a box filter of width `2T_o + 1` over the column counts (prefix sums,
//!   columns outside the image count 0), its argmax the window where most goal is visible,
//!   the least covered by a keeper: where to shoot. Ties go to the smallest column (a design
//!   choice).

use super::colors::ColorClass;
use crate::camera::{Camera, Pinhole, Pixel};

/// The column and row counts of a class (eqs 16–17) in a `width × height` class map; empty
/// when the sizes do not fit the map.
pub fn projections(
    classes: &[u8],
    width: u32,
    height: u32,
    class: ColorClass,
) -> (Vec<u32>, Vec<u32>) {
    let (w, h) = (width as usize, height as usize);
    if w == 0 || h == 0 || classes.len() < w.saturating_mul(h) {
        return (Vec::new(), Vec::new());
    }
    let want = class as u8;
    let (mut cols, mut rows) = (vec![0u32; w], vec![0u32; h]);
    for (j, row) in classes.chunks_exact(w).take(h).enumerate() {
        for (i, &c) in row.iter().enumerate() {
            if c == want {
                cols[i] += 1;
                rows[j] += 1;
            }
        }
    }
    (cols, rows)
}

/// The column counts (eq. 16) of both goal colours, yellow then blue, in one pass over a
/// `width × height` class map; empty when the sizes do not fit the map.
pub fn goal_columns(classes: &[u8], width: u32, height: u32) -> [Vec<u32>; 2] {
    let (w, h) = (width as usize, height as usize);
    if w == 0 || h == 0 || classes.len() < w.saturating_mul(h) {
        return [Vec::new(), Vec::new()];
    }
    let (yellow, blue) = (ColorClass::GoalYellow as u8, ColorClass::GoalBlue as u8);
    let (mut ys, mut bs) = (vec![0u32; w], vec![0u32; w]);
    for row in classes.chunks_exact(w).take(h) {
        for ((y, b), &c) in ys.iter_mut().zip(bs.iter_mut()).zip(row) {
            *y += u32::from(c == yellow);
            *b += u32::from(c == blue);
        }
    }
    [ys, bs]
}

/// The nearest point's row: the last row (bottom-most in the image) whose count exceeds `t_p`.
pub fn nearest_row(rows: &[u32], t_p: u32) -> Option<usize> {
    rows.iter().rposition(|&n| n > t_p)
}

/// The open space's column (eq. 18): the centre of the window of `2·t_o + 1` columns holding
/// the most goal pixels, the smallest such column on a tie; `None` when no column has any.
pub fn open_space(cols: &[u32], t_o: usize) -> Option<usize> {
    if cols.iter().all(|&c| c == 0) {
        return None;
    }
    // prefix[i] = Σ cols[..i]
    let mut prefix = Vec::with_capacity(cols.len() + 1);
    prefix.push(0u64);
    for &c in cols {
        let last = prefix.last().copied().unwrap_or(0);
        prefix.push(last + u64::from(c));
    }
    let window = |x: usize| {
        let lo = x.saturating_sub(t_o);
        let hi = (x + t_o + 1).min(cols.len());
        prefix[hi] - prefix[lo]
    };
    (0..cols.len()).max_by(|&a, &b| window(a).cmp(&window(b)).then(b.cmp(&a)))
}

/// A goal as the camera saw it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GoalPercept {
    /// Which goal.
    pub class: ColorClass,
    /// Its pixels.
    pub pixels: u32,
    /// The nearest point: the goal's mean column on its nearest row, and that row.
    pub nearest: Pixel,
    /// Distance on the floor from the point under the camera to the nearest point, m.
    pub distance: f64,
    /// Bearing of the nearest point, rad, counter-clockwise from the robot's heading.
    pub bearing: f64,
    /// The open space's column (eq. 18).
    pub open_column: f64,
    /// Bearing of the open space on the nearest row, rad: where to shoot.
    pub open_bearing: f64,
}

/// Noise threshold of the nearest point's row (`T_p`), pixels (a design choice).
pub const ROW_NOISE: u32 = 2;

/// The goal of `class` in a class map seen by `camera`, when at least `min_pixels` of it show
/// and its nearest point lies on the floor below the horizon. `t_o` is the open-space half
/// window in columns (the ball's apparent radius is a good value); 0 picks an eighth of the
/// goal's visible width.
pub fn find_goal(
    classes: &[u8],
    camera: &Pinhole,
    class: ColorClass,
    min_pixels: u32,
    t_o: usize,
) -> Option<GoalPercept> {
    let (w, h) = camera.size();
    let (cols, rows) = projections(classes, w, h, class);
    let pixels: u32 = cols.iter().sum();
    if pixels < min_pixels.max(1) {
        return None;
    }
    let row = nearest_row(&rows, ROW_NOISE)?;
    // The goal's columns on its nearest row.
    let line = &classes[row * w as usize..(row + 1) * w as usize];
    let on: Vec<usize> = (0..line.len()).filter(|&i| line[i] == class as u8).collect();
    let mean = on.iter().sum::<usize>() as f64 / on.len().max(1) as f64;
    let nearest = Pixel::new(mean + 0.5, row as f64 + 0.5);
    let floor = camera.unproject(nearest)?;
    let d = floor - camera.mount;
    let t_o = if t_o == 0 { (cols.iter().filter(|&&c| c > 0).count() / 8).max(1) } else { t_o };
    let open = open_space(&cols, t_o)?;
    let open_floor = camera.unproject(Pixel::new(open as f64 + 0.5, row as f64 + 0.5))?;
    let o = open_floor - camera.mount;
    Some(GoalPercept {
        class,
        pixels,
        nearest,
        distance: d.norm(),
        bearing: d.y.atan2(d.x),
        open_column: open as f64 + 0.5,
        open_bearing: o.y.atan2(o.x),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Intrinsics;
    use nalgebra::Point3;

    #[test]
    fn both_goal_colours_are_counted_in_one_pass_as_each_alone() {
        let (w, h) = (7u32, 5u32);
        let map: Vec<u8> = (0..w * h).map(|i| (i * 7 % 5) as u8).collect();
        let [y, b] = goal_columns(&map, w, h);
        assert_eq!(y, projections(&map, w, h, ColorClass::GoalYellow).0);
        assert_eq!(b, projections(&map, w, h, ColorClass::GoalBlue).0);
        assert!(y.iter().sum::<u32>() > 0 && b.iter().sum::<u32>() > 0);
        assert!(goal_columns(&map, w, h + 1).iter().all(Vec::is_empty));
    }

    /// A worked test vector of eq. 18: p_h = [0,0,3,5,5,0,0,4,6,6,6,2], T_o = 1: windowed sums
    /// [0,3,8,13,10,5,4,10,16,18,14,8], x_o = 9.
    #[test]
    fn open_space_by_the_worked_vector() {
        let p_h = [0, 0, 3, 5, 5, 0, 0, 4, 6, 6, 6, 2];
        assert_eq!(open_space(&p_h, 1), Some(9));
        assert_eq!(open_space(&[0, 0, 0], 1), None);
        // A tie goes to the smallest column.
        assert_eq!(open_space(&[1, 0, 1], 0), Some(0));
    }

    /// The nearest point is the extreme row, not the report's literal argmin (which would pick
    /// the sparsest row).
    #[test]
    fn the_nearest_row_is_the_lowest_goal_row() {
        let p_v = [0, 9, 9, 9, 3, 1, 0];
        assert_eq!(nearest_row(&p_v, 2), Some(4), "rows 5 (1 pixel) is noise");
        let literal = (0..p_v.len()).filter(|&y| p_v[y] > 2).min_by_key(|&y| p_v[y]);
        assert_eq!(literal, Some(4), "here the same by chance");
        let p_v = [0, 3, 9, 9, 9, 0];
        assert_eq!(nearest_row(&p_v, 2), Some(4));
        let literal = (0..p_v.len()).filter(|&y| p_v[y] > 2).min_by_key(|&y| p_v[y]);
        assert_eq!(literal, Some(1), "the report's argmin: the goal's top, the far edge");
    }

    /// A goal painted where a camera sees it (its bottom edge on the floor 3 m ahead, 1 m wide,
    /// a keeper covering its left half): found at 3 m, the open space on its right.
    #[test]
    fn a_goal_with_a_keeper_has_its_open_space_beside_the_keeper() {
        let cam = Pinhole::new(Intrinsics::centred(320, 240, 260.0), 0.45, 0.35);
        let (w, h) = (320usize, 240usize);
        let mut m = vec![ColorClass::Field as u8; w * h];
        let left = cam.project(Point3::new(3.0, 0.5, 0.0)).unwrap();
        let right = cam.project(Point3::new(3.0, -0.5, 0.0)).unwrap();
        let top = cam.project(Point3::new(3.0, 0.0, 0.8)).unwrap();
        let bottom = left.y;
        for y in top.y as usize..bottom as usize {
            for x in left.x as usize..right.x as usize {
                m[y * w + x] = ColorClass::GoalBlue as u8;
            }
        }
        // The keeper: a dark block over the left half of the goal's mouth.
        let mid = (left.x + right.x) / 2.0;
        for y in (top.y as usize + 5)..bottom as usize {
            for x in left.x as usize..mid as usize {
                m[y * w + x] = ColorClass::Robot as u8;
            }
        }
        let half = ((right.x - left.x) / 8.0) as usize;
        let g = find_goal(&m, &cam, ColorClass::GoalBlue, 20, half).unwrap();
        // At 3 m a row is about 8 cm of floor: within 5 %.
        assert!((g.distance - 3.0).abs() < 0.15, "{g:?}");
        assert!(g.open_bearing < 0.0, "to the right of the keeper: {g:?}");
        assert!(find_goal(&m, &cam, ColorClass::GoalYellow, 20, half).is_none());
    }
}
