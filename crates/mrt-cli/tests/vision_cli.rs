//! `mrt vision detect` on images it has never seen: frames drawn here through the shipped
//! camera file (green carpet, noise, an orange ball where the camera sees it, with the size a
//! sphere has), read back as PNG and JPEG.
#![allow(clippy::unwrap_used)]

use image::{Rgb, RgbImage};
use mrt_perception::camera::{ball_diameter_px, Camera, CameraFile};
use nalgebra::Point3;
use std::path::{Path, PathBuf};
use std::process::Command;

fn config(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/vision").join(name)
}

/// A 320×240 frame of the shipped camera with the ball centred at `(x, y)` on the floor (m),
/// or none.
fn frame(ball: Option<(f64, f64)>, seed: u32) -> RgbImage {
    let cam = CameraFile::from_file(config("camera.toml")).unwrap().camera().unwrap();
    let (w, h) = cam.size();
    let disc = ball.map(|(x, y)| {
        let centre = Point3::new(x, y, 0.11);
        let px = cam.project(centre).unwrap();
        let r = ball_diameter_px(0.11, cam.intrinsics.fx, (centre - cam.centre()).norm()) / 2.0;
        (px, r)
    });
    // A cheap deterministic noise, ±6 per channel.
    let mut state = seed.wrapping_mul(2_654_435_761).max(1);
    let mut noise = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        (state % 13) as i32 - 6
    };
    RgbImage::from_fn(w, h, |x, y| {
        let mut c = [30, 140, 40];
        if let Some((px, r)) = disc {
            if (f64::from(x) + 0.5 - px.x).hypot(f64::from(y) + 0.5 - px.y) <= r {
                c = [255, 120, 0];
            }
        }
        Rgb(c.map(|v: i32| (v + noise()).clamp(0, 255) as u8))
    })
}

fn detect(images: &[&Path], extra: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_mrt"))
        .args(["vision", "detect", "--camera"])
        .arg(config("camera.toml"))
        .arg("--colors")
        .arg(config("colors.toml"))
        .args(extra)
        .args(images)
        .output()
        .unwrap();
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (out.status.success(), text(&out.stdout), text(&out.stderr))
}

#[test]
fn the_ball_is_found_in_images_at_its_distance_and_bearing() {
    let dir = std::env::temp_dir().join(format!("mrt-vision-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let spots = [(1.0, 0.0), (1.5, 0.4), (2.5, -0.6), (3.5, 0.5)];
    let mut files = Vec::new();
    for (i, &(x, y)) in spots.iter().enumerate() {
        let ext = if i % 2 == 0 { "png" } else { "jpg" };
        let path = dir.join(format!("ball-{i}.{ext}"));
        frame(Some((x, y)), i as u32 + 1).save(&path).unwrap();
        files.push(path);
    }
    let empty = dir.join("empty.png");
    frame(None, 9).save(&empty).unwrap();
    files.push(empty.clone());
    let paths: Vec<&Path> = files.iter().map(|p| p.as_path()).collect();
    let (ok, out, err) = detect(&paths, &[]);
    assert!(ok, "{err}");
    let lines: Vec<serde_json::Value> =
        out.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), files.len());
    for (line, &(x, y)) in lines.iter().zip(&spots) {
        let ball = &line["objects"][0];
        assert_eq!(ball["class"], "ball", "{line}");
        let d = ball["distance_m"].as_f64().unwrap();
        let b = ball["bearing_deg"].as_f64().unwrap();
        let (td, tb) = (x.hypot(y), y.atan2(x).to_degrees());
        assert!((d - td).abs() <= 0.05 * td, "({x}, {y}): {line}");
        assert!((b - tb).abs() <= 1.5, "({x}, {y}): {line}");
    }
    assert_eq!(lines[4]["objects"].as_array().unwrap().len(), 0, "no ball: {}", lines[4]);
    // A blue goal 3 m ahead, 1 m wide: its nearest point at 3 m, straight ahead.
    let goal = dir.join("goal.png");
    let mut img = frame(None, 5);
    let cam = CameraFile::from_file(config("camera.toml")).unwrap().camera().unwrap();
    let l = cam.project(Point3::new(3.0, 0.5, 0.0)).unwrap();
    let r = cam.project(Point3::new(3.0, -0.5, 0.0)).unwrap();
    let t = cam.project(Point3::new(3.0, 0.0, 0.8)).unwrap();
    for y in t.y as u32..l.y as u32 {
        for x in l.x as u32..r.x as u32 {
            img.put_pixel(x, y, Rgb([20, 60, 220]));
        }
    }
    img.save(&goal).unwrap();
    let (ok, out, err) = detect(&[&goal], &[]);
    assert!(ok, "{err}");
    let line: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    let g = &line["objects"][0];
    assert_eq!(g["class"], "goal_blue", "{line}");
    assert!((g["distance_m"].as_f64().unwrap() - 3.0).abs() < 0.15, "{line}");
    assert!(g["bearing_deg"].as_f64().unwrap().abs() < 1.5, "{line}");
    // The drawing.
    let drawn = dir.join("drawn.png");
    let (ok, _, err) = detect(&[&files[0]], &["--png", drawn.to_str().unwrap()]);
    assert!(ok && image::open(&drawn).unwrap().width() == 320, "{err}");
    // An image of another size than the camera's is refused, with both sizes.
    let small = dir.join("small.png");
    RgbImage::new(32, 24).save(&small).unwrap();
    let (ok, _, err) = detect(&[&small], &[]);
    assert!(!ok && err.contains("32×24") && err.contains("320×240"), "{err}");
    // Not an image.
    let text = dir.join("not-an-image.png");
    std::fs::write(&text, "hello").unwrap();
    let (ok, _, err) = detect(&[&text], &[]);
    assert!(!ok && err.contains("not-an-image.png") && !err.contains("panicked"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

fn render(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_mrt"))
        .args(["vision", "render"])
        .args(args)
        .output()
        .unwrap();
    (out.status.success(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// `mrt vision render` draws what the simulator's camera sees; `mrt vision detect` finds the
/// ball in it where it was put, 2 m ahead-left of a robot at (-3, 1) facing 30°, and the robot
/// in view with its team's marker.
#[test]
fn detect_finds_the_ball_in_a_rendered_frame() {
    let dir = std::env::temp_dir().join(format!("mrt-vision-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("frame.png");
    // The ball 2 m away, 10° left of the heading: 40° in the field frame.
    let (bx, by) = (-3.0 + 2.0 * 40f64.to_radians().cos(), 1.0 + 2.0 * 40f64.to_radians().sin());
    let ball = format!("{bx},{by}");
    let (ok, err) = render(&[
        "--at",
        "-3,1,30",
        "--ball",
        &ball,
        "--robot",
        "0,2,away",
        "--robot",
        "1,0.5,home",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let (ok, out, err) = detect(&[&png], &[]);
    assert!(ok, "{err}");
    let line: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    let ball = &line["objects"][0];
    assert_eq!(ball["class"], "ball", "{line}");
    let d = ball["distance_m"].as_f64().unwrap();
    let b = ball["bearing_deg"].as_f64().unwrap();
    assert!((d - 2.0).abs() < 0.1 && (b - 10.0).abs() < 1.5, "{line}");
    // The away robot at (0, 2) is 3.16 m away at -11.6°, its nearest point 2.91 m; the home
    // one at (1, 0.5) is 37° to the right, out of view.
    let robots: Vec<&serde_json::Value> =
        line["objects"].as_array().unwrap().iter().filter(|o| o["class"] == "robot").collect();
    assert_eq!(robots.len(), 1, "{line}");
    let d = robots[0]["distance_m"].as_f64().unwrap();
    let b = robots[0]["bearing_deg"].as_f64().unwrap();
    assert!((d - 2.91).abs() < 0.15 && (b + 11.6).abs() < 2.0, "{line}");
    assert_eq!(robots[0]["marker"], "cyan", "{line}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Facing the east goal from 9, 5 and 3 m, the goal is wholly in view: `detect` reports its
/// net, the centre of its goal line, within 3 % (near the goal too, where the posts slant
/// outwards in the image and the slant's columns do not stand on the carpet).
#[test]
fn detect_reports_the_net_of_a_goal_wholly_in_view() {
    let dir = std::env::temp_dir().join(format!("mrt-vision-net-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (x, want) in [(0.0, 9.0), (4.0, 5.0), (6.0, 3.0)] {
        let png = dir.join(format!("net-{x}.png"));
        let (ok, err) = render(&["--at", &format!("{x},0,0"), "--out", png.to_str().unwrap()]);
        assert!(ok, "{err}");
        let (ok, out, err) = detect(&[&png], &[]);
        assert!(ok, "{err}");
        let line: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
        let nets: Vec<&serde_json::Value> =
            line["objects"].as_array().unwrap().iter().filter(|o| o["class"] == "net").collect();
        assert_eq!(nets.len(), 1, "{line}");
        assert_eq!(nets[0]["goal"], "east", "{line}");
        let d = nets[0]["distance_m"].as_f64().unwrap();
        let b = nets[0]["bearing_deg"].as_f64().unwrap();
        assert!((d - want).abs() < 0.03 * want && b.abs() < 1.0, "from x = {x}: {line}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn render_says_what_is_wrong_with_its_arguments() {
    let out = std::env::temp_dir().join("mrt-never-written.png");
    let out = out.to_str().unwrap();
    let (ok, err) = render(&["--at", "1,2", "--out", out]);
    assert!(!ok && err.contains("expected X,Y,HEADING_DEG"), "{err}");
    let (ok, err) = render(&["--at", "0,0,0", "--robot", "1,1,referee", "--out", out]);
    assert!(!ok && err.contains("home or away"), "{err}");
    let (ok, err) = render(&["--at", "0,0,0", "--ball", "1,nan", "--out", out]);
    assert!(!ok && err.contains("is not a number"), "{err}");
    let (ok, err) = render(&["--at", "0,0,0", "--world", "/nonexistent/world.toml", "--out", out]);
    assert!(!ok && err.contains("/nonexistent/world.toml"), "{err}");
}

/// A directory is a recorded sequence: its images in name order, other files skipped.
#[test]
fn detect_reads_a_directory_of_frames_in_name_order() {
    let dir = std::env::temp_dir().join(format!("mrt-vision-seq-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    frame(Some((2.0, 0.0)), 1).save(dir.join("002.png")).unwrap();
    frame(Some((1.0, 0.0)), 2).save(dir.join("001.png")).unwrap();
    frame(None, 3).save(dir.join("003.png")).unwrap();
    std::fs::write(dir.join("README.txt"), "the frames of one run").unwrap();
    let (ok, out, err) = detect(&[&dir], &[]);
    assert!(ok, "{err}");
    let lines: Vec<serde_json::Value> =
        out.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 3, "{out}");
    let distance = |l: &serde_json::Value| l["objects"][0]["distance_m"].as_f64();
    assert!(lines[0]["image"].as_str().unwrap().ends_with("001.png"));
    assert!((distance(&lines[0]).unwrap() - 1.0).abs() < 0.05, "{}", lines[0]);
    assert!((distance(&lines[1]).unwrap() - 2.0).abs() < 0.1, "{}", lines[1]);
    assert_eq!(lines[2]["objects"].as_array().map(Vec::len), Some(0), "{}", lines[2]);
    // A directory without images says so.
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let (ok, _, err) = detect(&[&empty], &[]);
    assert!(!ok && err.contains("no .png, .jpg or .jpeg files"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `mrt vision calibrate` on a rendered frame: every pixel counted once, each class's pixels
/// within its thresholds, an SVG of the histograms and one coverage image per class.
#[test]
fn calibrate_reports_what_each_class_takes() {
    let dir = std::env::temp_dir().join(format!("mrt-vision-calib-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("frame.png");
    let (ok, err) =
        render(&["--at", "-3,0,0", "--ball", "-1.5,0.3", "--out", png.to_str().unwrap()]);
    assert!(ok, "{err}");
    let out_dir = dir.join("out");
    let out = Command::new(env!("CARGO_BIN_EXE_mrt"))
        .args(["vision", "calibrate", "--colors"])
        .arg(config("colors.toml"))
        .arg("--out")
        .arg(&out_dir)
        .arg(&png)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["images"], 1);
    assert_eq!(report["pixels"], 320 * 240);
    let classes = report["classes"].as_array().unwrap();
    let sum: u64 = classes.iter().map(|c| c["pixels"].as_u64().unwrap()).sum();
    assert_eq!(sum, 320 * 240, "every pixel under exactly one class");
    let class = |name: &str| classes.iter().find(|c| c["class"] == name).unwrap();
    let ball = class("ball");
    assert!(ball["pixels"].as_u64().unwrap() > 50, "{ball}");
    // The rendered ball is orange: its hues between 10° and 40°, its saturation high.
    let hue = ball["hue_range_deg"].as_array().unwrap();
    assert!(hue[0].as_f64().unwrap() >= 10.0 && hue[1].as_f64().unwrap() <= 40.0, "{ball}");
    assert!(
        ball["sat_range"][0].as_f64().unwrap()
            >= ball["thresholds"]["sat_min"].as_f64().unwrap() - 0.05
    );
    assert!(class("field")["share"].as_f64().unwrap() > 0.5);
    assert!(class("unknown")["thresholds"].is_null());
    let svg = std::fs::read_to_string(out_dir.join("histograms.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    for c in classes {
        let name = c["class"].as_str().unwrap();
        assert!(svg.contains(&format!(">{name}<")), "{name} missing from the SVG");
        let cover = image::open(out_dir.join(format!("frame-{name}.png"))).unwrap();
        assert_eq!((cover.width(), cover.height()), (320, 240));
    }
    // A colour file that does not exist is named in the error.
    let out = Command::new(env!("CARGO_BIN_EXE_mrt"))
        .args(["vision", "calibrate", "--colors", "/nonexistent/colors.toml"])
        .arg(&png)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/colors.toml"));
    std::fs::remove_dir_all(&dir).ok();
}

/// `mrt vision survey`: the table of the vision against the truth, and its JSON, whose counts
/// agree with each other; a count of 0 scenes is refused.
#[test]
fn survey_prints_the_vision_against_the_truth() {
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_mrt"))
            .args(["vision", "survey"])
            .args(args)
            .output()
            .unwrap();
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stdout).to_string(),
            String::from_utf8_lossy(&out.stderr).to_string(),
        )
    };
    let (ok, table, err) = run(&["--scenes", "40", "--seed", "5"]);
    assert!(ok, "{err}");
    assert!(table.starts_with("40 scenes, seed 5"), "{table}");
    for kind in ["| ball |", "| net |", "| post |", "| obstacle |"] {
        assert!(table.contains(kind), "{kind} in {table}");
    }
    let (ok, json, err) = run(&["--scenes", "40", "--seed", "5", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let ball = &v["kinds"][0];
    assert_eq!(ball["kind"], "ball");
    assert!(ball["found"].as_u64().unwrap() <= ball["in_view"].as_u64().unwrap());
    assert!(ball["in_view"].as_u64().unwrap() > 5, "{json}");
    let (ok, _, err) = run(&["--scenes", "0"]);
    assert!(!ok && err.contains("--scenes"), "{err}");
}

/// The USB camera path is built in and says clearly when there is no camera.
#[test]
fn detect_from_a_missing_camera_says_so() {
    let (ok, out, err) = detect(&[], &["--device", "/dev/video-mrt-none", "--frames", "2"]);
    assert!(!ok && out.is_empty());
    assert!(
        err.contains("/dev/video-mrt-none: no such device: is the camera plugged in?"),
        "{err}"
    );
    let (ok, _, err) = detect(&[], &["--device", "/dev/null"]);
    assert!(!ok && err.contains("/dev/null: cannot open it as a V4L2 device"), "{err}");
    let (ok, _, err) = detect(&["x.png".as_ref()], &["--frames", "2"]);
    assert!(!ok && err.contains("--frames counts the frames grabbed from --device"), "{err}");
    let (ok, _, err) = detect(&[], &["--device", "/dev/video0", "--frames", "0"]);
    assert!(!ok && err.contains("--frames"), "{err}");
}

/// The up camera (`configs/vision/omni.toml`): `render` draws what its mirror images and
/// `detect` finds the ball in it through the same file, 2.12 m away at 5° (a robot at
/// (-2, 1) facing 40°, the ball at (-0.5, 2.5)); `--png` draws it.
#[test]
fn the_up_camera_renders_and_detects_through_its_camera_file() {
    let dir = std::env::temp_dir().join(format!("mrt-vision-omni-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (png, found) = (dir.join("up.png"), dir.join("found.png"));
    let omni = config("omni.toml");
    let (ok, err) = render(&[
        "--camera",
        omni.to_str().unwrap(),
        "--at",
        "-2,1,40",
        "--ball",
        "-0.5,2.5",
        "--robot",
        "0,0,away",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let out = Command::new(env!("CARGO_BIN_EXE_mrt"))
        .args(["vision", "detect", "--camera"])
        .arg(&omni)
        .arg("--colors")
        .arg(config("colors.toml"))
        .arg("--png")
        .arg(&found)
        .arg(&png)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let line: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    let ball = &line["objects"][0];
    assert_eq!(ball["class"], "ball", "{line}");
    let (d, b) = (ball["distance_m"].as_f64().unwrap(), ball["bearing_deg"].as_f64().unwrap());
    assert!((d - 1.5f64.hypot(1.5)).abs() < 0.05 * d && (b - 5.0).abs() < 1.5, "{line}");
    assert_eq!(image::open(&found).unwrap().to_rgb8().dimensions(), (480, 480));
    std::fs::remove_dir_all(&dir).unwrap();
}
