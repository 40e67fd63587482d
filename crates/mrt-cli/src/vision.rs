//! `mrt vision`: the vision µAgent's tools for a competition. `detect` classifies
//! images with a colour file and finds the ball and the goals (their nearest point and the open
//! space for a shot) through a camera file, one JSON line per image (or per image of a
//! directory, `mrt_perception::source::ImageSequence`); `--png OUT` draws what it found.
//! `calibrate` shows per class what the thresholds take (histograms, coverage images). `render`
//! saves what a simulated camera sees (the simulator's renderer, `mrt_sim::render`). `survey`
//! measures the vision on random rendered scenes against the truth (`mrt_sim::survey`).

use anyhow::{anyhow, bail, Context as _, Result};
use image::{Rgb, RgbImage};
use mrt_msgs::Image;
use mrt_perception::camera::{Camera, CameraFile, CameraModel};
use mrt_perception::source::{load_image, ImageSequence, ImageSource};
use mrt_perception::vision::agent::VisionAgent;
use mrt_perception::vision::blobs::BallPercept;
use mrt_perception::vision::colors::{ColorClass, ColorTable, Lut};
use mrt_perception::vision::up::UpMode;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// `mrt vision detect`.
#[derive(clap::Args)]
pub struct DetectArgs {
    /// The camera file (TOML; see configs/vision/camera.toml).
    #[arg(long)]
    pub camera: PathBuf,
    /// The colour file (TOML; see configs/vision/colors.toml).
    #[arg(long)]
    pub colors: PathBuf,
    /// The ball's radius, m.
    #[arg(long, default_value_t = 0.11)]
    pub ball_radius: f64,
    /// Draw the classified image with the detections to this PNG file (one image only).
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// The images (PNG or JPEG), each the camera's size; a directory stands for its image
    /// files in name order (a recorded sequence).
    #[arg(required_unless_present = "device", conflicts_with = "device")]
    pub images: Vec<PathBuf>,
    /// Grab the images from a USB camera instead (Video4Linux2, e.g. /dev/video0), at the
    /// camera file's size.
    #[arg(long)]
    pub device: Option<PathBuf>,
    /// How many frames to grab from --device (1 to 1000000; default 1).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub frames: Option<u32>,
}

/// The image files the arguments name: files as given, directories as their image files in
/// name order.
fn image_files(args: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut images = Vec::new();
    for path in args {
        images.extend_from_slice(ImageSequence::open(path)?.files());
    }
    Ok(images)
}

/// The colour a class is drawn with.
fn paint(c: ColorClass) -> Rgb<u8> {
    Rgb(match c {
        ColorClass::Unknown => [128, 128, 128],
        ColorClass::Ball => [255, 120, 0],
        ColorClass::GoalYellow => [240, 220, 0],
        ColorClass::GoalBlue => [0, 80, 255],
        ColorClass::Robot => [0, 0, 0],
        ColorClass::Line => [255, 255, 255],
        ColorClass::Field => [0, 130, 0],
        ColorClass::MarkerMagenta => [255, 0, 255],
        ColorClass::MarkerCyan => [0, 255, 255],
        ColorClass::BallShade => [150, 70, 0],
    })
}

/// Runs `mrt vision detect`.
pub fn detect(args: &DetectArgs) -> Result<()> {
    if !(args.ball_radius.is_finite() && args.ball_radius > 0.0 && args.ball_radius < 1.0) {
        bail!("--ball-radius must be between 0 and 1 m, not {}", args.ball_radius);
    }
    if args.frames.is_some() && args.device.is_none() {
        bail!("--frames counts the frames grabbed from --device: give a device with it");
    }
    let images = image_files(&args.images)?;
    let count = match args.device {
        Some(_) => args.frames.unwrap_or(1) as usize,
        None => images.len(),
    };
    if args.png.is_some() && count != 1 {
        bail!("--png draws one image: give one image (or one frame) with it");
    }
    let camera = CameraModel::from_file(&args.camera).map_err(|e| anyhow!("{e}"))?;
    let colors = ColorTable::from_file(&args.colors).map_err(|e| anyhow!("{e}"))?;
    let mut detector = match camera {
        CameraModel::Pinhole(c) => Detector::Front(VisionAgent::new(c, &colors, args.ball_radius)),
        CameraModel::Omni(omni) => {
            Detector::Up { up: UpMode::new(omni), lut: Lut::new(&colors), radius: args.ball_radius }
        }
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let mut source = match &args.device {
        Some(device) => Some(open_device(device, camera.size())?),
        None => None,
    };
    for k in 0..count {
        let (name, img) = match (&mut source, images.get(k)) {
            (Some(usb), _) => {
                let img = usb.grab()?.ok_or_else(|| anyhow!("{}: ended", usb.describe()))?;
                (format!("{}#{k}", usb.describe()), img)
            }
            (None, Some(path)) => (path.display().to_string(), load_image(path)?),
            (None, None) => break,
        };
        let line = detect_one(&name, &img, &mut detector, args.png.as_deref())?;
        if writeln!(out, "{line}").is_err() {
            return Ok(()); // the reader went away
        }
    }
    Ok(())
}

/// A USB camera streaming frames of `(width, height)`.
#[cfg(target_os = "linux")]
fn open_device(device: &Path, (width, height): (u32, u32)) -> Result<Box<dyn ImageSource>> {
    Ok(Box::new(mrt_perception::v4l2::V4l2Camera::open(device, width, height)?))
}

/// USB cameras are read through Video4Linux2, on Linux only.
#[cfg(not(target_os = "linux"))]
fn open_device(device: &Path, _: (u32, u32)) -> Result<Box<dyn ImageSource>> {
    bail!("{}: USB cameras are read through Video4Linux2, on Linux only", device.display())
}

/// What `detect` runs on each image: the vision µAgent of a pinhole camera (front mode), or
/// the up mode's ball finder on an omnidirectional camera's image (ISocRob-2000 report §3.2.1).
/// One is built for a whole run, so its size does not matter.
#[allow(clippy::large_enum_variant)]
enum Detector {
    Front(VisionAgent),
    Up { up: UpMode, lut: Lut, radius: f64 },
}

fn detect_one(
    name: &str,
    img: &Image,
    detector: &mut Detector,
    png: Option<&Path>,
) -> Result<serde_json::Value> {
    let (w, h) = (img.width, img.height);
    let camera = match detector {
        Detector::Front(agent) => agent.camera().size(),
        Detector::Up { up, .. } => up.omni().size(),
    };
    if (w, h) != camera {
        bail!("{name}: the image is {w}×{h}, the camera file says {}×{}", camera.0, camera.1);
    }
    let mut objects = Vec::new();
    let ball_json = |b: &BallPercept| {
        serde_json::json!({
            "class": "ball",
            "pixel": [round3(b.pixel.x), round3(b.pixel.y)],
            "radius_px": round3(b.radius_px),
            "distance_m": round3(b.distance),
            "bearing_deg": round3(b.bearing.to_degrees()),
        })
    };
    let (ball, posts, classes) = match detector {
        Detector::Front(agent) => {
            let pan = agent.camera().pan;
            let sight = agent.look(img, 0.0, pan).map_err(|e| anyhow!("{name}: {e}"))?;
            objects.extend(sight.ball.as_ref().map(ball_json));
            for g in &sight.goals {
                objects.push(serde_json::json!({
                    "class": g.class.name(),
                    "pixel": [round3(g.nearest.x), round3(g.nearest.y)],
                    "distance_m": round3(g.distance),
                    "bearing_deg": round3(g.bearing.to_degrees()),
                    "open_bearing_deg": round3(g.open_bearing.to_degrees()),
                }));
            }
            for p in &sight.posts {
                objects.push(serde_json::json!({
                    "class": "post",
                    "outer": p.outer.name(),
                    "pixel": [round3(p.pixel.x), round3(p.pixel.y)],
                    "distance_m": round3(p.at.coords.norm()),
                    "bearing_deg": round3(p.at.y.atan2(p.at.x).to_degrees()),
                }));
            }
            // The nets (sightings 1 and 2: the east and the west goal): the centres of the
            // goal lines, when a goal is wholly in view, as the world model localizes on them.
            for (k, goal) in [(1, "east"), (2, "west")] {
                if let Some(n) = sight.percepts.sightings[k] {
                    objects.push(serde_json::json!({
                        "class": "net",
                        "goal": goal,
                        "distance_m": round3(n.distance),
                        "bearing_deg": round3(n.bearing.to_degrees()),
                    }));
                }
            }
            for r in &sight.percepts.robots {
                objects.push(serde_json::json!({
                    "class": "robot",
                    "distance_m": round3(r.sighting.distance),
                    "bearing_deg": round3(r.sighting.bearing.to_degrees()),
                    "marker": r.marker,
                }));
            }
            (sight.ball, sight.posts, agent.classes())
        }
        Detector::Up { up, lut, radius } => {
            up.classify(lut, img).map_err(|e| anyhow!("{name}: {e}"))?;
            let ball = up.ball(*radius);
            objects.extend(ball.as_ref().map(ball_json));
            (ball, Vec::new(), up.classes())
        }
    };
    if let Some(out) = png {
        let mut drawn = RgbImage::from_fn(w, h, |x, y| {
            paint(ColorClass::from_u8(classes[(y * w + x) as usize]))
        });
        if let Some(b) = ball {
            let c = (b.pixel.x as i32, b.pixel.y as i32);
            let r = b.radius_px.round().max(1.0) as i32;
            imageproc::drawing::draw_hollow_circle_mut(&mut drawn, c, r + 2, Rgb([255, 0, 255]));
            imageproc::drawing::draw_cross_mut(&mut drawn, Rgb([255, 0, 255]), c.0, c.1);
        }
        for p in &posts {
            let (x0, x1) = (p.columns.0 as i32 - 2, p.columns.1 as i32 + 2);
            let y = p.pixel.y as i32;
            let rect = imageproc::rect::Rect::at(x0, (y - 4 * (x1 - x0)).max(0))
                .of_size((x1 - x0 + 1) as u32, (4 * (x1 - x0)).min(y).max(1) as u32);
            imageproc::drawing::draw_hollow_rect_mut(&mut drawn, rect, Rgb([255, 0, 255]));
        }
        drawn.save(out).with_context(|| format!("cannot write {}", out.display()))?;
    }
    Ok(serde_json::json!({ "image": name, "objects": objects }))
}

/// Three decimals: what `round3` keeps (a rounding, not a unit).
const DECIMALS: f64 = 1e3;

fn round3(x: f64) -> f64 {
    (x * DECIMALS).round() / DECIMALS
}

/// `mrt vision render`.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// The world: a simulator configuration (TOML; see configs/sim/default.toml), for the
    /// field, its camera (`[vision.camera]`) and what is drawn (`[render]`). Default: the built-in
    /// world.
    #[arg(long)]
    pub world: Option<PathBuf>,
    /// A camera file instead of the world's `[vision.camera]` (see configs/vision/camera.toml).
    #[arg(long)]
    pub camera: Option<PathBuf>,
    /// Where the viewing robot stands: `X,Y,HEADING_DEG` (field frame: m from the centre spot,
    /// x towards the east (yellow) goal, heading counter-clockwise from east).
    #[arg(long, value_parser = parse_pose, allow_hyphen_values = true)]
    pub at: (f64, f64, f64),
    /// The pan joint, degrees (positive: to the left).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub pan: f64,
    /// The ball: `X,Y` (m). No ball when not given.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    pub ball: Option<(f64, f64)>,
    /// Another robot: `X,Y,home` or `X,Y,away` (repeat for more).
    #[arg(long = "robot", value_parser = parse_robot, allow_hyphen_values = true)]
    pub robots: Vec<(f64, f64, bool)>,
    /// Seed of the image noise (when the world's `[render]` turns noise on).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The PNG file to write.
    #[arg(long)]
    pub out: PathBuf,
}

fn numbers(text: &str, n: usize, what: &str) -> Result<Vec<f64>, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != n {
        return Err(format!("expected {what}, got {text:?}"));
    }
    parts
        .iter()
        .map(|p| match p.parse::<f64>() {
            Ok(v) if v.is_finite() && v.abs() <= 1000.0 => Ok(v),
            _ => Err(format!("{p:?} in {text:?} is not a number from -1000 to 1000 ({what})")),
        })
        .collect()
}

fn parse_point(text: &str) -> Result<(f64, f64), String> {
    let v = numbers(text, 2, "X,Y")?;
    Ok((v[0], v[1]))
}

fn parse_pose(text: &str) -> Result<(f64, f64, f64), String> {
    let v = numbers(text, 3, "X,Y,HEADING_DEG")?;
    Ok((v[0], v[1], v[2]))
}

fn parse_robot(text: &str) -> Result<(f64, f64, bool), String> {
    let Some((xy, team)) = text.rsplit_once(',') else {
        return Err(format!("expected X,Y,home or X,Y,away, got {text:?}"));
    };
    let home = match team.trim() {
        "home" => true,
        "away" => false,
        other => return Err(format!("the team is home or away, not {other:?}")),
    };
    let (x, y) = parse_point(xy)?;
    Ok((x, y, home))
}

/// Runs `mrt vision render`.
pub fn render(args: &RenderArgs) -> Result<()> {
    use mrt_core::Pose2;
    use mrt_sim::render::{CameraState, Renderer, Scene};
    let mut cfg = match &args.world {
        Some(path) => mrt_sim::config::SimConfig::from_file(path).map_err(|e| anyhow!("{e}"))?,
        None => mrt_sim::config::SimConfig::default(),
    };
    let camera = match &args.camera {
        Some(path) => CameraModel::from_file(path).map_err(|e| anyhow!("{e}"))?,
        None => CameraModel::Pinhole(
            cfg.vision.camera.camera().map_err(|e| anyhow!("vision.camera: {e}"))?,
        ),
    };
    if let (Some(path), CameraModel::Pinhole(_)) = (&args.camera, camera) {
        // The world's robots carry this camera (its file keeps the pan and the mount).
        cfg.vision.camera = CameraFile::from_file(path).map_err(|e| anyhow!("{e}"))?;
    }
    if !(args.pan.is_finite() && args.pan.abs() <= 180.0) {
        bail!("--pan must be -180 to 180 degrees, not {}", args.pan);
    }
    let renderer =
        Renderer::with_camera(&cfg, camera).map_err(|e| anyhow!("vision.camera: {e}"))?;
    let (x, y, heading) = args.at;
    let scene = Scene {
        ball: args.ball,
        robots: args.robots.iter().map(|&(x, y, home)| (Pose2::new(x, y, 0.0), home)).collect(),
    };
    let frame = renderer.render(
        &scene,
        Pose2::new(x, y, heading.to_radians()),
        args.pan.to_radians(),
        None,
        &mut CameraState::new(args.seed),
    );
    let image = RgbImage::from_raw(frame.width, frame.height, frame.rgb)
        .ok_or_else(|| anyhow!("the renderer made an image of the wrong size"))?;
    image.save(&args.out).with_context(|| format!("cannot write {}", args.out.display()))?;
    Ok(())
}

/// `mrt vision calibrate`.
#[derive(clap::Args)]
pub struct CalibrateArgs {
    /// The colour file to tune (TOML; see configs/vision/colors.toml).
    #[arg(long)]
    pub colors: PathBuf,
    /// A directory to write `histograms.svg` and, per image and class, `<image>-<class>.png`
    /// (the class's pixels in their colours, the rest dimmed).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// The images (PNG or JPEG; a directory stands for its image files).
    #[arg(required = true)]
    pub images: Vec<PathBuf>,
}

/// The classes in the report: the colour file's, then the pixels none of them takes.
fn report_classes() -> impl Iterator<Item = ColorClass> {
    ColorClass::ALL.into_iter().chain(std::iter::once(ColorClass::Unknown))
}

/// Runs `mrt vision calibrate`.
pub fn calibrate(args: &CalibrateArgs) -> Result<()> {
    use mrt_perception::vision::calibrate::{ClassHistogram, Histograms};
    let colors = ColorTable::from_file(&args.colors).map_err(|e| anyhow!("{e}"))?;
    let lut = Lut::new(&colors);
    let images = image_files(&args.images)?;
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let mut hist = Histograms::default();
    for path in &images {
        let img = load_image(path)?;
        hist.add(&lut, &img.rgb);
        if let Some(dir) = &args.out {
            coverage(&img, &lut, path, dir)?;
        }
    }
    let total = hist.pixels().max(1) as f64;
    let range = |bins: &[u64], width: f64| {
        ClassHistogram::central_range(bins, width, 0.02).map(|(a, b)| [round3(a), round3(b)])
    };
    let classes: Vec<serde_json::Value> = report_classes()
        .map(|class| {
            let h = hist.class(class);
            serde_json::json!({
                "class": class.name(),
                "pixels": h.pixels,
                "share": round3(h.pixels as f64 / total),
                "thresholds": colors.get(class),
                "hue_range_deg": range(&h.hue, 10.0),
                "sat_range": range(&h.sat, 0.05),
                "val_range": range(&h.val, 0.05),
                "hue": h.hue.to_vec(),
                "sat": h.sat.to_vec(),
                "val": h.val.to_vec(),
            })
        })
        .collect();
    let report =
        serde_json::json!({ "images": images.len(), "pixels": hist.pixels(), "classes": classes });
    outln!("{report}");
    if let Some(dir) = &args.out {
        let svg = dir.join("histograms.svg");
        std::fs::write(&svg, histogram_svg(&hist, &colors))
            .with_context(|| format!("cannot write {}", svg.display()))?;
    }
    Ok(())
}

/// Writes one image per class of `img`: the class's pixels as they are, the rest dimmed to a
/// quarter, so that a person sees what the class takes.
fn coverage(img: &mrt_msgs::Image, lut: &Lut, path: &Path, dir: &Path) -> Result<()> {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("image");
    let mut classes = vec![0u8; img.rgb.len() / 3];
    lut.classify(&img.rgb, &mut classes);
    for class in report_classes() {
        let mut rgb = img.rgb.clone();
        for (px, &c) in rgb.chunks_exact_mut(3).zip(&classes) {
            if c != class as u8 {
                px.iter_mut().for_each(|v| *v /= 4);
            }
        }
        let out = dir.join(format!("{stem}-{}.png", class.name()));
        RgbImage::from_raw(img.width, img.height, rgb)
            .ok_or_else(|| anyhow!("{}: inconsistent image buffer", path.display()))?
            .save(&out)
            .with_context(|| format!("cannot write {}", out.display()))?;
    }
    Ok(())
}

/// One row per class, three bar charts (hue, saturation, value), each bar in the colour of its
/// bin, the class's thresholds as red lines and the shaded band between them.
fn histogram_svg(
    hist: &mrt_perception::vision::calibrate::Histograms,
    colors: &ColorTable,
) -> String {
    use std::fmt::Write as _;
    const W: f64 = 216.0; // chart width, px
    const H: f64 = 60.0; // chart height, px
    const ROW: f64 = 95.0;
    const LEFT: f64 = 110.0;
    let rows = report_classes().count() as f64;
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{}" font-family="sans-serif" font-size="11">"#,
        LEFT + 3.0 * (W + 30.0),
        40.0 + rows * ROW
    );
    let _ = write!(s, r##"<rect width="100%" height="100%" fill="#fff"/>"##);
    for (j, title) in ["hue (°)", "saturation", "value"].iter().enumerate() {
        let x = LEFT + j as f64 * (W + 30.0);
        let _ = write!(s, r#"<text x="{x}" y="20" font-weight="bold">{title}</text>"#);
    }
    for (i, class) in report_classes().enumerate() {
        let h = hist.class(class);
        let y0 = 40.0 + i as f64 * ROW;
        let _ = write!(
            s,
            r#"<text x="8" y="{}" font-weight="bold">{}</text><text x="8" y="{}">{} px</text>"#,
            y0 + H / 2.0,
            class.name(),
            y0 + H / 2.0 + 14.0,
            h.pixels
        );
        let t = colors.get(class);
        type Chart<'a> = (&'a [u64], f64, Option<(f64, f64)>);
        let charts: [Chart<'_>; 3] = [
            (&h.hue, 360.0, t.map(|t| (t.hue_min, t.hue_max))),
            (&h.sat, 1.0, t.map(|t| (t.sat_min, t.sat_max))),
            (&h.val, 1.0, t.map(|t| (t.val_min, t.val_max))),
        ];
        for (j, (bins, span, limits)) in charts.into_iter().enumerate() {
            let x0 = LEFT + j as f64 * (W + 30.0);
            let sx = |v: f64| x0 + v / span * W;
            // The accepted band (hue may wrap through 0°).
            if let Some((lo, hi)) = limits {
                let bands = if lo <= hi { vec![(lo, hi)] } else { vec![(lo, span), (0.0, hi)] };
                for (a, b) in bands {
                    let _ = write!(
                        s,
                        r##"<rect x="{:.1}" y="{y0}" width="{:.1}" height="{H}" fill="#fdd"/>"##,
                        sx(a),
                        sx(b) - sx(a)
                    );
                }
            }
            let max = bins.iter().copied().max().unwrap_or(0).max(1) as f64;
            let bw = W / bins.len() as f64;
            for (k, &n) in bins.iter().enumerate() {
                let bh = (n as f64 / max).sqrt() * H; // square root: small counts stay visible
                let fill = match j {
                    0 => hue_colour(k as f64 * 360.0 / bins.len() as f64 + 5.0),
                    _ => {
                        let g = (k as f64 / bins.len() as f64 * 255.0) as u8;
                        format!("rgb({g},{g},{g})")
                    }
                };
                let _ = write!(
                    s,
                    r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{bh:.1}" fill="{fill}" stroke="#444" stroke-width="0.3"/>"##,
                    x0 + k as f64 * bw,
                    y0 + H - bh,
                    bw
                );
            }
            let _ = write!(
                s,
                r##"<line x1="{x0}" y1="{0}" x2="{1}" y2="{0}" stroke="#000"/>"##,
                y0 + H,
                x0 + W
            );
            if let Some((lo, hi)) = limits {
                for v in [lo, hi] {
                    let _ = write!(
                        s,
                        r##"<line x1="{0:.1}" y1="{y0}" x2="{0:.1}" y2="{1}" stroke="#d00" stroke-width="1.5"/>"##,
                        sx(v),
                        y0 + H
                    );
                }
            }
            let _ = write!(
                s,
                r##"<text x="{x0}" y="{0}" fill="#555">0</text><text x="{1}" y="{0}" fill="#555" text-anchor="end">{2}</text>"##,
                y0 + H + 12.0,
                x0 + W,
                span
            );
        }
    }
    s.push_str("</svg>\n");
    s
}

/// The fully saturated colour of a hue (degrees), as an SVG colour.
fn hue_colour(h: f64) -> String {
    let x = 1.0 - ((h / 60.0) % 2.0 - 1.0).abs();
    let (r, g, b) = match (h / 60.0) as u32 {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    format!("rgb({},{},{})", (r * 255.0) as u8, (g * 255.0) as u8, (b * 255.0) as u8)
}

/// `mrt vision survey`.
#[derive(clap::Args)]
pub struct SurveyArgs {
    /// The world: a simulator configuration (TOML; see configs/sim/default.toml), for the
    /// field, the camera and what is drawn. Default: the built-in world.
    #[arg(long)]
    pub world: Option<PathBuf>,
    /// Random scenes to render and see (1 to 1 000 000).
    #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub scenes: u32,
    /// The seed of the scenes.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `mrt vision survey`.
pub fn survey(args: &SurveyArgs) -> Result<()> {
    let cfg = match &args.world {
        Some(path) => mrt_sim::config::SimConfig::from_file(path).map_err(|e| anyhow!("{e}"))?,
        None => mrt_sim::config::SimConfig::default(),
    };
    let report = mrt_sim::survey::survey(&cfg, args.seed, args.scenes as usize)
        .map_err(|e| anyhow!("survey: {e}"))?;
    let mut out = std::io::stdout().lock();
    if args.json {
        writeln!(out, "{}", serde_json::to_string(&report)?)?;
    } else {
        write!(out, "{}", report.table())?;
    }
    Ok(())
}
