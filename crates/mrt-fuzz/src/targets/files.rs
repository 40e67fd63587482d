//! The text configuration files: DCDT Agora configurations, Mr. BRIAN configuration
//! directories, the simulator's TOML, the blackboard's `config.dat`, and the relay's request
//! lines.

use super::{files_under, Harness, Seed, Target};
use crate::FuzzError;
use mrt_blackboard::relay::{parse_request, Request};
use mrt_blackboard::{BbLimits, Blackboard};
use mrt_core::SimClock;
use mrt_dcdt::config::AgoraConfig;
use mrt_fuzzy::brian::{Brian, BrianSources};
use mrt_robot::config::RobotFile;
use mrt_sim::config::SimConfig;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

/// DCDT Agora configuration files (MRT manual §3.3.1).
pub(super) const DCDT_CONFIG: Target = Target {
    name: "dcdt-config",
    about: "DCDT Agora configuration files: AgoraConfig::parse_bytes, then the canonical form must parse back to the same value",
    keywords: &["PostOffice:", "SLWB", "SLWDWCV", "SLWSM", "PMQ", "ip", "ser", "link", "bridge", "::1", "ff02::1", "224.0.0.1", "/dev/ttyS0"],
    structured: None,
    seeds: |root| files_under(&root.join("configs/dcdt"), |_| true),
    harness: |_| Ok(Box::new(DcdtConfig)),
};

struct DcdtConfig;

impl Harness for DcdtConfig {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        let Ok(config) = AgoraConfig::parse_bytes(input, "fuzz.cfg") else { return false };
        let _ = config.policy_or_default();
        // Documented: the canonical form of a parsed configuration parses to an equal value.
        let text = config.to_string();
        match AgoraConfig::parse(&text, "canonical.cfg") {
            Ok(again) => assert_eq!(again, config, "canonical form read back differently"),
            Err(e) => panic!("canonical form does not parse: {e}\n{text}"),
        }
        true
    }
}

/// Mr. BRIAN configuration directories: each file kind.
pub(super) const BRIAN: Target = Target {
    name: "brian",
    about: "Mr. BRIAN configurations (every file of configs/brian/*, one mutated at a time): Brian::from_sources, then cycles on extreme inputs",
    keywords: &["TRI", "TOL", "TOR", "DIV", "TRA", "REC", "SNG", "AND", "OR", "NOT", "P", "D", "&DEL", "level", "=>", "=", ";", "(", ")", "code:", "threshold_filter", "weight_composer", "float_composer", "composition", "argmax", "weighted", "semantics", "original", "manual"],
    structured: None,
    seeds: |root| {
        files_under(&root.join("configs/brian"), |slot| !slot.ends_with(".md") && slot.contains('/'))
    },
    harness: |root| {
        let mut dirs = BTreeMap::new();
        for seed in files_under(&root.join("configs/brian"), |s| !s.ends_with(".md"))? {
            let Some((dir, rel)) = seed.slot.split_once('/') else { continue };
            dirs.entry(dir.to_string())
                .or_insert_with(BrianSources::new)
                .insert(rel, seed.bytes);
        }
        Ok(Box::new(BrianFiles { dirs }))
    },
};

struct BrianFiles {
    /// Each shipped configuration, by directory name.
    dirs: BTreeMap<String, BrianSources>,
}

/// Inputs of the cycles run on a configuration that loads: ordinary, extreme, missing.
const BRIAN_VALUES: [(f64, f64); 6] =
    [(45.0, 1.0), (0.0, 0.5), (-1.0, 1.0), (1e308, 1.0), (f64::NAN, 1.0), (300.0, f64::NAN)];

impl Harness for BrianFiles {
    fn exec(&mut self, seed: &Seed, input: &[u8]) -> bool {
        let Some((dir, rel)) = seed.slot.split_once('/') else { return false };
        let Some(base) = self.dirs.get(dir) else { return false };
        let mut sources = base.clone();
        sources.insert(rel, input);
        let Ok(mut brian) = Brian::from_sources(&sources) else { return false };
        let _ = brian.warnings().len();
        brian.set_tracing(true);
        let names: Vec<String> = brian.input_names().map(str::to_string).collect();
        for (k, _) in BRIAN_VALUES.iter().enumerate() {
            let inputs: Vec<(&str, f64, f64)> = names
                .iter()
                .enumerate()
                .map(|(i, n)| {
                    let (v, r) = BRIAN_VALUES[(i + k) % BRIAN_VALUES.len()];
                    (n.as_str(), v, r)
                })
                .collect();
            let commands = brian.run(&inputs);
            let _ = commands.to_map();
            let _ = brian.trace();
        }
        true
    }
}

/// The simulator's TOML configuration.
pub(super) const SIM_CONFIG: Target = Target {
    name: "sim-config",
    about: "the simulator's TOML configuration: SimConfig::from_toml (parse + validate), the derived objects, and to_toml read back",
    keywords: &["[field]", "[ball]", "[body]", "[sensors]", "[rules]", "[sensor]", "[sonar]", "[odometry]", "[guidance]", "[vision]", "[vision.camera]", "=", "true", "false", "\"\"", "[]", "{}", "nan", "inf", "-inf", "1e400"],
    structured: Some(crate::mutate::mutate_toml),
    seeds: |root| files_under(&root.join("configs/sim"), |s| s.ends_with(".toml")),
    harness: |_| Ok(Box::new(SimToml)),
};

struct SimToml;

impl Harness for SimToml {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        // `SimConfig::from_file` reads the file as UTF-8 text.
        let Ok(text) = std::str::from_utf8(input) else { return false };
        let Ok(cfg) = SimConfig::from_toml(text, "fuzz.toml") else { return false };
        let _ = cfg.robot();
        let _ = cfg.robot_file(0, "chaos").to_toml();
        // Documented: to_toml gives a file from_toml reads back.
        match cfg.to_toml() {
            Ok(again) => {
                if let Err(e) = SimConfig::from_toml(&again, "again.toml") {
                    panic!("to_toml's output does not read back: {e}\n{again}");
                }
            }
            Err(e) => panic!("a valid configuration does not write as TOML: {e}"),
        }
        true
    }
}

/// The vision's files (`mrt vision --camera`, `--colors`): camera files of either model, and
/// colour files.
pub(super) const VISION_FILES: Target = Target {
    name: "vision-files",
    about: "a camera file (CameraModel::from_toml, pinhole or omni; a camera that reads must project and unproject) or a colour file (ColorTable::from_toml and its lookup table)",
    keywords: &["model", "\"pinhole\"", "\"omni\"", "[ball]", "[goal_yellow]", "[goal_blue]", "[robot]", "[line]", "[field]", "hue_min", "hue_max", "sat_min", "val_min", "=", "true", "false", "nan", "inf", "-inf", "1e400", "-1", "0"],
    structured: Some(crate::mutate::mutate_toml),
    seeds: |root| files_under(&root.join("configs/vision"), |s| s.ends_with(".toml")),
    harness: |_| Ok(Box::new(VisionToml)),
};

struct VisionToml;

impl Harness for VisionToml {
    fn exec(&mut self, seed: &Seed, input: &[u8]) -> bool {
        use mrt_perception::camera::{Camera, CameraModel, Pixel};
        use mrt_perception::vision::colors::{ColorTable, Lut};
        let Ok(text) = std::str::from_utf8(input) else { return false };
        if seed.slot.contains("colors") {
            let Ok(table) = ColorTable::from_toml(text, "fuzz.toml") else { return false };
            let lut = Lut::new(&table);
            let _ = lut.class(255, 120, 0);
            return true;
        }
        let Ok(camera) = CameraModel::from_toml(text, "fuzz.toml") else { return false };
        let (w, h) = camera.size();
        let centre = Pixel::new(f64::from(w) / 2.0, f64::from(h) / 2.0);
        let p = nalgebra::Point3::new(2.0, 0.5, 0.1);
        match camera {
            CameraModel::Pinhole(c) => {
                let _ = c.project(p).map(|px| c.unproject(px));
                let _ = c.unproject(centre);
            }
            CameraModel::Omni(c) => {
                let _ = c.project(p).map(|px| c.unproject_at_height(px, 0.1));
                let _ = c.unproject(centre);
            }
        }
        true
    }
}

/// SPIKE's map files (`mrt plan path --map`): a map that reads is planned on.
pub(super) const PLAN_MAP: Target = Target {
    name: "plan-map",
    about: "a SPIKE map file (PlanMap::from_toml); a map that reads is planned on across its area, at 5 cm",
    keywords: &["[area]", "[field]", "[[disc]]", "[[wall]]", "[[polygon]]", "[[door]]", "min", "max", "centre", "radius", "from", "to", "corners", "length", "width", "=", "[]", "nan", "inf", "-inf", "1e400", "-1", "0", "1e12"],
    structured: Some(crate::mutate::mutate_toml),
    seeds: |root| files_under(&root.join("configs/plan"), |s| s.ends_with(".toml")),
    harness: |_| Ok(Box::new(PlanToml)),
};

struct PlanToml;

impl Harness for PlanToml {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        use mrt_plan::spike::{PlanMap, Spike, SpikeParams};
        let Ok(text) = std::str::from_utf8(input) else { return false };
        let Ok(map) = PlanMap::from_toml(text, "fuzz.toml") else { return false };
        let (lo, hi) = (map.min, map.max);
        let params = SpikeParams { accuracy: 0.05, ..SpikeParams::default() };
        let Ok(spike) = Spike::new(map, params) else { return true };
        let at = |t: f64| mrt_core::Point2::new(lo.x + t * (hi.x - lo.x), lo.y + t * (hi.y - lo.y));
        // Documented: a plan that is made keeps its clearance at its corners past the start.
        if let Ok(plan) = spike.plan(at(0.2), at(0.8)) {
            for c in plan.waypoints.iter().skip(1).take(plan.waypoints.len().saturating_sub(2)) {
                let d = spike.map().clearance(*c);
                if d < spike.clearance() - 1e-6 {
                    panic!("corner {c:?} of a plan is {d} m from an obstacle");
                }
            }
        }
        true
    }
}

/// The two-mice calibration's readings log (`mrt mice calibrate LOG`, docs/mice.md).
pub(super) const MICE_LOG: Target = Target {
    name: "mice-log",
    about: "a two-mice calibration log (CalibrationLog::parse); a log that reads is calibrated (manual §4.2), every estimate a number or NaN, never a panic",
    keywords: &["kind,run,mouse,x,y", "straight", "turn", "left", "right", "l", "r", ",", "#", "\r\n", "0", "-1", "1000000", "1000001", "9223372036854775807", "-9223372036854775808"],
    structured: None,
    seeds: |root| files_under(&root.join("configs/mice"), |s| s.ends_with(".csv")),
    harness: |_| Ok(Box::new(MiceLog)),
};

struct MiceLog;

impl Harness for MiceLog {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        use mrt_perception::mice_calibration::{log::CalibrationLog, Procedure};
        let Ok(log) = CalibrationLog::parse("fuzz.csv", input) else { return false };
        // Documented: every run has both mice; a log that reads calibrates or says why.
        let _ = log.calibrate(&Procedure::default());
        let _ = log.to_text(&Procedure::default());
        true
    }
}

/// A robot's file (`mrt robot --config`).
pub(super) const ROBOT_FILE: Target = Target {
    name: "robot-file",
    about: "a robot file (mrt robot --config): RobotFile::from_toml (parse + config + spec), and to_toml read back",
    keywords: &["[robot]", "[body]", "[sensors]", "[ball]", "[field]", "[guidance]", "[devices]", "id", "team_size", "stack", "=", "\"chaos\"", "\"linked\"", "nan", "inf", "-inf", "1e400", "-1"],
    structured: Some(crate::mutate::mutate_toml),
    seeds: |root| files_under(&root.join("configs/robot"), |s| s.ends_with(".toml")),
    harness: |_| Ok(Box::new(RobotToml)),
};

struct RobotToml;

impl Harness for RobotToml {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        let Ok(text) = std::str::from_utf8(input) else { return false };
        let Ok(file) = RobotFile::from_toml(text, "fuzz.toml") else { return false };
        // Documented: a file that reads gives a configuration and a robot.
        if let Err(e) = file.config().and(file.spec().map(|_| ())) {
            panic!("a robot file that reads does not make a robot: {e}");
        }
        match file.to_toml() {
            Ok(again) => {
                if let Err(e) = RobotFile::from_toml(&again, "again.toml") {
                    panic!("to_toml's output does not read back: {e}\n{again}");
                }
            }
            Err(e) => panic!("a valid robot file does not write as TOML: {e}"),
        }
        true
    }
}

/// The blackboard's `config.dat` files.
pub(super) const BB_CONFIG: Target = Target {
    name: "bb-config",
    about: "blackboard config.dat files: config::parse, then every binding set on a blackboard as load_file does",
    keywords: &["Int", "Float", "Bool", "String", "true", "false", "local", "var", "talk", "*", "\"", "\\\"", "\\n", "\\u{0}"],
    structured: None,
    seeds: |root| files_under(&root.join("configs/bb"), |s| s.ends_with(".dat")),
    harness: |_| Ok(Box::new(BbConfig)),
};

struct BbConfig;

impl Harness for BbConfig {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        // `load_file` reads the file as UTF-8 text.
        let Ok(text) = std::str::from_utf8(input) else { return false };
        let Ok(bindings) = mrt_blackboard::config::parse(text, Path::new("config.dat")) else {
            return false;
        };
        let bb = Blackboard::new(1, Arc::new(SimClock::new()));
        for b in &bindings {
            let _ = bb.set(&b.symbol.to_string(), b.value.clone());
        }
        true
    }
}

/// The relay's request lines.
pub(super) const RELAY_LINE: Target = Target {
    name: "relay-line",
    about: "relay request lines: UTF-8 check and parse_request per line as the relay's client thread does, SETV/GETV/LSTV served on a small blackboard",
    keywords: &["AUTH", "REFR", "ADDW", "DELW", "CLRW", "LSTW", "SETV", "GETV", "LSTV", "QUIT", "Int", "Float", "Bool", "String", "local.var.", "*.var.", "*", "-", "\r"],
    structured: None,
    seeds: relay_seeds,
    harness: |_| Ok(Box::new(RelayLines)),
};

/// The request lines of `docs/relay-protocol.md`, a `SETV` for each binding of the shipped
/// `config.dat` files, and one line of each request.
fn relay_seeds(root: &Path) -> Result<Vec<Seed>, FuzzError> {
    const WORDS: [&str; 10] =
        ["AUTH", "REFR", "ADDW", "DELW", "CLRW", "LSTW", "SETV", "GETV", "LSTV", "QUIT"];
    let mut seeds = Vec::new();
    let doc = root.join("docs/relay-protocol.md");
    let text =
        std::fs::read_to_string(&doc).map_err(|source| FuzzError::Io { path: doc, source })?;
    for line in text.lines() {
        if WORDS.iter().any(|w| line.starts_with(w)) {
            seeds.push(Seed::new("doc", line));
        }
    }
    for dat in files_under(&root.join("configs/bb"), |s| s.ends_with(".dat"))? {
        for line in String::from_utf8_lossy(&dat.bytes).lines() {
            let line = line.trim();
            if !line.is_empty() && !line.starts_with('#') {
                seeds.push(Seed::new("setv", format!("SETV {line}")));
            }
        }
    }
    for line in [
        "AUTH s3cret-token",
        "REFR 100",
        "ADDW local.var.machine.*",
        "DELW *.var.team.*",
        "CLRW",
        "LSTW",
        "GETV local.var.kicker.kick",
        "LSTV",
        "LSTV local.var.* local.var.kicker.kick",
        "LSTV * -",
        "SETV local.var.machine.config.role String \"keeper \\\"one\\\"\"",
        "SETV local.talk.team.msg String \"hi\"",
        "QUIT\r",
    ] {
        seeds.push(Seed::new("builtin", line));
    }
    Ok(seeds)
}

struct RelayLines;

impl Harness for RelayLines {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        let limits = BbLimits { max_symbols: 64, ..BbLimits::default() };
        let bb = Blackboard::with_limits(2, Arc::new(SimClock::new()), limits);
        let mut accepted = false;
        for raw in input.split(|b| *b == b'\n') {
            let Ok(text) = std::str::from_utf8(raw) else { continue };
            let request = parse_request(text);
            accepted |= matches!(request, Ok(Some(_)));
            match request {
                Ok(Some(Request::Setv(symbol, value))) => {
                    let _ = bb.set(&symbol, value);
                }
                Ok(Some(Request::Getv(symbol))) => {
                    let _ = bb.get_stamped(&symbol);
                }
                Ok(_) => {}
                Err(refusal) => {
                    let line = refusal.line();
                    assert!(!line.contains('\n'), "a refusal spans lines: {line:?}");
                }
            }
        }
        accepted
    }
}
