//! Camera models: where a point of the world appears in the image, and which floor point a
//! pixel sees (ISocRob-2000 report §2.2 and §3.2.1: its equations 7–11, with their typos and
//! approximations fixed).
//!
//! Two models behind one trait, [`Camera`]:
//! - [`Pinhole`]: a perspective camera mounted on the robot at a height, tilted down, on a
//!   **pan joint** the robot can turn (TeamChaos' head, ThinkingCap/TeamChaos report §2.1; ISocRob's front camera
//!   is the pan-0 case), with intrinsics `(fx, fy, cx, cy)` and optional radial distortion
//!   `(k1, k2)`;
//! - [`Omni`]: ISocRob's omnidirectional "up" camera, whose mirror images the floor
//!   orthographically up to an affine map (ISocRob-2000 report §2.2): a floor point `(x, y)` of the
//!   robot frame appears at pixel `A·(x, y) + b`; a point above the floor appears where the
//!   line from the mirror's viewpoint through it meets the floor.
//!
//! A camera file names its model ([`CameraModel::from_file`]): [`CameraFile`] for a pinhole
//! camera, [`OmniFile`] for the mirror.
//!
//! Frames and units: the **robot frame** (m): x forward, y to the left, z up from the floor,
//! origin on the floor under the robot's centre. **Pixels**: `(col, row)`, the origin at the
//! top-left corner, rows growing downwards (the usual image convention; the report's `(u, v)`
//! is `u = cy − row` upwards and `v = cx − col` to the left).
//!
//! The report's inverse projection (eq. 8) is exact for the forward distance; its lateral one
//! (`y = (v/f)·√(h² + x²)`) divides by the slant range instead of the depth along the optical
//! axis and over-estimates `|y|` by `1/cos δ` off the axis. [`Pinhole`] intersects the pixel's
//! ray with the floor, which is the exact form; tests check it on worked vectors (computed
//! from the exact forms) and measure the report's error.

use nalgebra::{Matrix2, Point2, Point3, Rotation3, Vector2, Vector3};

/// The largest image side the vision accepts (larger frames are refused, not processed), and
/// so the largest a camera file may describe.
pub const MAX_SIDE: u32 = 16_384;

/// A pixel position `(col, row)`, sub-pixel, top-left origin, rows downwards.
pub type Pixel = Point2<f64>;

/// A camera's geometry: forward and inverse projection (module doc).
pub trait Camera {
    /// The image size, `(width, height)` in pixels.
    fn size(&self) -> (u32, u32);

    /// Where the point `p` (robot frame, m) appears, or `None` when the camera cannot see it
    /// (behind a pinhole camera; for [`Omni`], at or above its viewpoint). The pixel may lie
    /// outside the image: [`Camera::in_image`] says.
    fn project(&self, p: Point3<f64>) -> Option<Pixel>;

    /// The point at height `z` (m above the floor) that pixel `px` sees, robot frame, or `None`
    /// when its ray never meets that plane (at or above the horizon).
    fn unproject_at_height(&self, px: Pixel, z: f64) -> Option<Point3<f64>>;

    /// The floor point pixel `px` sees (robot frame, m), or `None` above the horizon.
    fn unproject(&self, px: Pixel) -> Option<Point2<f64>> {
        self.unproject_at_height(px, 0.0).map(|p| Point2::new(p.x, p.y))
    }

    /// Whether a pixel lies within the image.
    fn in_image(&self, px: Pixel) -> bool {
        let (w, h) = self.size();
        px.x >= 0.0 && px.y >= 0.0 && px.x < f64::from(w) && px.y < f64::from(h)
    }
}

/// A pinhole camera's intrinsics, in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Intrinsics {
    /// Focal length along the columns.
    pub fx: f64,
    /// Focal length along the rows.
    pub fy: f64,
    /// Principal point's column.
    pub cx: f64,
    /// Principal point's row.
    pub cy: f64,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
}

impl Intrinsics {
    /// A `width × height` image with focal length `f` for both axes and the principal point at
    /// the image's centre.
    pub fn centred(width: u32, height: u32, f: f64) -> Intrinsics {
        Intrinsics {
            fx: f,
            fy: f,
            cx: f64::from(width) / 2.0,
            cy: f64::from(height) / 2.0,
            width,
            height,
        }
    }
}

/// A perspective camera on a pan joint (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pinhole {
    /// Intrinsics.
    pub intrinsics: Intrinsics,
    /// Where the pan joint's axis stands (robot frame, m): x forward, y to the left.
    pub mount: Point2<f64>,
    /// The optical centre's height above the floor, m.
    pub height: f64,
    /// The optical axis below the horizontal, rad (positive: looking down).
    pub tilt: f64,
    /// The pan joint's angle, rad, counter-clockwise from straight ahead (positive: looking
    /// left).
    pub pan: f64,
    /// Radial distortion `(k1, k2)`: a normalized point at radius `r` is imaged at radius
    /// `r·(1 + k1·r² + k2·r⁴)`. `(0, 0)` for an ideal lens.
    pub distortion: (f64, f64),
}

impl Pinhole {
    /// A camera at `height` (m), tilted down by `tilt` (rad), looking straight ahead from the
    /// robot's centre, without distortion.
    pub fn new(intrinsics: Intrinsics, height: f64, tilt: f64) -> Pinhole {
        Pinhole {
            intrinsics,
            mount: Point2::origin(),
            height,
            tilt,
            pan: 0.0,
            distortion: (0.0, 0.0),
        }
    }

    /// The same camera with the pan joint at `pan` (rad).
    pub fn panned(mut self, pan: f64) -> Pinhole {
        self.pan = pan;
        self
    }

    /// Half the horizontal field of view, rad: the angle from the optical axis to the nearer
    /// side of the image, on the principal row (what a gaze control may count as in view).
    pub fn half_fov(&self) -> f64 {
        let k = &self.intrinsics;
        let side = k.cx.min(f64::from(k.width) - k.cx).max(0.0);
        (side / k.fx).atan()
    }

    /// The optical centre (robot frame, m).
    pub fn centre(&self) -> Point3<f64> {
        Point3::new(self.mount.x, self.mount.y, self.height)
    }

    /// The rotation from camera axes (x right, y down, z along the optical axis) to the robot
    /// frame: pan about z, then tilt down about the panned y axis.
    fn camera_to_robot(&self) -> Rotation3<f64> {
        // Columns: the camera's right, down and forward axes in the pan-0 level frame.
        let (s, c) = self.tilt.sin_cos();
        let axes = nalgebra::Matrix3::new(0.0, -s, c, -1.0, 0.0, 0.0, 0.0, -c, -s);
        Rotation3::from_axis_angle(&Vector3::z_axis(), self.pan)
            * Rotation3::from_matrix_unchecked(axes)
    }

    /// The direction of the ray that pixel `px` sees, from the optical centre (robot frame, not
    /// normalized: its component along the optical axis is 1).
    pub fn ray(&self, px: Pixel) -> Vector3<f64> {
        let k = &self.intrinsics;
        let n = self.undistort(Vector2::new((px.x - k.cx) / k.fx, (px.y - k.cy) / k.fy));
        self.camera_to_robot() * Vector3::new(n.x, n.y, 1.0)
    }

    /// How far in front of the optical centre the point `p` (robot frame, m) lies, along the
    /// optical axis (negative: behind the camera).
    pub fn depth(&self, p: Point3<f64>) -> f64 {
        self.to_camera(p).z
    }

    /// The point `p` (robot frame, m) in camera axes (x right, y down, z along the optical
    /// axis; origin at the optical centre).
    pub fn to_camera(&self, p: Point3<f64>) -> Vector3<f64> {
        self.robot_to_camera() * (p - self.centre())
    }

    /// The rotation from the robot frame to camera axes, for [`Pinhole::to_camera`] on many
    /// points: `rotation * (p - centre)`.
    pub fn robot_to_camera(&self) -> Rotation3<f64> {
        self.camera_to_robot().inverse()
    }

    /// The pixel at which a point given in camera axes ([`Pinhole::to_camera`]) is imaged, or
    /// `None` when it lies on or behind the image plane.
    pub fn project_camera(&self, v: Vector3<f64>) -> Option<Pixel> {
        // On or behind the image plane (a NaN point is not seen either).
        if v.z.is_nan() || v.z <= 1e-9 {
            return None;
        }
        let d = self.distort(Vector2::new(v.x / v.z, v.y / v.z));
        let k = &self.intrinsics;
        Some(Pixel::new(k.cx + k.fx * d.x, k.cy + k.fy * d.y))
    }

    /// Applies the radial distortion to a normalized point.
    fn distort(&self, n: Vector2<f64>) -> Vector2<f64> {
        let (k1, k2) = self.distortion;
        let r2 = n.norm_squared();
        n * (1.0 + k1 * r2 + k2 * r2 * r2)
    }

    /// Removes the radial distortion from a normalized point (fixed-point iteration; exact for
    /// an ideal lens).
    fn undistort(&self, d: Vector2<f64>) -> Vector2<f64> {
        let (k1, k2) = self.distortion;
        if k1 == 0.0 && k2 == 0.0 {
            return d;
        }
        let mut n = d;
        for _ in 0..30 {
            let r2 = n.norm_squared();
            let scale = 1.0 + k1 * r2 + k2 * r2 * r2;
            if !(scale.is_finite() && scale > 0.0) {
                break;
            }
            n = d / scale;
        }
        n
    }
}

impl Camera for Pinhole {
    fn size(&self) -> (u32, u32) {
        (self.intrinsics.width, self.intrinsics.height)
    }

    fn project(&self, p: Point3<f64>) -> Option<Pixel> {
        self.project_camera(self.to_camera(p))
    }

    fn unproject_at_height(&self, px: Pixel, z: f64) -> Option<Point3<f64>> {
        let ray = self.ray(px);
        let t = (z - self.height) / ray.z;
        (t.is_finite() && t > 0.0).then(|| self.centre() + ray * t)
    }
}

/// ISocRob's omnidirectional "up" camera (module doc): a floor point `(x, y)` appears at pixel
/// `A·(x, y) + b`. The mirror sees the world from a viewpoint `viewpoint` metres above the
/// robot's centre (a camera under a mirror on the robot's top): a point at height `z` appears
/// where its line from the viewpoint meets the floor, `viewpoint / (viewpoint − z)` times
/// farther out than the point itself (with `viewpoint = ∞`, every point above a floor point
/// appears at that floor point). The robot's own body hides the floor within `blind` of its
/// centre, and the mirror's rim everything beyond `range` (ISocRob: about 4.5 m, ISocRob-2000 report
/// §3.2.1 "up").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Omni {
    /// The affine map's matrix, pixels per metre.
    pub a: Matrix2<f64>,
    /// The pixel of the robot's centre.
    pub b: Vector2<f64>,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The mirror's viewpoint above the floor, m (`f64::INFINITY`: orthographic).
    pub viewpoint: f64,
    /// The floor hidden by the robot's body: within this distance of its centre, m.
    pub blind: f64,
    /// The mirror's reach: floor points farther than this from the robot's centre are not
    /// imaged, m.
    pub range: f64,
}

impl Omni {
    /// A mirror whose image has `scale` pixels per metre, the robot's centre at `centre` and
    /// the robot's forward direction towards the top of the image (x forward → rows up, y left
    /// → columns left); orthographic, seeing every floor point.
    pub fn upright(width: u32, height: u32, scale: f64, centre: Pixel) -> Omni {
        Omni {
            a: Matrix2::new(0.0, -scale, -scale, 0.0),
            b: centre.coords,
            width,
            height,
            viewpoint: f64::INFINITY,
            blind: 0.0,
            range: f64::INFINITY,
        }
    }

    /// The same mirror seen from `viewpoint` (m above the floor), imaging the floor between
    /// `blind` and `range` (m from the robot's centre).
    pub fn with_mirror(mut self, viewpoint: f64, blind: f64, range: f64) -> Omni {
        self.viewpoint = viewpoint;
        self.blind = blind;
        self.range = range;
        self
    }

    /// The floor point at which the point `p` (robot frame) appears: `p`'s own floor point
    /// pushed out by `viewpoint / (viewpoint − z)`; `None` at or above the viewpoint.
    pub fn floor_image(&self, p: Point3<f64>) -> Option<Point2<f64>> {
        let k = if self.viewpoint.is_finite() {
            let below = self.viewpoint - p.z;
            if below.is_nan() || below <= 0.0 {
                return None;
            }
            self.viewpoint / below
        } else {
            1.0
        };
        Some(Point2::new(p.x * k, p.y * k))
    }

    /// The floor point a pixel images (robot frame), or `None` for a degenerate map.
    pub fn floor_of(&self, px: Pixel) -> Option<Point2<f64>> {
        let f = self.a.try_inverse()? * (px.coords - self.b);
        Some(Point2::new(f.x, f.y))
    }

    /// Whether the mirror images the floor point `f` (robot frame): between `blind` and
    /// `range` of the robot's centre.
    pub fn images(&self, f: Point2<f64>) -> bool {
        let d = f.coords.norm();
        d >= self.blind && d <= self.range
    }
}

impl Camera for Omni {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn project(&self, p: Point3<f64>) -> Option<Pixel> {
        let f = self.floor_image(p)?;
        Some(Pixel::from(self.a * f.coords + self.b))
    }

    fn unproject_at_height(&self, px: Pixel, z: f64) -> Option<Point3<f64>> {
        let f = self.floor_of(px)?;
        // Back along the viewpoint's line from the floor point to height z.
        let k =
            if self.viewpoint.is_finite() { (self.viewpoint - z) / self.viewpoint } else { 1.0 };
        (k > 0.0).then(|| Point3::new(f.x * k, f.y * k, z))
    }
}

/// The report's ball correction (eqs 10–11): the centroid of a ball's pixels images its
/// centre, at height `radius`; where that ray meets the floor is `floor_hit`, at horizontal
/// run `r` from the camera's foot. The ball's own floor point lies on the same line at
/// `r·(1 − radius/h)` (`h`: the camera's height). **The report corrects x only; the same
/// factor applies to y**: both are scalings of the ray's run.
pub fn ball_floor_point(
    camera_foot: Point2<f64>,
    height: f64,
    floor_hit: Point2<f64>,
    radius: f64,
) -> Point2<f64> {
    camera_foot + (floor_hit - camera_foot) * (1.0 - radius / height)
}

/// The apparent diameter (pixels) of a ball of `radius` (m) whose centre is at `range` (m)
/// from the optical centre, for focal length `f` (pixels): `w = 2·radius·f / range` (the
/// report's eq. 11b divides by the range to the *floor* point, which under-estimates `w` by
/// exactly `1 − D/(2h)`, and names the diameter a radius).
pub fn ball_diameter_px(radius: f64, f: f64, range: f64) -> f64 {
    2.0 * radius * f / range
}

/// A camera file (CAMERA.toml, `mrt vision --camera`): `model = "pinhole"`, `width`, `height`,
/// `fx`, `fy`, `cx`, `cy` (pixels, rows downwards), `height_m` (the optical centre above the
/// floor), `tilt_deg` (the optical axis below the horizontal), and optionally `pan_deg` (0 =
/// straight ahead, positive to the left), `k1`, `k2` (radial distortion), `mount_x_m`,
/// `mount_y_m` (the pan axis in the robot frame). Degrees here because people measure them;
/// radians inside.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraFile {
    /// `pinhole` (the only model a file describes today).
    pub model: String,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Focal length along the columns, pixels.
    pub fx: f64,
    /// Focal length along the rows, pixels.
    pub fy: f64,
    /// Principal point's column.
    pub cx: f64,
    /// Principal point's row.
    pub cy: f64,
    /// The optical centre above the floor, m.
    pub height_m: f64,
    /// The optical axis below the horizontal, degrees.
    pub tilt_deg: f64,
    /// The pan joint, degrees (positive: looking left).
    #[serde(default)]
    pub pan_deg: f64,
    /// Radial distortion k1.
    #[serde(default)]
    pub k1: f64,
    /// Radial distortion k2.
    #[serde(default)]
    pub k2: f64,
    /// The pan axis, forward of the robot's centre, m.
    #[serde(default)]
    pub mount_x_m: f64,
    /// The pan axis, left of the robot's centre, m.
    #[serde(default)]
    pub mount_y_m: f64,
}

impl Default for CameraFile {
    /// The shipped `configs/vision/camera.toml`: a 320×240 pinhole camera 0.45 m above the
    /// floor, tilted 20° down, straight ahead from the robot's centre.
    fn default() -> Self {
        CameraFile {
            model: "pinhole".to_string(),
            width: 320,
            height: 240,
            fx: 260.0,
            fy: 260.0,
            cx: 160.0,
            cy: 120.0,
            height_m: 0.45,
            tilt_deg: 20.0,
            pan_deg: 0.0,
            k1: 0.0,
            k2: 0.0,
            mount_x_m: 0.0,
            mount_y_m: 0.0,
        }
    }
}

/// A camera file's value that no camera can have; each names the key at fault.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CameraFileError {
    /// `model` is not the file's model.
    #[error("model = {found:?}: {expected}")]
    Model {
        /// The file's `model`.
        found: String,
        /// What it may be.
        expected: &'static str,
    },
    /// The file names no model.
    #[error("no model: say model = \"pinhole\" or \"omni\"")]
    NoModel,
    /// `width` or `height` is 0 or larger than [`MAX_SIDE`].
    #[error("width and height must be 1 to {max} pixels")]
    Size {
        /// [`MAX_SIDE`].
        max: u32,
    },
    /// A value that must be a finite number is not.
    #[error("{key} must be a finite number, not {value}")]
    NotFinite {
        /// The key.
        key: &'static str,
        /// Its value.
        value: f64,
    },
    /// A value that must be a finite number > 0 is not.
    #[error("{key} must be a finite number > 0, not {value}")]
    NotPositive {
        /// The key.
        key: &'static str,
        /// Its value.
        value: f64,
    },
    /// Two values out of their ranges or order.
    #[error("{rule} (got {} and {})", got.0, got.1)]
    Range {
        /// What the two keys must be.
        rule: &'static str,
        /// Their values.
        got: (f64, f64),
    },
}

impl CameraFileError {
    /// Checks that each `(key, value)` is finite.
    fn finite(values: &[(&'static str, f64)]) -> Result<(), CameraFileError> {
        match values.iter().find(|(_, v)| !v.is_finite()) {
            Some(&(key, value)) => Err(CameraFileError::NotFinite { key, value }),
            None => Ok(()),
        }
    }

    /// Checks that each `(key, value)` is finite and > 0.
    fn positive(values: &[(&'static str, f64)]) -> Result<(), CameraFileError> {
        match values.iter().find(|(_, v)| !(v.is_finite() && *v > 0.0)) {
            Some(&(key, value)) => Err(CameraFileError::NotPositive { key, value }),
            None => Ok(()),
        }
    }

    /// Checks that an image is 1 to [`MAX_SIDE`] pixels each way.
    fn size(width: u32, height: u32) -> Result<(), CameraFileError> {
        let sides = 1..=MAX_SIDE;
        if sides.contains(&width) && sides.contains(&height) {
            Ok(())
        } else {
            Err(CameraFileError::Size { max: MAX_SIDE })
        }
    }
}

/// A camera file of type `F` parsed from `text` and checked by `check`; `file` names it in
/// errors (line and column for syntax).
fn checked_file<F: serde::de::DeserializeOwned, C>(
    text: &str,
    file: &str,
    check: impl Fn(&F) -> Result<C, CameraFileError>,
) -> Result<F, mrt_core::FileError> {
    let parsed: F = toml::from_str(text).map_err(|e| {
        mrt_core::FileError::parse(file, text, e.span().map(|s| s.start), e.message())
    })?;
    check(&parsed).map_err(|e| mrt_core::FileError::Invalid {
        file: file.to_string(),
        message: e.to_string(),
    })?;
    Ok(parsed)
}

impl CameraFile {
    /// Parses a camera file; `file` names it in errors (line and column for syntax).
    pub fn from_toml(text: &str, file: &str) -> Result<CameraFile, mrt_core::FileError> {
        checked_file(text, file, CameraFile::camera)
    }

    /// Reads a camera file.
    pub fn from_file(path: impl AsRef<std::path::Path>) -> Result<CameraFile, mrt_core::FileError> {
        let (text, file) = mrt_core::FileError::read(path.as_ref())?;
        CameraFile::from_toml(&text, &file)
    }

    /// The camera it describes, every value checked.
    pub fn camera(&self) -> Result<Pinhole, CameraFileError> {
        if self.model != "pinhole" {
            let expected = "the models are \"pinhole\"";
            return Err(CameraFileError::Model { found: self.model.clone(), expected });
        }
        CameraFileError::size(self.width, self.height)?;
        CameraFileError::finite(&[
            ("cx", self.cx),
            ("cy", self.cy),
            ("k1", self.k1),
            ("k2", self.k2),
            ("mount_x_m", self.mount_x_m),
            ("mount_y_m", self.mount_y_m),
        ])?;
        CameraFileError::positive(&[
            ("fx", self.fx),
            ("fy", self.fy),
            ("height_m", self.height_m),
        ])?;
        if !(-90.0..=90.0).contains(&self.tilt_deg) || !(-180.0..=180.0).contains(&self.pan_deg) {
            return Err(CameraFileError::Range {
                rule: "tilt_deg must be -90 to 90 and pan_deg -180 to 180",
                got: (self.tilt_deg, self.pan_deg),
            });
        }
        let intrinsics = Intrinsics {
            fx: self.fx,
            fy: self.fy,
            cx: self.cx,
            cy: self.cy,
            width: self.width,
            height: self.height,
        };
        let mut cam = Pinhole::new(intrinsics, self.height_m, self.tilt_deg.to_radians())
            .panned(self.pan_deg.to_radians());
        cam.mount = Point2::new(self.mount_x_m, self.mount_y_m);
        cam.distortion = (self.k1, self.k2);
        Ok(cam)
    }
}

/// An omnidirectional camera file (`model = "omni"`, `mrt vision --camera`): `width`, `height`
/// (pixels), `cx`, `cy` (the pixel under the robot's centre), `scale_px_per_m` (pixels per
/// metre of floor), and optionally `rotation_deg` (the robot's forward direction, counter-
/// clockwise from the top of the image; 0 by default), `mirrored` (a mirror's image is
/// reflected left-right; false by default), `viewpoint_m` (the mirror's viewpoint above the
/// floor, 0.8 by default), `blind_m` (the floor the robot's body hides around its centre, 1.0
/// by default: ISocRob's "about 1 m") and `range_m` (the mirror's reach, 4.5 by default).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OmniFile {
    /// `omni`.
    pub model: String,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// The column of the robot's centre.
    pub cx: f64,
    /// The row of the robot's centre.
    pub cy: f64,
    /// Pixels per metre of floor.
    pub scale_px_per_m: f64,
    /// The robot's forward direction in the image, degrees counter-clockwise from up.
    #[serde(default)]
    pub rotation_deg: f64,
    /// Whether the image is reflected left-right.
    #[serde(default)]
    pub mirrored: bool,
    /// The mirror's viewpoint above the floor, m.
    #[serde(default = "OmniFile::default_viewpoint")]
    pub viewpoint_m: f64,
    /// The floor hidden around the robot's centre, m.
    #[serde(default = "OmniFile::default_blind")]
    pub blind_m: f64,
    /// The mirror's reach on the floor, m.
    #[serde(default = "OmniFile::default_range")]
    pub range_m: f64,
}

impl Default for OmniFile {
    /// The shipped `configs/vision/omni.toml`: a 480×480 image, 50 px a metre, the robot's
    /// centre in the middle and its forward direction up.
    fn default() -> Self {
        OmniFile {
            model: "omni".to_string(),
            width: 480,
            height: 480,
            cx: 240.0,
            cy: 240.0,
            scale_px_per_m: 50.0,
            rotation_deg: 0.0,
            mirrored: false,
            viewpoint_m: OmniFile::default_viewpoint(),
            blind_m: OmniFile::default_blind(),
            range_m: OmniFile::default_range(),
        }
    }
}

impl OmniFile {
    fn default_viewpoint() -> f64 {
        0.8
    }

    fn default_blind() -> f64 {
        1.0
    }

    fn default_range() -> f64 {
        4.5
    }

    /// Parses an omnidirectional camera file; `file` names it in errors (line and column for
    /// syntax).
    pub fn from_toml(text: &str, file: &str) -> Result<OmniFile, mrt_core::FileError> {
        checked_file(text, file, OmniFile::camera)
    }

    /// Reads an omnidirectional camera file.
    pub fn from_file(path: impl AsRef<std::path::Path>) -> Result<OmniFile, mrt_core::FileError> {
        let (text, file) = mrt_core::FileError::read(path.as_ref())?;
        OmniFile::from_toml(&text, &file)
    }

    /// The camera it describes, every value checked.
    pub fn camera(&self) -> Result<Omni, CameraFileError> {
        if self.model != "omni" {
            let expected = "an omnidirectional camera file says \"omni\"";
            return Err(CameraFileError::Model { found: self.model.clone(), expected });
        }
        CameraFileError::size(self.width, self.height)?;
        CameraFileError::finite(&[
            ("cx", self.cx),
            ("cy", self.cy),
            ("rotation_deg", self.rotation_deg),
        ])?;
        CameraFileError::positive(&[
            ("scale_px_per_m", self.scale_px_per_m),
            ("viewpoint_m", self.viewpoint_m),
        ])?;
        if !(self.blind_m.is_finite() && self.blind_m >= 0.0 && self.range_m.is_finite())
            || self.range_m <= self.blind_m
        {
            return Err(CameraFileError::Range {
                rule: "blind_m must be ≥ 0 and less than range_m",
                got: (self.blind_m, self.range_m),
            });
        }
        let centre = Pixel::new(self.cx, self.cy);
        let mut cam = Omni::upright(self.width, self.height, self.scale_px_per_m, centre);
        // Turn the image by the rotation (counter-clockwise on the screen, whose rows grow
        // downwards), after an optional left-right reflection.
        let (s, c) = self.rotation_deg.to_radians().sin_cos();
        let turn = Matrix2::new(c, s, -s, c);
        let flip = Matrix2::new(if self.mirrored { -1.0 } else { 1.0 }, 0.0, 0.0, 1.0);
        cam.a = turn * flip * cam.a;
        Ok(cam.with_mirror(self.viewpoint_m, self.blind_m, self.range_m))
    }
}

/// A camera of either model, from a camera file whose `model` names it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CameraModel {
    /// `model = "pinhole"` ([`CameraFile`]).
    Pinhole(Pinhole),
    /// `model = "omni"` ([`OmniFile`]).
    Omni(Omni),
}

impl CameraModel {
    /// Parses a camera file of either model; `file` names it in errors (line and column for
    /// syntax).
    pub fn from_toml(text: &str, file: &str) -> Result<CameraModel, mrt_core::FileError> {
        let parse = |e: toml::de::Error| {
            mrt_core::FileError::parse(file, text, e.span().map(|s| s.start), e.message())
        };
        let table: toml::Table = toml::from_str(text).map_err(parse)?;
        let invalid = |e: CameraFileError| mrt_core::FileError::Invalid {
            file: file.to_string(),
            message: e.to_string(),
        };
        match table.get("model").and_then(|m| m.as_str()) {
            Some("omni") => {
                let f: OmniFile = toml::from_str(text).map_err(parse)?;
                f.camera().map(CameraModel::Omni).map_err(invalid)
            }
            Some("pinhole") => {
                let f: CameraFile = toml::from_str(text).map_err(parse)?;
                f.camera().map(CameraModel::Pinhole).map_err(invalid)
            }
            Some(other) => Err(invalid(CameraFileError::Model {
                found: other.to_string(),
                expected: "the models are \"pinhole\" and \"omni\"",
            })),
            None => Err(invalid(CameraFileError::NoModel)),
        }
    }

    /// Reads a camera file of either model.
    pub fn from_file(
        path: impl AsRef<std::path::Path>,
    ) -> Result<CameraModel, mrt_core::FileError> {
        let (text, file) = mrt_core::FileError::read(path.as_ref())?;
        CameraModel::from_toml(&text, &file)
    }

    /// The image size, `(width, height)` in pixels.
    pub fn size(&self) -> (u32, u32) {
        match self {
            CameraModel::Pinhole(c) => c.size(),
            CameraModel::Omni(c) => c.size(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_core::frames::metres;
    use proptest::prelude::*;

    /// A worked example of the report's front camera: h = 450 mm and f = 400 px (example
    /// values: the report does not give them), the optical axis meets the floor c = 625 mm
    /// ahead (the report's value). In metres here.
    fn isocrob_front() -> Pinhole {
        let (h, c) = (0.45, 0.625);
        Pinhole::new(Intrinsics::centred(640, 480, 400.0), h, (h / c).atan())
    }

    /// The report's (u, v): u upwards from the centre, v to the left.
    fn report_uv(cam: &Pinhole, px: Pixel) -> (f64, f64) {
        (cam.intrinsics.cy - px.y, cam.intrinsics.cx - px.x)
    }

    #[test]
    fn the_worked_vectors_project_and_come_back() {
        let cam = isocrob_front();
        // floor (x, y) mm → (u, v) px, computed from the exact forward model.
        for ((x, y), (u, v)) in [
            ((1000.0, 200.0), (81.571, 74.455)),
            ((625.0, 300.0), (0.0, 155.815)),
            ((3000.0, 500.0), (205.776, 74.142)),
        ] {
            let p = Point3::new(metres(x), metres(y), 0.0);
            let px = cam.project(p).unwrap();
            let (pu, pv) = report_uv(&cam, px);
            assert!((pu - u).abs() < 1e-3 && (pv - v).abs() < 1e-3, "({x}, {y}): {pu} {pv}");
            let back = cam.unproject(px).unwrap();
            assert!((back.x - p.x).abs() < 1e-9 && (back.y - p.y).abs() < 1e-9, "{back:?}");
        }
    }

    /// The report's lateral inverse (eq. 8's y = (v/f)·√(h² + x²)) is not the pinhole one: at
    /// (3000, 500) mm it gives 562.283 mm; the model gives 500.
    #[test]
    fn the_reports_lateral_formula_overestimates_off_axis() {
        let cam = isocrob_front();
        let px = cam.project(Point3::new(3.0, 0.5, 0.0)).unwrap();
        let (_, v) = report_uv(&cam, px);
        let x = cam.unproject(px).unwrap().x;
        let report_y = v / 400.0 * (0.45f64.powi(2) + x * x).sqrt();
        assert!((report_y - 0.562283).abs() < 1e-5, "{report_y}");
        assert!((cam.unproject(px).unwrap().y - 0.5).abs() < 1e-9);
    }

    #[test]
    fn above_the_horizon_there_is_no_floor() {
        let cam = isocrob_front();
        // The horizon is u = f·h/c = 288 px above the centre: row 240 − 288 < 0, outside this
        // image; with the camera level, the horizon is the centre row.
        assert!(cam.unproject(Pixel::new(320.0, 0.0)).is_some());
        let level = Pinhole::new(Intrinsics::centred(640, 480, 400.0), 0.45, 0.0);
        assert!(level.unproject(Pixel::new(320.0, 240.0)).is_none(), "the horizon");
        assert!(level.unproject(Pixel::new(320.0, 100.0)).is_none(), "above it");
        assert!(level.unproject(Pixel::new(320.0, 300.0)).is_some());
        // A point behind the camera is not seen.
        assert!(level.project(Point3::new(-1.0, 0.0, 0.0)).is_none());
    }

    /// A worked test vector: camera at h = 0.45 m, ball of diameter 0.22 m centred at
    /// 1.5 m: its centre's ray meets the floor at 1.985294 m, the correction gives 1.5 back;
    /// the exact apparent diameter is 57.215 px (the report's formula: 43.229).
    #[test]
    fn ball_correction_and_size_by_the_worked_vector() {
        let (h, f, radius) = (0.45, 400.0, 0.11);
        let cam = Pinhole::new(Intrinsics::centred(640, 480, f), h, 0.0);
        let centre = Point3::new(1.5, 0.0, radius);
        let px = cam.project(centre).unwrap();
        let hit = cam.unproject_at_height(Pixel::new(px.x, px.y + 1e-9), 0.0);
        // (A level camera's centre ray is horizontal at the ball's height below it.)
        let hit = hit.map(|p| Point2::new(p.x, p.y)).unwrap();
        assert!((hit.x - 1.985294).abs() < 1e-5, "{hit:?}");
        let b = ball_floor_point(Point2::origin(), h, hit, radius);
        assert!((b.x - 1.5).abs() < 1e-6 && b.y.abs() < 1e-9);
        let range = (centre - cam.centre()).norm();
        assert!((ball_diameter_px(radius, f, range) - 57.215).abs() < 1e-3);
        let report = 2.0 * radius * f / (h * h + hit.x * hit.x).sqrt();
        assert!((report - 43.229).abs() < 1e-3, "{report}");
    }

    /// The lateral correction applies to y too (the report corrects x only): a ball off to the
    /// side.
    #[test]
    fn the_ball_correction_scales_y_as_well() {
        let cam = isocrob_front();
        let centre = Point3::new(1.2, -0.4, 0.11);
        let px = cam.project(centre).unwrap();
        let hit = cam.unproject(px).unwrap();
        let b = ball_floor_point(Point2::origin(), cam.height, hit, 0.11);
        assert!((b.x - 1.2).abs() < 1e-9 && (b.y + 0.4).abs() < 1e-9, "{b:?}");
        // Correcting x only (the report) leaves y wrong by the same factor.
        assert!((hit.y + 0.4).abs() > 0.05);
    }

    #[test]
    fn a_panned_camera_sees_to_its_side() {
        let cam = isocrob_front().panned(std::f64::consts::FRAC_PI_2);
        // Looking left: a floor point 0.625 m to the left is at the image centre.
        let px = cam.project(Point3::new(0.0, 0.625, 0.0)).unwrap();
        assert!((px.x - 320.0).abs() < 1e-9 && (px.y - 240.0).abs() < 1e-9, "{px:?}");
        assert!(cam.project(Point3::new(0.0, -1.0, 0.0)).is_none(), "behind it now");
    }

    #[test]
    fn the_omni_camera_maps_the_floor_affinely() {
        let cam = Omni::upright(480, 480, 100.0, Pixel::new(240.0, 240.0));
        // 1 m ahead: 100 px up; 0.5 m to the left: 50 px left.
        let px = cam.project(Point3::new(1.0, 0.5, 0.3)).unwrap();
        assert_eq!((px.x, px.y), (190.0, 140.0));
        let back = cam.unproject(px).unwrap();
        assert!((back.x - 1.0).abs() < 1e-12 && (back.y - 0.5).abs() < 1e-12);
        assert!(cam.in_image(px) && !cam.in_image(Pixel::new(-1.0, 3.0)));
    }

    /// Seen from a viewpoint 0.8 m up, a point 0.4 m high appears twice as far out as its
    /// own floor point (0.8 / (0.8 − 0.4)); unprojected at its height it comes back.
    #[test]
    fn the_mirror_pushes_raised_points_out_along_its_viewpoints_lines() {
        let cam =
            Omni::upright(480, 480, 100.0, Pixel::new(240.0, 240.0)).with_mirror(0.8, 0.5, 4.5);
        let px = cam.project(Point3::new(1.0, 0.5, 0.4)).unwrap();
        assert!((px.x - 140.0).abs() < 1e-9 && (px.y - 40.0).abs() < 1e-9, "{px:?}");
        let back = cam.unproject_at_height(px, 0.4).unwrap();
        assert!((back - Point3::new(1.0, 0.5, 0.4)).norm() < 1e-12, "{back:?}");
        assert!(cam.project(Point3::new(1.0, 0.0, 0.8)).is_none(), "at the viewpoint's height");
        assert!(cam.images(Point2::new(0.0, 1.0)) && !cam.images(Point2::new(0.3, 0.0)));
        assert!(!cam.images(Point2::new(4.0, 3.0)), "5 m: beyond the mirror's reach");
    }

    #[test]
    fn omni_files_read_turn_and_reflect_and_say_where_they_are_wrong() {
        let shipped = concat!(env!("CARGO_MANIFEST_DIR"), "/../../configs/vision/omni.toml");
        let CameraModel::Omni(cam) = CameraModel::from_file(shipped).unwrap() else {
            panic!("the shipped omni file is an omni camera")
        };
        assert_eq!(cam, OmniFile::default().camera().unwrap());
        // 1 m ahead: 50 px up from the centre.
        let px = cam.project(Point3::new(1.0, 0.0, 0.0)).unwrap();
        assert!((px.x - 240.0).abs() < 1e-9 && (px.y - 190.0).abs() < 1e-9, "{px:?}");
        // Forward turned 90° counter-clockwise on the screen: ahead is to the left.
        let turned = OmniFile { rotation_deg: 90.0, ..OmniFile::default() }.camera().unwrap();
        let px = turned.project(Point3::new(1.0, 0.0, 0.0)).unwrap();
        assert!((px.x - 190.0).abs() < 1e-9 && (px.y - 240.0).abs() < 1e-9, "{px:?}");
        // Reflected: the left appears on the right.
        let mirrored = OmniFile { mirrored: true, ..OmniFile::default() }.camera().unwrap();
        let px = mirrored.project(Point3::new(0.0, 1.0, 0.0)).unwrap();
        assert!((px.x - 290.0).abs() < 1e-9 && (px.y - 240.0).abs() < 1e-9, "{px:?}");
        let text = "model = \"omni\"\nwidth = 480\nheight = 480\ncx = 240.0\ncy = 240.0\n\
                    scale_px_per_m = 50.0\n";
        assert!(matches!(CameraModel::from_toml(text, "o.toml"), Ok(CameraModel::Omni(_))));
        let e = CameraModel::from_toml(&format!("{text}range_m = 0.5\n"), "o.toml").unwrap_err();
        assert!(e.to_string().contains("blind_m must be ≥ 0 and less than range_m"), "{e}");
        let e = CameraModel::from_toml(&format!("{text}fx = 3.0\n"), "o.toml").unwrap_err();
        assert!(e.to_string().contains("o.toml:7:"), "{e}");
        let e = CameraModel::from_toml(&text.replace("omni", "fisheye"), "o.toml").unwrap_err();
        assert!(e.to_string().contains("the models are \"pinhole\" and \"omni\""), "{e}");
        let e = CameraModel::from_toml("width = 3\n", "o.toml").unwrap_err();
        assert!(e.to_string().contains("no model"), "{e}");
        // The MuJoCo world's IANUS3 camera: 32 px a metre, blind only under the body.
        let ianus = concat!(env!("CARGO_MANIFEST_DIR"), "/../../configs/vision/omni-ianus3.toml");
        let file = OmniFile::from_file(ianus).unwrap();
        assert_eq!((file.width, file.scale_px_per_m, file.blind_m), (320, 32.0, 0.3));
        let e = OmniFile::from_toml(&format!("{text}range_m = 0.5\n"), "o.toml").unwrap_err();
        assert!(e.to_string().contains("blind_m must be"), "{e}");
        let e = OmniFile::from_toml("model = \"omni\"\nwidth = \"wide\"\n", "o.toml").unwrap_err();
        assert!(e.to_string().contains("o.toml:2:"), "{e}");
    }

    #[test]
    fn camera_files_read_and_say_where_they_are_wrong() {
        let text = "model = \"pinhole\"\nwidth = 320\nheight = 240\nfx = 260.0\nfy = 260.0\n\
                    cx = 160.0\ncy = 120.0\nheight_m = 0.45\ntilt_deg = 20.0\n";
        let cam = CameraFile::from_toml(text, "cam.toml").unwrap().camera().unwrap();
        assert!((cam.tilt - 20f64.to_radians()).abs() < 1e-12 && cam.pan == 0.0);
        let shipped = concat!(env!("CARGO_MANIFEST_DIR"), "/../../configs/vision/camera.toml");
        assert_eq!(CameraFile::from_file(shipped).unwrap(), CameraFile::default());
        let e = CameraFile::from_toml(&text.replace("fx = 260.0", "fx = -1.0"), "c.toml");
        assert_eq!(e.unwrap_err().to_string(), "c.toml: fx must be a finite number > 0, not -1");
        let e = CameraFile::from_toml(&format!("{text}roll_deg = 3\n"), "c.toml").unwrap_err();
        assert!(e.to_string().starts_with("c.toml:10:1: unknown field `roll_deg`"), "{e}");
        let e = CameraFile::from_toml(&text.replace("pinhole", "fisheye"), "c.toml").unwrap_err();
        assert!(e.to_string().contains("the models are \"pinhole\""), "{e}");
    }

    #[test]
    fn a_camera_file_s_errors_name_the_key_and_escape_the_model() {
        let bad = |f: CameraFile| f.camera().unwrap_err();
        let e = bad(CameraFile { model: "pin\u{1b}[2Jhole".into(), ..CameraFile::default() });
        assert!(matches!(e, CameraFileError::Model { .. }) && !e.to_string().contains('\u{1b}'));
        assert_eq!(
            bad(CameraFile { width: 0, ..CameraFile::default() }),
            CameraFileError::Size { max: MAX_SIDE }
        );
        let e = bad(CameraFile { k1: f64::INFINITY, ..CameraFile::default() });
        assert!(matches!(e, CameraFileError::NotFinite { key: "k1", .. }), "{e}");
        let e = bad(CameraFile { height_m: 0.0, ..CameraFile::default() });
        assert!(matches!(e, CameraFileError::NotPositive { key: "height_m", .. }), "{e}");
        let e = bad(CameraFile { tilt_deg: 95.0, ..CameraFile::default() });
        assert_eq!(
            e.to_string(),
            "tilt_deg must be -90 to 90 and pan_deg -180 to 180 (got 95 and 0)"
        );
        let e = OmniFile { viewpoint_m: f64::NAN, ..OmniFile::default() }.camera().unwrap_err();
        assert!(matches!(e, CameraFileError::NotPositive { key: "viewpoint_m", .. }), "{e}");
    }

    proptest! {
        /// Random text never panics the camera file's parser.
        #[test]
        fn random_camera_files_are_parsed_or_refused(text in "\\PC{0,300}") {
            let _ = CameraFile::from_toml(&text, "fuzz.toml");
        }

        /// Every floor point in view comes back from its pixel, with any pan, tilt, height and a
        /// mild lens distortion.
        #[test]
        fn pinhole_round_trips(x in 0.3f64..6.0, y in -3.0f64..3.0, h in 0.2f64..1.0,
                               tilt in 0.1f64..1.2, pan in -1.0f64..1.0,
                               k1 in -0.1f64..0.1, k2 in -0.02f64..0.02) {
            let mut cam = Pinhole::new(Intrinsics::centred(640, 480, 500.0), h, tilt).panned(pan);
            cam.distortion = (k1, k2);
            let p = Point3::new(x, y, 0.0);
            // Only where the lens model is meant to hold: within 0.8 (about 39°) of the axis,
            // where the distortion is one-to-one.
            let ideal = Pinhole { distortion: (0.0, 0.0), ..cam };
            let k = cam.intrinsics;
            let undistorted = ideal.project(p).map(|q| (q.x - k.cx).hypot(q.y - k.cy) / k.fx);
            prop_assume!(undistorted.is_some_and(|r| r < 0.8));
            let px = cam.project(p).unwrap();
            let back = cam.unproject(px).unwrap();
            let tol = 1e-6 * (1.0 + x * x);
            prop_assert!((back.x - x).abs() < tol && (back.y - y).abs() < tol,
                         "{back:?} for ({x}, {y})");
        }

        #[test]
        fn omni_round_trips(
            x in -5.0f64..5.0, y in -5.0f64..5.0, z in 0.0f64..0.7, s in 10.0f64..200.0,
            rotation in -180.0f64..180.0, mirrored: bool,
        ) {
            let file = OmniFile { scale_px_per_m: s, rotation_deg: rotation, mirrored, ..OmniFile::default() };
            let cam = file.camera().unwrap();
            let back = cam.unproject_at_height(cam.project(Point3::new(x, y, z)).unwrap(), z).unwrap();
            prop_assert!((back.x - x).abs() < 1e-9 && (back.y - y).abs() < 1e-9);
        }

        /// Random bytes as a camera file: an error or a camera, never a panic.
        #[test]
        fn camera_model_files_never_panic(text in ".{0,200}") {
            let _ = CameraModel::from_toml(&text, "random.toml");
            let with_model = format!("model = \"omni\"\n{text}");
            let _ = CameraModel::from_toml(&with_model, "random.toml");
        }
    }
}
