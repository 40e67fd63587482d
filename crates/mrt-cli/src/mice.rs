//! `mrt mice calibrate LOG` and `mrt sim --calibrate-mice`: the two-mice calibration (MRT
//! manual §4.2; `docs/mice.md`). Millimetres, degrees and cpi here, at the edge: the library
//! works in metres, radians and counts per metre.

use anyhow::{anyhow, Context as _, Result};
use mrt_core::frames::{metres, millimetres, MM_PER_M};
use mrt_perception::mice_calibration::log::CalibrationLog;
use mrt_perception::mice_calibration::{
    Estimate, MiceCalibration, MiceMounting, Mouse, MouseCalibration, MouseMounting, Procedure, CPI,
};
use mrt_sim::config::SimConfig;
use mrt_sim::mice_calibration::{self as rig, Tolerances};
use std::path::{Path, PathBuf};

/// `mrt mice ...`.
#[derive(clap::Subcommand)]
pub enum MiceCommand {
    /// Calibrate the two-mice odometry sensor (MRT manual §4.2) from the log of its readings
    /// on the procedure's straight runs and turns in place (format: docs/mice.md): each
    /// mouse's resolution, orientation and position, the distance D between the mice and the
    /// angle δ, each ± its standard error.
    Calibrate(CalibrateArgs),
}

/// `mrt mice calibrate`'s options.
#[derive(clap::Args)]
pub struct CalibrateArgs {
    /// The log of the readings (CSV: kind,run,mouse,x,y; docs/mice.md).
    pub log: PathBuf,
    /// Print the parameters as JSON (SI units: m, rad, counts per metre).
    #[arg(long)]
    pub json: bool,
    /// Length of each straight run, mm (the manual: 500).
    #[arg(long, default_value_t = 500.0)]
    pub length_mm: f64,
    /// Angle of each turn in place, degrees, counter-clockwise positive (the manual: 360).
    #[arg(long, default_value_t = 360.0, allow_negative_numbers = true)]
    pub turn_deg: f64,
}

/// Runs `mrt mice ...`.
pub fn run(command: &MiceCommand) -> Result<()> {
    match command {
        MiceCommand::Calibrate(args) => calibrate(args),
    }
}

fn calibrate(args: &CalibrateArgs) -> Result<()> {
    let procedure = Procedure::new(metres(args.length_mm), args.turn_deg.to_radians())
        .map_err(|e| anyhow!("--length-mm / --turn-deg: {e}"))?;
    let log = CalibrationLog::read(&args.log)?;
    let c = log.calibrate(&procedure).with_context(|| format!("{}", args.log.display()))?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&c)?);
    } else {
        outln!("{}", table(&c, None));
    }
    Ok(())
}

/// `mrt sim --calibrate-mice`: the simulator's rig (`mrt_sim::mice_calibration`) on the
/// configuration `cfg`, from `seed`; the log written to `log` when given.
pub fn sim(cfg: &SimConfig, seed: u64, json: bool, log: Option<&Path>) -> Result<()> {
    let truth = rig::default_mounting();
    let report = rig::run(cfg, &truth, seed).map_err(|e| anyhow!("{e}"))?;
    if let Some(path) = log {
        std::fs::write(path, report.log.to_text(&report.procedure))
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    let tol = Tolerances::default();
    let check = report.check(&tol);
    if json {
        let expected = |m| report.expected_resolution(m);
        let value = serde_json::json!({
            "simulated": truth,
            "expected_resolution": { "left": expected(Mouse::Left), "right": expected(Mouse::Right) },
            "calibration": report.calibration,
            "tolerances": {
                "resolution": tol.resolution, "angle": tol.angle,
                "position": tol.position, "distance": tol.distance,
            },
            "within_tolerances": check.is_ok(),
            "outside": check.as_ref().err(),
            "simulated_seconds": report.seconds,
            "validation": {
                "path": report.validation.path,
                "error_calibrated": report.validation.error_calibrated,
                "error_true_mounting": report.validation.error_true_mounting,
                "heading_error_calibrated": report.validation.heading_error_calibrated,
                "heading_error_true_mounting": report.validation.heading_error_true_mounting,
                "error_reduced": report.validation.error_reduced,
                "heading_error_reduced": report.validation.heading_error_reduced,
            },
        });
        outln!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        outln!(
            "the simulator's calibration rig: one robot, mice mounted as below, noise {:.1} % per \
             reading and axis, {:.0} % of readings short by up to half; {:.0} simulated seconds",
            100.0 * cfg.odometry.mice_noise,
            100.0 * cfg.odometry.mice_miss_probability,
            report.seconds
        );
        if let Some(path) = log {
            outln!("readings written to {}", path.display());
        }
        let expected =
            [report.expected_resolution(Mouse::Left), report.expected_resolution(Mouse::Right)];
        outln!("{}", table(&report.calibration, Some((&truth, expected))));
        outln!(
            "tolerances: resolution {:.0} % of the expected (the mounting's × {:.4}, the mice's \
             mean read fraction), angles {:.1}°, positions {:.0} mm, D {:.0} mm: {}",
            100.0 * tol.resolution,
            report.read_fraction,
            tol.angle.to_degrees(),
            millimetres(tol.position),
            millimetres(tol.distance),
            if check.is_ok() { "all within" } else { "NOT all within" }
        );
        let v = &report.validation;
        outln!(
            "put to use: dead reckoning on a {:.2} m test drive ends {:.1} mm and {:.2}° off through \
             the calibrated mounting, {:.1} mm and {:.2}° through the simulated one, {:.1} mm and \
             {:.2}° through the calibrated one with §4.2's error reduction",
            v.path,
            millimetres(v.error_calibrated),
            v.heading_error_calibrated.to_degrees(),
            millimetres(v.error_true_mounting),
            v.heading_error_true_mounting.to_degrees(),
            millimetres(v.error_reduced),
            v.heading_error_reduced.to_degrees()
        );
    }
    check.map_err(|bad| anyhow!("estimates outside the tolerances: {}", bad.join("; ")))
}

/// `value ± error` with `digits` decimals, after scaling by `scale`.
fn pm(e: &Estimate, scale: f64, digits: usize) -> String {
    format!("{:.digits$} ± {:.digits$}", e.value * scale, e.std_error * scale)
}

/// One row of the table: its name, the scale and decimals of its unit, the estimate of a
/// mouse, and the simulated value (resolution to expect, counts/m; mounting) when known.
type Row =
    (&'static str, f64, usize, fn(&MouseCalibration) -> Estimate, fn(f64, &MouseMounting) -> f64);

/// A row of the pair's quantities: name, estimate, simulated value, scale of the unit.
type PairRow<'a> = (&'static str, &'a Estimate, fn(&MiceMounting) -> f64, f64);

/// The calibration as a table, one row per parameter, a column per mouse; with the simulated
/// mounting (and the resolutions to expect) beside the estimates when given.
fn table(c: &MiceCalibration, truth: Option<(&MiceMounting, [f64; 2])>) -> String {
    let deg = 180.0 / std::f64::consts::PI;
    let p = &c.procedure;
    let mut out = format!(
        "two-mice calibration (MRT manual §4.2): {} straight runs of {} mm, {} turns of {}° in \
         place; value ± one standard error\n",
        c.straight_runs,
        millimetres(p.length),
        c.turns,
        p.turn * deg
    );
    let header = match truth {
        Some(_) => ["left", "simulated", "right", "simulated"].as_slice(),
        None => ["left", "right"].as_slice(),
    };
    out += &format!("{:<24}", "");
    for h in header {
        out += &format!("{h:>20}");
    }
    out.push('\n');
    let rows: [Row; 7] = [
        ("resolution (counts/mm)", 1.0 / MM_PER_M, 3, |m| m.resolution, |k, _| k),
        ("resolution (cpi)", 1.0 / CPI, 1, |m| m.resolution, |k, _| k),
        ("σ, orientation (°)", deg, 2, |m| m.sigma, |_, t| t.sigma),
        ("x (mm)", MM_PER_M, 2, |m| m.x, |_, t| t.x),
        ("y (mm)", MM_PER_M, 2, |m| m.y, |_, t| t.y),
        ("radius (mm)", MM_PER_M, 2, |m| m.radius, |_, t| t.x.hypot(t.y)),
        (
            "tangent angle (°)",
            deg,
            2,
            |m| m.tangent_angle,
            |_, t| mrt_core::normalize_angle(t.x.atan2(-t.y) - t.sigma),
        ),
    ];
    for (name, scale, digits, est, tru) in rows {
        out += &format!("{name:<24}");
        for (which, m) in [(Mouse::Left, &c.left), (Mouse::Right, &c.right)] {
            out += &format!("{:>20}", pm(&est(m), scale, digits));
            if let Some((mounting, expected)) = truth {
                let k = expected[which as usize];
                out += &format!("{:>20.digits$}", tru(k, mounting.mouse(which)) * scale);
            }
        }
        out.push('\n');
    }
    let pair: [PairRow; 4] = [
        ("D (mm)", &c.distance, |m| m.distance(), MM_PER_M),
        ("D along x (mm)", &c.distance_x, |m| m.right.x - m.left.x, MM_PER_M),
        ("D along y (mm)", &c.distance_y, |m| m.right.y - m.left.y, MM_PER_M),
        ("δ (°)", &c.delta, |m| m.delta(), deg),
    ];
    for (name, est, tru, scale) in pair {
        out += &format!("{name:<24}{:>20}", pm(est, scale, 2));
        if let Some((m, _)) = truth {
            out += &format!("{:>20.2}", tru(m) * scale);
        }
        out.push('\n');
    }
    if truth.is_some() {
        out +=
            "(simulated resolution: the mounting's times the simulated mice's mean read fraction)";
    }
    out.trim_end().to_string()
}
