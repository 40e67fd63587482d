//! `mrt behave` and `mrt hfsm dot`: try a Lua behavior or HFSM offline, draw an HFSM.

use anyhow::{bail, Context as _, Result};
use mrt_msgs::robot::WorldSnapshot;
use mrt_script::chaos::{self, RobotIo};
use mrt_script::hfsm::Hfsm;
use mrt_script::offline::{cycle_line, parse_worlds, world_at, WorldsError};
use mrt_script::{LuaRuntime, Sandbox, ThinkingCap};
use std::cell::RefCell;
use std::io::Write as _;
use std::path::Path;
use std::rc::Rc;

/// The most cycles `mrt behave` runs (at 100 ms a cycle, more than three years simulated).
pub const MAX_CYCLES: u64 = 1_000_000_000;
/// The longest simulated time between cycles, ms (one hour).
pub const MAX_PERIOD_MS: u64 = 3_600_000;

/// The worlds to run, one per cycle, produced as the cycles go: nothing is allocated per cycle
/// up front.
struct Worlds {
    /// The snapshots of the file: one (used every cycle) or one per cycle, the last one
    /// repeated when `--cycles` asks for more.
    list: Vec<WorldSnapshot>,
    cycles: u64,
}

impl Worlds {
    /// Reads the worlds; `cycles` defaults to 1, or to the array's length.
    fn load(path: Option<&Path>, cycles: Option<u64>) -> Result<Worlds> {
        if let Some(n) = cycles {
            if !(1..=MAX_CYCLES).contains(&n) {
                bail!("--cycles must be 1 to {MAX_CYCLES}, not {n}");
            }
        }
        let Some(path) = path else {
            return Ok(Worlds {
                list: vec![WorldSnapshot::default()],
                cycles: cycles.unwrap_or(1),
            });
        };
        let text = mrt_core::read_text(path, mrt_core::MAX_LOG_BYTES)
            .with_context(|| format!("cannot read {}", path.display()))?;
        let list = parse_worlds(&text).map_err(|e| match e {
            WorldsError::Syntax { .. } => anyhow::anyhow!("{}:{e}", path.display()),
            other => anyhow::anyhow!("{}: {other}", path.display()),
        })?;
        // One world a cycle: an object is one, an empty array none.
        Ok(Worlds { cycles: cycles.unwrap_or(list.len() as u64), list })
    }
}

/// Runs `file` (a behavior, or an HFSM when it ends in `.hfsm.lua`) against the worlds, one
/// JSON line of commands per cycle. Returns an error (exit status 1) if any cycle failed.
pub fn behave(
    file: &Path,
    world: Option<&Path>,
    cycles: Option<u64>,
    period_ms: u64,
) -> Result<()> {
    if !(1..=MAX_PERIOD_MS).contains(&period_ms) {
        bail!("--period-ms must be 1 to {MAX_PERIOD_MS}, not {period_ms}");
    }
    let worlds = Worlds::load(world, cycles)?;
    let dir = file.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = file.file_name().and_then(|n| n.to_str()).unwrap_or_default();
    let mut cap = if name.ends_with(".hfsm.lua") {
        ThinkingCap::with_hfsm(dir, file, Sandbox::default())
    } else {
        let stem = name.strip_suffix(".lua").unwrap_or(name);
        ThinkingCap::with_behavior(dir, stem, Sandbox::default())
    }
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut failed: u64 = 0;
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    for k in 0..worlds.cycles {
        let w = world_at(&worlds.list, k, period_ms);
        let time = w.time;
        let c = cap.cycle(w);
        for e in &c.errors {
            eprintln!("error: cycle {k}: {}", mrt_core::printable(&e.to_string()));
        }
        failed += u64::from(!c.errors.is_empty());
        let line = cycle_line(k, time, &c);
        writeln!(out, "{line}")?;
    }
    out.flush()?;
    if failed > 0 {
        bail!("{failed} cycle(s) had script errors");
    }
    Ok(())
}

/// Writes an HFSM file as Graphviz dot (to `dot`, or standard output) and as SVG.
pub fn hfsm_dot(file: &Path, dot: Option<&Path>, svg: Option<&Path>) -> Result<()> {
    let rt = LuaRuntime::new(Sandbox::default()).map_err(|e| anyhow::anyhow!("{e}"))?;
    let io = Rc::new(RefCell::new(RobotIo::default()));
    chaos::install(&rt, io.clone()).map_err(|e| anyhow::anyhow!("{e}"))?;
    let hfsm = Hfsm::from_file(&rt, file, io).map_err(|e| anyhow::anyhow!("{e}"))?;
    let text = hfsm.to_dot(true);
    match dot {
        Some(p) => {
            std::fs::write(p, &text).with_context(|| format!("cannot write {}", p.display()))?
        }
        None => {
            use std::io::Write as _;
            std::io::stdout().lock().write_all(text.as_bytes())?
        }
    }
    if let Some(p) = svg {
        std::fs::write(p, hfsm.to_svg())
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    Ok(())
}
