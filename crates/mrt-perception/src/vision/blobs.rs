//! Blobs of one colour class and the ball percept (ISocRob-2000 report §3.2.1: the windowed
//! blob of the ball's pixels, its distance-dependent size test and its centre correction, eqs
//! 10–11, fixed: the correction scales y as well as x, and the expected size divides by the
//! range to the ball's centre, not to the floor point).
//!
//! Connected components are `imageproc`'s (8-connected); this module only gathers each
//! component's pixel count, centre of mass and bounding box, and turns the best ball blob into
//! a floor position through the camera model. **MRT's addition**, for real light: the ball's
//! shade joins its blob ([`blobs_joined`]), and the ball's centre is the centre of the circle
//! fitted to the blob's outline ([`Silhouette`]) rather than its centre of mass, which moves
//! towards the part in view when shade, a robot or the image's border hides the rest.

use super::colors::ColorClass;
use crate::camera::{ball_diameter_px, ball_floor_point, Camera, Pinhole, Pixel};
use image::{GrayImage, Luma};
use imageproc::region_labelling::{connected_components, Connectivity};
use nalgebra::{Point2, Point3};

// The largest image side the vision accepts, defined with the camera models (whose files may
// not describe a larger image).
pub use crate::camera::MAX_SIDE;

/// One connected region of a class.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blob {
    /// Its pixels.
    pub pixels: u32,
    /// Its centre of mass `(col, row)`.
    pub centroid: Pixel,
    /// Its bounding box: first and last column, first and last row.
    pub bbox: BoundingBox,
    /// Its pixels of the core class ([`blobs_joined`]; all of them for [`blobs`]).
    pub core: u32,
}

/// First and last column, first and last row.
pub type BoundingBox = (u32, u32, u32, u32);

/// Side of the coarse cells in which [`blobs`] first looks for a class (pixels).
const CELL: u32 = 8;

/// The blobs of `class` in a class map (`classes`: one `ColorClass as u8` a pixel, row after
/// row, `width × height`), largest first; blobs under `min_pixels` are left out. An empty list
/// when the sizes do not fit the map or exceed [`MAX_SIDE`].
///
/// Windowed, for speed (the seed's "windowed centre of mass"): the map is first reduced to
/// 8 × 8 cells that hold any pixel of the class; `imageproc` labels the cells' connected
/// regions, then the full-resolution pixels inside each region's cells. An 8-connected blob
/// only touches 8-connected cells, so every blob lies within one region: the result is the
/// same as labelling the whole map, at a fraction of the cost when the class is rare.
pub fn blobs(
    classes: &[u8],
    width: u32,
    height: u32,
    class: ColorClass,
    min_pixels: u32,
) -> Vec<Blob> {
    blobs_joined(classes, width, height, class, class, min_pixels)
}

/// [`blobs`] of the pixels of `core` and of `joins` together: a blob is a connected region of
/// either class, and [`Blob::core`] counts its pixels of `core` (the ball's lit and shaded
/// sides, [`find_ball`]).
pub fn blobs_joined(
    classes: &[u8],
    width: u32,
    height: u32,
    core: ColorClass,
    joins: ColorClass,
    min_pixels: u32,
) -> Vec<Blob> {
    let n = (width as usize).saturating_mul(height as usize);
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE || classes.len() < n {
        return Vec::new();
    }
    let (a, b) = (core as u8, joins as u8);
    let (cw, ch) = (width.div_ceil(CELL), height.div_ceil(CELL));
    let mut cells = vec![0u8; (cw * ch) as usize];
    for (y, row) in classes[..n].chunks_exact(width as usize).enumerate() {
        let cy = y / CELL as usize;
        for (cx, chunk) in row.chunks(CELL as usize).enumerate() {
            // Without a branch a pixel (`contains` calls memchr for 8 bytes).
            if chunk.iter().fold(false, |any, &c| any | (c == a) | (c == b)) {
                cells[cy * cw as usize + cx] = 255;
            }
        }
    }
    let Some(cells) = GrayImage::from_raw(cw, ch, cells) else { return Vec::new() };
    let regions = connected_components(&cells, Connectivity::Eight, Luma([0u8]));
    // Each region's bounding box, in cells.
    let mut boxes: Vec<BoundingBox> = Vec::new();
    for (x, y, l) in regions.enumerate_pixels() {
        let l = l.0[0] as usize;
        if l == 0 {
            continue;
        }
        if boxes.len() < l {
            boxes.resize(l, (u32::MAX, 0, u32::MAX, 0));
        }
        let b = &mut boxes[l - 1];
        *b = (b.0.min(x), b.1.max(x), b.2.min(y), b.3.max(y));
    }
    let mut out = Vec::new();
    for (i, &(x0, x1, y0, y1)) in boxes.iter().enumerate() {
        let label = i as u32 + 1;
        // The region's window in pixels; only the pixels of its own cells take part.
        let (px0, py0) = (x0 * CELL, y0 * CELL);
        let (px1, py1) = (((x1 + 1) * CELL).min(width), ((y1 + 1) * CELL).min(height));
        let (ww, wh) = (px1 - px0, py1 - py0);
        let mut mask = vec![0u8; (ww * wh) as usize];
        for y in 0..wh {
            let row = ((py0 + y) * width + px0) as usize;
            for x in 0..ww {
                let (gx, gy) = (px0 + x, py0 + y);
                let c = classes[row + x as usize];
                if (c == a || c == b) && regions.get_pixel(gx / CELL, gy / CELL).0[0] == label {
                    mask[(y * ww + x) as usize] = 255;
                }
            }
        }
        let Some(mask) = GrayImage::from_raw(ww, wh, mask) else { continue };
        let is_core = |x: u32, y: u32| classes[(y * width + x) as usize] == a;
        out.extend(label_blobs(&mask, (px0, py0), min_pixels, is_core));
    }
    out.sort_by(|a, b| b.pixels.cmp(&a.pixels).then(a.bbox.cmp(&b.bbox)));
    out
}

/// The blobs of a mask (255: the class), offset by the window's origin; `is_core` tells a
/// pixel of the core class (image coordinates).
fn label_blobs(
    mask: &GrayImage,
    (ox, oy): (u32, u32),
    min_pixels: u32,
    is_core: impl Fn(u32, u32) -> bool,
) -> Vec<Blob> {
    let labels = connected_components(mask, Connectivity::Eight, Luma([0u8]));
    // Per label: count, sums of columns and rows, bounding box, core pixels.
    let mut stats: Vec<(u32, f64, f64, BoundingBox, u32)> = Vec::new();
    for (x, y, l) in labels.enumerate_pixels() {
        let l = l.0[0] as usize;
        if l == 0 {
            continue;
        }
        if stats.len() < l {
            stats.resize(l, (0, 0.0, 0.0, (u32::MAX, 0, u32::MAX, 0), 0));
        }
        let (x, y) = (x + ox, y + oy);
        let s = &mut stats[l - 1];
        s.0 += 1;
        s.4 += u32::from(is_core(x, y));
        s.1 += f64::from(x);
        s.2 += f64::from(y);
        s.3 = (s.3 .0.min(x), s.3 .1.max(x), s.3 .2.min(y), s.3 .3.max(y));
    }
    stats
        .into_iter()
        .filter(|s| s.0 >= min_pixels.max(1))
        .map(|(count, sx, sy, bbox, core)| Blob {
            pixels: count,
            // Pixel centres: a pixel (x, y) covers [x, x + 1).
            centroid: Pixel::new(sx / f64::from(count) + 0.5, sy / f64::from(count) + 0.5),
            bbox,
            core,
        })
        .collect()
}

/// The ball as the camera saw it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BallPercept {
    /// Its centre in the image: the centre of the circle fitted to its outline (its
    /// silhouette's centre of mass where no circle fits).
    pub pixel: Pixel,
    /// Its apparent radius, pixels (from its silhouette's area).
    pub radius_px: f64,
    /// The ball's floor point (robot frame, m): under its centre.
    pub at: Point2<f64>,
    /// Distance on the floor from the point under the camera to the ball's floor point, m.
    pub distance: f64,
    /// Bearing from the robot's heading (pan included), rad, counter-clockwise, seen from the
    /// point under the camera.
    pub bearing: f64,
    /// Its pixels.
    pub pixels: u32,
}

/// The size test's bounds on a blob's area against the expected one, π(w/2)² (a design
/// choice: partial segmentation and occlusion on the low side, merged noise on the high
/// side).
pub const BALL_AREA_RANGE: (f64, f64) = (0.3, 3.0);

/// Of a ball blob, this share of its pixels at least must be of the ball's own class (its lit
/// side): a blob of the shade's darker orange alone is not a ball.
pub const BALL_CORE_SHARE: f64 = 0.2;

/// The farthest a ball is looked for, m (floor distance from the point under the camera): a
/// blob farther away is a few pixels of something else of the ball's colour, or so small that
/// its position would mean little.
pub const MAX_BALL_RANGE: f64 = 12.0;

/// The ball in a class map seen by `camera`: of the blobs of the ball's class and its shade
/// ([`ColorClass::BallShade`], joined where it touches), the largest whose silhouette fits the
/// size a ball of `radius` (m) would have where its centre's ray says it is, within
/// [`MAX_BALL_RANGE`], corrected from the floor point of that ray to the point under the ball
/// (both coordinates). A joined blob that is mostly shade, or that does not fit (the shade ran
/// on into something else of its colour, such as a wall under a warm light), is tried by its
/// lit side alone: the blobs of the ball's class within it.
pub fn find_ball(classes: &[u8], camera: &Pinhole, radius: f64) -> Option<BallPercept> {
    let (w, h) = camera.size();
    let mut lit: Option<Vec<Blob>> = None;
    let mut best: Option<BallPercept> = None;
    for blob in blobs_joined(classes, w, h, ColorClass::Ball, ColorClass::BallShade, 3) {
        let lit_enough = f64::from(blob.core) >= BALL_CORE_SHARE * f64::from(blob.pixels);
        let joined =
            if lit_enough { sized_ball(classes, camera, radius, &blob, true) } else { None };
        let found = joined.or_else(|| {
            if blob.core == 0 || blob.core == blob.pixels {
                return None;
            }
            let lit = lit.get_or_insert_with(|| blobs(classes, w, h, ColorClass::Ball, 3));
            let (x0, x1, y0, y1) = blob.bbox;
            lit.iter()
                .filter(|b| b.bbox.0 >= x0 && b.bbox.1 <= x1 && b.bbox.2 >= y0 && b.bbox.3 <= y1)
                .find_map(|b| sized_ball(classes, camera, radius, b, false))
        });
        if let Some(ball) = found {
            if best.is_none_or(|b| ball.pixels > b.pixels) {
                best = Some(ball);
            }
        }
    }
    best
}

/// The ball `blob` shows, if its silhouette (of the ball's pixels and, `with_shade`, its
/// shade's) has a ball's size where it stands.
fn sized_ball(
    classes: &[u8],
    camera: &Pinhole,
    radius: f64,
    blob: &Blob,
    with_shade: bool,
) -> Option<BallPercept> {
    let shade = if with_shade { ColorClass::BallShade } else { ColorClass::Ball };
    let outline = Silhouette::of(classes, camera.size(), blob.bbox, [ColorClass::Ball, shade]);
    let centre = outline.circle().map_or(outline.centroid, |c| c.0);
    let hit = camera.unproject(centre)?;
    let foot = camera.mount;
    let at = ball_floor_point(foot, camera.height, hit, radius);
    if (at - foot).norm() > MAX_BALL_RANGE {
        return None;
    }
    let centre_3d = Point3::new(at.x, at.y, radius);
    let range = (centre_3d - camera.centre()).norm();
    let expected = ball_diameter_px(radius, camera.intrinsics.fx, range) / 2.0;
    let area = std::f64::consts::PI * expected * expected;
    BallPercept::sized(outline.area, centre, area, at, foot)
}

/// A ball blob's outline: each row's span from its first to its last pixel of the ball's
/// classes (a highlight or a hole inside is filled), and the ends of those spans and of each
/// column's, the points a circle is fitted to. Ends on the image's border are left out: there
/// the ball goes on beyond the image.
#[derive(Clone, Debug, PartialEq)]
pub struct Silhouette {
    /// Pixels inside the spans.
    pub area: u32,
    /// The spans' centre of mass.
    pub centroid: Pixel,
    /// The outline's points, on the outer sides of the spans' end pixels.
    pub edge: Vec<Pixel>,
}

/// Outline points fewer than this: no circle is fitted.
const MIN_EDGE_POINTS: usize = 8;

impl Silhouette {
    /// The outline of the pixels of `of` within `bbox` (first and last column, first and last
    /// row, clipped to the map) of a class map of `(width, height)`.
    pub fn of(
        classes: &[u8],
        (width, height): (u32, u32),
        bbox: BoundingBox,
        of: [ColorClass; 2],
    ) -> Silhouette {
        let (w, h) = (width as usize, height as usize);
        let (x0, y0) = (bbox.0 as usize, bbox.2 as usize);
        let (x1, y1) = ((bbox.1 as usize).min(w.max(1) - 1), (bbox.3 as usize).min(h.max(1) - 1));
        let of = of.map(|c| c as u8);
        let at = |x: usize, y: usize| classes.get(y * w + x).is_some_and(|c| of.contains(c));
        // The first and last pixel of the ball's classes along one line, if any.
        let ends = |mut line: std::ops::RangeInclusive<usize>, at: &dyn Fn(usize) -> bool| {
            let first = line.find(|&k| at(k))?;
            Some((first, line.rev().find(|&k| at(k)).unwrap_or(first)))
        };
        let (mut area, mut sx, mut sy) = (0u32, 0.0, 0.0);
        let mut edge = Vec::new();
        for y in y0..=y1 {
            let Some((first, last)) = ends(x0..=x1, &|x| at(x, y)) else { continue };
            let n = (last - first + 1) as u32;
            area += n;
            sx += f64::from(n) * (first + last + 1) as f64 / 2.0;
            sy += f64::from(n) * (y as f64 + 0.5);
            push_ends(&mut edge, (first, last), w, |along| Pixel::new(along, y as f64 + 0.5));
        }
        for x in x0..=x1 {
            let Some(span) = ends(y0..=y1, &|y| at(x, y)) else { continue };
            push_ends(&mut edge, span, h, |along| Pixel::new(x as f64 + 0.5, along));
        }
        let centroid = if area > 0 {
            Pixel::new(sx / f64::from(area), sy / f64::from(area))
        } else {
            Pixel::new((x0 + x1 + 1) as f64 / 2.0, (y0 + y1 + 1) as f64 / 2.0)
        };
        Silhouette { area, centroid, edge }
    }

    /// The circle through the outline (centre, radius in pixels): a least-squares fit, then
    /// fitted again, twice, without the points well inside it (where the ball's edge is not
    /// seen: a shade too dark for its class, a robot in front) or half a radius outside
    /// (another blob in the corner of its box). `None` for too few points, or a circle that could not be
    /// the outline's: its centre farther than its radius from the outline's box, or a radius
    /// larger than the box's longer side.
    pub fn circle(&self) -> Option<(Pixel, f64)> {
        let mut points = self.edge.clone();
        let mut fit = fit_circle(&points)?;
        for _ in 0..2 {
            let (c, r) = fit;
            points.retain(|p| (-1.0..=0.5 * r).contains(&((p - c).norm() - r)));
            match fit_circle(&points) {
                Some(refit) => fit = refit,
                None => break,
            }
        }
        let (lo, hi) = self.edge.iter().fold(
            (
                Pixel::new(f64::INFINITY, f64::INFINITY),
                Pixel::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.inf(p), hi.sup(p)),
        );
        let (c, r) = fit;
        let side = (hi.x - lo.x).max(hi.y - lo.y);
        let inside = c.x >= lo.x - r && c.x <= hi.x + r && c.y >= lo.y - r && c.y <= hi.y + r;
        (inside && r <= side).then_some(fit)
    }
}

/// The ends of a span `(first, last)` on a line of `len` pixels as outline points, `point`
/// placing a position along the line; an end on the image's border is left out.
fn push_ends(
    edge: &mut Vec<Pixel>,
    (first, last): (usize, usize),
    len: usize,
    point: impl Fn(f64) -> Pixel,
) {
    if first > 0 {
        edge.push(point(first as f64));
    }
    if last + 1 < len {
        edge.push(point((last + 1) as f64));
    }
}

/// The least-squares circle through `points` (Kåsa's algebraic fit: `x² + y² + Dx + Ey + F =
/// 0`), centred on their mean for conditioning.
fn fit_circle(points: &[Pixel]) -> Option<(Pixel, f64)> {
    if points.len() < MIN_EDGE_POINTS {
        return None;
    }
    let n = points.len() as f64;
    let mean = points.iter().fold(nalgebra::Vector2::zeros(), |s, p| s + p.coords) / n;
    let mut a = nalgebra::Matrix3::<f64>::zeros();
    let mut b = nalgebra::Vector3::<f64>::zeros();
    for p in points {
        let (x, y) = (p.x - mean.x, p.y - mean.y);
        let row = nalgebra::Vector3::new(x, y, 1.0);
        a += row * row.transpose();
        b -= row * (x * x + y * y);
    }
    let s = a.lu().solve(&b)?;
    let (cx, cy) = (-s.x / 2.0, -s.y / 2.0);
    let r2 = cx * cx + cy * cy - s.z;
    if !(r2.is_finite() && r2 > 0.0) {
        return None;
    }
    Some((Pixel::new(cx + mean.x, cy + mean.y), r2.sqrt()))
}

impl BallPercept {
    /// The ball of `pixels` pixels centred at `pixel`, standing at `at` and seen from `foot`
    /// (robot frame), when its pixels fit the `expected` area ([`BALL_AREA_RANGE`]).
    pub(crate) fn sized(
        pixels: u32,
        pixel: Pixel,
        expected: f64,
        at: Point2<f64>,
        foot: Point2<f64>,
    ) -> Option<BallPercept> {
        let (lo, hi) = BALL_AREA_RANGE;
        let n = f64::from(pixels);
        if n < lo * expected || n > hi * expected {
            return None;
        }
        let d = at - foot;
        Some(BallPercept {
            pixel,
            radius_px: (n / std::f64::consts::PI).sqrt(),
            at,
            distance: d.norm(),
            bearing: d.y.atan2(d.x),
            pixels,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Intrinsics;

    /// A class map with discs of `class` painted at `(col, row, radius)`.
    fn map(w: u32, h: u32, discs: &[(ColorClass, f64, f64, f64)]) -> Vec<u8> {
        let mut m = vec![ColorClass::Field as u8; (w * h) as usize];
        for &(class, cx, cy, r) in discs {
            for y in 0..h {
                for x in 0..w {
                    let (dx, dy) = (f64::from(x) + 0.5 - cx, f64::from(y) + 0.5 - cy);
                    if dx * dx + dy * dy <= r * r {
                        m[(y * w + x) as usize] = class as u8;
                    }
                }
            }
        }
        m
    }

    #[test]
    fn blobs_are_counted_centred_and_sorted() {
        let m = map(
            80,
            60,
            &[(ColorClass::Ball, 20.0, 20.0, 5.0), (ColorClass::Ball, 60.0, 40.0, 3.0)],
        );
        let b = blobs(&m, 80, 60, ColorClass::Ball, 1);
        assert_eq!(b.len(), 2);
        assert!(b.iter().all(|b| b.core == b.pixels), "one class: every pixel is core");
        assert!(b[0].pixels > b[1].pixels);
        assert!((b[0].centroid.x - 20.0).abs() < 0.05 && (b[0].centroid.y - 20.0).abs() < 0.05);
        assert_eq!(b[0].bbox, (15, 24, 15, 24));
        assert!(blobs(&m, 80, 60, ColorClass::GoalBlue, 1).is_empty());
        // Sizes that do not fit the map: nothing, no panic.
        assert!(blobs(&m, 81, 60, ColorClass::Ball, 1).is_empty());
        assert!(blobs(&m, MAX_SIDE + 1, 1, ColorClass::Ball, 1).is_empty());
    }

    /// The windowed labelling gives what labelling the whole map gives, on random maps.
    #[test]
    fn windowed_blobs_equal_whole_map_blobs() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..20 {
            let (w, h) = (rng.random_range(1..90u32), rng.random_range(1..70u32));
            let density = rng.random_range(0.0..0.6);
            let m: Vec<u8> = (0..w * h)
                .map(|_| if rng.random_bool(density) { ColorClass::Ball as u8 } else { 0 })
                .collect();
            let mut fast = blobs(&m, w, h, ColorClass::Ball, 1);
            let full = GrayImage::from_raw(
                w,
                h,
                m.iter().map(|&c| if c == 1 { 255 } else { 0 }).collect(),
            )
            .unwrap();
            let mut slow = label_blobs(&full, (0, 0), 1, |_, _| true);
            for v in [&mut fast, &mut slow] {
                v.sort_by(|a, b| a.bbox.cmp(&b.bbox).then(a.pixels.cmp(&b.pixels)));
            }
            assert_eq!(fast.len(), slow.len(), "{w}×{h}");
            for (a, b) in fast.iter().zip(&slow) {
                assert_eq!((a.pixels, a.bbox), (b.pixels, b.bbox));
                assert!((a.centroid - b.centroid).norm() < 1e-9);
            }
        }
    }

    /// The ball across the field: painted where the camera would see it, with the apparent
    /// size of a sphere, found at the right distance and bearing (error ≤ 5 % of the
    /// distance and ≤ 1.5°).
    #[test]
    fn the_ball_is_found_at_its_distance_and_bearing_across_the_field() {
        let cam = Pinhole::new(Intrinsics::centred(320, 240, 260.0), 0.45, 0.35);
        let radius = 0.11;
        for (x, y) in [(0.8, 0.0), (1.2, 0.3), (2.0, -0.5), (3.0, 0.8), (4.5, -1.0), (6.0, 0.0)] {
            let centre = Point3::new(x, y, radius);
            let px = cam.project(centre).unwrap();
            let range = (centre - cam.centre()).norm();
            let r_px = ball_diameter_px(radius, 260.0, range) / 2.0;
            let m = map(320, 240, &[(ColorClass::Ball, px.x, px.y, r_px)]);
            let ball = find_ball(&m, &cam, radius).unwrap_or_else(|| panic!("({x}, {y})"));
            let (d, b) = (x.hypot(y), y.atan2(x));
            assert!((ball.distance - d).abs() <= 0.05 * d, "({x}, {y}): {ball:?}");
            assert!((ball.bearing - b).abs() <= 1.5f64.to_radians(), "({x}, {y}): {ball:?}");
        }
    }

    /// Which pixels (column, row) of a ball a case takes away.
    type Cut = dyn Fn(usize, usize) -> bool;

    /// A ball whose lower half is in shade too dark for either ball class, or whose shade is
    /// of the shade's class, or that a robot hides in part: still found where it is (its
    /// outline's circle, not its centre of mass).
    #[test]
    fn a_ball_half_in_shade_or_half_hidden_is_found_at_its_centre() {
        let cam = Pinhole::new(Intrinsics::centred(320, 240, 260.0), 0.45, 0.35);
        let radius = 0.11;
        for (x, y) in [(1.0, 0.2), (2.0, -0.4), (3.5, 0.5)] {
            let centre = Point3::new(x, y, radius);
            let px = cam.project(centre).unwrap();
            let r_px = ball_diameter_px(radius, 260.0, (centre - cam.centre()).norm()) / 2.0;
            let whole = map(320, 240, &[(ColorClass::Ball, px.x, px.y, r_px)]);
            let (d, b) = (x.hypot(y), y.atan2(x));
            let below = move |_: usize, row: usize| (row as f64 + 0.5) > px.y + 0.2 * r_px;
            let left = move |col: usize, _: usize| (col as f64 + 0.5) < px.x - 0.3 * r_px;
            // Shade of no class below the middle; the shade's class; a robot on the left.
            let cases: [(&str, &Cut, ColorClass); 3] = [
                ("dark lower part", &below, ColorClass::Unknown),
                ("shaded lower part", &below, ColorClass::BallShade),
                ("a robot in front", &left, ColorClass::Robot),
            ];
            for (name, cut, fill) in cases {
                let mut m = whole.clone();
                for (k, class) in m.iter_mut().enumerate() {
                    if *class == ColorClass::Ball as u8 && cut(k % 320, k / 320) {
                        *class = fill as u8;
                    }
                }
                let ball = find_ball(&m, &cam, radius).unwrap_or_else(|| panic!("{name}"));
                assert!((ball.distance - d).abs() <= 0.05 * d, "{name} ({x}, {y}): {ball:?}");
                assert!((ball.bearing - b).abs() <= 1.5f64.to_radians(), "{name}: {ball:?}");
            }
        }
    }

    /// A wall of the shade's colour (grey under a warm lamp) touching the ball: the joined
    /// blob is too big, the ball's lit side alone is the ball.
    #[test]
    fn a_ball_against_a_wall_of_its_shades_colour_is_found_by_its_lit_side() {
        let cam = Pinhole::new(Intrinsics::centred(320, 240, 260.0), 0.45, 0.35);
        let (x, y, radius) = (3.0, 0.3, 0.11);
        let centre = Point3::new(x, y, radius);
        let px = cam.project(centre).unwrap();
        let r_px = ball_diameter_px(radius, 260.0, (centre - cam.centre()).norm()) / 2.0;
        let mut m = map(320, 240, &[(ColorClass::Ball, px.x, px.y, r_px)]);
        let wall_top = px.y - r_px - 10.0;
        for (k, c) in m.iter_mut().enumerate() {
            let row = (k / 320) as f64 + 0.5;
            if *c != ColorClass::Ball as u8 && row > wall_top && row < px.y {
                *c = ColorClass::BallShade as u8;
            }
        }
        let ball = find_ball(&m, &cam, radius).unwrap();
        let d = x.hypot(y);
        assert!((ball.distance - d).abs() <= 0.05 * d, "{ball:?}");
        assert!((ball.bearing - y.atan2(x)).abs() <= 1.5f64.to_radians(), "{ball:?}");
    }

    /// A few pixels of the ball's colour high in the image (a post's band under an orange
    /// light) would be a ball far beyond the field: not a ball.
    #[test]
    fn no_ball_beyond_the_farthest_range() {
        let cam = Pinhole::new(Intrinsics::centred(320, 240, 260.0), 0.45, 0.35);
        for d in [MAX_BALL_RANGE - 1.0, MAX_BALL_RANGE + 1.0, 2.0 * MAX_BALL_RANGE] {
            let centre = Point3::new(d, 0.0, 0.11);
            let px = cam.project(centre).unwrap();
            let r_px = ball_diameter_px(0.11, 260.0, (centre - cam.centre()).norm()) / 2.0;
            let m = map(320, 240, &[(ColorClass::Ball, px.x, px.y, r_px.max(1.5))]);
            let found = find_ball(&m, &cam, 0.11);
            assert_eq!(found.is_some(), d < MAX_BALL_RANGE, "{d} m: {found:?}");
        }
    }

    #[test]
    fn a_joined_blob_counts_its_core() {
        let mut m = map(80, 60, &[(ColorClass::Ball, 30.0, 30.0, 8.0)]);
        let lit = m.iter().filter(|&&c| c == ColorClass::Ball as u8).count() as u32;
        for c in m.iter_mut().skip(31 * 80).take(80) {
            if *c == ColorClass::Field as u8 {
                *c = ColorClass::BallShade as u8;
            }
        }
        let b = blobs_joined(&m, 80, 60, ColorClass::Ball, ColorClass::BallShade, 1);
        assert_eq!(b.len(), 1, "the shade's row runs through the ball: one blob");
        assert_eq!(b[0].core, lit);
        assert_eq!(b[0].pixels, lit + 80 - 16, "the row's shade beside the ball joins it");
    }

    #[test]
    fn a_blob_of_the_shade_alone_is_no_ball() {
        let cam = Pinhole::new(Intrinsics::centred(320, 240, 260.0), 0.45, 0.35);
        let px = cam.project(Point3::new(2.0, 0.0, 0.11)).unwrap();
        let m = map(320, 240, &[(ColorClass::BallShade, px.x, px.y, 14.0)]);
        assert!(find_ball(&m, &cam, 0.11).is_none());
    }

    #[test]
    fn a_circle_is_fitted_to_a_discs_outline_and_not_to_too_few_points() {
        let m = map(80, 60, &[(ColorClass::Ball, 30.3, 25.6, 9.0)]);
        let blob = blobs(&m, 80, 60, ColorClass::Ball, 1)[0];
        let outline = Silhouette::of(&m, (80, 60), blob.bbox, [ColorClass::Ball; 2]);
        assert_eq!(outline.area, blob.pixels, "a disc has no holes to fill");
        let (c, r) = outline.circle().unwrap();
        assert!((c.x - 30.3).abs() < 0.3 && (c.y - 25.6).abs() < 0.3, "{c}");
        assert!((r - 9.0).abs() < 0.5, "{r}");
        assert!(fit_circle(&outline.edge[..MIN_EDGE_POINTS - 1]).is_none());
        // Points on a line: no circle.
        let line: Vec<Pixel> = (0..20).map(|k| Pixel::new(f64::from(k), 3.0)).collect();
        assert!(fit_circle(&line).is_none_or(|(_, r)| r > 1e3), "{:?}", fit_circle(&line));
    }

    #[test]
    fn no_ball_when_there_is_none_or_the_blob_has_the_wrong_size() {
        let cam = Pinhole::new(Intrinsics::centred(320, 240, 260.0), 0.45, 0.35);
        assert!(find_ball(&map(320, 240, &[]), &cam, 0.11).is_none());
        // An orange disc 3× too big for where it is: not a ball.
        let px = cam.project(Point3::new(2.0, 0.0, 0.11)).unwrap();
        let m = map(320, 240, &[(ColorClass::Ball, px.x, px.y, 3.0 * 16.0)]);
        assert!(find_ball(&m, &cam, 0.11).is_none());
    }
}
