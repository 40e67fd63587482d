//! The vision µAgent (ISocRob-2000 report §3.2.1): one camera image in, [`Percepts`] out. The
//! pieces of this module put together: the colour lookup table, the ball (size test and centre
//! correction), the goals, the field-line points, other robots with their team markers.
//!
//! The nets of the world model's sightings ([`mrt_msgs::CameraFrame::sightings`]) are the
//! centres of the goal lines. The goal's outermost columns whose lowest goal pixel has carpet
//! right below it are the feet of its posts (or of a back corner, seen obliquely); the net is
//! the middle of those two floor points, when they are about a goal's width apart. Which colour
//! is the east goal is the field's, not the camera's: [`VisionAgent::east_goal`] (yellow by
//! default, as the simulator paints it). A goal that touches the image's side is not reported
//! (where its far end stands is unknown), and the columns of the landmark posts
//! ([`super::posts`]), whose bands wear the goal colours, do not count as goal.

use super::balance::BalancedLut;
use super::blobs::{find_ball, BallPercept};
use super::colors::{ColorClass, ColorTable, Lut};
use super::goals::{find_goal, goal_columns, GoalPercept};
use super::lines::line_points;
use super::posts::{find_posts_in, PostPercept, PostShape};
use super::up::UpMode;
use crate::camera::{Camera, Omni, Pinhole, Pixel};
use mrt_core::frames::Framed;
use mrt_msgs::sighting::{BALL, EAST_NET, WEST_NET};
use mrt_msgs::{
    DetectionKind, Image, ImageDetection, ImageDetections, Marker, Percepts, PostSighting,
    RobotSighting, Sighting,
};
use nalgebra::{Point2, Point3, Vector2};

/// Pixels a goal must show to count.
pub const MIN_GOAL_PIXELS: u32 = 30;
/// Rows by which a goal's lowest pixel drops from one column to the next, at least, where a
/// goal's side slants in the image (its floor edge drops less).
pub const SLANT_STEP: f64 = 3.0;
/// Obstacle scan lines: every this many columns.
pub const OBSTACLE_STEP: usize = 4;
/// Robot pixels in a row, up a column, that make a robot's foot.
pub const OBSTACLE_MIN_RUN: usize = 3;
/// Neighbouring obstacle feet closer than this on the floor are one robot, m.
pub const SAME_ROBOT: f64 = 0.4;
/// Marker pixels a robot must show, up its scanned columns, for its team to be told.
pub const MARKER_MIN_PIXELS: u32 = 2;
/// Pixels of neither the robot's body nor a marker (edges, blur) crossed going up a robot
/// before its top is taken as reached.
pub const MARKER_GAP: usize = 2;
/// How high above its foot, at least, a robot's body (its dark and marker pixels) must reach
/// in the image, m: a shadow on the carpet or the dark band at a wall's foot is as dark as a
/// robot but lies flat or low (the body is dark up to its marker band, 0.48 m).
pub const ROBOT_MIN_RISE: f64 = 0.3;
/// Field-line scan lines: every this many columns.
pub const LINE_STEP: usize = 8;
/// The longest white run that is a line, pixels.
pub const LINE_MAX_RUN: usize = 24;

/// Why an image was not processed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum VisionError {
    /// The image is not the camera's size, or its buffer does not hold its pixels.
    #[error("the image is {width}×{height} with {bytes} bytes; the camera takes {cam_w}×{cam_h}")]
    WrongSize {
        /// Its width.
        width: u32,
        /// Its height.
        height: u32,
        /// Its buffer's length.
        bytes: usize,
        /// The camera's width.
        cam_w: u32,
        /// The camera's height.
        cam_h: u32,
    },
}

/// A goal seen whole (see [`VisionAgent::net`]).
struct Net {
    /// The middle of its outermost columns' floor points (robot frame, m).
    at: Point2<f64>,
    /// One of those feet's pixels.
    foot: Pixel,
    /// The goal's pixel count.
    pixels: u32,
    /// Its box in the image: from its first to its last column, from its feet up by its
    /// columns' mean height.
    shown: ImageDetection,
}

/// Everything the µAgent found in one image ([`VisionAgent::look`]): the percepts, and the
/// objects in the image's own terms (pixels, radii, columns) for tools that draw or print
/// them.
#[derive(Clone, Debug, PartialEq)]
pub struct Sight {
    /// What the robot's world model gets.
    pub percepts: Percepts,
    /// The ball.
    pub ball: Option<BallPercept>,
    /// The landmark posts.
    pub posts: Vec<PostPercept>,
    /// The goals by their nearest point and open space (eqs 16–18; [`find_goal`]), the
    /// posts' columns left out, even when part of the goal is out of view.
    pub goals: Vec<GoalPercept>,
}

/// The vision µAgent of one camera (module doc).
#[derive(Debug)]
pub struct VisionAgent {
    camera: Pinhole,
    lut: Lut,
    /// The lookup table under the last image's light.
    balanced: BalancedLut,
    ball_radius: f64,
    east_goal: ColorClass,
    posts: PostShape,
    goal_width: f64,
    classes: Vec<u8>,
    /// The up camera, when the robot has one.
    up: Option<UpMode>,
}

/// Refuses an image that is not `(cam_w, cam_h)` or whose buffer does not hold its pixels.
pub(crate) fn check_size(image: &Image, (cam_w, cam_h): (u32, u32)) -> Result<(), VisionError> {
    if (image.width, image.height) == (cam_w, cam_h) && image.is_consistent() {
        return Ok(());
    }
    Err(VisionError::WrongSize {
        width: image.width,
        height: image.height,
        bytes: image.rgb.len(),
        cam_w,
        cam_h,
    })
}

impl VisionAgent {
    /// The µAgent of `camera` with the colour classes of `colors`, for a ball of `ball_radius`
    /// (m).
    pub fn new(camera: Pinhole, colors: &ColorTable, ball_radius: f64) -> VisionAgent {
        VisionAgent {
            camera,
            lut: Lut::new(colors),
            balanced: BalancedLut::default(),
            ball_radius,
            east_goal: ColorClass::GoalYellow,
            posts: PostShape::default(),
            goal_width: 2.0,
            classes: Vec::new(),
            up: None,
        }
    }

    /// The robot's omnidirectional up camera too (ISocRob-2000 report §2.2): its images give
    /// the ball all around the robot ([`VisionAgent::see_with_up`]).
    pub fn up_camera(mut self, omni: Omni) -> VisionAgent {
        self.up = Some(UpMode::new(omni));
        self
    }

    /// The up camera, if the robot has one.
    pub fn up(&self) -> Option<&Omni> {
        self.up.as_ref().map(UpMode::omni)
    }

    /// [`VisionAgent::see`] on the front camera's image, multiplexed with the up camera's
    /// (ISocRob-2000 report §3.2.1: the µAgent's front, up and self modes): the up camera's field-line
    /// points all around join the front camera's ([`crate::vision::up::line_points_up`]), and
    /// when the front camera does not see the ball and the up camera does
    /// ([`crate::vision::up::find_ball_up`]), the ball is the up camera's, with one pixel of
    /// the mirror's floor for its error. Without an up camera (or image) this is `see`.
    pub fn see_with_up(
        &mut self,
        front: &Image,
        up: Option<&Image>,
        time: f64,
        pan: f64,
    ) -> Result<Percepts, VisionError> {
        let mut p = self.see(front, time, pan)?;
        let (Some(image), Some(up)) = (up, self.up.as_mut()) else { return Ok(p) };
        up.classify(&self.lut, image)?;
        // The self mode's input: the field lines all around.
        p.line_points.extend(up.lines().into_iter().map(|l| Framed::new(l.at)));
        if p.sightings[BALL].is_some() {
            return Ok(p);
        }
        if let Some(ball) = up.ball(self.ball_radius) {
            p.sightings[BALL] = Some(sighting(ball.at));
            // One pixel of the mirror's floor, across and along the line of sight.
            let metre_per_px = 1.0 / up.omni().a.determinant().abs().sqrt().max(1e-9);
            p.sigmas[BALL] = Some((metre_per_px, metre_per_px / ball.distance.max(0.1)));
            p.pixels[BALL] = ball.pixels;
        }
        Ok(p)
    }

    /// The colour of the east goal (the other goal colour is the west's).
    pub fn east_goal(mut self, colour: ColorClass) -> VisionAgent {
        self.east_goal = colour;
        self
    }

    /// The landmark posts' shape (0.1 m radius, 0.8 m high by default).
    pub fn post_shape(mut self, shape: PostShape) -> VisionAgent {
        self.posts = shape;
        self
    }

    /// The goals' inner width, m (2 m by default, the Middle Size League's of the seeds' time).
    pub fn goal_width(mut self, width: f64) -> VisionAgent {
        self.goal_width = width;
        self
    }

    /// The camera, with its pan joint where the last image was taken.
    pub fn camera(&self) -> &Pinhole {
        &self.camera
    }

    /// The class of every pixel of the last image (`ColorClass as u8`, row after row).
    pub fn classes(&self) -> &[u8] {
        &self.classes
    }

    /// What `image`, taken at `time` (s) with the pan joint at `pan` (rad), shows.
    pub fn see(&mut self, image: &Image, time: f64, pan: f64) -> Result<Percepts, VisionError> {
        self.percepts(image, time, pan).map(|(p, ..)| p)
    }

    /// What [`VisionAgent::see`] finds, with the objects in the image's terms and the goals'
    /// nearest points too (the `mrt vision detect` tool's view; the goals cost a pass over
    /// the image more than `see`).
    pub fn look(&mut self, image: &Image, time: f64, pan: f64) -> Result<Sight, VisionError> {
        let (percepts, ball, posts) = self.percepts(image, time, pan)?;
        let w = self.camera.size().0 as usize;
        // The posts' bands wear the goal colours: the goals are looked for without them.
        let mut goal_classes = self.classes.clone();
        for p in &posts {
            for row in goal_classes.chunks_exact_mut(w) {
                for c in &mut row[p.masked_columns(w)] {
                    if *c == ColorClass::GoalYellow as u8 || *c == ColorClass::GoalBlue as u8 {
                        *c = ColorClass::Unknown as u8;
                    }
                }
            }
        }
        let goals = [ColorClass::GoalYellow, ColorClass::GoalBlue]
            .into_iter()
            .filter_map(|class| find_goal(&goal_classes, &self.camera, class, MIN_GOAL_PIXELS, 0))
            .collect();
        Ok(Sight { percepts, ball, posts, goals })
    }

    /// The percepts of `image`, with the ball and the posts as found in it.
    fn percepts(
        &mut self,
        image: &Image,
        time: f64,
        pan: f64,
    ) -> Result<(Percepts, Option<BallPercept>, Vec<PostPercept>), VisionError> {
        let (w, h) = self.camera.size();
        check_size(image, (w, h))?;
        self.camera.pan = pan;
        self.classes.resize(w as usize * h as usize, 0);
        self.balanced.classify(&self.lut, &image.rgb, w as usize, &mut self.classes);
        let mut p = Percepts { time, pan: Some(pan), ..Default::default() };
        // Where in the image each object was found, for monitors (ISocRob-2000 report §3.2.7).
        let mut shown = Vec::with_capacity(8 + ImageDetections::MAX_LINE_POINTS);
        let ball = find_ball(&self.classes, &self.camera, self.ball_radius);
        if let Some(ball) = ball {
            p.sightings[BALL] = Some(sighting(ball.at));
            p.sigmas[BALL] = self.sigma(ball.pixel, 1.0 - self.ball_radius / self.camera.height);
            p.pixels[BALL] = ball.pixels;
            let d = 2.0 * ball.radius_px;
            shown.push(detection(DetectionKind::Ball, ball.pixel, d, d));
        }
        let west = if self.east_goal == ColorClass::GoalYellow {
            ColorClass::GoalBlue
        } else {
            ColorClass::GoalYellow
        };
        let columns = goal_columns(&self.classes, w, h);
        let posts = find_posts_in(&self.classes, &self.camera, self.posts, &columns);
        let [yellow, blue] = columns;
        let (east_count, west_count) =
            if self.east_goal == ColorClass::GoalYellow { (yellow, blue) } else { (blue, yellow) };
        for (k, class, count) in
            [(EAST_NET, self.east_goal, east_count), (WEST_NET, west, west_count)]
        {
            let count = without_posts(count, &posts, w as usize);
            if let Some(net) = self.net(class, &count) {
                p.sightings[k] = Some(sighting(net.at));
                p.sigmas[k] = self.sigma(net.foot, 1.0);
                p.pixels[k] = net.pixels;
                shown.push(net.shown);
            } else if let Some((px, at)) = self.cut_goal_corner(class, &count) {
                if let Some(sigma) = self.sigma(px, 1.0) {
                    shown.push(detection(DetectionKind::GoalCorner, px, 0.0, 0.0));
                    let pixels = count.iter().sum();
                    let east = k == EAST_NET;
                    p.goal_corners.push(PostSighting {
                        sighting: sighting(at),
                        sigma,
                        east,
                        pixels,
                    });
                }
            }
        }
        let lines = line_points(&self.classes, &self.camera, LINE_STEP, LINE_MAX_RUN);
        p.line_points = lines.iter().map(|l| Framed::new(l.at)).collect();
        p.robots = self.robots(&mut shown);
        p.posts = posts
            .iter()
            .filter_map(|post| {
                let s = PostSighting {
                    sighting: sighting(post.at),
                    sigma: self
                        .sigma(post.pixel, if post.foot { 1.0 } else { self.boundary_scale() })?,
                    east: post.outer == self.east_goal,
                    pixels: post.pixels,
                };
                shown.push(self.post_box(post));
                Some(s)
            })
            .collect();
        // At most so many line points, spread over all of them.
        let every = lines.len().div_ceil(ImageDetections::MAX_LINE_POINTS).max(1);
        shown.extend(
            lines.iter().step_by(every).map(|l| detection(DetectionKind::Line, l.pixel, 0.0, 0.0)),
        );
        p.detections = Some(ImageDetections { width: w, height: h, items: shown });
        Ok((p, ball, posts))
    }

    /// The box of a landmark post in the image: its columns, from its foot up to its top as
    /// the camera projects them (its measured pixel when a projection fails).
    fn post_box(&self, post: &PostPercept) -> ImageDetection {
        let (c0, c1) = (post.columns.0 as f64, post.columns.1 as f64 + 1.0);
        let row = |z: f64| self.camera.project(Point3::new(post.at.x, post.at.y, z)).map(|p| p.y);
        let bottom = row(0.0).unwrap_or(post.pixel.y);
        let top = row(self.posts.height).unwrap_or(post.pixel.y).min(bottom);
        detection(
            DetectionKind::Post,
            Pixel::new(0.5 * (c0 + c1), 0.5 * (top + bottom)),
            c1 - c0,
            bottom - top,
        )
    }

    /// A distance measured at the posts' lower band boundary is this many times as uncertain
    /// as one measured on the floor at the same pixel (the boundary's plane is nearer the
    /// camera's height).
    fn boundary_scale(&self) -> f64 {
        let h = self.camera.height;
        h / (h - self.posts.height / 3.0).abs().max(0.05)
    }

    /// Where the goal of `class` stands on the carpet in column `col` of the image: its lowest
    /// pixel there has carpet (or a line) right below it. `count` holds the goal's column
    /// counts (eq. 16). (Under a tilted camera the goal's sides slant outwards upwards; the
    /// columns of those slants end on the wall or the hall, and a robot in front hides the
    /// foot.) The pixel under the foot, and its floor point (robot frame, m).
    fn goal_foot(
        &self,
        class: ColorClass,
        count: &[u32],
        col: usize,
    ) -> Option<(Pixel, Point2<f64>)> {
        let (w, h) = self.camera.size();
        let (w, h) = (w as usize, h as usize);
        if count.get(col).is_none_or(|&c| c < 2) {
            return None;
        }
        let want = class as u8;
        let row = (0..h).rev().find(|&r| self.classes[r * w + col] == want)?;
        let below = *self.classes.get((row + 1) * w + col)?;
        if below != ColorClass::Field as u8 && below != ColorClass::Line as u8 {
            return None;
        }
        let px = Pixel::new(col as f64 + 0.5, row as f64 + 1.0);
        Some((px, self.camera.unproject(px)?))
    }

    /// The net of the goal of `class` ([`Net`]). `count` holds the goal's column counts (eq.
    /// 16), the posts' columns left out.
    fn net(&self, class: ColorClass, count: &[u32]) -> Option<Net> {
        let w = count.len();
        let pixels: u32 = count.iter().sum();
        // Too little of it, or cut by the image's side: where its far end is is unknown.
        if pixels < MIN_GOAL_PIXELS || count[0] > 0 || count[w - 1] > 0 {
            return None;
        }
        // The outermost columns where the goal stands on the carpet. Under a tilted camera a
        // post slants outwards upwards, and the outermost such column can be the slant's, its
        // lowest goal pixel a few rows above the post's foot: walk inwards while the foot
        // comes lower in the image.
        let foot = |col: usize| self.goal_foot(class, count, col).map(|f| (col, f));
        let lowest = |start: (usize, (Pixel, Point2<f64>)), step: fn(usize) -> Option<usize>| {
            let mut at = start;
            while let Some(next) = step(at.0).filter(|&c| c < w).and_then(foot) {
                if next.1 .0.y <= at.1 .0.y {
                    break;
                }
                at = next;
            }
            at.1
        };
        let (pl, l) = lowest((0..w).find_map(foot)?, |c| c.checked_add(1));
        let (pr, r) = lowest((0..w).rev().find_map(foot)?, |c| c.checked_sub(1));
        // The two feet are the goal's posts (or a post and a back corner): as far apart as
        // the goal is wide, give or take its depth. Anything else is not the whole goal.
        let apart = (l - r).norm();
        if !(0.5 * self.goal_width..=1.5 * self.goal_width).contains(&apart) {
            return None;
        }
        // Its box: its first to last column, up from its lower foot by its mean column height.
        let first = count.iter().position(|&c| c > 0).unwrap_or(0);
        let last = count.iter().rposition(|&c| c > 0).unwrap_or(w - 1);
        let columns = count[first..=last].iter().filter(|&&c| c > 0).count().max(1);
        let tall = f64::from(pixels) / columns as f64;
        let bottom = pl.y.max(pr.y);
        let width = (last + 1 - first) as f64;
        let centre = Pixel::new(first as f64 + 0.5 * width, bottom - 0.5 * tall);
        let shown = detection(DetectionKind::Net, centre, width, tall);
        let at = Point2::from((l.coords + r.coords) / 2.0);
        Some(Net { at, foot: pl, pixels, shown })
    }

    /// The goal of `class` cut by one side of the image: the outermost foot on the other side
    /// ([`VisionAgent::goal_foot`]), one of its four corners on the floor (an upright, or a
    /// back corner seen obliquely). Its pixel and floor point (robot frame, m). `None` when the
    /// goal shows too little, is whole (then its net is seen) or is cut on both sides.
    fn cut_goal_corner(&self, class: ColorClass, count: &[u32]) -> Option<(Pixel, Point2<f64>)> {
        let w = count.len();
        let pixels: u32 = count.iter().sum();
        let (left, right) =
            (count.first().is_some_and(|&c| c > 0), count.last().is_some_and(|&c| c > 0));
        if pixels < MIN_GOAL_PIXELS || left == right {
            return None;
        }
        let foot = |col: usize| self.goal_foot(class, count, col);
        // The goal is the columns of its colour that reach the cut side without a gap;
        // anything of its colour beyond them is something else (a post's band, a far goal).
        let blob = if left {
            0..(0..w).find(|&c| count[c] == 0).unwrap_or(w)
        } else {
            (0..w).rev().find(|&c| count[c] == 0).map_or(0, |c| c + 1)..w
        };
        let with_col = |c: usize| foot(c).map(|f| (c, f));
        let (mut col, mut here) = if left {
            blob.rev().find_map(with_col)?
        } else {
            blob.into_iter().find_map(with_col)?
        };
        // Outside the corner the goal's side, slanting outwards as it rises, shows carpet
        // below it too, each column's "foot" several rows higher than the next one in:
        // follow those steps down to the corner.
        let inward =
            |c: usize| if left { c.checked_sub(1) } else { Some(c + 1).filter(|&c| c < w) };
        while let Some((next, there)) = inward(col).and_then(with_col) {
            if there.0.y < here.0.y + SLANT_STEP {
                break;
            }
            (col, here) = (next, there);
        }
        let (px, at) = here;
        // A landmark post cut by the image's side, and so not found as a post, shows its
        // lower band like a goal: a goal stands taller than the band between the foot and
        // the cut side.
        let between = if left { 0..px.x as usize + 1 } else { px.x as usize..w };
        (self.tallest_run(class, between) >= self.rows_up(at, 1.5 * self.posts.height / 3.0)?)
            .then_some((px, at))
    }

    /// How many rows `height` (m) above the floor point `at` (robot frame) spans in the image.
    fn rows_up(&self, at: Point2<f64>, height: f64) -> Option<f64> {
        let floor = self.camera.project(Point3::new(at.x, at.y, 0.0))?;
        let up = self.camera.project(Point3::new(at.x, at.y, height))?;
        Some(floor.y - up.y)
    }

    /// The tallest run of `class` that rises from the lowest pixel of that class in one of
    /// the `columns`, rows (a few rows of another class inside it do not end it).
    fn tallest_run(&self, class: ColorClass, columns: std::ops::Range<usize>) -> f64 {
        let (w, h) = self.camera.size();
        let (w, h) = (w as usize, h as usize);
        let want = class as u8;
        let run = |col: usize| {
            let is = |r: usize| self.classes[r * w + col] == want;
            let Some(bottom) = (0..h).rev().find(|&r| is(r)) else { return 0 };
            let (mut top, mut gap) = (bottom, 0);
            for r in (0..bottom).rev() {
                if is(r) {
                    (top, gap) = (r, 0);
                } else if gap == 2 {
                    break;
                } else {
                    gap += 1;
                }
            }
            bottom - top + 1
        };
        columns.filter(|&c| c < w).map(run).max().unwrap_or(0) as f64
    }

    /// Other robots: scanning every [`OBSTACLE_STEP`]-th column from the bottom up over the
    /// carpet, the first run of robot pixels is a robot's foot; neighbouring columns whose
    /// feet are within [`SAME_ROBOT`] of each other on the floor are one robot, seen at its
    /// lowest foot, with the colour of the marker band its columns show above the foot
    /// ([`VisionAgent::marker`]), if its body rises [`ROBOT_MIN_RISE`] above the foot.
    /// (Cheaper than labelling the dark blobs, which are large, and it gives the foot.)
    /// Each robot's box in the image (its columns, from its foot up to the top the marker
    /// scan reached) goes into `shown`.
    fn robots(&self, shown: &mut Vec<ImageDetection>) -> Vec<RobotSighting> {
        let (w, h) = self.camera.size();
        let (w, h) = (w as usize, h as usize);
        let (robot, field, line) =
            (ColorClass::Robot as u8, ColorClass::Field as u8, ColorClass::Line as u8);
        // The foot row of each scanned column, if it meets a robot over the floor.
        let feet = (0..w).step_by(OBSTACLE_STEP).map(|col| {
            let mut run = 0;
            for row in (0..h).rev() {
                match self.classes[row * w + col] {
                    c if c == robot => {
                        run += 1;
                        if run == OBSTACLE_MIN_RUN {
                            return (col, Some(row + OBSTACLE_MIN_RUN - 1));
                        }
                    }
                    c if c == field || c == line => run = 0,
                    // Anything else (a goal, the ball, the wall) ends the floor.
                    _ => return (col, None),
                }
            }
            (col, None)
        });
        // Groups of neighbouring feet: first column, last column, lowest foot row, and the
        // floor point of the last foot.
        let mut groups: Vec<(usize, usize, usize, Point2<f64>)> = Vec::new();
        for (col, foot) in feet {
            let Some(f) = foot else { continue };
            let Some(at) = self.camera.unproject(Pixel::new(col as f64 + 0.5, f as f64 + 1.0))
            else {
                continue;
            };
            match groups.last_mut() {
                // Neighbouring feet on the floor within a robot's size of each other: one
                // robot (the bottom of a near robot's body curves over many rows).
                Some(g) if col - g.1 <= OBSTACLE_STEP && (at - g.3).norm() <= SAME_ROBOT => {
                    *g = (g.0, col, g.2.max(f), at);
                }
                _ => groups.push((col, col, f, at)),
            }
        }
        // A narrow group right beside a nearer one is the nearer robot's slanted side (a
        // tilted camera leans vertical edges outwards), its "foot" high up on the body.
        let beside_nearer = |i: usize| {
            let (a, b, r, _) = groups[i];
            let near = |j: Option<usize>| {
                j.and_then(|j| groups.get(j)).is_some_and(
                    |n: &(usize, usize, usize, Point2<f64>)| {
                        (n.1 + OBSTACLE_STEP == a || b + OBSTACLE_STEP == n.0) && n.2 > r
                    },
                )
            };
            b - a <= OBSTACLE_STEP && (near(i.checked_sub(1)) || near(Some(i + 1)))
        };
        let mut out = Vec::new();
        for (i, g) in groups.iter().enumerate() {
            if beside_nearer(i) {
                continue;
            }
            let px = Pixel::new((g.0 + g.1) as f64 / 2.0 + 0.5, g.2 as f64 + 1.0);
            if let Some(at) = self.camera.unproject(px) {
                let (marker, top) = self.marker((g.0..=g.1).step_by(OBSTACLE_STEP), g.2);
                // The body must reach the image's top or rise ROBOT_MIN_RISE above the foot.
                let risen = px.y - top as f64;
                if top > 0 && self.rows_up(at, ROBOT_MIN_RISE).is_some_and(|rows| risen < rows) {
                    continue;
                }
                out.push(RobotSighting {
                    sighting: sighting(at),
                    sigma: self.sigma(px, 1.0),
                    marker,
                });
                let (left, right) = (g.0 as f64, (g.1 + OBSTACLE_STEP).min(w) as f64);
                let (top, bottom) = (top as f64, g.2 as f64 + 1.0);
                let centre = Pixel::new(0.5 * (left + right), 0.5 * (top + bottom));
                shown.push(detection(DetectionKind::Robot, centre, right - left, bottom - top));
            }
        }
        out
    }

    /// The team marker of a robot whose scanned `columns` stand on the floor at row `foot`:
    /// going up each column from the foot through the robot's body (robot and marker pixels,
    /// gaps of at most [`MARKER_GAP`] others), the marker colour with at least
    /// [`MARKER_MIN_PIXELS`] pixels and twice the other's; `None` when the band is out of the
    /// image, too small, or both colours show alike (two robots one behind the other). With
    /// it, the highest row of the robot the scan reached.
    fn marker(&self, columns: impl Iterator<Item = usize>, foot: usize) -> (Option<Marker>, usize) {
        let w = self.camera.size().0 as usize;
        let (robot, magenta, cyan) = (
            ColorClass::Robot as u8,
            ColorClass::MarkerMagenta as u8,
            ColorClass::MarkerCyan as u8,
        );
        let (mut m, mut c, mut top) = (0u32, 0u32, foot);
        for col in columns {
            let mut gap = 0;
            for row in (0..=foot).rev() {
                match self.classes.get(row * w + col).copied() {
                    Some(k) if k == robot => (gap, top) = (0, top.min(row)),
                    Some(k) if k == magenta => (m, gap, top) = (m + 1, 0, top.min(row)),
                    Some(k) if k == cyan => (c, gap, top) = (c + 1, 0, top.min(row)),
                    _ => {
                        gap += 1;
                        if gap > MARKER_GAP {
                            break;
                        }
                    }
                }
            }
        }
        let marker = match (m, c) {
            (m, c) if m >= MARKER_MIN_PIXELS && m >= 2 * c => Some(Marker::Magenta),
            (m, c) if c >= MARKER_MIN_PIXELS && c >= 2 * m => Some(Marker::Cyan),
            _ => None,
        };
        (marker, top)
    }

    /// One pixel's worth of error at `px`, whose floor point is `scale` times as far as the
    /// floor point its ray meets (the ball's centre correction; 1 for a point on the floor):
    /// `(σ distance, σ bearing)`.
    fn sigma(&self, px: Pixel, scale: f64) -> Option<(f64, f64)> {
        let here = self.camera.unproject(px)?;
        let below = self.camera.unproject(px + Vector2::new(0.0, 1.0))?;
        let d = (here.coords.norm() - below.coords.norm()).abs() * scale;
        Some((d.max(0.005), (1.0 / self.camera.intrinsics.fx).atan()))
    }
}

/// A goal's column counts (eq. 16) with the columns of the landmark `posts` cleared: their
/// bands wear the goal colours. `w`: the image's width.
fn without_posts(mut count: Vec<u32>, posts: &[PostPercept], w: usize) -> Vec<u32> {
    for post in posts {
        count[post.masked_columns(w)].iter_mut().for_each(|c| *c = 0);
    }
    count
}

/// An object of `kind` in the image, its box `w` × `h` round `centre` (pixels).
fn detection(kind: DetectionKind, centre: Pixel, w: f64, h: f64) -> ImageDetection {
    ImageDetection { kind, x: centre.x as f32, y: centre.y as f32, w: w as f32, h: h as f32 }
}

fn sighting(at: Point2<f64>) -> Sighting {
    Sighting { distance: at.coords.norm(), bearing: at.y.atan2(at.x) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Intrinsics;
    use proptest::prelude::*;

    fn agent() -> VisionAgent {
        let cam = Pinhole::new(Intrinsics::centred(32, 24, 26.0), 0.45, 0.35);
        VisionAgent::new(cam, &ColorTable::shipped(), 0.11)
    }

    /// A 160 × 120 image of carpet with a ball of radius 0.11 m painted where the camera sees
    /// one 1.5 m ahead and 0.3 m to the left (each pixel whose ray meets the ball's sphere),
    /// and a white line across the carpet at 1 m: the ball's detection is in the image, at
    /// the painted blob, about its size; the line points are in the image, capped.
    #[test]
    fn detections_are_in_the_image_at_the_rendered_ball() {
        let cam = Pinhole::new(Intrinsics::centred(160, 120, 130.0), 0.45, 0.35);
        let mut agent = VisionAgent::new(cam, &ColorTable::shipped(), 0.11);
        let (w, h) = (160usize, 120usize);
        let centre = Point3::new(1.5, 0.3, 0.11);
        let mut image = Image::new(w as u32, h as u32);
        let (mut sum, mut n) = ((0.0, 0.0), 0.0);
        for row in 0..h {
            for col in 0..w {
                let px = Pixel::new(col as f64 + 0.5, row as f64 + 0.5);
                let floor = cam.unproject(px);
                // The ray from the camera's centre through the pixel, near the ball's sphere.
                let hits = cam.project(centre).is_some_and(|c| {
                    let r = 0.11 * 130.0 / (centre - cam.centre()).norm();
                    (c - px).norm() <= r
                });
                let rgb = if hits {
                    (sum.0, sum.1, n) = (sum.0 + px.x, sum.1 + px.y, n + 1.0);
                    [255, 120, 0]
                } else if floor.is_some_and(|f| (f.x - 1.0).abs() < 0.03) {
                    [245, 245, 245]
                } else {
                    [30, 140, 40]
                };
                image.rgb[(row * w + col) * 3..][..3].copy_from_slice(&rgb);
            }
        }
        assert!(n > 20.0, "the ball shows: {n} pixels");
        let p = agent.see(&image, 2.0, 0.0).unwrap();
        assert!(p.sightings[BALL].is_some(), "the vision finds the painted ball");
        let d = p.detections.expect("the vision says where it found things");
        assert_eq!((d.width, d.height), (160, 120));
        let ball = d.items[0];
        assert_eq!(ball.kind, DetectionKind::Ball, "the ball first");
        let (cx, cy) = (sum.0 / n, sum.1 / n);
        assert!((f64::from(ball.x) - cx).abs() < 0.5 && (f64::from(ball.y) - cy).abs() < 0.5);
        let diameter = 2.0 * (n / std::f64::consts::PI).sqrt();
        assert!((f64::from(ball.w) - diameter).abs() < 1.0, "{} against {diameter}", ball.w);
        let lines = d.items.iter().filter(|i| i.kind == DetectionKind::Line).count();
        assert!(lines > 0 && lines <= ImageDetections::MAX_LINE_POINTS, "{lines}");
        for i in &d.items {
            let inside = |v: f32, size: f32, len: u32| {
                v - size / 2.0 >= -0.5 && v + size / 2.0 <= len as f32 + 0.5
            };
            assert!(
                inside(i.x, i.w, d.width) && inside(i.y, i.h, d.height),
                "{i:?} out of the image"
            );
        }
    }

    /// A 160 × 120 image of carpet with, 1.6 m ahead, either a robot (a dark board facing the
    /// camera, 0.4 m wide, its marker band magenta from 0.48 to 0.6 m) or a shadow as wide and
    /// 0.5 m long lying flat on the carpet, as dark as the robot's body.
    fn robot_or_shadow(standing: bool) -> (Pinhole, Image) {
        let cam = Pinhole::new(Intrinsics::centred(160, 120, 130.0), 0.45, 0.35);
        let (w, h) = (160usize, 120usize);
        let mut image = Image::new(w as u32, h as u32);
        for row in 0..h {
            for col in 0..w {
                let px = Pixel::new(col as f64 + 0.5, row as f64 + 0.5);
                let ray = cam.ray(px);
                let body =
                    (ray.x > 0.0).then(|| cam.centre() + ray * ((1.6 - cam.centre().x) / ray.x));
                let rgb = match (standing, body, cam.unproject(px)) {
                    (true, Some(p), _) if p.y.abs() < 0.2 && (0.0..0.48).contains(&p.z) => {
                        [22, 22, 26]
                    }
                    (true, Some(p), _) if p.y.abs() < 0.2 && (0.48..0.6).contains(&p.z) => {
                        [200, 40, 190]
                    }
                    (false, _, Some(f)) if f.y.abs() < 0.2 && (1.6..2.1).contains(&f.x) => {
                        [22, 22, 26]
                    }
                    _ => [30, 130, 50],
                };
                image.rgb[(row * w + col) * 3..][..3].copy_from_slice(&rgb);
            }
        }
        (cam, image)
    }

    /// A robot standing on the carpet is seen, with its marker, at its foot; a shadow as dark
    /// and as wide lying flat on the carpet is no robot.
    #[test]
    fn a_robot_rises_from_the_carpet_and_a_shadow_does_not() {
        let (cam, robot) = robot_or_shadow(true);
        let mut agent = VisionAgent::new(cam, &ColorTable::shipped(), 0.11);
        let seen = agent.see(&robot, 0.0, 0.0).unwrap().robots;
        assert_eq!(seen.len(), 1, "{seen:?}");
        assert_eq!(seen[0].marker, Some(Marker::Magenta));
        assert!((seen[0].sighting.distance - 1.6).abs() < 0.05, "{:?}", seen[0]);
        assert!(seen[0].sighting.bearing.abs() < 0.02, "{:?}", seen[0]);
        let (_, shadow) = robot_or_shadow(false);
        let seen = agent.see(&shadow, 0.0, 0.0).unwrap().robots;
        assert!(seen.is_empty(), "a shadow taken for a robot: {seen:?}");
    }

    proptest! {
        /// Images of any size and content (a frame from the network) never panic the µAgent:
        /// the camera's size is processed, anything else refused.
        #[test]
        fn any_image_is_processed_or_refused(
            width in 0u32..64,
            height in 0u32..48,
            bytes in proptest::collection::vec(any::<u8>(), 0..8000),
        ) {
            let image = Image { width, height, rgb: bytes };
            let fits = (width, height) == (32, 24) && image.rgb.len() == 32 * 24 * 3;
            prop_assert_eq!(agent().see(&image, 0.0, 0.0).is_ok(), fits);
        }

        /// Random pixels of the right size: every percept is finite.
        #[test]
        fn random_frames_give_finite_percepts(bytes in proptest::collection::vec(any::<u8>(), 2304)) {
            let image = Image { width: 32, height: 24, rgb: bytes };
            let p = agent().see(&image, 1.0, 0.2).unwrap();
            let d = p.detections.as_ref().unwrap();
            prop_assert!(d.items.iter().filter(|i| i.kind == DetectionKind::Line).count()
                <= ImageDetections::MAX_LINE_POINTS);
            for i in &d.items {
                prop_assert!(i.x.is_finite() && i.y.is_finite() && i.w >= 0.0 && i.h >= 0.0);
            }
            for s in p.sightings.iter().flatten().chain(p.robots.iter().map(|r| &r.sighting)) {
                prop_assert!(s.distance.is_finite() && s.bearing.is_finite());
            }
        }
    }
}
