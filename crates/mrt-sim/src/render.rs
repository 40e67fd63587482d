//! Camera images: what each robot's camera sees, drawn from the simulator's world (issue 19,
//! the input of the ISocRob vision µAgent, seed `003` §3.2.1).
//!
//! The world is "3-D enough": the physics is 2-D, and the renderer gives every thing a height
//! ([`RenderConfig`]). It draws, for a [`Pinhole`] camera on a robot:
//! - the **floor**: the green carpet up to the walls with the white field lines and centre
//!   circle, read from a texture of the field made once (2 cm texels);
//! - the **walls** around the field and, above them, the hall;
//! - the **goals**: coloured back, sides and crossbar (the east goal yellow, the west goal
//!   blue), with height;
//! - the **landmark posts** of the field map (corners, ends of the half-way line): striped
//!   cylinders, yellow-blue-yellow on the yellow goal's side, blue-yellow-blue on the other;
//! - the **ball**, an orange sphere, and the **robots**, dark cylinders with a band of their
//!   team's colour (magenta home, cyan away).
//!
//! It is not a general ray tracer: the floor is one texture lookup per pixel, from floor points
//! that depend only on the camera and are computed once; each object is tested only on the
//! pixels of its projected bounding box, with a depth test against the other objects. Optional
//! effects: Gaussian noise, lighting variation, motion blur ([`RenderConfig`]).
//!
//! ```
//! use mrt_sim::config::SimConfig;
//! use mrt_sim::render::{Renderer, Scene};
//! use mrt_core::Pose2;
//!
//! let cfg = SimConfig::default();
//! let renderer = Renderer::new(&cfg)?;
//! let scene = Scene { ball: Some((1.0, 0.0)), robots: vec![] };
//! let image = renderer.render(&scene, Pose2::new(0.0, 0.0, 0.0), 0.0, None, &mut Default::default());
//! assert_eq!((image.width, image.height), (320, 240));
//! // The ball is 1 m straight ahead: the middle column shows its orange (shaded).
//! let orange = |p: [u8; 3]| p[0] > 150 && p[1] > 60 && p[1] < 120 && p[2] < 30;
//! assert!((0..240).filter_map(|row| image.pixel(160, row)).any(orange));
//! # Ok::<(), String>(())
//! ```

use crate::config::{RenderConfig, SimConfig};
use mrt_core::Pose2;
use mrt_msgs::Image;
use mrt_perception::camera::{Camera, Pinhole, Pixel};
use mrt_world::FieldMap;
use nalgebra::Point3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The colours of the simulated world (RGB), each one classified as its class by the shipped
/// `configs/vision/colors.toml` (a test checks it).
pub mod palette {
    /// The carpet.
    pub const CARPET: [u8; 3] = [30, 130, 50];
    /// Field lines.
    pub const LINE: [u8; 3] = [235, 235, 235];
    /// The east goal, and the outer bands of the east side's posts.
    pub const YELLOW: [u8; 3] = [225, 200, 30];
    /// The west goal, and the outer bands of the west side's posts.
    pub const BLUE: [u8; 3] = [25, 70, 190];
    /// The ball.
    pub const BALL: [u8; 3] = [250, 110, 15];
    /// Robot bodies.
    pub const ROBOT: [u8; 3] = [22, 22, 26];
    /// The home team's marker.
    pub const MAGENTA: [u8; 3] = [200, 40, 190];
    /// The away team's marker.
    pub const CYAN: [u8; 3] = [40, 190, 210];
    /// The walls around the field.
    pub const WALL: [u8; 3] = [140, 140, 140];
    /// The hall above the walls.
    pub const HALL: [u8; 3] = [90, 82, 74];
}

/// Noise samples in the table (a power of two).
const NOISE_SAMPLES: usize = 1 << 16;

/// One texel in the floor pass's fixed-point coordinates.
const FIXED_ONE: f64 = (1u64 << 32) as f64;

/// Side of a floor texel, m.
const TEXEL: f64 = 0.02;

/// What moves: the ball and the robots, field frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// The ball's centre on the floor (m), when it is on the pitch.
    pub ball: Option<(f64, f64)>,
    /// Every robot: its pose and whether it plays for the home team.
    pub robots: Vec<(Pose2, bool)>,
}

/// One camera's state between frames: its noise generator and the last frame (motion blur).
#[derive(Clone, Debug)]
pub struct CameraState {
    rng: ChaCha8Rng,
    previous: Option<Image>,
    /// The objects' depth per pixel (valid within this frame's objects' boxes only).
    depth: Vec<f64>,
}

impl Default for CameraState {
    fn default() -> Self {
        CameraState::new(0)
    }
}

impl CameraState {
    /// A camera whose noise is drawn from `seed` (the simulator seeds one per robot).
    pub fn new(seed: u64) -> CameraState {
        CameraState { rng: ChaCha8Rng::seed_from_u64(seed), previous: None, depth: Vec::new() }
    }
}

/// How a thing is painted: bands from the floor up, each to its top height (m).
#[derive(Clone, Copy, Debug)]
struct Bands {
    tops: [f64; 3],
    colours: [[u8; 3]; 3],
}

impl Bands {
    fn flat(colour: [u8; 3]) -> Bands {
        Bands { tops: [f64::INFINITY; 3], colours: [colour; 3] }
    }

    fn at(&self, z: f64) -> [u8; 3] {
        let k = self.tops.iter().position(|&t| z <= t).unwrap_or(2);
        self.colours[k]
    }
}

/// A solid the camera may see, field frame.
#[derive(Clone, Copy, Debug)]
enum Shape {
    Sphere {
        c: [f64; 3],
        r: f64,
    },
    /// Vertical, standing on the floor.
    Cylinder {
        x: f64,
        y: f64,
        r: f64,
        top: f64,
    },
    /// Axis-aligned.
    Cuboid {
        min: [f64; 3],
        max: [f64; 3],
    },
}

/// A hit: the distance along the ray (in units of the ray's length), the height hit and the
/// shading factor.
type Hit = (f64, f64, f64);

impl Shape {
    fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        match *self {
            Shape::Sphere { c, r } => {
                ([c[0] - r, c[1] - r, c[2] - r], [c[0] + r, c[1] + r, c[2] + r])
            }
            Shape::Cylinder { x, y, r, top } => ([x - r, y - r, 0.0], [x + r, y + r, top]),
            Shape::Cuboid { min, max } => (min, max),
        }
    }

    /// Where the ray `o + t·d` (t > 0) first meets the solid.
    fn hit(&self, o: [f64; 3], d: [f64; 3]) -> Option<Hit> {
        match *self {
            Shape::Sphere { c, r } => {
                let oc = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
                let a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                let b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
                let cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - r * r;
                let disc = b * b - a * cc;
                if disc < 0.0 {
                    return None;
                }
                let t = (-b - disc.sqrt()) / a;
                let z = o[2] + t * d[2];
                // Lit from above: the top bright, the underside darker.
                (t > 0.0).then(|| (t, z, 0.8 + 0.2 * (z - c[2]) / r))
            }
            Shape::Cylinder { x, y, r, top } => {
                let (ox, oy) = (o[0] - x, o[1] - y);
                let a = d[0] * d[0] + d[1] * d[1];
                let b = ox * d[0] + oy * d[1];
                let cc = ox * ox + oy * oy - r * r;
                let disc = b * b - a * cc;
                if a > 0.0 && disc >= 0.0 {
                    let t = (-b - disc.sqrt()) / a;
                    let z = o[2] + t * d[2];
                    if t > 0.0 && (0.0..=top).contains(&z) {
                        // Lit from the north-east, a little.
                        let (nx, ny) = ((ox + t * d[0]) / r, (oy + t * d[1]) / r);
                        return Some((
                            t,
                            z,
                            0.9 + 0.1 * (nx + ny) * std::f64::consts::FRAC_1_SQRT_2,
                        ));
                    }
                }
                // The top, seen from above.
                if d[2] < 0.0 {
                    let t = (top - o[2]) / d[2];
                    let (px, py) = (ox + t * d[0], oy + t * d[1]);
                    if t > 0.0 && px * px + py * py <= r * r {
                        return Some((t, top, 1.0));
                    }
                }
                None
            }
            Shape::Cuboid { min, max } => {
                let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
                for k in 0..3 {
                    if d[k] == 0.0 {
                        if o[k] < min[k] || o[k] > max[k] {
                            return None;
                        }
                        continue;
                    }
                    let (a, b) = ((min[k] - o[k]) / d[k], (max[k] - o[k]) / d[k]);
                    t0 = t0.max(a.min(b));
                    t1 = t1.min(a.max(b));
                }
                (t0 <= t1 && t0 > 0.0).then(|| (t0, o[2] + t0 * d[2], 1.0))
            }
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct Thing {
    shape: Shape,
    paint: Bands,
}

/// Where each pixel's ray meets the floor, relative to the point under the camera (robot axes,
/// pan 0, m).
#[derive(Clone, Debug)]
enum FloorMap {
    /// An ideal lens: per row, the first pixel's floor point and the step from one pixel to the
    /// next (`None`: the row is at or above the horizon).
    Rows(Vec<Option<([f32; 2], [f32; 2])>>),
    /// A distorting lens: per pixel (NaN: at or above the horizon).
    Pixels(Vec<[f32; 2]>),
}

/// Draws camera images of the simulated world. Made once per world: the floor texture and the
/// camera's rays are computed here.
#[derive(Clone, Debug)]
pub struct Renderer {
    camera: Pinhole,
    cfg: RenderConfig,
    robot_radius: f64,
    ball_radius: f64,
    /// The walls: |x| ≤ wall_x, |y| ≤ wall_y.
    wall: (f64, f64),
    /// Floor texture, row-major from (−wall_x, −wall_y), one bit a texel: 1 where a line is
    /// painted (bits: 90 KB for the default field, which stay in the cache).
    texture: Vec<u64>,
    texture_size: (usize, usize),
    /// Per pixel, the ray's direction (robot frame, pan 0).
    rays: Vec<[f32; 3]>,
    /// Where the pixels' rays meet the floor.
    floor: FloorMap,
    /// Goals and posts.
    fixed: Vec<Thing>,
    /// Gaussian noise samples, σ = [`RenderConfig::noise`].
    noise: Vec<i8>,
}

impl Renderer {
    /// The renderer of `cfg`'s world, with its camera (`[camera]`) and settings (`[render]`).
    pub fn new(cfg: &SimConfig) -> Result<Renderer, String> {
        let camera = cfg.camera.camera()?.panned(0.0);
        let map = cfg.field.map();
        let wall = (map.half_length() + cfg.field.border, map.half_width() + cfg.field.border);
        let (texture, texture_size) = floor_texture(&map, wall, cfg.render.line_width);
        let (w, h) = camera.size();
        let ray =
            |col: u32, row: u32| camera.ray(Pixel::new(f64::from(col) + 0.5, f64::from(row) + 0.5));
        let on_floor = |col: u32, row: u32| {
            let d = ray(col, row);
            let t = -camera.height / d.z;
            (d.z < 0.0 && t.is_finite()).then(|| [(t * d.x) as f32, (t * d.y) as f32])
        };
        let rays: Vec<[f32; 3]> = (0..h)
            .flat_map(|row| (0..w).map(move |col| (col, row)))
            .map(|(col, row)| ray(col, row).map(|v| v as f32).into())
            .collect();
        let floor = if camera.distortion == (0.0, 0.0) {
            FloorMap::Rows(
                (0..h)
                    .map(|row| {
                        let (a, b) = (on_floor(0, row)?, on_floor(1, row)?);
                        Some((a, [b[0] - a[0], b[1] - a[1]]))
                    })
                    .collect(),
            )
        } else {
            FloorMap::Pixels(
                (0..h)
                    .flat_map(|row| (0..w).map(move |col| (col, row)))
                    .map(|(col, row)| on_floor(col, row).unwrap_or([f32::NAN; 2]))
                    .collect(),
            )
        };
        let noise = noise_table(cfg.render.noise);
        Ok(Renderer {
            camera,
            cfg: cfg.render.clone(),
            robot_radius: cfg.robot.radius,
            ball_radius: cfg.ball.radius,
            wall,
            texture,
            texture_size,
            rays,
            floor,
            fixed: fixed_things(&map, cfg),
            noise,
        })
    }

    /// The camera at pan 0.
    pub fn camera(&self) -> &Pinhole {
        &self.camera
    }

    /// What the camera of a robot at `viewer` (field frame), its pan joint at `pan` (rad), sees
    /// of `scene`; `me` is the viewer's index in [`Scene::robots`] (its own body is not drawn).
    pub fn render(
        &self,
        scene: &Scene,
        viewer: Pose2,
        pan: f64,
        me: Option<usize>,
        state: &mut CameraState,
    ) -> Image {
        let (w, h) = self.camera.size();
        let mut image = Image::new(w, h);
        let brightness = if self.cfg.lighting > 0.0 {
            1.0 + self.cfg.lighting * state.rng.random_range(-1.0..1.0)
        } else {
            1.0
        };
        let light = |c: [u8; 3], k: f64| c.map(|v| (f64::from(v) * k).min(255.0) as u8);
        let (carpet, line) = (light(palette::CARPET, brightness), light(palette::LINE, brightness));
        let (wall, hall) = (light(palette::WALL, brightness), light(palette::HALL, brightness));
        // The optical centre and the ray rotation, field frame.
        let (s, c) = viewer.theta.sin_cos();
        let m = self.camera.mount;
        let eye = [viewer.x + c * m.x - s * m.y, viewer.y + s * m.x + c * m.y, self.camera.height];
        let (sp, cp) = (viewer.theta + pan).sin_cos();
        let (sp32, cp32) = (sp as f32, cp as f32);
        let inv = (1.0 / TEXEL) as f32;
        // Field-frame texel coordinates of a floor point given relative to the camera's foot,
        // robot axes at pan 0.
        let (ox, oy) = ((eye[0] + self.wall.0) as f32 * inv, (eye[1] + self.wall.1) as f32 * inv);
        let to_texels = |f: [f32; 2]| (cp32 * f[0] - sp32 * f[1], sp32 * f[0] + cp32 * f[1]);
        let w = w as usize;
        for (row, pixels) in image.rgb.chunks_exact_mut(3 * w).enumerate() {
            let background = |col: usize| {
                if self.wall_hit(eye, self.rays[row * w + col], cp, sp) {
                    wall
                } else {
                    hall
                }
            };
            match &self.floor {
                // Without lens distortion a row of pixels sees a straight line of the floor,
                // evenly spaced: two additions a pixel.
                FloorMap::Rows(rows) => {
                    let Some((start, step)) = rows[row] else {
                        for (col, px) in pixels.chunks_exact_mut(3).enumerate() {
                            px.copy_from_slice(&background(col));
                        }
                        continue;
                    };
                    let (sx, sy) = to_texels(start);
                    let (dx, dy) = to_texels(step);
                    // Texel coordinates in 32.32 fixed point: an integer addition a pixel.
                    let fixed = |v: f32| (f64::from(v) * FIXED_ONE).clamp(-1e18, 1e18) as i64;
                    let (mut x, mut y) = (fixed(ox + sx * inv), fixed(oy + sy * inv));
                    let (dx, dy) = (fixed(dx * inv), fixed(dy * inv));
                    let (tw, th) = (self.texture_size.0 as u64, self.texture_size.1 as u64);
                    for (col, px) in pixels.chunks_exact_mut(3).enumerate() {
                        let (i, j) = ((x >> 32) as u64, (y >> 32) as u64);
                        let colour = if i < tw && j < th {
                            let k = (j * tw + i) as usize;
                            match self.texture.get(k >> 6) {
                                Some(word) if word >> (k & 63) & 1 != 0 => line,
                                _ => carpet,
                            }
                        } else {
                            background(col)
                        };
                        px.copy_from_slice(&colour);
                        x = x.wrapping_add(dx);
                        y = y.wrapping_add(dy);
                    }
                }
                FloorMap::Pixels(floor) => {
                    let floor = &floor[row * w..(row + 1) * w];
                    for (col, (px, f)) in pixels.chunks_exact_mut(3).zip(floor).enumerate() {
                        let (fx, fy) = to_texels(*f);
                        let colour = match self.texel(ox + fx * inv, oy + fy * inv) {
                            Some(true) => line,
                            Some(false) => carpet,
                            None => background(col),
                        };
                        px.copy_from_slice(&colour);
                    }
                }
            }
        }
        // The objects, each on its projected bounding box, nearest wins.
        let mut things = Vec::with_capacity(self.fixed.len() + scene.robots.len() + 1);
        things.extend_from_slice(&self.fixed);
        if let Some((bx, by)) = scene.ball {
            let r = self.ball_radius;
            things.push(Thing {
                shape: Shape::Sphere { c: [bx, by, r], r },
                paint: Bands::flat(palette::BALL),
            });
        }
        let top = self.cfg.robot_height;
        for (k, (pose, home)) in scene.robots.iter().enumerate() {
            if Some(k) == me {
                continue;
            }
            let marker = if *home { palette::MAGENTA } else { palette::CYAN };
            things.push(Thing {
                shape: Shape::Cylinder { x: pose.x, y: pose.y, r: self.robot_radius, top },
                paint: Bands {
                    tops: [top - 0.12, top - 0.03, f64::INFINITY],
                    colours: [palette::ROBOT, marker, palette::ROBOT],
                },
            });
        }
        let boxes: Vec<_> = things
            .iter()
            .filter_map(|t| Some((t, self.image_box(t.shape, viewer, pan)?)))
            .collect();
        // The depth buffer only where an object may be: cleared on those boxes alone.
        state.depth.resize(self.rays.len(), f64::INFINITY);
        for (_, (c0, r0, c1, r1)) in &boxes {
            for row in *r0..*r1 {
                state.depth[row * w + c0..row * w + c1].fill(f64::INFINITY);
            }
        }
        for (thing, (c0, r0, c1, r1)) in boxes {
            for row in r0..r1 {
                // A convex solid covers one run of pixels in a row: past its end, the row is done.
                let mut hit_in_row = false;
                for col in c0..c1 {
                    let i = row * w + col;
                    let d0 = self.rays[i];
                    let (dx, dy) = (f64::from(d0[0]), f64::from(d0[1]));
                    let d = [cp * dx - sp * dy, sp * dx + cp * dy, f64::from(d0[2])];
                    let Some((t, z, shade)) = thing.shape.hit(eye, d) else {
                        if hit_in_row {
                            break;
                        }
                        continue;
                    };
                    if state.depth[i] <= t {
                        continue;
                    }
                    state.depth[i] = t;
                    let k = (brightness * shade * 256.0).clamp(0.0, 1024.0) as u32;
                    let colour =
                        thing.paint.at(z).map(|v| ((u32::from(v) * k) >> 8).min(255) as u8);
                    image.rgb[i * 3..i * 3 + 3].copy_from_slice(&colour);
                    hit_in_row = true;
                }
            }
        }
        self.effects(&mut image, state);
        image
    }

    /// Whether the floor texel at `(tx, ty)` (texel units from the south-west corner between the
    /// walls) shows a line; `None` beyond the walls (and for NaN: no floor).
    #[inline]
    fn texel(&self, tx: f32, ty: f32) -> Option<bool> {
        let (tw, th) = self.texture_size;
        if !(tx >= 0.0 && ty >= 0.0) {
            return None;
        }
        let (i, j) = (tx as usize, ty as usize);
        if i >= tw || j >= th {
            return None;
        }
        let k = j * tw + i;
        Some(self.texture.get(k >> 6).is_some_and(|word| word >> (k & 63) & 1 != 0))
    }

    /// Whether a ray that leaves the floor texture meets a wall below its top.
    fn wall_hit(&self, eye: [f64; 3], d: [f32; 3], c: f64, s: f64) -> bool {
        let (dx0, dy0) = (f64::from(d[0]), f64::from(d[1]));
        let (dx, dy) = (c * dx0 - s * dy0, s * dx0 + c * dy0);
        let mut t = f64::INFINITY;
        if dx != 0.0 {
            t = t.min((dx.signum() * self.wall.0 - eye[0]) / dx);
        }
        if dy != 0.0 {
            t = t.min((dy.signum() * self.wall.1 - eye[1]) / dy);
        }
        let z = eye[2] + t * f64::from(d[2]);
        t.is_finite() && z <= self.cfg.wall_height
    }

    /// The pixels `(col0, row0, col1, row1)` (end exclusive) that may show `shape`, from its
    /// bounding box clipped to the space in front of the camera; `None` when nothing of it is
    /// in front or its projection misses the image.
    fn image_box(
        &self,
        shape: Shape,
        viewer: Pose2,
        pan: f64,
    ) -> Option<(usize, usize, usize, usize)> {
        /// Points nearer to the image plane than this (m) are clipped.
        const NEAR: f64 = 0.01;
        let (min, max) = shape.bounds();
        let cam = self.camera.panned(pan);
        let (s, c) = viewer.theta.sin_cos();
        let corners: [Point3<f64>; 8] = std::array::from_fn(|k| {
            let p = [
                if k & 1 == 0 { min[0] } else { max[0] },
                if k & 2 == 0 { min[1] } else { max[1] },
                if k & 4 == 0 { min[2] } else { max[2] },
            ];
            let (dx, dy) = (p[0] - viewer.x, p[1] - viewer.y);
            Point3::new(c * dx + s * dy, -s * dx + c * dy, p[2])
        });
        let depth = corners.map(|p| cam.depth(p));
        let mut lo = (f64::INFINITY, f64::INFINITY);
        let mut hi = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        let mut take = |p: Point3<f64>| {
            if let Some(px) = cam.project(p).filter(|px| px.x.is_finite() && px.y.is_finite()) {
                lo = (lo.0.min(px.x), lo.1.min(px.y));
                hi = (hi.0.max(px.x), hi.1.max(px.y));
            }
        };
        for k in 0..8 {
            if depth[k] >= NEAR {
                take(corners[k]);
            }
            // The box's edges from this corner (to the corners differing in one coordinate)
            // that cross the near plane: their crossing point bounds the visible part.
            for bit in [1, 2, 4] {
                let l = k | bit;
                if l != k && (depth[k] >= NEAR) != (depth[l] >= NEAR) {
                    let t = (NEAR - depth[k]) / (depth[l] - depth[k]);
                    take(corners[k] + (corners[l] - corners[k]) * t);
                }
            }
        }
        if !(lo.0.is_finite() && hi.0.is_finite()) {
            return None;
        }
        let (w, h) = cam.size();
        let (wf, hf) = (f64::from(w), f64::from(h));
        // Two pixels of margin: the corners bound the solid's projection up to lens distortion.
        let clamp = |v: f64, max: f64| v.clamp(0.0, max) as usize;
        let (c0, r0) = (clamp(lo.0 - 2.0, wf), clamp(lo.1 - 2.0, hf));
        let (c1, r1) = (clamp(hi.0 + 3.0, wf), clamp(hi.1 + 3.0, hf));
        (c0 < c1 && r0 < r1).then_some((c0, r0, c1, r1))
    }

    /// Noise and motion blur.
    fn effects(&self, image: &mut Image, state: &mut CameraState) {
        if self.cfg.noise > 0.0 && !self.noise.is_empty() {
            let offset = state.rng.random_range(0..NOISE_SAMPLES);
            for (k, v) in image.rgb.iter_mut().enumerate() {
                let e = self.noise[(k + offset) & (NOISE_SAMPLES - 1)];
                *v = v.saturating_add_signed(e);
            }
        }
        if self.cfg.motion_blur > 0.0 {
            // In 1/256ths: integer arithmetic a byte.
            let keep = (self.cfg.motion_blur * 256.0).round() as u16;
            match &mut state.previous {
                Some(prev) if prev.rgb.len() == image.rgb.len() => {
                    for (v, p) in image.rgb.iter_mut().zip(prev.rgb.iter_mut()) {
                        let mixed =
                            (u16::from(*v) * (256 - keep) + u16::from(*p) * keep + 128) >> 8;
                        *v = mixed as u8;
                        *p = *v;
                    }
                    return;
                }
                _ => {}
            }
            state.previous = Some(image.clone());
        }
    }
}

/// The floor texture between the walls: 1 on the field lines and the centre circle.
fn floor_texture(map: &FieldMap, wall: (f64, f64), line_width: f64) -> (Vec<u64>, (usize, usize)) {
    let (tw, th) = ((2.0 * wall.0 / TEXEL).ceil() as usize, (2.0 * wall.1 / TEXEL).ceil() as usize);
    let mut texture = vec![0u64; (tw * th).div_ceil(64)];
    let mut paint = |k: usize| texture[k >> 6] |= 1 << (k & 63);
    let half = line_width / 2.0;
    let centre = |i: usize, j: usize| {
        (-wall.0 + (i as f64 + 0.5) * TEXEL, -wall.1 + (j as f64 + 0.5) * TEXEL)
    };
    let cells = |lo: f64, hi: f64, origin: f64, n: usize| {
        let a = (((lo + origin) / TEXEL).floor().max(0.0) as usize).min(n);
        let b = (((hi + origin) / TEXEL).ceil().max(0.0) as usize).min(n);
        a..b
    };
    for seg in map.lines() {
        let (a, b) = (seg.a, seg.b);
        let ab = b - a;
        let len2 = ab.norm_squared().max(1e-12);
        for j in cells(a.y.min(b.y) - half, a.y.max(b.y) + half, wall.1, th) {
            for i in cells(a.x.min(b.x) - half, a.x.max(b.x) + half, wall.0, tw) {
                let (x, y) = centre(i, j);
                let t = (((x - a.x) * ab.x + (y - a.y) * ab.y) / len2).clamp(0.0, 1.0);
                let (dx, dy) = (x - (a.x + t * ab.x), y - (a.y + t * ab.y));
                if dx * dx + dy * dy <= half * half {
                    paint(j * tw + i);
                }
            }
        }
    }
    let r = map.centre_circle_radius;
    if r > 0.0 {
        for j in cells(-r - half, r + half, wall.1, th) {
            for i in cells(-r - half, r + half, wall.0, tw) {
                let (x, y) = centre(i, j);
                if ((x * x + y * y).sqrt() - r).abs() <= half {
                    paint(j * tw + i);
                }
            }
        }
    }
    (texture, (tw, th))
}

/// The goals (east yellow, west blue) and the landmark posts.
fn fixed_things(map: &FieldMap, cfg: &SimConfig) -> Vec<Thing> {
    let (hl, gw, gd) = (map.half_length(), map.goal_width / 2.0, cfg.field.goal_depth);
    let (gh, t) = (cfg.render.goal_height, 0.05);
    let mut things = Vec::new();
    for (side, colour) in [(1.0, palette::YELLOW), (-1.0, palette::BLUE)] {
        let x = |a: f64, b: f64| (side * a).min(side * b)..=(side * a).max(side * b);
        let mut cuboid = |xs: std::ops::RangeInclusive<f64>, y0: f64, y1: f64, z0: f64| {
            things.push(Thing {
                shape: Shape::Cuboid { min: [*xs.start(), y0, z0], max: [*xs.end(), y1, gh] },
                paint: Bands::flat(colour),
            });
        };
        cuboid(x(hl + gd, hl + gd + t), -gw - t, gw + t, 0.0); // back
        cuboid(x(hl, hl + gd + t), gw, gw + t, 0.0); // north side
        cuboid(x(hl, hl + gd + t), -gw - t, -gw, 0.0); // south side
        cuboid(x(hl, hl + t), -gw, gw, gh - t); // crossbar
    }
    let (r, top) = (cfg.render.post_radius, cfg.render.post_height);
    for k in 3..mrt_msgs::FIELD_OBJECTS {
        let Some(p) = map.object(k) else { continue };
        let (outer, inner) = if map.east_pattern(k) == Some(true) {
            (palette::YELLOW, palette::BLUE)
        } else {
            (palette::BLUE, palette::YELLOW)
        };
        things.push(Thing {
            shape: Shape::Cylinder { x: p.x, y: p.y, r, top },
            paint: Bands {
                tops: [top / 3.0, 2.0 * top / 3.0, f64::INFINITY],
                colours: [outer, inner, outer],
            },
        });
    }
    things
}

/// 65 536 samples of N(0, σ²), rounded and clipped to ±127 (fixed seed: the frames' noise
/// differs by where each frame starts reading).
fn noise_table(sigma: f64) -> Vec<i8> {
    if sigma <= 0.0 {
        return Vec::new();
    }
    let mut rng = ChaCha8Rng::seed_from_u64(0x4d52_545f_6e6f_6973);
    (0..NOISE_SAMPLES)
        .map(|_| (crate::sensor::gauss(&mut rng) * sigma).round().clamp(-127.0, 127.0) as i8)
        .collect()
}
