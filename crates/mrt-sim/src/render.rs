//! Camera images: what each robot's camera sees, drawn from the simulator's world
//! (the input of the ISocRob vision µAgent, ISocRob-2000 report §3.2.1).
//!
//! The world is "3-D enough": the physics is 2-D, and the renderer gives every thing a height
//! ([`RenderConfig`]). It draws, for a [`Pinhole`] camera on a robot:
//! - the **floor**: the green carpet up to the walls with the white field lines (strips of
//!   the line width) and the centre circle (a ring);
//! - the **walls** around the field and, above them, the hall;
//! - the **goals**: coloured back, sides and crossbar (the east goal yellow, the west goal
//!   blue), with height;
//! - the **landmark posts** of the field map (corners, ends of the half-way line): striped
//!   cylinders, yellow-blue-yellow on the yellow goal's side, blue-yellow-blue on the other;
//! - the **ball**, an orange sphere, and the **robots**, dark cylinders with a band of their
//!   team's colour (magenta home, cyan away).
//!
//! It is not a general ray tracer. An ideal lens without roll sees a straight line of the
//! floor along each row of pixels, evenly stepped, so the floor, the walls and the hall are
//! drawn a row at a time as spans of one colour, cut analytically where the row's floor line
//! crosses a field line, the ring or the walls (a lens with distortion falls back to a lookup
//! a pixel in a 2 cm texture of the same paint). Each object is tested only on the pixels of
//! its projected bounding box, and within a row only on the columns whose rays point at its
//! footprint, with a depth test against the other objects; robots and posts (cylinders, most
//! of what a camera sees) are traced a row at a time in `f32` in a loop the compiler
//! vectorizes. Optional effects: Gaussian noise, lighting variation, motion blur
//! ([`RenderConfig`]).
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
//! # Ok::<(), mrt_sim::SimError>(())
//! ```

use crate::config::{RenderConfig, SimConfig};
use crate::error::SimError;
use mrt_core::Pose2;
use mrt_msgs::Image;
use mrt_perception::camera::{Camera, CameraModel, Omni, Pinhole, Pixel};
use mrt_world::FieldMap;
use nalgebra::{Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::ops::Range;

mod floor;
mod solids;

use floor::{disc, fill, pixels, within, FloorPaint, Texture, ALL};
use solids::{Bands, Hits, Lit, Shape, Thing};

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
    /// What an omnidirectional camera's mirror does not image (its rim, the robot's body).
    pub const UNSEEN: [u8; 3] = [0, 0, 0];
}

/// Noise samples in the table (a power of two).
const NOISE_SAMPLES: usize = 1 << 16;

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
    scratch: Scratch,
}

/// Buffers a frame's objects pass reuses from frame to frame.
#[derive(Clone, Debug, Default)]
struct Scratch {
    /// The objects' depth per pixel (valid within this frame's objects' boxes only).
    depth: Vec<f32>,
    /// One object's hits on a run of pixels of a row ([`Hits`]).
    ts: Vec<f32>,
    zs: Vec<f32>,
    shades: Vec<f32>,
}

impl Default for CameraState {
    fn default() -> Self {
        CameraState::new(0)
    }
}

impl CameraState {
    /// A camera whose noise is drawn from `seed` (the simulator seeds one per robot).
    pub fn new(seed: u64) -> CameraState {
        CameraState {
            rng: ChaCha8Rng::seed_from_u64(seed),
            previous: None,
            scratch: Scratch::default(),
        }
    }
}

/// The flat colours of one frame, under its lighting.
struct Colours {
    carpet: [u8; 3],
    line: [u8; 3],
    wall: [u8; 3],
    hall: [u8; 3],
}

/// The rays of one row of pixels of an ideal lens: `start + k·step` for the pixel in column
/// `k` (robot frame at pan 0, not normalized). A pinhole camera without roll images each row
/// as a straight line of directions, evenly stepped, at one height component.
#[derive(Clone, Copy, Debug)]
struct RowRays {
    start: [f64; 3],
    step: [f64; 3],
}

/// The pixels' rays.
#[derive(Clone, Debug)]
enum Rays {
    /// An ideal lens: a row at a time.
    Rows(Vec<RowRays>),
    /// A distorting lens: per pixel, its ray and where the ray meets the floor, relative to
    /// the point under the camera (robot frame, pan 0; NaN at or above the horizon), and the
    /// floor as a texture.
    Pixels { rays: Vec<[f32; 3]>, floor: Vec<[f32; 2]>, texture: Texture },
}

/// Draws camera images of the simulated world. Made once per world: the floor's paint and
/// the camera's rays are computed here.
#[derive(Clone, Debug)]
pub struct Renderer {
    camera: CameraModel,
    cfg: RenderConfig,
    robot_radius: f64,
    ball_radius: f64,
    floor: FloorPaint,
    rays: Rays,
    /// Goals and posts.
    fixed: Vec<Thing>,
    /// Gaussian noise samples, σ = [`RenderConfig::noise`].
    noise: Vec<i8>,
}

impl Renderer {
    /// The renderer of `cfg`'s world, with its camera (`[vision.camera]`) and settings (`[render]`).
    pub fn new(cfg: &SimConfig) -> Result<Renderer, SimError> {
        let camera = cfg
            .vision
            .camera
            .camera()
            .map_err(|e| SimError::Config(format!("vision.camera: {e}")))?;
        Renderer::with_camera(cfg, CameraModel::Pinhole(camera))
    }

    /// The renderer of `cfg`'s world for `camera`: a pinhole camera (drawn at pan 0 and turned
    /// by [`Renderer::render`]'s `pan`), or an omnidirectional one (its mirror needs a finite
    /// viewpoint).
    pub fn with_camera(cfg: &SimConfig, camera: CameraModel) -> Result<Renderer, SimError> {
        let map = cfg.field;
        let wall = (map.half_length() + cfg.field.border, map.half_width() + cfg.field.border);
        let floor = FloorPaint::new(&map, wall, cfg.render.line_width);
        let (camera, rays) = match camera {
            CameraModel::Pinhole(camera) => {
                let camera = camera.panned(0.0);
                (CameraModel::Pinhole(camera), pinhole_rays(&camera, &floor))
            }
            CameraModel::Omni(omni) => (CameraModel::Omni(omni), Rays::Rows(omni_rays(&omni)?)),
        };
        Ok(Renderer {
            camera,
            cfg: cfg.render.clone(),
            robot_radius: cfg.body.radius,
            ball_radius: cfg.ball.radius,
            floor,
            rays,
            fixed: fixed_things(&map, cfg),
            noise: noise_table(cfg.render.noise),
        })
    }

    /// The camera it draws for (a pinhole camera at pan 0).
    pub fn camera(&self) -> &CameraModel {
        &self.camera
    }

    /// The pinhole camera it draws for, at pan 0; `None` for an omnidirectional one.
    pub fn pinhole(&self) -> Option<&Pinhole> {
        match &self.camera {
            CameraModel::Pinhole(c) => Some(c),
            CameraModel::Omni(_) => None,
        }
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
        let colours = Colours {
            carpet: light(palette::CARPET, brightness),
            line: light(palette::LINE, brightness),
            wall: light(palette::WALL, brightness),
            hall: light(palette::HALL, brightness),
        };
        // The optical centre (a mirror's viewpoint), field frame, and the rotation of the
        // camera's pan-0 robot axes into the field's (a mirror does not pan).
        let (s, c) = viewer.theta.sin_cos();
        let (eye, rot) = match &self.camera {
            CameraModel::Pinhole(cam) => {
                let m = cam.mount;
                let eye = [viewer.x + c * m.x - s * m.y, viewer.y + s * m.x + c * m.y, cam.height];
                (eye, (viewer.theta + pan).sin_cos())
            }
            CameraModel::Omni(omni) => ([viewer.x, viewer.y, omni.viewpoint], (s, c)),
        };
        let w = w as usize;
        self.draw_floor(&mut image, eye, rot, &colours);
        // The objects, each on its projected bounding box, nearest wins. They are placed
        // relative to the optical centre with the camera's axes, so that a ray needs no turn.
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
            .filter_map(|t| {
                let b = self.image_box(t.shape, viewer, pan)?;
                Some((t.shape.relative(eye, rot), t.paint, b))
            })
            .collect();
        // The depth buffer only where an object may be: cleared on those boxes alone.
        let depth = &mut state.scratch.depth;
        depth.resize(w * h as usize, f32::INFINITY);
        for buffer in [&mut state.scratch.ts, &mut state.scratch.zs, &mut state.scratch.shades] {
            buffer.resize(w, 0.0);
        }
        for (_, _, (c0, r0, c1, r1)) in &boxes {
            for row in *r0..*r1 {
                depth[row * w + c0..row * w + c1].fill(f32::INFINITY);
            }
        }
        let o = [0.0, 0.0, eye[2]];
        let Scratch { depth, ts, zs, shades } = &mut state.scratch;
        for (shape, paint, (c0, r0, c1, r1)) in boxes {
            let lit = Lit::new(&paint, brightness);
            let wedge = shape.wedge(rot);
            for row in r0..r1 {
                let cols = match &self.rays {
                    Rays::Rows(rows) => {
                        let RowRays { start, step } = rows[row];
                        let wedge = wedge
                            .map_or(ALL, |w| within(w, [start[0], start[1]], [step[0], step[1]]));
                        // A pixel of margin for rounding: the test below is exact.
                        let cols = pixels((wedge.0 - 1.0, wedge.1 + 1.0), c1);
                        cols.start.max(c0)..cols.end
                    }
                    Rays::Pixels { .. } => c0..c1,
                };
                let n = cols.len();
                if n == 0 {
                    continue;
                }
                let (ts, zs, shades) = (&mut ts[..n], &mut zs[..n], &mut shades[..n]);
                match &self.rays {
                    Rays::Rows(rows) => {
                        let RowRays { start, step } = rows[row];
                        let hits = Hits { ts, zs, shades };
                        shape.trace_row(o, (start, step), cols.start, rot, hits);
                    }
                    Rays::Pixels { rays, .. } => {
                        let rays = &rays[row * w + cols.start..row * w + cols.end];
                        for (((t, z), shade), d) in
                            ts.iter_mut().zip(zs.iter_mut()).zip(shades.iter_mut()).zip(rays)
                        {
                            (*t, *z, *shade) = Hits::of(shape.hit(o, d.map(f64::from), rot));
                        }
                    }
                }
                let pixels = row * w + cols.start..row * w + cols.end;
                let depth = &mut depth[pixels.clone()];
                let image = &mut image.rgb[3 * pixels.start..3 * pixels.end];
                for (((t, z), shade), (d, px)) in ts
                    .iter()
                    .zip(zs.iter())
                    .zip(shades.iter())
                    .zip(depth.iter_mut().zip(image.chunks_exact_mut(3)))
                {
                    if *t < *d {
                        *d = *t;
                        px.copy_from_slice(&lit.colour(*z, *shade));
                    }
                }
            }
        }
        if let (CameraModel::Omni(omni), Rays::Rows(rows)) = (&self.camera, &self.rays) {
            blind_and_rim(&mut image, omni, rows);
        }
        self.effects(&mut image, state);
        image
    }

    /// The floor, the walls and the hall: a row at a time as spans of one colour (an ideal
    /// lens), or a pixel at a time through the floor's texture (a distorting lens).
    fn draw_floor(&self, image: &mut Image, eye: [f64; 3], (s, c): (f64, f64), colours: &Colours) {
        let w = image.width as usize;
        let turn = |v: [f64; 3]| [c * v[0] - s * v[1], s * v[0] + c * v[1]];
        let wall_height = self.cfg.wall_height;
        // Paints the pixels `parts` of a row whose rays `r + k·dr` miss the floor inside the
        // walls (where the wall's top cuts the row is solved for once a row).
        let background = |px: &mut [u8], parts: [Range<usize>; 2], r, dr, rz| {
            if parts.iter().all(Range::is_empty) {
                return;
            }
            let (span, wall) = self.floor.walls(eye, r, dr, rz, wall_height);
            let (inner, outer) =
                if wall { (colours.wall, colours.hall) } else { (colours.hall, colours.wall) };
            let within = pixels(span, px.len() / 3);
            for cols in parts {
                let mid = within.start.clamp(cols.start, cols.end)
                    ..within.end.clamp(cols.start, cols.end);
                fill(px, cols.start..mid.start, outer);
                fill(px, mid.clone(), inner);
                fill(px, mid.end..cols.end, outer);
            }
        };
        match &self.rays {
            Rays::Rows(rows) => {
                for (px, ray) in image.rgb.chunks_exact_mut(3 * w).zip(rows) {
                    let (r, dr, rz) = (turn(ray.start), turn(ray.step), ray.start[2]);
                    let floor = if rz < 0.0 {
                        // The floor line that the row sees: the ray scaled to the floor.
                        let t = -eye[2] / rz;
                        let p = [eye[0] + t * r[0], eye[1] + t * r[1]];
                        let d = [t * dr[0], t * dr[1]];
                        let floor = pixels(self.floor.within_walls(p, d), w);
                        fill(px, floor.clone(), colours.carpet);
                        self.floor.lines(p, d, w, |span| {
                            let cols = pixels(span, w);
                            fill(
                                px,
                                cols.start.max(floor.start)..cols.end.min(floor.end),
                                colours.line,
                            );
                        });
                        floor
                    } else {
                        0..0
                    };
                    background(px, [0..floor.start, floor.end.max(floor.start)..w], r, dr, rz);
                }
            }
            Rays::Pixels { rays, floor, texture } => {
                for (k, px) in image.rgb.chunks_exact_mut(3).enumerate() {
                    let f = floor[k].map(f64::from);
                    let f = turn([f[0], f[1], 0.0]);
                    let p = [eye[0] + f[0], eye[1] + f[1]];
                    let colour = match texture.texel(p, self.floor.wall) {
                        Some(true) => colours.line,
                        Some(false) => colours.carpet,
                        None => {
                            let d = rays[k].map(f64::from);
                            let mut one = [0u8; 3];
                            background(&mut one, [0..1, 0..0], turn(d), [0.0, 0.0], d[2]);
                            one
                        }
                    };
                    px.copy_from_slice(&colour);
                }
            }
        }
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
        let (s, c) = viewer.theta.sin_cos();
        // The box's corners in the robot frame.
        let corners: [Point3<f64>; 8] = std::array::from_fn(|k| {
            let p = [
                if k & 1 == 0 { min[0] } else { max[0] },
                if k & 2 == 0 { min[1] } else { max[1] },
                if k & 4 == 0 { min[2] } else { max[2] },
            ];
            let (dx, dy) = (p[0] - viewer.x, p[1] - viewer.y);
            Point3::new(c * dx + s * dy, -s * dx + c * dy, p[2])
        });
        let mut lo = (f64::INFINITY, f64::INFINITY);
        let mut hi = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        let mut take = |px: Pixel| {
            if px.x.is_finite() && px.y.is_finite() {
                lo = (lo.0.min(px.x), lo.1.min(px.y));
                hi = (hi.0.max(px.x), hi.1.max(px.y));
            }
        };
        let cam = match &self.camera {
            CameraModel::Pinhole(cam) => cam.panned(pan),
            CameraModel::Omni(omni) => {
                // Straight lines from the viewpoint: the corners bound the image, unless one
                // is at or above the viewpoint (then the solid may cover any of it).
                for p in corners {
                    match omni.project(p) {
                        Some(px) => take(px),
                        None => {
                            let (w, h) = omni.size();
                            return self.clip_box((0.0, 0.0), (f64::from(w), f64::from(h)));
                        }
                    }
                }
                return self.clip_box(lo, hi);
            }
        };
        // The corners in camera axes; their z is the depth along the optical axis.
        let (rotation, centre) = (cam.robot_to_camera(), cam.centre());
        let corners = corners.map(|p| rotation * (p - centre));
        for k in 0..8 {
            let near = |k: usize| corners[k].z >= NEAR;
            let mut project = |v: Vector3<f64>| {
                if let Some(px) = cam.project_camera(v) {
                    take(px);
                }
            };
            if near(k) {
                project(corners[k]);
            }
            // The box's edges from this corner (to the corners differing in one coordinate)
            // that cross the near plane: their crossing point bounds the visible part.
            for bit in [1, 2, 4] {
                let l = k | bit;
                if l != k && near(k) != near(l) {
                    let t = (NEAR - corners[k].z) / (corners[l].z - corners[k].z);
                    project(corners[k] + (corners[l] - corners[k]) * t);
                }
            }
        }
        self.clip_box(lo, hi)
    }

    /// The pixels `(col0, row0, col1, row1)` (end exclusive) of the image within the bounds
    /// `lo`, `hi` of a solid's projection, with a margin; `None` when it misses the image.
    fn clip_box(&self, lo: (f64, f64), hi: (f64, f64)) -> Option<(usize, usize, usize, usize)> {
        if !(lo.0.is_finite() && hi.0.is_finite()) {
            return None;
        }
        let (w, h) = self.camera.size();
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

/// The rays of a pinhole camera at pan 0: a row at a time for an ideal lens, a pixel at a
/// time (with the floor's texture) for a distorting one.
fn pinhole_rays(camera: &Pinhole, floor: &FloorPaint) -> Rays {
    let (w, h) = camera.size();
    let ray = |col: f64, row: u32| camera.ray(Pixel::new(col + 0.5, f64::from(row) + 0.5));
    if camera.distortion == (0.0, 0.0) {
        return Rays::Rows(
            (0..h)
                .map(|row| {
                    let (a, b) = (ray(0.0, row), ray(1.0, row));
                    RowRays { start: a.into(), step: (b - a).into() }
                })
                .collect(),
        );
    }
    let pixels = || (0..h).flat_map(|row| (0..w).map(move |col| (f64::from(col), row)));
    let on_floor = |d: nalgebra::Vector3<f64>| {
        let t = -camera.height / d.z;
        if d.z < 0.0 && t.is_finite() {
            [(t * d.x) as f32, (t * d.y) as f32]
        } else {
            [f32::NAN; 2]
        }
    };
    Rays::Pixels {
        rays: pixels().map(|(col, row)| ray(col, row).map(|v| v as f32).into()).collect(),
        floor: pixels().map(|(col, row)| on_floor(ray(col, row))).collect(),
        texture: Texture::new(floor),
    }
}

/// The rays of an omnidirectional camera: from the mirror's viewpoint to the floor point each
/// pixel images (an affine map: a row of pixels is an evenly stepped line of the floor).
fn omni_rays(omni: &Omni) -> Result<Vec<RowRays>, SimError> {
    if !(omni.viewpoint.is_finite() && omni.viewpoint > 0.0) {
        return Err(SimError::Config(format!(
            "the mirror's viewpoint must be finite and > 0, not {}",
            omni.viewpoint
        )));
    }
    let (_, h) = omni.size();
    let floor = |col: f64, row: u32| omni.floor_of(Pixel::new(col + 0.5, f64::from(row) + 0.5));
    (0..h)
        .map(|row| {
            let (Some(a), Some(b)) = (floor(0.0, row), floor(1.0, row)) else {
                return Err(SimError::Config("the camera's affine map has no inverse".into()));
            };
            Ok(RowRays { start: [a.x, a.y, -omni.viewpoint], step: [b.x - a.x, b.y - a.y, 0.0] })
        })
        .collect()
}

/// What a mirror does not image: the floor its robot's body hides and the floor beyond its
/// reach, black (the image around a real mirror's rim). Each row of an omnidirectional image
/// sees an evenly stepped line of the floor (`rows`' rays, from the viewpoint to the floor).
fn blind_and_rim(image: &mut Image, omni: &Omni, rows: &[RowRays]) {
    let w = image.width as usize;
    for (px, ray) in image.rgb.chunks_exact_mut(3 * w).zip(rows) {
        let (p, d) = ([ray.start[0], ray.start[1]], [ray.step[0], ray.step[1]]);
        let seen = pixels(disc(p, d, omni.range * omni.range), w);
        let hidden = pixels(disc(p, d, omni.blind * omni.blind), w);
        fill(px, 0..seen.start, palette::UNSEEN);
        fill(px, seen.end..w, palette::UNSEEN);
        fill(px, hidden, palette::UNSEEN);
    }
}

/// The goals (east yellow, west blue) and the landmark posts.
fn fixed_things(map: &FieldMap, cfg: &SimConfig) -> Vec<Thing> {
    let (hl, gw, gd) = (map.half_length(), map.goal_width / 2.0, map.goal_depth);
    let (gh, t) = (cfg.render.goal_height, map.goal_wall);
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
    let (r, top) = (cfg.vision.post_radius, cfg.vision.post_height);
    for k in mrt_msgs::sighting::LANDMARK0..mrt_msgs::FIELD_OBJECTS {
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
