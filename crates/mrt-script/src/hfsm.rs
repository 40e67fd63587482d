//! Hierarchical finite state machines for high-level behaviors (ThinkingCap, ThinkingCap/TeamChaos report §5.1).
//!
//! A machine is defined in one Lua file, as the seed's HFSM editor generated:
//!
//! ```lua
//! machine "Attacker" {
//!   initial = "FaceBall",
//!   states = {
//!     FaceBall = function() chaos.setBehavior("faceball") end,          -- state code
//!     GoToBall = { run = function() ... end, enter = function() ... end, exit = ... },
//!     Score = meta "Score",                                              -- a meta-state
//!   },
//!   transitions = {
//!     { name = "BallAhead", from = "FaceBall", to = "GoToBall", priority = 1,
//!       test = function() return math.abs(chaos.lps_getLpo(BALL).theta) < 0.2 end },
//!     { name = "NearBall", from = "GoToBall", to = "Score",
//!       test = "chaos.lps_getLpo(BALL).rho < 500" },                   -- a predicate
//!   },
//! }
//! machine "Score" { ... }
//! ```
//!
//! - **Meta-states** name another machine of the file (`meta "Score"`), which runs from its
//!   initial state each time the meta-state is entered. A machine can be used from several
//!   places without copying, but never contains itself, directly or through others: checked
//!   at load with the chain in the error.
//! - The **root** is the first machine defined that no other machine uses.
//! - **Transitions** have a test (a Lua function, or a string holding a Lua expression) and a
//!   priority (default 0; smaller is checked first, then file order). A test passes when it
//!   returns `true` or a number of at least 0.5 (a fuzzy predicate).
//! - **Each cycle**: the transitions of the enclosing meta-states are checked before those of
//!   the current state (outermost first, as the seed says: "transitions from meta-states have
//!   more priority than transitions from states"); the first test that passes changes state
//!   (exit hooks innermost first, enter hooks outermost first, into initial states of
//!   meta-states). At most one transition is taken per cycle. Then the code of the active leaf
//!   state runs.
//! - Scripts see the machine through `hfsm.path()` (e.g. `"Attacker/Score/Align"`),
//!   `hfsm.state()` (the leaf state) and `hfsm.time()` (milliseconds in the leaf state).
//! - **Limits**: a file (with what it includes) defines at most [`MAX_MACHINES`] machines,
//!   [`MAX_STATES`] states and [`MAX_TRANSITIONS`] transitions in all, and meta-states nest at
//!   most [`MAX_NESTING`] machines deep; a file beyond them is refused with the limit it passed
//!   before anything deep is walked, so no file can exhaust a thread's stack or take long to
//!   load.

use crate::chaos::RobotIo;
use crate::error::ScriptError;
use crate::runtime::LuaRuntime;
use crate::script::mtime;
use mlua::chunk::ChunkMode;
use mlua::{Function, Lua, Table, Value};
use mrt_core::frames::millis;
use mrt_core::Time;
use std::cell::RefCell;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

mod draw;
use std::rc::Rc;

/// Machines one HFSM file may define, with the files it includes.
pub const MAX_MACHINES: usize = 256;

/// States of all the machines of one HFSM file together.
pub const MAX_STATES: usize = 4096;

/// Transitions of all the machines of one HFSM file together.
pub const MAX_TRANSITIONS: usize = 16384;

/// Machines in the longest chain of meta-states (the root's level counted): a deeper
/// hierarchy is refused.
pub const MAX_NESTING: usize = 32;

/// A state of a machine.
struct State {
    name: String,
    kind: StateKind,
    enter: Option<Function>,
    exit: Option<Function>,
}

enum StateKind {
    /// Lua code run each cycle while the state is active (none: the state only waits).
    Code(Option<Function>),
    /// A meta-state: the index of the machine it runs.
    Meta(usize),
}

struct Transition {
    name: String,
    from: usize,
    to: usize,
    priority: f64,
    test: Function,
    /// The test's source for drawings: the predicate text, or `function (line N)`.
    shown: String,
}

struct Machine {
    name: String,
    initial: usize,
    states: Vec<State>,
    /// Sorted by (from, priority, file order).
    transitions: Vec<Transition>,
    /// Per state: one Lua function that runs its transitions' tests in order and returns the
    /// 1-based position (among that state's transitions) of the first that passes, or 0. One
    /// call from Rust per level instead of one per transition.
    dispatch: Vec<Option<Function>>,
}

/// One level of the active path.
#[derive(Clone, Copy, Debug)]
struct Active {
    machine: usize,
    state: usize,
    since: Time,
}

/// What scripts can see of the running machine (`hfsm.*`).
#[derive(Debug, Default)]
struct Status {
    path: String,
    state: String,
    since: Time,
}

/// A loaded HFSM and its active path.
pub struct Hfsm {
    file: String,
    path_on_disk: Option<PathBuf>,
    modified: Option<std::time::SystemTime>,
    machines: Vec<Machine>,
    root: usize,
    active: Vec<Active>,
    status: Rc<RefCell<Status>>,
    io: Rc<RefCell<RobotIo>>,
}

impl std::fmt::Debug for Hfsm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Hfsm")
            .field("file", &self.file)
            .field("machines", &self.machine_names())
            .field("path", &self.status.borrow().path)
            .finish_non_exhaustive()
    }
}

/// One transition taken during a step.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Taken {
    /// The machine it belongs to.
    pub machine: String,
    /// Its name (or `from->to` when unnamed).
    pub name: String,
    /// The state path after it.
    pub path: String,
}

fn invalid(file: &str, line: usize, message: String) -> ScriptError {
    ScriptError::Invalid { file: file.to_string(), line, message }
}

/// A raw `machine "Name" { ... }` call: name, table, line of the call, file it is in.
type RawMachine = (String, Table, usize, String);

impl Hfsm {
    /// Loads a machine file. The runtime must have `chaos` installed on `io`.
    pub fn from_file(
        rt: &LuaRuntime,
        path: impl AsRef<Path>,
        io: Rc<RefCell<RobotIo>>,
    ) -> Result<Hfsm, ScriptError> {
        let path = path.as_ref();
        let source = mrt_core::read_text(path, mrt_core::MAX_SCRIPT_BYTES)
            .map_err(|source| ScriptError::Io { file: path.display().to_string(), source })?;
        let mut h = Hfsm::from_source(rt, &path.display().to_string(), &source, io)?;
        h.path_on_disk = Some(path.to_path_buf());
        h.modified = mtime(path);
        Ok(h)
    }

    /// Loads a machine from text; `name` appears in errors.
    pub fn from_source(
        rt: &LuaRuntime,
        name: &str,
        source: &str,
        io: Rc<RefCell<RobotIo>>,
    ) -> Result<Hfsm, ScriptError> {
        let (machines, root) = build(rt, name, source)?;
        let status = Rc::new(RefCell::new(Status::default()));
        install_status(&rt.lua, &status, &io).map_err(ScriptError::setup)?;
        Ok(Hfsm {
            file: name.to_string(),
            path_on_disk: None,
            modified: None,
            machines,
            root,
            active: Vec::new(),
            status,
            io,
        })
    }

    /// The file it came from.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The root machine's name.
    pub fn root(&self) -> &str {
        &self.machines[self.root].name
    }

    /// The active path, e.g. `Attacker/Score/Align` (empty before the first step).
    pub fn path(&self) -> String {
        self.status.borrow().path.clone()
    }

    /// Milliseconds spent in the active leaf state at `now`.
    pub fn time_in_state(&self, now: Time) -> f64 {
        millis((now - self.status.borrow().since).as_secs_f64())
    }

    /// Runs one cycle at the world time of the robot io: check transitions (enclosing
    /// meta-states first), then run the active state's code. Returns the transition taken, if
    /// any. On a Lua error the machine stays in a consistent state (the one it was in, or the
    /// one it entered) and the error names the script and line.
    pub fn step(&mut self, rt: &LuaRuntime) -> Result<Option<Taken>, ScriptError> {
        let now = self.io.borrow().world.time;
        let _call = rt.start_call();
        let mut taken = None;
        let incomplete =
            self.active.last().and_then(|a| match self.machines[a.machine].states[a.state].kind {
                StateKind::Meta(inner) => Some(inner),
                StateKind::Code(_) => None,
            });
        if self.active.is_empty() {
            self.enter(rt, self.root, None, now)?;
        } else if let Some(inner) = incomplete {
            // An enter hook failed half-way into a meta-state last cycle: finish entering.
            self.enter(rt, inner, None, now)?;
        } else {
            'levels: for level in 0..self.active.len() {
                let Active { machine, state, .. } = self.active[level];
                let m = &self.machines[machine];
                let Some(dispatch) = &m.dispatch[state] else { continue };
                let k: usize = match dispatch.call(()) {
                    Ok(k) => k,
                    Err(e) => return Err(self.transition_error(rt, machine, state, e)),
                };
                if let Some(t) = k
                    .checked_sub(1)
                    .and_then(|k| m.transitions.iter().filter(|t| t.from == state).nth(k))
                {
                    {
                        let (name, to) = (t.name.clone(), t.to);
                        self.exit_from(rt, level)?;
                        self.enter(rt, machine, Some(to), now)?;
                        taken = Some(Taken {
                            machine: self.machines[machine].name.clone(),
                            name,
                            path: self.status.borrow().path.clone(),
                        });
                        break 'levels;
                    }
                }
            }
        }
        if let Some(leaf) = self.active.last() {
            if let StateKind::Code(Some(f)) = &self.machines[leaf.machine].states[leaf.state].kind {
                f.call::<()>(()).map_err(|e| self.err(rt, e))?;
            }
        }
        Ok(taken)
    }

    /// The error of a state's transition tests, naming the transition that raised it. The
    /// dispatcher runs all tests in one call, so on a runtime error (and only then) the tests
    /// run again one by one to find the culprit.
    fn transition_error(
        &self,
        rt: &LuaRuntime,
        machine: usize,
        state: usize,
        e: mlua::Error,
    ) -> ScriptError {
        let mut err = self.err(rt, e);
        if let ScriptError::Runtime { message, .. } = &mut err {
            let m = &self.machines[machine];
            let mut tests = m.transitions.iter().filter(|t| t.from == state);
            if let Some(t) = tests.find(|t| t.test.call::<Value>(()).is_err()) {
                message.push_str(&format!(
                    " (test of transition '{}' of machine '{}')",
                    t.name, m.name
                ));
            }
        }
        err
    }

    fn err(&self, rt: &LuaRuntime, e: mlua::Error) -> ScriptError {
        ScriptError::from_lua(&self.file, rt, e)
    }

    /// Leaves the states of `active[level..]`, innermost first, running exit hooks.
    fn exit_from(&mut self, rt: &LuaRuntime, level: usize) -> Result<(), ScriptError> {
        while self.active.len() > level {
            let Some(a) = self.active.pop() else { break };
            if let Some(f) = &self.machines[a.machine].states[a.state].exit {
                f.call::<()>(()).map_err(|e| self.err(rt, e))?;
            }
        }
        Ok(())
    }

    /// Enters `state` of `machine` (its initial state when `None`), and down through the
    /// initial states of meta-states, running enter hooks outermost first.
    fn enter(
        &mut self,
        rt: &LuaRuntime,
        machine: usize,
        state: Option<usize>,
        now: Time,
    ) -> Result<(), ScriptError> {
        let (mut m, mut s) = (machine, state.unwrap_or(self.machines[machine].initial));
        loop {
            self.active.push(Active { machine: m, state: s, since: now });
            self.publish(now);
            let st = &self.machines[m].states[s];
            if let Some(f) = &st.enter {
                f.call::<()>(()).map_err(|e| self.err(rt, e))?;
            }
            match st.kind {
                StateKind::Meta(inner) => {
                    m = inner;
                    s = self.machines[inner].initial;
                }
                StateKind::Code(_) => return Ok(()),
            }
        }
    }

    fn publish(&self, now: Time) {
        let mut st = self.status.borrow_mut();
        st.path.clear();
        st.path.push_str(&self.machines[self.root].name);
        for a in &self.active {
            st.path.push('/');
            st.path.push_str(&self.machines[a.machine].states[a.state].name);
        }
        let leaf = self.active.last().map(|a| &self.machines[a.machine].states[a.state].name);
        st.state = leaf.cloned().unwrap_or_default();
        st.since = now;
    }

    /// Reloads the file (an explicit request, or a watcher's): builds the new machine and, only if it
    /// loads, swaps it in, keeping the active path where the same states still exist (else the
    /// new machine starts over). On error the running machine is untouched.
    pub fn reload(&mut self, rt: &LuaRuntime) -> Result<(), ScriptError> {
        let Some(path) = self.path_on_disk.clone() else { return Ok(()) };
        self.modified = mtime(&path);
        let source = mrt_core::read_text(&path, mrt_core::MAX_SCRIPT_BYTES)
            .map_err(|source| ScriptError::Io { file: self.file.clone(), source })?;
        self.reload_source(rt, &source)
    }

    /// Reloads the file if it changed since the last (attempted) load; `Ok(true)` when the
    /// new version was swapped in. A broken file is reported once, not at every poll.
    pub fn reload_if_changed(&mut self, rt: &LuaRuntime) -> Result<bool, ScriptError> {
        let Some(path) = &self.path_on_disk else { return Ok(false) };
        let stamp = mtime(path);
        if stamp == self.modified {
            return Ok(false);
        }
        self.reload(rt).map(|()| true)
    }

    /// Replaces the machine with `source` if it loads (see [`Hfsm::reload`]).
    pub fn reload_source(&mut self, rt: &LuaRuntime, source: &str) -> Result<(), ScriptError> {
        let (machines, root) = build(rt, &self.file, source)?;
        // Keep the active path by names, as far as it still exists.
        let names: Vec<(String, String)> = self
            .active
            .iter()
            .map(|a| {
                let m = &self.machines[a.machine];
                (m.name.clone(), m.states[a.state].name.clone())
            })
            .collect();
        let old = std::mem::take(&mut self.active);
        self.machines = machines;
        self.root = root;
        let mut m = root;
        for ((_, state), prev) in names.iter().zip(&old) {
            let Some(s) = self.machines[m].states.iter().position(|s| &s.name == state) else {
                break;
            };
            self.active.push(Active { machine: m, state: s, since: prev.since });
            match self.machines[m].states[s].kind {
                StateKind::Meta(inner) => m = inner,
                StateKind::Code(_) => break,
            }
        }
        // A path that no longer reaches a plain state starts the new machine over.
        let ends_in_code = self.active.last().is_some_and(|a| {
            matches!(self.machines[a.machine].states[a.state].kind, StateKind::Code(_))
        });
        if !ends_in_code {
            self.active.clear();
        }
        let since = self.active.last().map_or(Time::ZERO, |a| a.since);
        if !self.active.is_empty() {
            self.publish(since);
        }
        Ok(())
    }

    /// The machine as Graphviz dot. With `clusters`, each machine is a cluster (for
    /// Graphviz); without, the machines are drawn side by side (for simple renderers).
    pub fn to_dot(&self, clusters: bool) -> String {
        let q = |s: &str| {
            let s = s.replace('\\', "\\\\").replace('"', "\\\"").replace('\n', "\\n");
            format!("\"{s}\"")
        };
        let mut out = String::from("digraph hfsm {\n  rankdir=LR;\n  node [fontname=\"Helvetica\", fontsize=11];\n  edge [fontname=\"Helvetica\", fontsize=9];\n");
        for (mi, m) in self.machines.iter().enumerate() {
            let id = |s: usize| q(&format!("{}/{}", m.name, m.states[s].name));
            if clusters {
                let _ = writeln!(
                    out,
                    "  subgraph {} {{\n    label={};",
                    q(&format!("cluster_{}", m.name)),
                    q(&m.name)
                );
            }
            let root = if mi == self.root { " (root)" } else { "" };
            let entry = q(&format!("{}/^", m.name));
            let _ = writeln!(
                out,
                "  {entry} [shape=point, width=0.15, label={}];\n  {entry} -> {};",
                q(&format!("{}{root}", m.name)),
                id(m.initial)
            );
            for (si, s) in m.states.iter().enumerate() {
                let (shape, label) = match s.kind {
                    StateKind::Meta(inner) => {
                        ("box3d", format!("{}\n[{}]", s.name, self.machines[inner].name))
                    }
                    StateKind::Code(_) => ("box", s.name.clone()),
                };
                let _ = writeln!(
                    out,
                    "  {} [shape={shape}, style=rounded, label={}];",
                    id(si),
                    q(&label)
                );
                if let StateKind::Meta(inner) = s.kind {
                    let target = &self.machines[inner];
                    let _ = writeln!(
                        out,
                        "  {} -> {} [style=dashed, arrowhead=empty];",
                        id(si),
                        q(&format!("{}/{}", target.name, target.states[target.initial].name))
                    );
                }
            }
            for t in &m.transitions {
                let _ = writeln!(
                    out,
                    "  {} -> {} [label={}];",
                    id(t.from),
                    id(t.to),
                    q(&format!("{} [{}]\n{}", t.name, t.priority, t.shown))
                );
            }
            if clusters {
                out.push_str("  }\n");
            }
        }
        out.push_str("}\n");
        out
    }

    /// The machines' shape for monitors (ThinkingCap/TeamChaos report §4.1, §5.1: the HFSM view),
    /// the root first: what [`Hfsm::to_dot`] and [`Hfsm::to_svg`] draw, as a bus message. A
    /// meta-state `runs` the machine whose states are its children; the active path
    /// ([`Hfsm::path`]) is the root's name, then one state name per level.
    pub fn structure(&self) -> mrt_msgs::HfsmStructure {
        let order =
            std::iter::once(self.root).chain((0..self.machines.len()).filter(|&m| m != self.root));
        let machines = order
            .map(|mi| {
                let m = &self.machines[mi];
                let name = |s: usize| m.states[s].name.clone();
                mrt_msgs::HfsmMachine {
                    name: m.name.clone(),
                    initial: name(m.initial),
                    states: m
                        .states
                        .iter()
                        .map(|s| mrt_msgs::HfsmState {
                            name: s.name.clone(),
                            runs: match s.kind {
                                StateKind::Meta(inner) => Some(self.machines[inner].name.clone()),
                                StateKind::Code(_) => None,
                            },
                        })
                        .collect(),
                    transitions: m
                        .transitions
                        .iter()
                        .map(|t| mrt_msgs::HfsmTransition {
                            name: t.name.clone(),
                            from: name(t.from),
                            to: name(t.to),
                            priority: t.priority,
                            test: t.shown.clone(),
                        })
                        .collect(),
                }
            })
            .collect();
        mrt_msgs::HfsmStructure {
            file: self.file.clone(),
            root: self.machines[self.root].name.clone(),
            machines,
        }
    }

    /// Names of the machines, root first.
    pub fn machine_names(&self) -> Vec<String> {
        let root = &self.machines[self.root].name;
        let others = self.machines.iter().filter(|m| &m.name != root).map(|m| m.name.clone());
        std::iter::once(root.clone()).chain(others).collect()
    }
}

/// Builds a state's transition dispatcher (see `Machine::dispatch`). A test passes when it
/// returns `true` or a number of at least 0.5.
const DISPATCH: &str = r#"
return function(tests)
  local n = #tests
  return function()
    for i = 1, n do
      local r = tests[i]()
      if r == true or (type(r) == "number" and r >= 0.5) then return i end
    end
    return 0
  end
end
"#;

/// Runs the file and checks every machine: states, initial states, meta-states (which must
/// exist and never contain themselves) and transitions (known states, a test).
fn build(rt: &LuaRuntime, file: &str, source: &str) -> Result<(Vec<Machine>, usize), ScriptError> {
    let lua = &rt.lua;
    let raw: Rc<RefCell<Vec<RawMachine>>> = Rc::new(RefCell::new(Vec::new()));
    // The file whose chunk is running (the main file, or an included one).
    let current = Rc::new(RefCell::new(file.to_string()));
    let collector = raw.clone();
    let cur = current.clone();
    let machine = lua
        .create_function(move |lua, name: String| {
            let line = lua.inspect_stack(1, |d| d.current_line()).flatten().unwrap_or(0);
            let (collector, at) = (collector.clone(), cur.borrow().clone());
            lua.create_function(move |_, body: Table| {
                collector.borrow_mut().push((name.clone(), body, line, at.clone()));
                Ok(())
            })
        })
        .map_err(ScriptError::setup)?;
    let meta = lua
        .create_function(|lua, name: String| {
            let t = lua.create_table()?;
            t.set("meta", name)?;
            Ok(t)
        })
        .map_err(ScriptError::setup)?;
    // `include "other.hfsm.lua"`: machines of another file of the same directory, so that a
    // machine is reused across files without copying. Each file once; plain names only.
    let dir = Path::new(file).parent().map(Path::to_path_buf);
    let included = Rc::new(RefCell::new(vec![file.to_string()]));
    let cur = current.clone();
    let include = lua
        .create_function(move |lua, name: String| {
            let plain = !name.contains(['/', '\\']) && name != ".." && name.ends_with(".hfsm.lua");
            let Some(dir) = dir.as_ref().filter(|_| plain) else {
                return Err(mlua::Error::runtime(format!(
                    "include \"{name}\": give the plain name of a .hfsm.lua file in the same directory"
                )));
            };
            let path = dir.join(&name);
            let shown = path.display().to_string();
            if included.borrow().contains(&shown) {
                return Ok(());
            }
            included.borrow_mut().push(shown.clone());
            let text = mrt_core::read_text(&path, mrt_core::MAX_SCRIPT_BYTES)
                .map_err(|e| mlua::Error::runtime(format!("include \"{name}\": {e}")))?;
            let outer = std::mem::replace(&mut *cur.borrow_mut(), shown.clone());
            let result = lua.load(text).set_name(format!("@{shown}")).set_mode(ChunkMode::Text).exec();
            *cur.borrow_mut() = outer;
            result
        })
        .map_err(ScriptError::setup)?;
    let g = lua.globals();
    g.set("machine", machine).map_err(ScriptError::setup)?;
    g.set("meta", meta).map_err(ScriptError::setup)?;
    g.set("include", include).map_err(ScriptError::setup)?;
    let _call = rt.start_call();
    lua.load(source)
        .set_name(format!("@{file}"))
        .set_mode(ChunkMode::Text)
        .exec()
        .map_err(|e| ScriptError::from_lua(file, rt, e))?;
    let raw = std::mem::take(&mut *raw.borrow_mut());
    if raw.is_empty() {
        return Err(invalid(
            file,
            0,
            "no machine defined (write `machine \"Name\" { ... }`)".into(),
        ));
    }
    if raw.len() > MAX_MACHINES {
        let (_, _, line, at) = &raw[MAX_MACHINES];
        return Err(invalid(
            at,
            *line,
            format!("more than {MAX_MACHINES} machines in one HFSM ({} defined)", raw.len()),
        ));
    }
    let mut index = HashMap::new();
    for (i, (name, _, line, at)) in raw.iter().enumerate() {
        if index.insert(name.clone(), i).is_some() {
            return Err(invalid(at, *line, format!("machine '{name}' is defined twice")));
        }
    }
    let make_dispatch: Function =
        lua.load(DISPATCH).set_name("=hfsm dispatch").eval().map_err(ScriptError::setup)?;
    let mut machines = Vec::with_capacity(raw.len());
    let (mut all_states, mut all_transitions) = (0, 0);
    for (name, body, line, at) in &raw {
        let e =
            |line: usize, m: &str, msg: String| invalid(at, line, format!("machine '{m}': {msg}"));
        let (name, line) = (name.as_str(), *line);
        let lua_err = |err: mlua::Error| e(line, name, err.to_string());
        let states_t: Table = body
            .get::<Option<Table>>("states")
            .map_err(lua_err)?
            .ok_or_else(|| e(line, name, "has no states".into()))?;
        let mut states = Vec::new();
        for pair in states_t.pairs::<String, Value>() {
            let (sname, v) = pair.map_err(lua_err)?;
            all_states += 1;
            if all_states > MAX_STATES {
                return Err(e(line, name, format!("more than {MAX_STATES} states in one HFSM")));
            }
            states.push(state(&sname, v, &index).map_err(|msg| e(line, name, msg))?);
        }
        if states.is_empty() {
            return Err(e(line, name, "has no states".into()));
        }
        states.sort_by(|a, b| a.name.cmp(&b.name));
        let by_name: HashMap<&str, usize> =
            states.iter().enumerate().map(|(i, st)| (st.name.as_str(), i)).collect();
        let find = |s: &str| by_name.get(s).copied();
        let known = || states.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ");
        let initial: Option<String> = body.get("initial").map_err(lua_err)?;
        let initial = initial.ok_or_else(|| e(line, name, "has no initial state".into()))?;
        let initial = find(&initial).ok_or_else(|| {
            e(
                line,
                name,
                format!("initial state '{initial}' is not one of its states ({})", known()),
            )
        })?;
        let mut transitions = Vec::new();
        let list: Option<Table> = body.get("transitions").map_err(lua_err)?;
        let list: Vec<mlua::Result<Table>> = list
            .map(|l| l.sequence_values::<Table>().take(MAX_TRANSITIONS + 1).collect())
            .unwrap_or_default();
        all_transitions += list.len();
        if all_transitions > MAX_TRANSITIONS {
            return Err(e(
                line,
                name,
                format!("more than {MAX_TRANSITIONS} transitions in one HFSM"),
            ));
        }
        for (k, t) in list.into_iter().enumerate() {
            let t = t.map_err(lua_err)?;
            let from: String = t.get("from").map_err(lua_err)?;
            let to: String = t.get("to").map_err(lua_err)?;
            let tname: String = t
                .get::<Option<String>>("name")
                .map_err(lua_err)?
                .unwrap_or(format!("{from}->{to}"));
            let state_index = |s: &str| {
                find(s).ok_or_else(|| {
                    e(
                        line,
                        name,
                        format!(
                            "transition '{tname}' names unknown state '{s}' (states: {})",
                            known()
                        ),
                    )
                })
            };
            let (f, to_i) = (state_index(&from)?, state_index(&to)?);
            let priority: f64 = t.get::<Option<f64>>("priority").map_err(lua_err)?.unwrap_or(0.0);
            let (test, shown) = match t.get::<Value>("test").map_err(lua_err)? {
                Value::Function(f) => {
                    let l = f.info().line_defined.unwrap_or(0);
                    (f, format!("function (line {l})"))
                }
                Value::String(s) => {
                    let expr = s.to_str().map_err(lua_err)?.to_string();
                    // Padded with newlines so that Lua's positions name the line of the
                    // machine's definition in the file.
                    let padded = format!("{}return ({expr})", "\n".repeat(line.saturating_sub(1)));
                    let f = lua
                        .load(padded)
                        .set_name(format!("@{at}"))
                        .set_mode(ChunkMode::Text)
                        .into_function()
                        .map_err(|err| {
                            e(line, name, format!("transition '{tname}': bad test `{expr}`: {err}"))
                        })?;
                    (f, expr)
                }
                _ => {
                    return Err(e(
                        line,
                        name,
                        format!(
                            "transition '{tname}' has no test (a function or a Lua expression)"
                        ),
                    ))
                }
            };
            transitions
                .push((Transition { name: tname, from: f, to: to_i, priority, test, shown }, k));
        }
        // Sorted by from, then priority, then file order.
        transitions.sort_by(|(a, ka), (b, kb)| {
            a.from.cmp(&b.from).then(a.priority.total_cmp(&b.priority)).then(ka.cmp(kb))
        });
        let transitions: Vec<Transition> = transitions.into_iter().map(|(t, _)| t).collect();
        let mut dispatch = Vec::with_capacity(states.len());
        let mut rest = transitions.as_slice();
        for s in 0..states.len() {
            // Sorted by `from`: this state's transitions come first in what is left.
            let k = rest.iter().position(|t| t.from != s).unwrap_or(rest.len());
            let (own, after) = rest.split_at(k);
            rest = after;
            let tests: Vec<&Function> = own.iter().map(|t| &t.test).collect();
            dispatch.push(if tests.is_empty() {
                None
            } else {
                let tests = lua.create_sequence_from(tests).map_err(ScriptError::setup)?;
                Some(make_dispatch.call::<Function>(tests).map_err(ScriptError::setup)?)
            });
        }
        machines.push(Machine { name: name.to_string(), initial, states, transitions, dispatch });
    }
    check_containment(&machines, &raw)?;
    check_nesting(&machines, &raw)?;
    let mut used = vec![false; machines.len()];
    for s in machines.iter().flat_map(|m| m.states.iter()) {
        if let StateKind::Meta(i) = s.kind {
            used[i] = true;
        }
    }
    let root = used.iter().position(|u| !u).unwrap_or(0);
    Ok((machines, root))
}

/// A state from its Lua value: a function, `{ run, enter, exit }`, or `meta "Name"`.
fn state(name: &str, v: Value, index: &HashMap<String, usize>) -> Result<State, String> {
    let mut st =
        State { name: name.to_string(), kind: StateKind::Code(None), enter: None, exit: None };
    match v {
        Value::Function(f) => st.kind = StateKind::Code(Some(f)),
        Value::Table(t) => {
            let get = |k: &str| t.get::<Option<Function>>(k).map_err(|e| format!("state '{name}': {k}: {e}"));
            if let Some(target) = t.get::<Option<String>>("meta").map_err(|e| e.to_string())? {
                let i = index.get(&target).ok_or_else(|| {
                    format!("meta-state '{name}' uses machine '{target}', which is not defined")
                })?;
                st.kind = StateKind::Meta(*i);
            } else {
                st.kind = StateKind::Code(get("run")?);
            }
            st.enter = get("enter")?;
            st.exit = get("exit")?;
        }
        Value::Boolean(true) => {}
        other => {
            return Err(format!(
                "state '{name}' must be a function, a table {{ run, enter, exit }} or meta \"Machine\", not {}",
                other.type_name()
            ))
        }
    }
    Ok(st)
}

/// Refuses a machine that contains itself, directly or through other machines, naming the
/// chain (`Score -> Approach -> Score`).
fn check_containment(machines: &[Machine], raw: &[RawMachine]) -> Result<(), ScriptError> {
    fn visit(
        m: usize,
        machines: &[Machine],
        stack: &mut Vec<usize>,
        done: &mut [bool],
    ) -> Option<Vec<usize>> {
        if let Some(pos) = stack.iter().position(|&s| s == m) {
            let mut chain = stack[pos..].to_vec();
            chain.push(m);
            return Some(chain);
        }
        if done[m] {
            return None;
        }
        stack.push(m);
        for s in &machines[m].states {
            if let StateKind::Meta(inner) = s.kind {
                if let Some(chain) = visit(inner, machines, stack, done) {
                    return Some(chain);
                }
            }
        }
        stack.pop();
        done[m] = true;
        None
    }
    let mut done = vec![false; machines.len()];
    for m in 0..machines.len() {
        if let Some(chain) = visit(m, machines, &mut Vec::new(), &mut done) {
            let names: Vec<&str> = chain.iter().map(|&i| machines[i].name.as_str()).collect();
            let first = chain[0];
            return Err(invalid(
                &raw[first].3,
                raw[first].2,
                format!(
                    "meta-state machine '{}' contains itself: {}",
                    names[0],
                    names.join(" -> ")
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses meta-states nested deeper than [`MAX_NESTING`] machines, naming the chain. The
/// machines contain no cycle (checked before) and are at most [`MAX_MACHINES`], which bounds
/// the recursion.
fn check_nesting(machines: &[Machine], raw: &[RawMachine]) -> Result<(), ScriptError> {
    /// The longest chain of machines from `m` down (`m` first), memoized in `longest`.
    fn chain(m: usize, machines: &[Machine], longest: &mut [Option<Vec<usize>>]) -> Vec<usize> {
        if let Some(c) = &longest[m] {
            return c.clone();
        }
        let mut best = Vec::new();
        for s in &machines[m].states {
            if let StateKind::Meta(inner) = s.kind {
                let c = chain(inner, machines, longest);
                if c.len() > best.len() {
                    best = c;
                }
            }
        }
        best.insert(0, m);
        best.truncate(MAX_NESTING + 1);
        longest[m] = Some(best.clone());
        best
    }
    let mut longest = vec![None; machines.len()];
    for (m, (_, _, line, at)) in raw.iter().enumerate().take(machines.len()) {
        let c = chain(m, machines, &mut longest);
        if c.len() > MAX_NESTING {
            let names: Vec<&str> = c.iter().map(|&i| machines[i].name.as_str()).collect();
            return Err(invalid(
                at,
                *line,
                format!(
                    "meta-states nested more than {MAX_NESTING} machines deep: {} -> ...",
                    names[..MAX_NESTING.min(names.len())].join(" -> ")
                ),
            ));
        }
    }
    Ok(())
}

/// Installs `hfsm.path()`, `hfsm.state()`, `hfsm.time()`.
fn install_status(
    lua: &Lua,
    status: &Rc<RefCell<Status>>,
    io: &Rc<RefCell<RobotIo>>,
) -> mlua::Result<()> {
    let t = lua.create_table()?;
    let s = status.clone();
    t.set("path", lua.create_function(move |_, ()| Ok(s.borrow().path.clone()))?)?;
    let s = status.clone();
    t.set("state", lua.create_function(move |_, ()| Ok(s.borrow().state.clone()))?)?;
    let (s, io) = (status.clone(), io.clone());
    t.set(
        "time",
        lua.create_function(move |_, ()| {
            Ok(millis((io.borrow().world.time - s.borrow().since).as_secs_f64()))
        })?,
    )?;
    lua.globals().set("hfsm", t)
}
