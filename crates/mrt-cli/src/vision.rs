//! `mrt vision`: the vision µAgent's tools for a competition (issue 19). `detect` classifies
//! images with a colour file and finds the ball and the goals (their nearest point and the open
//! space for a shot) through a camera file, one JSON line per image (or per image of a
//! directory, `mrt_perception::source::ImageSequence`); `--png OUT` draws what it found. `render` saves what a simulated camera sees (the simulator's renderer,
//! `mrt_sim::render`).

use anyhow::{anyhow, bail, Context as _, Result};
use image::{Rgb, RgbImage};
use mrt_perception::camera::{Camera, CameraFile, Pinhole};
use mrt_perception::source::{load_image, ImageSequence};
use mrt_perception::vision::blobs::find_ball;
use mrt_perception::vision::colors::{ColorClass, ColorTable, Lut};
use mrt_perception::vision::goals::find_goal;
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
    #[arg(required = true)]
    pub images: Vec<PathBuf>,
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
    })
}

/// Runs `mrt vision detect`.
pub fn detect(args: &DetectArgs) -> Result<()> {
    if !(args.ball_radius.is_finite() && args.ball_radius > 0.0 && args.ball_radius < 1.0) {
        bail!("--ball-radius must be between 0 and 1 m, not {}", args.ball_radius);
    }
    let mut images = Vec::new();
    for path in &args.images {
        images.extend_from_slice(ImageSequence::open(path)?.files());
    }
    if args.png.is_some() && images.len() != 1 {
        bail!("--png draws one image: give one image with it");
    }
    // `from_file` has checked the camera already: `camera()` cannot fail on what it read.
    let camera = CameraFile::from_file(&args.camera)
        .map_err(|e| anyhow!("{e}"))?
        .camera()
        .map_err(|e| anyhow!("{}: {e}", args.camera.display()))?;
    let colors = ColorTable::from_file(&args.colors).map_err(|e| anyhow!("{e}"))?;
    let lut = Lut::new(&colors);
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    for path in &images {
        let line = detect_one(path, &camera, &lut, args.ball_radius, args.png.as_deref())?;
        if writeln!(out, "{line}").is_err() {
            return Ok(()); // the reader went away
        }
    }
    Ok(())
}

fn detect_one(
    path: &Path,
    camera: &Pinhole,
    lut: &Lut,
    ball_radius: f64,
    png: Option<&Path>,
) -> Result<serde_json::Value> {
    let img = load_image(path)?;
    let (w, h) = (img.width, img.height);
    if (w, h) != camera.size() {
        bail!(
            "{}: the image is {w}×{h}, the camera file says {}×{}",
            path.display(),
            camera.size().0,
            camera.size().1
        );
    }
    let mut classes = vec![0u8; (w * h) as usize];
    lut.classify(&img.rgb, &mut classes);
    let ball = find_ball(&classes, camera, ball_radius);
    let mut objects = Vec::new();
    if let Some(b) = ball {
        objects.push(serde_json::json!({
            "class": "ball",
            "pixel": [round3(b.pixel.x), round3(b.pixel.y)],
            "radius_px": round3(b.radius_px),
            "distance_m": round3(b.distance),
            "bearing_deg": round3(b.bearing.to_degrees()),
        }));
    }
    for class in [ColorClass::GoalYellow, ColorClass::GoalBlue] {
        if let Some(g) = find_goal(&classes, camera, class, 20, 0) {
            objects.push(serde_json::json!({
                "class": class.name(),
                "pixel": [round3(g.nearest.x), round3(g.nearest.y)],
                "distance_m": round3(g.distance),
                "bearing_deg": round3(g.bearing.to_degrees()),
                "open_bearing_deg": round3(g.open_bearing.to_degrees()),
            }));
        }
    }
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
        drawn.save(out).with_context(|| format!("cannot write {}", out.display()))?;
    }
    Ok(serde_json::json!({ "image": path.display().to_string(), "objects": objects }))
}

fn round3(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

/// `mrt vision render`.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// The world: a simulator configuration (TOML; see configs/sim/default.toml), for the
    /// field, its camera (`[camera]`) and what is drawn (`[render]`). Default: the built-in
    /// world.
    #[arg(long)]
    pub world: Option<PathBuf>,
    /// A camera file instead of the world's `[camera]` (see configs/vision/camera.toml).
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
    if let Some(path) = &args.camera {
        cfg.camera = CameraFile::from_file(path).map_err(|e| anyhow!("{e}"))?;
    }
    if !(args.pan.is_finite() && args.pan.abs() <= 180.0) {
        bail!("--pan must be -180 to 180 degrees, not {}", args.pan);
    }
    let renderer = Renderer::new(&cfg).map_err(|e| anyhow!("camera: {e}"))?;
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
