//! Fuzzy HBM behaviors written in Lua and blended by context rules (ThinkingCap, ThinkingCap/TeamChaos report §4.1),
//! on the fuzzy core of `mrt-fuzzy` ([`mrt_fuzzy::hbm::Blender`]).
//!
//! A behavior directory holds one Lua file per behavior, named after it (`gkcutb.lua` is the
//! behavior `gkcutb`), and optionally `hbm.lua`, run once at load, for control variables and
//! predicates shared by all behaviors. `*.hfsm.lua` files are state machines, not behaviors.
//! A behavior file runs each time the behavior runs, like ThinkingCap's scripts; besides the
//! `chaos.*` API it may use this rule language (the seed's pseudocode, in Lua):
//!
//! | seed | Lua |
//! |---|---|
//! | `if posLeft then strafe RIGHT` | `rule(posLeft, "strafe", "RIGHT")` |
//! | `always go STAY` | `always("go", "STAY")` |
//! | `if and(freeToKick, ballClose) then kick FRONTKICK` | `rule(AND(freeToKick, ballClose), "kick", "FRONTKICK")` |
//! | `if ballClose then need NET1` | `need(ballClose, NET1)` |
//! | `if ballFar then use go2ball` | `use(ballFar, "go2ball")` |
//! | `or`, `not` | `OR(a, b, ...)`, `NOT(a)` (min / max / 1 − a) |
//! | membership functions (figure 5) | `TRI(a, b, c)`, `TRA(a, b, c, d)`, `TOL(a, b)`, `TOR(a, b)`, `REC(a, b)`, `SNG(a)`, `DIV(a, b, c, d)`; a set is called on a value: `TOL(250, 750)(ball.rho)` |
//! | control variables | `variable { name = "go", command = "vlin", min = -300, max = 300, mode = "centroid", labels = { STAY = TRI(-150, 0, 150), ... } }` |
//! | a variable in other units (a faster robot) | `scale("go", 4)`: its range and every label times 4, the labels' names and rules unchanged |
//!
//! Truth values are numbers in `[0, 1]` (booleans count as 0 and 1). A `use`d behavior runs at
//! activation `min(truth, activation of its user)`; what it asserts is clipped at that level
//! and blended per control variable ([`mrt_fuzzy::hbm`] says how); a behavior at activation 0
//! is not run. The default variables `go` (→ `vlin`), `turn` (→ `vrot`), `strafe` (→ `vlat`)
//! and `kick` (→ `kick`) are defined in `hbm_defaults.lua`; after a cycle each variable that
//! some rule asserted overrides the command field it drives, and the needs join the command's
//! needs. A behavior that sets the command directly (`chaos.setVrot`, like `lookball`) works
//! too.

use crate::chaos::RobotIo;
use crate::error::ScriptError;
use crate::runtime::LuaRuntime;
use crate::script::{LoadStrategy, Script};
use crate::watch::Change;
use mlua::{Lua, LuaString, MetaMethod, Table, Value, Variadic};
use mrt_core::frames::metres;
use mrt_fuzzy::hbm::{Blender, ControlVariable, Defuzzification};
use mrt_fuzzy::FuzzySet;
use mrt_msgs::robot::lps;
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// The default control variables, run before a directory's `hbm.lua`.
pub const DEFAULT_VARIABLES: &str = include_str!("hbm_defaults.lua");

/// How deep `use` may nest: deeper is a runaway hierarchy.
pub const MAX_DEPTH: usize = 32;

/// The most labels a control variable may have: the exact centroid's cost grows with the
/// cube of the labels asserted at once (32 overlapping ones take about 0.2 ms, 64 about 2).
pub const MAX_LABELS: usize = 32;

/// The largest magnitude of a control variable's range and of its labels' parameters (the
/// behaviors' units, mm/s and deg/s): far beyond any robot, small enough that the
/// defuzzifier's sums stay finite.
pub const MAX_MAGNITUDE: f64 = 1e9;

/// The robot command field a control variable drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Drives {
    Vlin,
    Vrot,
    Vlat,
    Kick,
}

/// The set identifiers, in the order of their codes in a Lua set table.
const SET_KINDS: [(&str, usize); 7] =
    [("TRI", 3), ("TRA", 4), ("TOL", 2), ("TOR", 2), ("REC", 2), ("SNG", 1), ("DIV", 4)];

/// A fuzzy set as Lua sees it: a plain table `{kind, p1, p2, ...}` whose metatable makes it
/// callable (`set(x)` is the membership of `x`). A table, not a userdata, so the garbage a
/// behavior makes by building sets each cycle is cheap for Lua's collector (no finalizers).
fn set_of(t: &Table) -> mlua::Result<FuzzySet> {
    let kind: i64 = t.raw_get(1)?;
    let (name, arity) =
        usize::try_from(kind).ok().and_then(|k| SET_KINDS.get(k)).copied().ok_or_else(|| {
            err("not a fuzzy set (build one with TRI, TRA, TOL, TOR, REC, SNG, DIV)".into())
        })?;
    let mut p = [0.0; 4];
    for (i, slot) in p.iter_mut().enumerate().take(arity) {
        *slot = t.raw_get(i + 2)?;
    }
    checked_set(name, &p[..arity])
}

/// The set `name` of parameters `p`, if they are finite, within ±[`MAX_MAGNITUDE`] and in
/// increasing order: the same checks for a set `TRI` built and one a script built by hand.
fn checked_set(name: &str, p: &[f64]) -> mlua::Result<FuzzySet> {
    let set =
        FuzzySet::from_parts(name, p).ok_or_else(|| err(format!("{name}: bad parameters")))?;
    if !set.is_ordered() || !p.iter().all(|v| v.abs() <= MAX_MAGNITUDE) {
        return Err(err(format!(
            "{name}{p:?}: parameters must be numbers within ±{MAX_MAGNITUDE:e}, in increasing order"
        )));
    }
    Ok(set)
}

/// A truth value from Lua: a number (clamped to `[0, 1]`) or a boolean.
fn truth(v: &Value, what: &str) -> mlua::Result<f64> {
    match v {
        Value::Boolean(b) => Ok(f64::from(u8::from(*b))),
        Value::Integer(i) => Ok((*i as f64).clamp(0.0, 1.0)),
        Value::Number(n) if n.is_nan() => Ok(0.0),
        Value::Number(n) => Ok(n.clamp(0.0, 1.0)),
        other => Err(mlua::Error::runtime(format!(
            "{what}: a truth value must be a number or a boolean, not {}",
            other.type_name()
        ))),
    }
}

/// What `variable { ... }` declared, in order, with the field each drives.
type Declared = Vec<(ControlVariable, Option<Drives>)>;

/// Everything the rule functions share.
struct Shared {
    behaviors: RefCell<BTreeMap<String, Script>>,
    cdb: RefCell<Blender>,
    declared: RefCell<Declared>,
    /// The behaviors being run, outermost first (to refuse a behavior using itself).
    running: RefCell<Vec<String>>,
    /// The robot's I/O: a `use`d behavior's `getBehaviorInfo` is its own.
    io: Rc<RefCell<RobotIo>>,
}

/// A directory of HBM behaviors loaded into one Lua runtime.
pub struct Hbm {
    /// The behavior directory; `None` for behaviors given as text ([`Hbm::from_sources`]).
    dir: Option<PathBuf>,
    shared: Rc<Shared>,
    drives: Vec<Option<Drives>>,
    setup: Option<Script>,
    io: Rc<RefCell<RobotIo>>,
}

impl Hbm {
    /// Loads every behavior of `dir` (`*.lua` except `hbm.lua` and `*.hfsm.lua`), after the
    /// default control variables and the directory's `hbm.lua`. The runtime must have `chaos`
    /// installed on `io`. Any file that does not compile is an error naming it and its line.
    pub fn load_dir(
        rt: &LuaRuntime,
        dir: impl AsRef<Path>,
        io: Rc<RefCell<RobotIo>>,
    ) -> Result<Hbm, ScriptError> {
        let dir = dir.as_ref().to_path_buf();
        let setup_path = dir.join("hbm.lua");
        let setup = |rt: &LuaRuntime| {
            setup_path
                .exists()
                .then(|| Script::from_file(rt, &setup_path, LoadStrategy::Compiled))
                .transpose()
        };
        let hbm = Hbm::prepare(rt, Some(dir.clone()), io, setup)?;
        for (name, path) in behavior_files(&dir)? {
            let script = Script::from_file(rt, &path, LoadStrategy::Compiled)?;
            hbm.shared.behaviors.borrow_mut().insert(name, script);
        }
        Ok(hbm)
    }

    /// [`Hbm::load_dir`] on behaviors given as text, for tools, tests and fuzzers without a
    /// directory: `setup` is the text of `hbm.lua` (if any), `behaviors` are (name, text)
    /// pairs; errors name `hbm.lua` and `<name>.lua`. The same checks as from a directory;
    /// reloading finds nothing to reload.
    ///
    /// ```
    /// use mrt_script::chaos::{self, RobotIo};
    /// use mrt_script::hbm::Hbm;
    /// use mrt_script::{LuaRuntime, Sandbox};
    /// use std::{cell::RefCell, rc::Rc};
    ///
    /// let rt = LuaRuntime::new(Sandbox::default())?;
    /// let io = Rc::new(RefCell::new(RobotIo::default()));
    /// chaos::install(&rt, io.clone())?;
    /// let hbm = Hbm::from_sources(&rt, None, &[("stop", r#"always("go", "STAY")"#)], io.clone())?;
    /// hbm.run(&rt, "stop")?;
    /// assert_eq!(io.borrow().command.twist.vx, 0.0);
    /// # Ok::<(), mrt_script::ScriptError>(())
    /// ```
    pub fn from_sources(
        rt: &LuaRuntime,
        setup: Option<&str>,
        behaviors: &[(&str, &str)],
        io: Rc<RefCell<RobotIo>>,
    ) -> Result<Hbm, ScriptError> {
        let setup = |rt: &LuaRuntime| {
            setup
                .map(|text| Script::from_source(rt, "hbm.lua", text, LoadStrategy::Compiled))
                .transpose()
        };
        let hbm = Hbm::prepare(rt, None, io, setup)?;
        for (name, text) in behaviors {
            let script =
                Script::from_source(rt, &format!("{name}.lua"), text, LoadStrategy::Compiled)?;
            hbm.shared.behaviors.borrow_mut().insert((*name).to_string(), script);
        }
        Ok(hbm)
    }

    /// Installs the rule language, runs the default variables, then the setup script.
    fn prepare(
        rt: &LuaRuntime,
        dir: Option<PathBuf>,
        io: Rc<RefCell<RobotIo>>,
        setup: impl FnOnce(&LuaRuntime) -> Result<Option<Script>, ScriptError>,
    ) -> Result<Hbm, ScriptError> {
        let shared = Rc::new(Shared {
            behaviors: RefCell::new(BTreeMap::new()),
            cdb: RefCell::new(Blender::new(Vec::new(), lps::COUNT)),
            declared: RefCell::new(Vec::new()),
            running: RefCell::new(Vec::new()),
            io: io.clone(),
        });
        install(&rt.lua, &shared).map_err(ScriptError::setup)?;
        let defaults =
            Script::from_source(rt, "hbm_defaults.lua", DEFAULT_VARIABLES, LoadStrategy::Compiled)?;
        defaults.call::<()>(rt)?;
        let setup = setup(rt)?;
        if let Some(s) = &setup {
            s.call::<()>(rt)?;
        }
        let mut hbm = Hbm { dir, shared, drives: Vec::new(), setup, io };
        hbm.rebuild_blender();
        Ok(hbm)
    }

    fn rebuild_blender(&mut self) {
        let declared = self.shared.declared.borrow();
        self.drives = declared.iter().map(|(_, d)| *d).collect();
        let vars = declared.iter().map(|(v, _)| v.clone()).collect();
        *self.shared.cdb.borrow_mut() = Blender::new(vars, lps::COUNT);
    }

    /// The behaviors' names, sorted.
    pub fn names(&self) -> Vec<String> {
        self.shared.behaviors.borrow().keys().cloned().collect()
    }

    /// Whether a behavior of that name is loaded.
    pub fn contains(&self, name: &str) -> bool {
        self.shared.behaviors.borrow().contains_key(name)
    }

    /// The control variables.
    pub fn variables(&self) -> Vec<ControlVariable> {
        self.shared.cdb.borrow().variables().to_vec()
    }

    /// Runs behavior `name` at top level (activation 1) within the sandbox's budget, then
    /// writes the blended outputs and needs into the robot command. Call
    /// [`RobotIo::new_cycle`] before. On error nothing fuzzy is written.
    pub fn run(&self, rt: &LuaRuntime, name: &str) -> Result<(), ScriptError> {
        let function = {
            let behaviors = self.shared.behaviors.borrow();
            let script = behaviors.get(name).ok_or_else(|| unknown(name, &behaviors))?;
            script.function()
        };
        self.shared.cdb.borrow_mut().begin_cycle();
        {
            let mut running = self.shared.running.borrow_mut();
            running.clear();
            running.push(name.to_string());
        }
        let _call = rt.start_call();
        let result = function.call::<()>(());
        self.shared.running.borrow_mut().clear();
        result.map_err(|e| ScriptError::from_lua(&self.file_of(name), rt, e))?;
        let cdb = self.shared.cdb.borrow();
        let mut io = self.io.borrow_mut();
        let c = &mut io.command;
        for (v, drives) in self.drives.iter().enumerate() {
            let (Some(drives), Some(value)) = (drives, cdb.output(v)) else { continue };
            match drives {
                // The control variables' mm/s and degrees/s, as `setVlin` and `setVrot` take them.
                Drives::Vlin => c.twist.vx = metres(value),
                Drives::Vrot => c.twist.omega = value.to_radians(),
                Drives::Vlat => c.twist.vy = metres(value),
                Drives::Kick => c.kick = (value != 0.0).then_some(value as i64),
            }
        }
        c.needs.extend(
            cdb.needs().iter().enumerate().filter(|(_, n)| **n > 0.0).map(|(i, n)| (i, *n)),
        );
        Ok(())
    }

    /// The label degrees of a variable after the last run (for tests and monitors).
    pub fn degrees(&self, variable: &str) -> Vec<(String, f64)> {
        let cdb = self.shared.cdb.borrow();
        let Some(v) = cdb.variable_index(variable) else { return Vec::new() };
        let labels = cdb.variables()[v].labels.iter().map(|(l, _)| l.clone());
        labels.zip(cdb.degrees(v).iter().copied()).collect()
    }

    fn file_of(&self, name: &str) -> String {
        let file = format!("{name}.lua");
        match &self.dir {
            Some(dir) => dir.join(file).display().to_string(),
            None => file,
        }
    }

    /// Applies changes reported by a [`ScriptWatcher`](crate::ScriptWatcher): a behavior
    /// compiled off the control path is swapped in as bytecode; a file that did not compile is
    /// reported and the running version kept; `hbm.lua` is re-run; a new file is loaded.
    /// Returns the names swapped in and the errors.
    pub fn apply(
        &mut self,
        rt: &LuaRuntime,
        changes: Vec<Change>,
    ) -> (Vec<String>, Vec<ScriptError>) {
        let (mut done, mut errors) = (Vec::new(), Vec::new());
        let mut others = Vec::new();
        for c in changes {
            let Some(name) =
                c.path.file_name().and_then(|n| n.to_str()).and_then(|n| n.strip_suffix(".lua"))
            else {
                continue;
            };
            let behaviors = self.shared.behaviors.borrow();
            match (behaviors.get(name), c.compiled) {
                (Some(script), Ok(k)) => match script.install(rt, &k) {
                    Ok(()) => done.push(name.to_string()),
                    Err(e) => errors.push(e),
                },
                (Some(_), Err(e)) => errors.push(e),
                (None, _) => others.push(name.to_string()),
            }
        }
        if !others.is_empty() {
            let (d, e) = self.reload(rt, &others);
            done.extend(d);
            errors.extend(e);
        }
        (done, errors)
    }

    /// Reloads what changed on disk: edited behaviors, new behavior files, and `hbm.lua`
    /// (re-run, control variables rebuilt). Each file that fails to compile is reported and
    /// keeps its running version; the others are swapped in. Returns the names reloaded and
    /// the errors. Call it at a cycle boundary.
    pub fn reload_changed(&mut self, rt: &LuaRuntime) -> (Vec<String>, Vec<ScriptError>) {
        self.reload(rt, &[])
    }

    /// Like [`Hbm::reload_changed`], and also reloads the files named in `forced` (behavior
    /// names, `hbm` for `hbm.lua`) whatever their modification times say: a file watcher
    /// reports edits that a coarse file-system clock may hide.
    pub fn reload(
        &mut self,
        rt: &LuaRuntime,
        forced: &[String],
    ) -> (Vec<String>, Vec<ScriptError>) {
        let (mut done, mut errors) = (Vec::new(), Vec::new());
        let forced_name = |n: &str| forced.iter().any(|f| f == n);
        if let Some(setup) = &self.setup {
            let attempt = if forced_name("hbm") {
                setup.reload(rt).map(|()| true)
            } else {
                setup.reload_if_changed(rt)
            };
            match attempt {
                Ok(false) => {}
                Ok(true) => {
                    let previous = std::mem::take(&mut *self.shared.declared.borrow_mut());
                    let rerun = Script::from_source(
                        rt,
                        "hbm_defaults.lua",
                        DEFAULT_VARIABLES,
                        LoadStrategy::Compiled,
                    )
                    .and_then(|d| d.call::<()>(rt))
                    .and_then(|()| setup.call::<()>(rt));
                    match rerun {
                        Ok(()) => {
                            done.push("hbm".to_string());
                            self.rebuild_blender();
                        }
                        Err(e) => {
                            // Keep the variables that were running.
                            *self.shared.declared.borrow_mut() = previous;
                            errors.push(e);
                        }
                    }
                }
                Err(e) => errors.push(e),
            }
        }
        let Some(dir) = &self.dir else { return (done, errors) };
        let files = match behavior_files(dir) {
            Ok(f) => f,
            Err(e) => {
                errors.push(e);
                return (done, errors);
            }
        };
        for (name, path) in files {
            let existing = self.shared.behaviors.borrow().contains_key(&name);
            let result = if existing {
                let behaviors = self.shared.behaviors.borrow();
                behaviors.get(&name).map_or(Ok(false), |s| {
                    if forced_name(&name) {
                        s.reload(rt).map(|()| true)
                    } else {
                        s.reload_if_changed(rt)
                    }
                })
            } else {
                Script::from_file(rt, &path, LoadStrategy::Compiled).map(|s| {
                    self.shared.behaviors.borrow_mut().insert(name.clone(), s);
                    true
                })
            };
            match result {
                Ok(true) => done.push(name),
                Ok(false) => {}
                Err(e) => errors.push(e),
            }
        }
        (done, errors)
    }
}

fn unknown(name: &str, behaviors: &BTreeMap<String, Script>) -> ScriptError {
    let known: Vec<&str> = behaviors.keys().map(String::as_str).collect();
    ScriptError::Setup(format!("no behavior named '{name}' (known: {})", known.join(", ")))
}

/// The behavior files of a directory, `(name, path)`, sorted.
pub fn behavior_files(dir: &Path) -> Result<Vec<(String, PathBuf)>, ScriptError> {
    let entries = std::fs::read_dir(dir)
        .map_err(|source| ScriptError::Io { file: dir.display().to_string(), source })?;
    let mut files: Vec<(String, PathBuf)> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter_map(|p| {
            let file = p.file_name()?.to_str()?;
            let name = file.strip_suffix(".lua")?;
            let skip = name == "hbm" || name.ends_with(".hfsm") || name.starts_with('.');
            // Anything else of the name (a link to a device) is read, and refused there.
            (!skip && !p.is_dir()).then(|| (name.to_string(), p.clone()))
        })
        .collect();
    files.sort();
    Ok(files)
}

fn err(msg: String) -> mlua::Error {
    mlua::Error::runtime(msg)
}

fn set_fn(lua: &Lua, g: &Table, kind: usize, meta: &Table) -> mlua::Result<()> {
    let (name, arity) = SET_KINDS[kind];
    let meta = meta.clone();
    let f = lua.create_function(move |lua, args: Variadic<f64>| {
        if args.len() != arity {
            return Err(err(format!("{name} takes {arity} numbers, got {}", args.len())));
        }
        checked_set(name, &args)?;
        let t = lua.create_table_with_capacity(1 + arity, 0)?;
        t.raw_set(1, kind)?;
        for (i, p) in args.iter().enumerate() {
            t.raw_set(i + 2, *p)?;
        }
        t.set_metatable(Some(meta.clone()))?;
        Ok(t)
    })?;
    g.set(name, f)
}

/// Installs the rule language in the runtime's globals.
fn install(lua: &Lua, shared: &Rc<Shared>) -> mlua::Result<()> {
    let g = lua.globals();
    let meta = lua.create_table()?;
    meta.set(
        MetaMethod::Call.name(),
        lua.create_function(|_, (t, x): (Table, f64)| Ok(set_of(&t)?.membership(x)))?,
    )?;
    meta.set(
        MetaMethod::ToString.name(),
        lua.create_function(|_, t: Table| {
            let s = set_of(&t)?;
            Ok(format!("{}{:?}", s.identifier(), s.params()))
        })?,
    )?;
    meta.set("__metatable", "fuzzy set")?;
    for kind in 0..SET_KINDS.len() {
        set_fn(lua, &g, kind, &meta)?;
    }
    g.set(
        "AND",
        lua.create_function(|_, args: Variadic<Value>| {
            args.iter().try_fold(1.0, |acc, v| Ok(f64::min(acc, truth(v, "AND")?)))
        })?,
    )?;
    g.set(
        "OR",
        lua.create_function(|_, args: Variadic<Value>| {
            args.iter().try_fold(0.0, |acc, v| Ok(f64::max(acc, truth(v, "OR")?)))
        })?,
    )?;
    g.set("NOT", lua.create_function(|_, v: Value| Ok(1.0 - truth(&v, "NOT")?))?)?;

    let s = shared.clone();
    g.set(
        "variable",
        lua.create_function(move |_, t: Table| {
            let declared = declare(&t)?;
            let mut all = s.declared.borrow_mut();
            match all.iter_mut().find(|(v, _)| v.name == declared.0.name) {
                Some(slot) => *slot = declared,
                None => all.push(declared),
            }
            Ok(())
        })?,
    )?;

    let s = shared.clone();
    g.set(
        "scale",
        lua.create_function(move |_, (name, k): (String, f64)| {
            if !(k.is_finite() && k > 0.0) {
                return Err(err(format!("scale('{name}', {k}): the factor must be a number > 0")));
            }
            let mut all = s.declared.borrow_mut();
            let Some((v, _)) = all.iter_mut().find(|(v, _)| v.name == name) else {
                let names: Vec<&str> = all.iter().map(|(v, _)| v.name.as_str()).collect();
                return Err(err(format!(
                    "scale('{name}', {k}): no control variable '{name}' (known: {})",
                    names.join(", ")
                )));
            };
            let labels = v
                .labels
                .iter()
                .map(|(l, set)| {
                    Ok((l.clone(), checked_set(set.identifier(), &set.scaled(k).params())?))
                })
                .collect::<mlua::Result<Vec<_>>>();
            let (min, max) = (v.min * k, v.max * k);
            match labels {
                Ok(labels) if min.abs() <= MAX_MAGNITUDE && max.abs() <= MAX_MAGNITUDE => {
                    (v.min, v.max, v.labels) = (min, max, labels);
                    Ok(())
                }
                _ => Err(err(format!(
                    "scale('{name}', {k}): the variable would reach beyond ±{MAX_MAGNITUDE:e}"
                ))),
            }
        })?,
    )?;

    let s = shared.clone();
    let fire = move |d: f64, var: &str, label: &str| -> mlua::Result<()> {
        let mut cdb = s.cdb.borrow_mut();
        let v = cdb.variable_index(var).ok_or_else(|| {
            let names: Vec<&str> = cdb.variables().iter().map(|v| v.name.as_str()).collect();
            err(format!("no control variable '{var}' (known: {})", names.join(", ")))
        })?;
        let l = cdb.variables()[v].label_index(label).ok_or_else(|| {
            let labels: Vec<&str> =
                cdb.variables()[v].labels.iter().map(|(l, _)| l.as_str()).collect();
            err(format!("control variable '{var}' has no label '{label}' ({})", labels.join(", ")))
        })?;
        cdb.fire(v, l, d);
        Ok(())
    };
    let fire = Rc::new(fire);
    let f = fire.clone();
    g.set(
        "rule",
        lua.create_function(move |_, (d, var, label): (Value, LuaString, LuaString)| {
            f(truth(&d, "rule")?, &var.to_str()?, &label.to_str()?)
        })?,
    )?;
    g.set(
        "always",
        lua.create_function(move |_, (var, label): (LuaString, LuaString)| {
            fire(1.0, &var.to_str()?, &label.to_str()?)
        })?,
    )?;

    let s = shared.clone();
    g.set(
        "need",
        lua.create_function(move |_, (d, object): (Value, i64)| {
            let d = truth(&d, "need")?;
            let i = usize::try_from(object).ok().filter(|i| *i < lps::COUNT).ok_or_else(|| {
                err(format!("need: no perceptual object {object} (0 to {})", lps::COUNT - 1))
            })?;
            s.cdb.borrow_mut().need(i, d);
            Ok(())
        })?,
    )?;

    let s = shared.clone();
    g.set(
        "use",
        lua.create_function(move |_, (d, name): (Value, String)| {
            let d = truth(&d, "use")?;
            let function = {
                let behaviors = s.behaviors.borrow();
                let script = behaviors.get(&name).ok_or_else(|| {
                    let known: Vec<&str> = behaviors.keys().map(String::as_str).collect();
                    err(format!("use: no behavior named '{name}' (known: {})", known.join(", ")))
                })?;
                script.function()
            };
            {
                let running = s.running.borrow();
                if running.contains(&name) {
                    return Err(err(format!(
                        "use: behavior '{name}' uses itself: {} -> {name}",
                        running.join(" -> ")
                    )));
                }
                if running.len() >= MAX_DEPTH {
                    return Err(err(format!("use: behaviors nested deeper than {MAX_DEPTH}")));
                }
            }
            let a = s.cdb.borrow_mut().enter(d);
            let result = if a > 0.0 {
                s.io.borrow_mut().enter_used(&name);
                s.running.borrow_mut().push(name);
                let r = function.call::<()>(());
                s.running.borrow_mut().pop();
                s.io.borrow_mut().leave_used();
                r
            } else {
                Ok(())
            };
            s.cdb.borrow_mut().leave();
            result
        })?,
    )?;
    g.set("hbm_activation", {
        let s = shared.clone();
        lua.create_function(move |_, ()| Ok(s.cdb.borrow().activation()))?
    })?;
    Ok(())
}

/// Reads `variable { name, command, min, max, mode, labels }`.
fn declare(t: &Table) -> mlua::Result<(ControlVariable, Option<Drives>)> {
    let name: String = t.get("name")?;
    let min: f64 = t.get("min")?;
    let max: f64 = t.get("max")?;
    let mode: Option<String> = t.get("mode")?;
    let mode = match mode.as_deref() {
        None | Some("centroid") => Defuzzification::Centroid,
        Some("singleton") => Defuzzification::Singleton,
        Some("choice") => Defuzzification::Choice,
        Some(other) => {
            return Err(err(format!(
                "variable '{name}': mode '{other}' is not centroid, singleton or choice"
            )))
        }
    };
    let drives = match t.get::<Option<String>>("command")?.as_deref() {
        None => None,
        Some("vlin") => Some(Drives::Vlin),
        Some("vrot") => Some(Drives::Vrot),
        Some("vlat") => Some(Drives::Vlat),
        Some("kick") => Some(Drives::Kick),
        Some(other) => {
            return Err(err(format!(
                "variable '{name}': command '{other}' is not vlin, vrot, vlat or kick"
            )))
        }
    };
    if !(min.abs() <= MAX_MAGNITUDE && max.abs() <= MAX_MAGNITUDE) || min >= max {
        return Err(err(format!(
            "variable '{name}': min {min} must be below max {max}, both within ±{MAX_MAGNITUDE:e}"
        )));
    }
    let labels: Table = t.get("labels")?;
    let mut list = Vec::new();
    for pair in labels.pairs::<String, Table>() {
        let (label, set) = pair?;
        if list.len() == MAX_LABELS {
            return Err(err(format!("variable '{name}' has more than {MAX_LABELS} labels")));
        }
        list.push((label, set_of(&set)?));
    }
    if list.is_empty() {
        return Err(err(format!("variable '{name}' has no labels")));
    }
    list.sort_by(|a, b| a.0.cmp(&b.0));
    let mut v = ControlVariable::new(&name, min, max, mode);
    v.labels = list;
    Ok((v, drives))
}
