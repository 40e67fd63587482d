//! The vision µAgent's **up** mode (ISocRob-2000 report §3.2.1): the omnidirectional camera
//! finds the ball all around the robot, within the mirror's reach and outside the floor the
//! robot's body hides. "Because of the mirror geometry (hardware unwrapping) it is trivial to
//! obtain floor objects positions": a pixel is a floor point through the camera's affine map
//! ([`Omni`]).
//!
//! Trivial for the floor, not quite for a ball: its centre is `radius` above the floor, so the
//! mirror, seeing from its viewpoint, images it farther out than the floor point under it, and
//! the ball's image is its silhouette cast on the floor from the viewpoint, an ellipse
//! stretched away from the robot whose centre of mass lies farther out still. [`find_ball_up`]
//! models that silhouette ([`silhouette`]: the circle where the viewpoint's lines touch the
//! sphere, cast on the floor) for the size test and to correct the centre of mass; the error
//! it removes is about 3 % of the distance at 3 m (tests).
//!
//! ```
//! use mrt_perception::camera::{Camera, OmniFile};
//! use mrt_perception::vision::colors::ColorClass;
//! use mrt_perception::vision::up::{find_ball_up, silhouette};
//! use nalgebra::Point2;
//!
//! let omni = OmniFile::default().camera()?; // 480×480, 50 px/m, viewpoint 0.8 m
//! // Paint the silhouette of a ball 2 m ahead and 1 m to the left into a class map.
//! let outline = silhouette(&omni, Point2::new(2.0, 1.0), 0.11);
//! let mut classes = vec![ColorClass::Field as u8; 480 * 480];
//! for row in 0..480u32 {
//!     for col in 0..480u32 {
//!         let p = (f64::from(col) + 0.5, f64::from(row) + 0.5);
//!         if mrt_perception::vision::up::inside(&outline, p) {
//!             classes[(row * 480 + col) as usize] = ColorClass::Ball as u8;
//!         }
//!     }
//! }
//! let ball = find_ball_up(&classes, &omni, 0.11).unwrap();
//! assert!((ball.distance - 5f64.sqrt()).abs() < 0.02, "{ball:?}");
//! assert!((ball.bearing - 0.5f64.atan()).abs() < 0.01, "{ball:?}");
//! # Ok::<(), mrt_perception::camera::CameraFileError>(())
//! ```

use super::agent::{check_size, VisionError};
use super::balance::BalancedLut;
use super::blobs::{blobs, BallPercept};
use super::colors::{ColorClass, Lut};
use crate::camera::{Camera, Omni, Pixel};
use mrt_msgs::Image;
use nalgebra::{Point2, Point3, Vector3};

/// Points on a silhouette's outline.
const OUTLINE: usize = 32;

/// The up camera's radial scan lines for field-line points (every 11.25°).
pub const UP_RAYS: usize = 32;
/// The longest white run along a radial scan line of the up camera that is a line, pixels (a
/// 10 cm line crossed at a slant, at 50 px/m).
pub const UP_LINE_MAX_RUN: usize = 12;

/// The up mode on one omnidirectional camera: its last image's classes, and the ball and the
/// field-line points in them. The vision µAgent multiplexes it with its front camera
/// ([`super::agent::VisionAgent::see_with_up`]); `mrt vision detect` runs it alone.
#[derive(Clone, Debug)]
pub struct UpMode {
    omni: Omni,
    classes: Vec<u8>,
    balanced: BalancedLut,
}

impl UpMode {
    /// The up mode of `omni`.
    pub fn new(omni: Omni) -> UpMode {
        UpMode { omni, classes: Vec::new(), balanced: BalancedLut::default() }
    }

    /// Its camera.
    pub fn omni(&self) -> &Omni {
        &self.omni
    }

    /// The class of every pixel of the last image (`ColorClass as u8`, row after row).
    pub fn classes(&self) -> &[u8] {
        &self.classes
    }

    /// Classifies an image of its camera through `lut`, white-balanced to its carpet first
    /// ([`super::balance`]); an image of another size (or whose buffer does not hold its
    /// pixels) is refused.
    pub fn classify(&mut self, lut: &Lut, image: &Image) -> Result<(), VisionError> {
        let (w, h) = self.omni.size();
        check_size(image, (w, h))?;
        self.classes.resize(w as usize * h as usize, 0);
        self.balanced.classify(lut, &image.rgb, w as usize, &mut self.classes);
        Ok(())
    }

    /// The ball of `radius` (m) in the last image ([`find_ball_up`]).
    pub fn ball(&self, radius: f64) -> Option<BallPercept> {
        find_ball_up(&self.classes, &self.omni, radius)
    }

    /// The field-line points of the last image ([`line_points_up`], [`UP_RAYS`] scan lines).
    pub fn lines(&self) -> Vec<super::lines::LinePoint> {
        line_points_up(&self.classes, &self.omni, UP_RAYS, UP_LINE_MAX_RUN)
    }
}

/// The outline (pixels) of a ball of `radius` standing on the floor at `at` (robot frame) as
/// the mirror images it: the circle along which lines from the viewpoint touch the sphere,
/// each point cast on the floor. Empty when the ball reaches the viewpoint's height.
pub fn silhouette(omni: &Omni, at: Point2<f64>, radius: f64) -> Vec<Pixel> {
    let centre = Point3::new(at.x, at.y, radius);
    let eye = Point3::new(0.0, 0.0, omni.viewpoint);
    if !omni.viewpoint.is_finite() {
        // Orthographic: the ball's own disc.
        return (0..OUTLINE)
            .filter_map(|k| {
                let a = std::f64::consts::TAU * k as f64 / OUTLINE as f64;
                omni.project(centre + Vector3::new(radius * a.cos(), radius * a.sin(), 0.0))
            })
            .collect();
    }
    let to_ball = centre - eye;
    let l = to_ball.norm();
    if l <= radius {
        return Vec::new();
    }
    let u = to_ball / l;
    // The circle of tangency: centre on the line of sight, radius ρ, in the plane across it.
    let middle = centre - u * (radius * radius / l);
    let rho = radius * (1.0 - radius * radius / (l * l)).sqrt();
    let side = u.cross(&Vector3::z()).try_normalize(1e-12).unwrap_or_else(Vector3::x);
    let up = side.cross(&u);
    (0..OUTLINE)
        .filter_map(|k| {
            let a = std::f64::consts::TAU * k as f64 / OUTLINE as f64;
            omni.project(middle + (side * a.cos() + up * a.sin()) * rho)
        })
        .collect()
}

/// The area (px²) and the centre of mass of a polygon.
fn area_and_centroid(outline: &[Pixel]) -> Option<(f64, Pixel)> {
    let n = outline.len();
    let (mut twice, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for k in 0..n {
        let (p, q) = (outline[k], outline[(k + 1) % n]);
        let cross = p.x * q.y - q.x * p.y;
        twice += cross;
        cx += (p.x + q.x) * cross;
        cy += (p.y + q.y) * cross;
    }
    (twice.abs() > 1e-12)
        .then(|| (twice.abs() / 2.0, Pixel::new(cx / (3.0 * twice), cy / (3.0 * twice))))
}

/// The part of an outline the image can show: points beyond the mirror's reach pulled in to
/// its rim along their line from the robot, then into the image (a ball near the rim is cut,
/// and its centre of mass with it).
fn visible(omni: &Omni, outline: &[Pixel]) -> Vec<Pixel> {
    let (w, h) = omni.size();
    outline
        .iter()
        .map(|&px| {
            let px = match omni.floor_of(px) {
                Some(f) if f.coords.norm() > omni.range => {
                    let rim = Point2::from(f.coords * (omni.range / f.coords.norm()));
                    omni.project(Point3::new(rim.x, rim.y, 0.0)).unwrap_or(px)
                }
                _ => px,
            };
            Pixel::new(px.x.clamp(0.0, f64::from(w)), px.y.clamp(0.0, f64::from(h)))
        })
        .collect()
}

/// Whether the point `(x, y)` (pixels) lies inside the polygon `outline` (even-odd rule).
pub fn inside(outline: &[Pixel], (x, y): (f64, f64)) -> bool {
    let n = outline.len();
    let mut within = false;
    for k in 0..n {
        let (p, q) = (outline[k], outline[(k + n - 1) % n]);
        if (p.y > y) != (q.y > y) && x < (q.x - p.x) * (y - p.y) / (q.y - p.y) + p.x {
            within = !within;
        }
    }
    within
}

/// The ball in a class map of an omnidirectional camera (module doc): the largest ball blob
/// whose size fits the silhouette a ball of `radius` (m) casts where its centre of mass says
/// it is, with its position corrected from the centre of mass to the floor point under the
/// ball; only where the mirror images the floor. Distance and bearing from the robot's
/// centre, where the mirror stands.
pub fn find_ball_up(classes: &[u8], omni: &Omni, radius: f64) -> Option<BallPercept> {
    let (w, h) = omni.size();
    for blob in blobs(classes, w, h, ColorClass::Ball, 3) {
        let Some(target) = omni.floor_of(blob.centroid) else { continue };
        // Where a ball would have to stand for its silhouette's centre of mass to fall on the
        // blob's: start under the centre's line of sight, then move by what is left over.
        let Some(first) = omni.unproject_at_height(blob.centroid, radius) else { continue };
        let mut at = Point2::new(first.x, first.y);
        let mut area = None;
        for _ in 0..4 {
            let outline = visible(omni, &silhouette(omni, at, radius));
            let Some((a, c)) = area_and_centroid(&outline) else { break };
            let Some(model) = omni.floor_of(c) else { break };
            let shrink = if omni.viewpoint.is_finite() {
                (omni.viewpoint - radius) / omni.viewpoint
            } else {
                1.0
            };
            at += (target - model) * shrink;
            area = Some(a);
        }
        let Some(area) = area else { continue };
        if !omni.images(at) {
            continue;
        }
        if let Some(ball) =
            BallPercept::sized(blob.pixels, blob.centroid, area, at, Point2::origin())
        {
            return Some(ball);
        }
    }
    None
}

/// The field-line points an omnidirectional camera's class map shows (the µAgent's "self"
/// mode, ISocRob-2000 report §3.2.1, its first step: green/white transitions found by
/// sampling the image): `rays` radial scan lines from the robot's blind disc out to the
/// mirror's reach, evenly spread round the robot, each looking (like
/// [`super::lines::line_points`] in a front image) for runs of at most `max_run` line pixels
/// between carpet; each run's middle is a floor point, robot frame, through the mirror's
/// affine map (exact for the floor).
pub fn line_points_up(
    classes: &[u8],
    omni: &Omni,
    rays: usize,
    max_run: usize,
) -> Vec<super::lines::LinePoint> {
    let (w, h) = omni.size();
    let (w, h) = (w as usize, h as usize);
    if classes.len() < w.saturating_mul(h) || !omni.range.is_finite() {
        return Vec::new();
    }
    let (line, field) = (ColorClass::Line as u8, ColorClass::Field as u8);
    let mut out = Vec::new();
    for k in 0..rays {
        let a = std::f64::consts::TAU * k as f64 / rays.max(1) as f64;
        let (s, c) = a.sin_cos();
        // The ray's pixels, one pixel apart, from the blind disc to the reach.
        let (Some(near), Some(far)) = (
            omni.project(Point3::new(omni.blind * c, omni.blind * s, 0.0)),
            omni.project(Point3::new(omni.range * c, omni.range * s, 0.0)),
        ) else {
            continue;
        };
        let steps = (far - near).norm().ceil() as usize;
        let step = (far - near) / steps.max(1) as f64;
        let mut after_field = false;
        let mut run: Option<(Pixel, usize)> = None;
        let mut last = None;
        for i in 0..=steps {
            let p = near + step * i as f64;
            let (x, y) = (p.x.floor(), p.y.floor());
            if x < 0.0 || y < 0.0 || x >= w as f64 || y >= h as f64 {
                break;
            }
            let cell = (x as usize, y as usize);
            if last == Some(cell) {
                continue;
            }
            last = Some(cell);
            match classes[cell.1 * w + cell.0] {
                c if c == line => {
                    if after_field && run.is_none() {
                        run = Some((Pixel::new(x + 0.5, y + 0.5), 0));
                    }
                    if let Some((_, n)) = run.as_mut() {
                        *n += 1;
                    }
                }
                c if c == field => {
                    if let Some((start, n)) = run.take() {
                        let end = Pixel::new(x + 0.5, y + 0.5) - step;
                        let middle = Pixel::from((start.coords + end.coords) / 2.0);
                        if n <= max_run {
                            if let Some(at) = omni.floor_of(middle) {
                                out.push(super::lines::LinePoint { pixel: middle, at });
                            }
                        }
                    }
                    after_field = true;
                }
                _ => {
                    after_field = false;
                    run = None;
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::OmniFile;

    /// A class map with the silhouettes of balls at `balls` painted in.
    fn painted(omni: &Omni, balls: &[Point2<f64>], radius: f64) -> Vec<u8> {
        let (w, h) = omni.size();
        let mut classes = vec![ColorClass::Field as u8; (w * h) as usize];
        for at in balls {
            let outline = silhouette(omni, *at, radius);
            for row in 0..h {
                for col in 0..w {
                    let p = (f64::from(col) + 0.5, f64::from(row) + 0.5);
                    // Only what the mirror images.
                    let seen = omni.floor_of(Pixel::new(p.0, p.1)).is_some_and(|f| omni.images(f));
                    if seen && inside(&outline, p) {
                        classes[(row * w + col) as usize] = ColorClass::Ball as u8;
                    }
                }
            }
        }
        classes
    }

    /// All around the robot, from just outside the blind disc to the rim (at 4 m and more the
    /// ball's image is cut by the mirror's reach): within 2 % of the distance and 1° of the
    /// bearing. Without the silhouette's correction the centre of mass alone (through the
    /// centre's line of sight) is off by more than 2 % from 3 m on: too far (the silhouette
    /// stretches outwards), then too near (the rim cuts it).
    #[test]
    fn the_ball_is_found_all_around_within_the_mirrors_reach() {
        let omni = OmniFile::default().camera().unwrap();
        let r = 0.11;
        for (d, bearing) in [(1.3, 0.0), (2.0, 1.0), (3.0, -2.0), (4.0, 3.0), (4.2, -0.4)] {
            let at = Point2::new(d * f64::cos(bearing), d * f64::sin(bearing));
            let classes = painted(&omni, &[at], r);
            let ball = find_ball_up(&classes, &omni, r).unwrap_or_else(|| panic!("{d} m"));
            assert!((ball.distance - d).abs() < 0.02 * d, "{d} m: {ball:?}");
            let off = (ball.bearing - bearing + std::f64::consts::PI)
                .rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            assert!(off.abs() < 1f64.to_radians(), "{d} m: {ball:?}");
            let naive = omni.unproject_at_height(ball.pixel, r).unwrap();
            let naive = naive.x.hypot(naive.y);
            if d >= 3.0 {
                assert!((naive - d).abs() > 0.02 * d, "{d} m: the correction matters ({naive})");
            }
        }
    }

    #[test]
    fn no_ball_in_the_blind_disc_beyond_the_rim_or_of_the_wrong_size() {
        let omni = OmniFile::default().camera().unwrap();
        let r = 0.11;
        assert!(find_ball_up(&painted(&omni, &[], r), &omni, r).is_none());
        // 0.6 m: the robot's body hides it.
        assert!(find_ball_up(&painted(&omni, &[Point2::new(0.6, 0.0)], r), &omni, r).is_none());
        // 5 m: beyond the mirror's reach.
        assert!(find_ball_up(&painted(&omni, &[Point2::new(0.0, 5.0)], r), &omni, r).is_none());
        // A ball three times too big for where it is.
        let big = painted(&omni, &[Point2::new(2.0, 0.0)], 3.0 * r);
        assert!(find_ball_up(&big, &omni, r).is_none());
    }

    #[test]
    fn the_orthographic_mirror_sees_the_balls_disc() {
        let omni = OmniFile::default().camera().unwrap().with_mirror(f64::INFINITY, 0.0, 10.0);
        let outline = silhouette(&omni, Point2::new(2.0, 0.0), 0.1);
        let (area, c) = area_and_centroid(&outline).unwrap();
        // A disc of 0.1 m at 50 px/m: π·5² px² (the 32-gon's area is 2 % less).
        assert!((area - std::f64::consts::PI * 25.0).abs() < 0.03 * area, "{area}");
        assert!((c - Pixel::new(240.0, 140.0)).norm() < 1e-9, "{c:?}");
    }
}
