//! Landmark posts (ISocRob-2000 report §3.2.1: the camera tells the field's landmarks apart by
//! colour): cylinders beside the field painted in three bands of the goal colours, the outer
//! bands the colour of the goal of their half and the middle band the other one (yellow,
//! blue, yellow on the yellow goal's half).
//!
//! Every column is scanned from the bottom up for runs of goal colour. A column crosses a post
//! when it shows, bottom to top, a run of one goal colour, a run of the other right above it,
//! and the first colour again right above that (or the image's top edge, which cuts the top
//! band of a near post). Neighbouring columns with the same outer colour and the same band
//! boundary (within a few rows) are one post. Its distance comes from its foot where carpet
//! shows below the bottom band, else from the boundary between its two lower bands, a
//! known height ([`PostShape`]); either gives the floor point of the post's front, and the post's
//! axis is its radius further along the ray.
//!
//! A post only says which half of the field it stands on (its outer colour), not which of
//! that half's posts it is: telling them apart is the world model's (by where the robot
//! believes it is).

use super::colors::ColorClass;
use super::goals::goal_columns;
use crate::camera::{Camera, Pinhole, Pixel};
use nalgebra::Point2;

/// Rows of another class tolerated inside a band (noise, a line's edge).
const GAP: usize = 2;
/// The shortest band, rows.
const MIN_BAND: usize = 2;
/// Neighbouring columns of one post have their lower boundary within this many rows.
const SAME_POST_ROWS: usize = 3;

/// The landmark posts' shape: radius and height (m); three bands of equal height.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PostShape {
    /// Radius.
    pub radius: f64,
    /// Height.
    pub height: f64,
}

impl Default for PostShape {
    /// 0.1 m radius, 0.8 m high (the simulator's posts).
    fn default() -> Self {
        PostShape { radius: 0.1, height: 0.8 }
    }
}

/// One post as the camera saw it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PostPercept {
    /// Its outer bands' colour: the colour of the goal of its half.
    pub outer: ColorClass,
    /// The post's axis on the floor (robot frame, m).
    pub at: Point2<f64>,
    /// The pixel the distance was measured at (the foot, or the lower band boundary).
    pub pixel: Pixel,
    /// Whether the foot was seen (else the distance comes from the band boundary).
    pub foot: bool,
    /// The first and the last image column it covers.
    pub columns: (usize, usize),
    /// Its pixels in the bands.
    pub pixels: u32,
}

impl PostPercept {
    /// The image columns whose goal colours belong to this post: its own and a margin for
    /// the cylinder's shaded, slanted edges, which may not pass as a post's columns. Goal
    /// finding leaves them out. `width`: the image's.
    pub fn masked_columns(&self, width: usize) -> std::ops::RangeInclusive<usize> {
        let margin = 2 + (self.columns.1 - self.columns.0) / 4;
        self.columns.0.saturating_sub(margin)
            ..=(self.columns.1 + margin).min(width.saturating_sub(1))
    }
}

/// What one column shows of a post.
#[derive(Clone, Copy, Debug)]
struct Cut {
    col: usize,
    outer: u8,
    /// The lower band's top row (the first boundary is just above it).
    boundary: usize,
    /// The lower band's bottom row, when carpet shows right below it.
    foot: Option<usize>,
    pixels: u32,
}

/// A run of one goal colour in a column: its class, bottom row and top row (inclusive).
#[derive(Clone, Copy, Debug)]
struct Run {
    class: u8,
    bottom: usize,
    top: usize,
}

/// The goal-colour runs of column `col`, from the bottom up, with gaps of up to [`GAP`] rows
/// of another class bridged.
fn runs(classes: &[u8], w: usize, h: usize, col: usize, out: &mut Vec<Run>) {
    out.clear();
    let (yellow, blue) = (ColorClass::GoalYellow as u8, ColorClass::GoalBlue as u8);
    for row in (0..h).rev() {
        let c = classes[row * w + col];
        if c != yellow && c != blue {
            continue;
        }
        match out.last_mut() {
            Some(r) if r.class == c && r.top - row <= GAP + 1 => r.top = row,
            _ => out.push(Run { class: c, bottom: row, top: row }),
        }
    }
}

fn len(r: &Run) -> usize {
    r.bottom - r.top + 1
}

/// The post cut of one column, if its runs show one (module doc).
fn cut(classes: &[u8], w: usize, h: usize, col: usize, runs: &[Run]) -> Option<Cut> {
    let (field, line) = (ColorClass::Field as u8, ColorClass::Line as u8);
    runs.windows(2).find_map(|pair| {
        let (low, mid) = (pair[0], pair[1]);
        let touching = |a: &Run, b: &Run| a.top > b.bottom && a.top - b.bottom <= GAP + 1;
        if low.class == mid.class
            || !touching(&low, &mid)
            || len(&low) < MIN_BAND
            || len(&mid) < MIN_BAND
        {
            return None;
        }
        // The top band above the middle one, or the image's edge cutting the post.
        let index = runs.iter().position(|r| r.bottom == mid.bottom)?;
        let top_ok = match runs.get(index + 1) {
            Some(top) => top.class == low.class && touching(&mid, top) && len(top) >= MIN_BAND,
            None => mid.top == 0,
        };
        // Bands of one post are alike in height; a goal seen behind a post of the other
        // colour is not.
        let (a, b) = (len(&low) as f64, len(&mid) as f64);
        if !top_ok || a > 2.5 * b || (mid.top > 0 && b > 2.5 * a) {
            return None;
        }
        let below = classes.get((low.bottom + 1) * w + col).copied();
        let foot = (low.bottom + 1 < h && (below == Some(field) || below == Some(line)))
            .then_some(low.bottom);
        Some(Cut {
            col,
            outer: low.class,
            boundary: low.top,
            foot,
            pixels: (len(&low) + len(&mid)) as u32,
        })
    })
}

/// The landmark posts in a class map seen by `camera` (module doc).
pub fn find_posts(classes: &[u8], camera: &Pinhole, shape: PostShape) -> Vec<PostPercept> {
    let (w, h) = camera.size();
    find_posts_in(classes, camera, shape, &goal_columns(classes, w, h))
}

/// [`find_posts`] with the class map's goal column counts ([`goal_columns`]) already taken,
/// as the vision µAgent has them for the goals: only columns holding both goal colours can
/// cross a post, and only those are scanned (a column scan reads across cache lines).
pub fn find_posts_in(
    classes: &[u8],
    camera: &Pinhole,
    shape: PostShape,
    [yellow, blue]: &[Vec<u32>; 2],
) -> Vec<PostPercept> {
    let (w, h) = camera.size();
    let (w, h) = (w as usize, h as usize);
    if w == 0 || h == 0 || classes.len() < w.saturating_mul(h) {
        return Vec::new();
    }
    let both = |col: usize| {
        yellow.get(col).is_some_and(|&n| n > 0) && blue.get(col).is_some_and(|&n| n > 0)
    };
    let mut buf = Vec::new();
    let mut out = Vec::new();
    let mut group: Vec<Cut> = Vec::new();
    for col in 0..=w {
        let c = if both(col) {
            runs(classes, w, h, col, &mut buf);
            cut(classes, w, h, col, &buf)
        } else {
            None
        };
        let joins = match (c, group.last()) {
            (Some(c), Some(g)) => {
                c.outer == g.outer
                    && c.col == g.col + 1
                    && c.boundary.abs_diff(g.boundary) <= SAME_POST_ROWS
            }
            _ => false,
        };
        if !joins && !group.is_empty() {
            if let Some(p) = post(&group, camera, shape) {
                out.push(p);
            }
            group.clear();
        }
        if let Some(c) = c {
            group.push(c);
        }
    }
    out
}

/// One post from the cuts of its columns.
fn post(group: &[Cut], camera: &Pinhole, shape: PostShape) -> Option<PostPercept> {
    let (first, last) = (group.first()?.col, group.last()?.col);
    // A post cut by the image's side: its middle column is unknown.
    let (w, _) = camera.size();
    if first == 0 || last + 1 >= w as usize {
        return None;
    }
    let column = (first + last) as f64 / 2.0 + 0.5;
    let foot = group.iter().filter_map(|c| c.foot).max();
    let (pixel, front) = match foot {
        Some(row) => {
            let px = Pixel::new(column, row as f64 + 1.0);
            (px, camera.unproject(px)?)
        }
        None => {
            let row = group.iter().map(|c| c.boundary).min()?;
            let px = Pixel::new(column, row as f64);
            let p = camera.unproject_at_height(px, shape.height / 3.0)?;
            (px, Point2::new(p.x, p.y))
        }
    };
    let ray = front - camera.mount;
    let norm = ray.norm();
    if !(norm.is_finite() && norm > 1e-6) {
        return None;
    }
    Some(PostPercept {
        outer: ColorClass::from_u8(group[0].outer),
        at: front + ray * (shape.radius / norm),
        pixel,
        foot: foot.is_some(),
        columns: (first, last),
        pixels: group.iter().map(|c| c.pixels).sum(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Intrinsics;

    /// A 40 × 30 class map of carpet with a post drawn at columns `cols`, its bands' bottom
    /// rows `rows` (lowest band first), the top band from `top`.
    fn map(cols: std::ops::Range<usize>, bands: [(usize, usize, ColorClass); 3]) -> Vec<u8> {
        let (w, h) = (40, 30);
        let mut m = vec![ColorClass::Field as u8; w * h];
        for (bottom, top, class) in bands {
            for row in top..=bottom {
                for col in cols.clone() {
                    m[row * w + col] = class as u8;
                }
            }
        }
        m
    }

    fn camera() -> Pinhole {
        Pinhole::new(Intrinsics::centred(40, 30, 40.0), 0.45, 0.35)
    }

    #[test]
    fn a_striped_post_standing_on_the_carpet_is_found_at_its_foot() {
        use ColorClass::{GoalBlue as B, GoalYellow as Y};
        let m = map(20..23, [(15, 12, Y), (11, 8, B), (7, 4, Y)]);
        let posts = find_posts(&m, &camera(), PostShape::default());
        assert_eq!(posts.len(), 1, "{posts:?}");
        let p = posts[0];
        assert_eq!((p.outer, p.columns, p.foot), (Y, (20, 22), true));
        assert_eq!(p.pixels, 3 * 8);
        // The foot: the bottom edge of row 15 in the middle column.
        let front = camera().unproject(Pixel::new(21.5, 16.0)).unwrap();
        let expect = front + (front - camera().mount).normalize() * 0.1;
        assert!((p.at - expect).norm() < 1e-9, "{p:?} {expect}");
    }

    #[test]
    fn a_goal_a_single_band_or_two_bands_below_the_top_edge_are_told_apart() {
        use ColorClass::{GoalBlue as B, GoalYellow as Y};
        // One colour from row 4 to 15: a goal, not a post.
        let goal = map(10..30, [(15, 12, Y), (11, 8, Y), (7, 4, Y)]);
        assert!(find_posts(&goal, &camera(), PostShape::default()).is_empty());
        // Two bands whose upper one ends below the image's top: no third band, no post.
        let two = map(20..23, [(15, 12, B), (11, 8, Y), (11, 8, Y)]);
        assert!(find_posts(&two, &camera(), PostShape::default()).is_empty());
        // Two bands, the upper one cut by the top edge: a near post.
        let near = map(20..23, [(15, 10, B), (9, 0, Y), (9, 0, Y)]);
        let posts = find_posts(&near, &camera(), PostShape::default());
        assert_eq!(posts.len(), 1, "{posts:?}");
        assert_eq!(posts[0].outer, B);
    }

    #[test]
    fn a_hidden_foot_gives_the_distance_from_the_band_boundary() {
        use ColorClass::{GoalBlue as B, GoalYellow as Y};
        let mut m = map(20..23, [(15, 12, Y), (11, 8, B), (7, 4, Y)]);
        // A robot in front of the post's foot.
        for row in 14..30 {
            for col in 15..28 {
                m[row * 40 + col] = ColorClass::Robot as u8;
            }
        }
        let posts = find_posts(&m, &camera(), PostShape::default());
        assert_eq!(posts.len(), 1, "{posts:?}");
        let p = posts[0];
        assert!(!p.foot);
        // The boundary between the bands (top edge of row 12) is 0.8 / 3 m high.
        let q = camera().unproject_at_height(Pixel::new(21.5, 12.0), 0.8 / 3.0).unwrap();
        let front = Point2::new(q.x, q.y);
        let expect = front + (front - camera().mount).normalize() * 0.1;
        assert!((p.at - expect).norm() < 1e-9, "{p:?} {expect}");
    }

    #[test]
    fn a_post_cut_by_the_images_side_is_not_reported() {
        use ColorClass::{GoalBlue as B, GoalYellow as Y};
        let m = map(0..3, [(15, 12, Y), (11, 8, B), (7, 4, Y)]);
        assert!(find_posts(&m, &camera(), PostShape::default()).is_empty());
    }

    #[test]
    fn any_class_map_gives_finite_posts() {
        use proptest::prelude::*;
        proptest!(|(m in proptest::collection::vec(0u8..7, 1200))| {
            for p in find_posts(&m, &camera(), PostShape::default()) {
                prop_assert!(p.at.x.is_finite() && p.at.y.is_finite());
            }
        });
    }
}
