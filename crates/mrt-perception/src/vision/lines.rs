//! Field-line points for localization (ISocRob-2000 report §3.2.1, the "self" mode: green/white
//! transitions found by sampling the image, fed to a line extraction).
//!
//! Scan lines: every `step`-th column, from the bottom of the image up (near to far), looking
//! for a run of line pixels between carpet pixels: green, then white for at most `max_run`
//! pixels, then green again. Each run gives one point: its middle pixel and, through the camera,
//! its floor point. Requiring carpet on both sides leaves out white that is not a line (a
//! robot's marker, the goal's posts against the wall).

use super::colors::ColorClass;
use crate::camera::{Camera, Pinhole, Pixel};
use nalgebra::Point2;

/// One point of a field line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinePoint {
    /// The middle of the white run.
    pub pixel: Pixel,
    /// Its floor point (robot frame, m).
    pub at: Point2<f64>,
}

/// The field-line points of a class map seen by `camera` (module doc): every `step`-th column
/// (at least 1), runs of at most `max_run` line pixels between carpet.
pub fn line_points(
    classes: &[u8],
    camera: &Pinhole,
    step: usize,
    max_run: usize,
) -> Vec<LinePoint> {
    let (w, h) = camera.size();
    let (w, h) = (w as usize, h as usize);
    if classes.len() < w.saturating_mul(h) {
        return Vec::new();
    }
    let (line, field) = (ColorClass::Line as u8, ColorClass::Field as u8);
    let mut out = Vec::new();
    for x in (0..w).step_by(step.max(1)) {
        // From the bottom up: the last carpet row seen, and the start of a white run after it.
        let mut after_field = false;
        let mut run_start: Option<usize> = None;
        for y in (0..h).rev() {
            let c = classes[y * w + x];
            if c == line {
                if after_field && run_start.is_none() {
                    run_start = Some(y);
                }
            } else if c == field {
                if let Some(start) = run_start.take() {
                    let len = start - y;
                    if len <= max_run {
                        let pixel = Pixel::new(x as f64 + 0.5, (y + 1 + start) as f64 / 2.0 + 0.5);
                        if let Some(at) = camera.unproject(pixel) {
                            out.push(LinePoint { pixel, at });
                        }
                    }
                }
                after_field = true;
            } else {
                after_field = false;
                run_start = None;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Intrinsics;
    use nalgebra::Point3;

    /// A white line across the floor 2 m ahead (5 cm wide), seen by a camera: every scan line
    /// finds one point on it, at 2 m; a white blob touching the image's edge, with no carpet
    /// above it, gives none.
    #[test]
    fn a_line_across_the_floor_is_found_where_it_is() {
        let cam = Pinhole::new(Intrinsics::centred(320, 240, 260.0), 0.45, 0.35);
        let (w, h) = (320usize, 240usize);
        let mut m = vec![ColorClass::Field as u8; w * h];
        let near = cam.project(Point3::new(1.975, 0.0, 0.0)).unwrap().y as usize;
        let far = cam.project(Point3::new(2.025, 0.0, 0.0)).unwrap().y as usize;
        for y in far..=near {
            for x in 0..w {
                m[y * w + x] = ColorClass::Line as u8;
            }
        }
        // White up to the top edge on the right: not between carpet.
        for y in 0..10 {
            for x in 300..w {
                m[y * w + x] = ColorClass::Line as u8;
            }
        }
        let pts = line_points(&m, &cam, 10, 12);
        assert_eq!(pts.len(), 32, "one point per scan line");
        for p in &pts {
            assert!((p.at.x - 2.0).abs() < 0.08, "{p:?}");
        }
        // A white region too tall to be a line at that distance: no point.
        assert!(line_points(&m, &cam, 10, 1).is_empty());
        assert!(line_points(&m[..10], &cam, 10, 12).is_empty(), "a map of the wrong size");
    }
}
