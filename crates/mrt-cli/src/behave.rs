//! `mrt behave` and `mrt hfsm dot`: try a Lua behavior or HFSM offline, draw an HFSM. Both
//! run the scripts as a match does: `behave` under the [`Watchdog`] (the simulated clock's
//! deadline, a stopped behavior restarting from its files), `hfsm dot` on a thread of its own
//! within the load deadline.

use anyhow::{bail, Context as _, Result};
use mrt_msgs::robot::WorldSnapshot;
use mrt_script::chaos::{self, RobotIo};
use mrt_script::hfsm::Hfsm;
use mrt_script::offline::{cycle_line, parse_worlds, world_at, WorldsError};
use mrt_script::{LuaRuntime, Sandbox, ThinkingCap, Watchdog, LOAD_DEADLINE, SIMULATED_DEADLINE};
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
    let name = file.file_name().and_then(|n| n.to_str()).unwrap_or_default().to_string();
    let (dir, machine) = (dir.to_path_buf(), file.to_path_buf());
    let top = name.clone();
    let mut cap = Watchdog::start(&name, SIMULATED_DEADLINE, move || {
        if top.ends_with(".hfsm.lua") {
            ThinkingCap::with_hfsm(&dir, &machine, Sandbox::default())
        } else {
            let stem = top.strip_suffix(".lua").unwrap_or(&top);
            ThinkingCap::with_behavior(&dir, stem, Sandbox::default())
        }
    })
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
    let (text, drawing) = draw_within_deadline(file, svg.is_some())?;
    match dot {
        Some(p) => {
            std::fs::write(p, &text).with_context(|| format!("cannot write {}", p.display()))?
        }
        None => {
            use std::io::Write as _;
            std::io::stdout().lock().write_all(text.as_bytes())?
        }
    }
    if let (Some(p), Some(drawing)) = (svg, drawing) {
        std::fs::write(p, drawing).with_context(|| format!("cannot write {}", p.display()))?;
    }
    Ok(())
}

/// The dot text (and the SVG drawing when asked) of an HFSM file, loaded on a thread of its
/// own within [`LOAD_DEADLINE`], as a robot loads its behaviors.
fn draw_within_deadline(file: &Path, svg: bool) -> Result<(String, Option<String>)> {
    let path = file.to_path_buf();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::Builder::new()
        .name("hfsm-dot".into())
        .spawn(move || {
            let drawn = (|| {
                let rt = LuaRuntime::new(Sandbox::default())?;
                let io = Rc::new(RefCell::new(RobotIo::default()));
                chaos::install(&rt, io.clone())?;
                let hfsm = Hfsm::from_file(&rt, &path, io)?;
                Ok::<_, mrt_script::ScriptError>((hfsm.to_dot(true), svg.then(|| hfsm.to_svg())))
            })();
            let _ = tx.send(drawn.map_err(|e| e.to_string()));
        })
        .context("cannot start the thread that loads the HFSM")?;
    match rx.recv_timeout(LOAD_DEADLINE) {
        Ok(drawn) => drawn.map_err(|e| anyhow::anyhow!("{e}")),
        Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
            bail!("{}: did not load within {} s", file.display(), LOAD_DEADLINE.as_secs())
        }
        Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
            bail!("{}: loading stopped unexpectedly", file.display())
        }
    }
}
