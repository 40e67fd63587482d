//! `mrt behave` and `mrt hfsm dot`: try a Lua behavior or HFSM offline, draw an HFSM.

use anyhow::{bail, Context as _, Result};
use mrt_core::robot::WorldSnapshot;
use mrt_core::Time;
use mrt_script::chaos::{self, RobotIo};
use mrt_script::hfsm::Hfsm;
use mrt_script::{LuaRuntime, Sandbox, ThinkingCap};
use std::cell::RefCell;
use std::io::Write as _;
use std::path::Path;
use std::rc::Rc;

/// The worlds to run: a JSON array gives one world per cycle; one object is used every cycle.
fn worlds(path: Option<&Path>, cycles: Option<usize>) -> Result<Vec<WorldSnapshot>> {
    let Some(path) = path else {
        return Ok(vec![WorldSnapshot::default(); cycles.unwrap_or(1)]);
    };
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| anyhow::anyhow!("{}:{}:{}: {e}", path.display(), e.line(), e.column()))?;
    let parse = |v: serde_json::Value| -> Result<WorldSnapshot> {
        serde_json::from_value(v)
            .with_context(|| format!("{}: not a world snapshot", path.display()))
    };
    Ok(match value {
        serde_json::Value::Array(list) => {
            let mut v = list.into_iter().map(parse).collect::<Result<Vec<_>>>()?;
            if let Some(n) = cycles {
                let last = v.last().cloned().unwrap_or_default();
                v.resize(n, last);
            }
            v
        }
        one => vec![parse(one)?; cycles.unwrap_or(1)],
    })
}

/// Runs `file` (a behavior, or an HFSM when it ends in `.hfsm.lua`) against the worlds, one
/// JSON line of commands per cycle. Returns an error (exit status 1) if any cycle failed.
pub fn behave(
    file: &Path,
    world: Option<&Path>,
    cycles: Option<usize>,
    period_ms: u64,
) -> Result<()> {
    let dir = file.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = file.file_name().and_then(|n| n.to_str()).unwrap_or_default();
    let mut cap = if name.ends_with(".hfsm.lua") {
        ThinkingCap::with_hfsm(dir, file, Sandbox::default())
    } else {
        let stem = name.strip_suffix(".lua").unwrap_or(name);
        ThinkingCap::with_behavior(dir, stem, Sandbox::default())
    }
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut failed = 0;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    for (k, mut w) in worlds(world, cycles)?.into_iter().enumerate() {
        if w.time == Time::ZERO {
            w.time = Time::from_secs_f64(k as f64 * period_ms as f64 / 1000.0);
        }
        let time_ms = (w.time.as_secs_f64() * 1e6).round() / 1e3;
        let c = cap.cycle(w);
        for e in &c.errors {
            eprintln!("error: cycle {k}: {e}");
        }
        failed += usize::from(!c.errors.is_empty());
        let line = serde_json::json!({
            "cycle": k,
            "time_ms": time_ms,
            "path": c.path,
            "behavior": c.behavior,
            "transition": c.taken.map(|t| t.name),
            "command": c.command,
        });
        writeln!(out, "{line}")?;
    }
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
