//! The robot API `chaos.*` of ThinkingCap's chaoslib (ThinkingCap report §3.3), so a TeamChaos
//! ports with minimal change. Reads a [`WorldSnapshot`], writes a [`RobotCommand`].
//!
//! | group | functions |
//! |---|---|
//! | data access | `lps_getLpo(i)` → `{rho, theta, reliability, seen_ago}`, `gsGetMyPos()` → `{x, y, theta, quality}`, `getBallVel()` → `{x, y}`, `getGlobalBall()` → `{x, y, quality}`, `getMates()` → `{{id, x, y, theta, quality, keeper}, ...}`, `getRobots()` → the robots MAP anchored, nearest first, `{{id, class ("teammate", "opponent", "robot": team unknown), x, y, vx, vy, sigma, rho, theta, reliability, seen_ago}, ...}`, `getNearestOpponent([min_reliability])` → one of those (not a teammate; reliability ≥ 0.3 unless told) or `nil`, `getFreeDirection([theta [, reach [, clearance]]])` → the bearing (rad) nearest `theta` (default: the opponent's net) of a corridor `2·clearance` wide (500 mm) and `reach` long (2000 mm) free of anchored robots, or `nil`, `getField()` → `{half_length, half_width, goal_half_width, penalty_area_depth}` (mm), `getKickoffPose()` → `{x, y, theta}` in `READY`, else `nil` |
//! | control | `setVlin(v)`, `setVrot(v)`, `setVlat(v)`, `setKick(id)`, `setNeeded(i, v)`, `trackLandMarks()`, `setBehavior(name)`, `setTarget(x, y, theta[, avoid[, plan]])` (a posture for guidance: position mode, or potential field round obstacles when `avoid`, the default; with `plan`, along a path SPIKE plans round the anchored robots) |
//! | coordination | `getRole()` → `{name}`, `haveBookedBall()` → `{booked}`, `bookBall()`, `releaseBookedBall()` |
//! | persistence | `getBehaviorInfo()` → `{timer (ms), isNew (1/0)}`, `setGlobal(key, type, value)`, `getGlobal(key)`, `getCurrentState()` → `"PLAYING"`... |
//!
//! Globals `BALL`, `NET1`, `NET2`, `LANDMARK0`.. and `INTEGER`, `FLOAT`, `STRING` are defined.
//! A wrong argument type is a Lua error in the calling script, never a panic.

use crate::error::ScriptError;
use crate::runtime::LuaRuntime;
use mlua::{Lua, LuaString, Table, Value};
use mrt_core::frames::{metres, millimetres, millis, pose_in_metres, pose_in_millimetres, Framed};
use mrt_core::Time;
use mrt_msgs::robot::{lps, RobotCommand, WorldSnapshot};
use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;

/// A value of the persistent global hash table (`setGlobal`).
#[derive(Clone, Debug, PartialEq)]
pub enum GlobalValue {
    /// `INTEGER`
    Integer(i64),
    /// `FLOAT`
    Float(f64),
    /// `STRING`
    String(String),
}

/// The robot as the scripts see it: this cycle's world, the command being built, the
/// persistent globals and the running behavior's activation info.
#[derive(Debug, Default)]
pub struct RobotIo {
    /// What the behaviors read this cycle.
    pub world: WorldSnapshot,
    /// What the behaviors asked for this cycle.
    pub command: RobotCommand,
    globals: HashMap<String, GlobalValue>,
    /// What `globals` holds, in bytes (see [`global_size`]).
    globals_bytes: usize,
    /// The behaviors `setBehavior` may name; `None` accepts any name.
    pub known_behaviors: Option<std::collections::BTreeSet<String>>,
    behavior: Option<String>,
    /// Counts cycles, so per-cycle caches know when the world changed.
    generation: u64,
    behavior_since: Time,
    is_new: bool,
    /// Each behavior run through `use`: the last cycle (generation) it ran and since when it
    /// has been running.
    used: HashMap<String, (u64, Time)>,
    /// The `use`d behaviors running now, innermost last, with their `(since, is_new)`.
    using: Vec<(Time, bool)>,
}

impl RobotIo {
    /// Starts a cycle: a new world, an empty command. `behavior` names the behavior about to
    /// run; when it differs from the previous cycle's, `getBehaviorInfo().isNew` is 1 and its
    /// timer restarts.
    pub fn begin_cycle(&mut self, world: WorldSnapshot, behavior: &str) {
        self.new_cycle(world);
        self.activate(behavior);
    }

    /// Starts a cycle: a new world, an empty command (the behavior is chosen later, e.g. by
    /// an HFSM: then call [`RobotIo::activate`]).
    pub fn new_cycle(&mut self, world: WorldSnapshot) {
        self.generation += 1;
        self.using.clear();
        self.world = world;
        self.command = RobotCommand::default();
    }

    /// Says which behavior runs this cycle: when it differs from the previous cycle's,
    /// `getBehaviorInfo().isNew` is 1 and its timer restarts.
    pub fn activate(&mut self, behavior: &str) {
        if self.behavior.as_deref() != Some(behavior) {
            self.behavior = Some(behavior.to_string());
            self.behavior_since = self.world.time;
            self.is_new = true;
        } else {
            self.is_new = false;
        }
    }

    /// A behavior starts running through `use`: from now on `getBehaviorInfo` is its own. It
    /// is new when it did not run in the previous cycle (nor earlier in this one).
    pub(crate) fn enter_used(&mut self, name: &str) {
        let (now, generation) = (self.world.time, self.generation);
        let (since, is_new) = match self.used.get(name) {
            Some(&(last, since)) if last + 1 >= generation => (since, false),
            _ => (now, true),
        };
        self.used.insert(name.to_string(), (generation, since));
        self.using.push((since, is_new));
    }

    /// The innermost `use`d behavior ended.
    pub(crate) fn leave_used(&mut self) {
        self.using.pop();
    }

    /// The behavior running (the last one activated).
    pub fn behavior(&self) -> Option<&str> {
        self.behavior.as_deref()
    }

    /// A persistent global (`getGlobal`), for tests and monitors.
    pub fn global(&self, key: &str) -> Option<&GlobalValue> {
        self.globals.get(key)
    }
}

/// The bytes a persistent global takes: its key, its value and the table's bookkeeping.
fn global_size(key: &str, v: &GlobalValue) -> usize {
    let value = match v {
        GlobalValue::String(s) => s.len(),
        GlobalValue::Integer(_) | GlobalValue::Float(_) => 0,
    };
    key.len() + value + std::mem::size_of::<(String, GlobalValue)>()
}

/// `v` when finite, else a Lua error naming the API function.
fn finite(f: &str, v: f64) -> mlua::Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(mlua::Error::runtime(format!("bad argument: chaos.{f} needs a finite number, not {v}")))
    }
}

/// How far from the field's centre a behavior's target may lie, mm (1000 km).
pub const MAX_TARGET: f64 = 1e9;

/// The largest set-point a behavior's speed is taken at, mm/s or deg/s (1 km/s): every base
/// scales a command beyond its top speed down as a whole, so a larger one means the same,
/// and one near `f64::MAX` would overflow to infinity on its way to the wheels.
pub const MAX_SETPOINT: f64 = 1e6;

/// A speed set-point: finite (else the script's error), clamped to ±[`MAX_SETPOINT`].
fn setpoint(f: &str, v: f64) -> mlua::Result<f64> {
    Ok(finite(f, v)?.clamp(-MAX_SETPOINT, MAX_SETPOINT))
}

const INTEGER: i64 = 1;
const FLOAT: i64 = 2;
const STRING: i64 = 3;

fn check_index(f: &str, i: i64) -> mlua::Result<usize> {
    usize::try_from(i).ok().filter(|i| *i < lps::COUNT).ok_or_else(|| {
        mlua::Error::runtime(format!(
            "chaos.{f}: no LPS object at index {i} (0 to {})",
            lps::COUNT - 1
        ))
    })
}

/// The field names of the data tables, interned once: setting a field by a `&str` key
/// interns the string again at every call, which cost more than the rest of a fill.
struct Keys {
    x: LuaString,
    y: LuaString,
    theta: LuaString,
    quality: LuaString,
    rho: LuaString,
    reliability: LuaString,
    seen_ago: LuaString,
}

impl Keys {
    fn new(lua: &Lua) -> mlua::Result<Keys> {
        let k = |s: &str| lua.create_string(s);
        Ok(Keys {
            x: k("x")?,
            y: k("y")?,
            theta: k("theta")?,
            quality: k("quality")?,
            rho: k("rho")?,
            reliability: k("reliability")?,
            seen_ago: k("seen_ago")?,
        })
    }

    fn fill_pose(
        &self,
        t: &Table,
        x: f64,
        y: f64,
        theta: Option<f64>,
        quality: Option<f64>,
    ) -> mlua::Result<()> {
        t.raw_set(&self.x, x)?;
        t.raw_set(&self.y, y)?;
        if let Some(th) = theta {
            t.raw_set(&self.theta, th)?;
        }
        if let Some(q) = quality {
            t.raw_set(&self.quality, q)?;
        }
        Ok(())
    }
}

/// One anchored robot as scripts see it: `{id, class, x, y, vx, vy, sigma, rho, theta,
/// reliability, seen_ago}` (team frame mm, mm/s; robot frame mm, rad).
fn robot_table(lua: &Lua, keys: &Keys, r: &mrt_msgs::AnchoredRobot) -> mlua::Result<Table> {
    let t = lua.create_table_with_capacity(0, 11)?;
    keys.fill_pose(&t, millimetres(r.at.inner.x), millimetres(r.at.inner.y), None, None)?;
    t.raw_set("id", r.id)?;
    t.raw_set("class", r.class.name())?;
    t.raw_set("vx", millimetres(r.velocity.inner.x))?;
    t.raw_set("vy", millimetres(r.velocity.inner.y))?;
    t.raw_set("sigma", millimetres(r.at_sigma))?;
    t.raw_set(&keys.rho, millimetres(r.rho))?;
    t.raw_set(&keys.theta, r.theta)?;
    t.raw_set(&keys.reliability, r.reliability)?;
    t.raw_set(&keys.seen_ago, r.seen_ago)?;
    Ok(t)
}

/// A table filled at most once per cycle (see `RobotIo::generation`).
#[derive(Default)]
struct CycleTable(RefCell<Option<(u64, Table)>>);

impl CycleTable {
    fn get(
        &self,
        lua: &Lua,
        generation: u64,
        fill: impl FnOnce(&Table) -> mlua::Result<()>,
    ) -> mlua::Result<Table> {
        let mut slot = self.0.borrow_mut();
        if let Some((g, t)) = &*slot {
            if *g == generation {
                return Ok(t.clone());
            }
        }
        let t = match slot.take() {
            Some((_, t)) => t,
            None => lua.create_table_with_capacity(0, 4)?,
        };
        fill(&t)?;
        *slot = Some((generation, t.clone()));
        Ok(t)
    }
}

/// Installs `chaos.*` and its constants in the runtime, bound to `io`.
pub fn install(rt: &LuaRuntime, io: Rc<RefCell<RobotIo>>) -> Result<(), ScriptError> {
    install_inner(&rt.lua, io, rt.sandbox().memory_limit).map_err(ScriptError::setup)
}

/// The `chaos` table being filled: each function sees the robot's [`RobotIo`].
struct Api<'a> {
    lua: &'a Lua,
    chaos: Table,
    io: Rc<RefCell<RobotIo>>,
}

impl Api<'_> {
    /// Declares `chaos.<name>`, a function of the Lua state, the robot and its arguments.
    fn func<A, R>(
        &self,
        name: &str,
        f: impl Fn(&Lua, &RefCell<RobotIo>, A) -> mlua::Result<R> + 'static,
    ) -> mlua::Result<()>
    where
        A: mlua::FromLuaMulti,
        R: mlua::IntoLuaMulti,
    {
        let io = self.io.clone();
        self.chaos.set(name, self.lua.create_function(move |lua, args: A| f(lua, &io, args))?)
    }
}

fn install_inner(lua: &Lua, io: Rc<RefCell<RobotIo>>, memory_limit: usize) -> mlua::Result<()> {
    let g = lua.globals();
    for (name, v) in [("BALL", lps::BALL), ("NET1", lps::NET1), ("NET2", lps::NET2)] {
        g.set(name, v)?;
    }
    for k in 0..lps::LANDMARKS {
        g.set(format!("LANDMARK{k}"), lps::LANDMARK0 + k)?;
    }
    g.set("INTEGER", INTEGER)?;
    g.set("FLOAT", FLOAT)?;
    g.set("STRING", STRING)?;
    let api = Api { lua, chaos: lua.create_table()?, io };
    let keys = Rc::new(Keys::new(lua)?);
    install_data(&api, &keys)?;
    install_anchors(&api, &keys)?;
    install_control(&api)?;
    install_coordination(&api)?;
    install_persistence(&api, memory_limit)?;
    g.set("chaos", api.chaos)
}

/// Data access: the world snapshot, in the Lua API's units.
fn install_data(api: &Api<'_>, keys: &Rc<Keys>) -> mlua::Result<()> {
    // Data access.
    // Data tables are filled at most once per cycle and handed out again on later calls of
    // the same cycle: behaviors and predicates ask for the ball many times a cycle. Treat them
    // as read-only, as the seed's copies were.
    let lpos: Vec<CycleTable> = (0..lps::COUNT).map(|_| CycleTable::default()).collect();
    let k = keys.clone();
    api.func("lps_getLpo", move |lua, io, i: i64| {
        let keys = &k;
        let i = check_index("lps_getLpo", i)?;
        let io = io.borrow();
        lpos[i].get(lua, io.generation, |t| {
            let o = io.world.lps.get(i).copied().unwrap_or_default();
            t.raw_set(&keys.rho, millimetres(o.rho))?;
            t.raw_set(&keys.theta, o.theta)?;
            t.raw_set(&keys.reliability, o.reliability)?;
            t.raw_set(&keys.seen_ago, o.seen_ago)
        })
    })?;
    let my_pos = CycleTable::default();
    let k = keys.clone();
    api.func("gsGetMyPos", move |lua, io, (): ()| {
        let keys = &k;
        let io = io.borrow();
        let (p, quality) =
            (pose_in_millimetres(io.world.my_pos.pose.inner), io.world.my_pos.quality);
        my_pos
            .get(lua, io.generation, |t| keys.fill_pose(t, p.x, p.y, Some(p.theta), Some(quality)))
    })?;
    let ball_vel = CycleTable::default();
    let k = keys.clone();
    api.func("getBallVel", move |lua, io, (): ()| {
        let keys = &k;
        let io = io.borrow();
        let v = io.world.ball_vel.inner.map(millimetres);
        ball_vel.get(lua, io.generation, |t| keys.fill_pose(t, v.x, v.y, None, None))
    })?;
    let field = CycleTable::default();
    api.func("getField", move |lua, io, (): ()| {
        let io = io.borrow();
        let f = io.world.field;
        field.get(lua, io.generation, |t| {
            t.raw_set("half_length", millimetres(f.half_length))?;
            t.raw_set("half_width", millimetres(f.half_width))?;
            t.raw_set("goal_half_width", millimetres(f.goal_half_width))?;
            t.raw_set("penalty_area_depth", millimetres(f.penalty_area_depth))
        })
    })?;
    let global_ball = CycleTable::default();
    let k = keys.clone();
    api.func("getGlobalBall", move |lua, io, (): ()| {
        let keys = &k;
        let io = io.borrow();
        let (b, quality) =
            (pose_in_millimetres(io.world.global_ball.pose.inner), io.world.global_ball.quality);
        global_ball.get(lua, io.generation, |t| keys.fill_pose(t, b.x, b.y, None, Some(quality)))
    })?;
    let k = keys.clone();
    // Role negotiation asks for the mates several times a cycle: one list per cycle.
    let mates = CycleTable::default();
    api.func("getMates", move |lua, io, (): ()| {
        let keys = &k;
        let io = io.borrow();
        mates.get(lua, io.generation, |t| {
            t.clear()?;
            for (k, m) in io.world.mates.iter().enumerate() {
                let e = lua.create_table_with_capacity(0, 6)?;
                let p = pose_in_millimetres(m.at.pose.inner);
                keys.fill_pose(&e, p.x, p.y, Some(p.theta), Some(m.at.quality))?;
                e.set("id", m.id)?;
                e.set("keeper", m.keeper)?;
                t.raw_set(k + 1, e)?;
            }
            Ok(())
        })
    })?;

    Ok(())
}

/// The other robots MAP anchored, and the kickoff pose.
fn install_anchors(api: &Api<'_>, keys: &Rc<Keys>) -> mlua::Result<()> {
    // The other robots MAP anchored (MRT manual ch. 8), nearest first.
    let k = keys.clone();
    let robots = CycleTable::default();
    api.func("getRobots", move |lua, io, (): ()| {
        let keys = &k;
        let io = io.borrow();
        robots.get(lua, io.generation, |t| {
            t.clear()?;
            for (n, r) in io.world.robots.iter().enumerate() {
                t.raw_set(n + 1, robot_table(lua, keys, r)?)?;
            }
            Ok(())
        })
    })?;
    let k = keys.clone();
    api.func("getNearestOpponent", move |lua, io, min: Option<f64>| {
        let min = finite("getNearestOpponent", min.unwrap_or(WorldSnapshot::ANCHORED))?;
        let io = io.borrow();
        match io.world.nearest_opponent(min) {
            Some(r) => Ok(Value::Table(robot_table(lua, &k, r)?)),
            None => Ok(Value::Nil),
        }
    })?;
    api.func(
        "getFreeDirection",
        move |_lua, io, (theta, reach, clearance): (Option<f64>, Option<f64>, Option<f64>)| {
            let io = io.borrow();
            let w = &io.world;
            // Towards the opponent's net when known, else straight ahead.
            let net = w.lps[lps::NET1];
            let toward = if net.reliability > 0.0 { net.theta } else { 0.0 };
            let theta = finite("getFreeDirection", theta.unwrap_or(toward))?;
            // The Lua API's millimetres to the snapshot's metres.
            let reach = reach.map(metres).unwrap_or(WorldSnapshot::FREE_REACH);
            let clearance = clearance.map(metres).unwrap_or(WorldSnapshot::FREE_CLEARANCE);
            let (reach, clearance) =
                (finite("getFreeDirection", reach)?, finite("getFreeDirection", clearance)?);
            Ok(w.free_direction(theta, reach, clearance, WorldSnapshot::ANCHORED))
        },
    )?;

    let k = keys.clone();
    api.func("getKickoffPose", move |lua, io, (): ()| {
        let Some(p) = io.borrow().world.kickoff_pose else { return Ok(Value::Nil) };
        let p = pose_in_millimetres(p.inner);
        let t = lua.create_table_with_capacity(0, 3)?;
        k.fill_pose(&t, p.x, p.y, Some(p.theta), None)?;
        Ok(Value::Table(t))
    })?;

    Ok(())
}

/// Control actions: the command being built.
fn install_control(api: &Api<'_>) -> mlua::Result<()> {
    type TargetArgs = (f64, f64, f64, Option<bool>, Option<bool>);
    api.func("setTarget", move |_lua, io, (x, y, theta, avoid, plan): TargetArgs| {
        if !(x.abs() <= MAX_TARGET && y.abs() <= MAX_TARGET && theta.is_finite()) {
            return Err(mlua::Error::runtime(format!(
                "bad argument: setTarget needs finite numbers, x and y within ±{MAX_TARGET:e} mm, \
                 not ({x}, {y}, {theta})"
            )));
        }
        // The Lua API's millimetres to the command's metres.
        let pose = Framed::new(pose_in_metres(mrt_core::Pose2::new(x, y, theta)));
        io.borrow_mut().command.target = Some(mrt_msgs::robot::Target {
            pose,
            avoid: avoid.unwrap_or(true),
            plan: plan.unwrap_or(false),
        });
        Ok(())
    })?;
    // A set-point that is not a finite number is the script's fault, reported as one: NaN
    // would silently stop the robot and infinity saturate it. A huge finite one is taken as
    // MAX_SETPOINT, far beyond any base's top speed, like any other too fast. The Lua API's
    // mm/s and degrees/s become the command's m/s and rad/s here.
    api.func("setVlin", move |_lua, io, v: f64| {
        io.borrow_mut().command.twist.vx = metres(setpoint("setVlin", v)?);
        Ok(())
    })?;
    api.func("setVrot", move |_lua, io, v: f64| {
        io.borrow_mut().command.twist.omega = setpoint("setVrot", v)?.to_radians();
        Ok(())
    })?;
    api.func("setVlat", move |_lua, io, v: f64| {
        io.borrow_mut().command.twist.vy = metres(setpoint("setVlat", v)?);
        Ok(())
    })?;
    api.func("setKick", move |_lua, io, id: i64| {
        io.borrow_mut().command.kick = Some(id);
        Ok(())
    })?;
    api.func("setNeeded", move |_lua, io, (i, v): (i64, f64)| {
        let i = check_index("setNeeded", i)?;
        let v = finite("setNeeded", v)?.clamp(0.0, 1.0);
        // The largest need per object wins: keep one entry per object, not one per call.
        let needs = &mut io.borrow_mut().command.needs;
        match needs.iter_mut().find(|(j, _)| *j == i) {
            Some((_, old)) => *old = old.max(v),
            None => needs.push((i, v)),
        }
        Ok(())
    })?;
    api.func("trackLandMarks", move |_lua, io, (): ()| {
        io.borrow_mut().command.track_landmarks = true;
        Ok(())
    })?;
    api.func("setBehavior", move |_lua, io, name: mlua::LuaString| {
        let name = name.to_str()?;
        let name: &str = &name;
        let mut io = io.borrow_mut();
        if let Some(known) = &io.known_behaviors {
            if !known.contains(name) {
                let list: Vec<&str> = known.iter().map(String::as_str).collect();
                return Err(mlua::Error::runtime(format!(
                    "chaos.setBehavior: no behavior named '{name}' (known: {})",
                    list.join(", ")
                )));
            }
        }
        io.command.behavior = Some(name.to_string());
        Ok(())
    })?;

    Ok(())
}

/// Coordination: role and ball booking.
fn install_coordination(api: &Api<'_>) -> mlua::Result<()> {
    api.func("getRole", move |lua, io, (): ()| {
        let t = lua.create_table_with_capacity(0, 1)?;
        t.set("name", io.borrow().world.role.clone())?;
        Ok(t)
    })?;
    api.func("haveBookedBall", move |lua, io, (): ()| {
        let t = lua.create_table_with_capacity(0, 1)?;
        t.set("booked", io.borrow().world.ball_booked)?;
        Ok(t)
    })?;
    api.func("bookBall", move |_lua, io, (): ()| {
        io.borrow_mut().command.book_ball = Some(true);
        Ok(())
    })?;
    api.func("releaseBookedBall", move |_lua, io, (): ()| {
        io.borrow_mut().command.book_ball = Some(false);
        Ok(())
    })?;

    Ok(())
}

/// Persistence: behavior info, the global hash table, the game state.
fn install_persistence(api: &Api<'_>, memory_limit: usize) -> mlua::Result<()> {
    api.func("getBehaviorInfo", move |lua, io, (): ()| {
        let io = io.borrow();
        let t = lua.create_table_with_capacity(0, 2)?;
        // The innermost behavior running: a `use`d one, or the top behavior.
        let (since, is_new) = io.using.last().copied().unwrap_or((io.behavior_since, io.is_new));
        t.set("timer", millis((io.world.time - since).as_secs_f64()))?;
        t.set("isNew", i64::from(is_new))?;
        Ok(t)
    })?;
    api.func("setGlobal", move |lua, io, (key, ty, value): (String, i64, Value)| {
        let v = match (ty, &value) {
            (INTEGER, Value::Integer(i)) => GlobalValue::Integer(*i),
            (INTEGER, Value::Number(n)) if n.fract() == 0.0 && n.is_finite() => GlobalValue::Integer(*n as i64),
            (FLOAT, Value::Integer(i)) => GlobalValue::Float(*i as f64),
            (FLOAT, Value::Number(n)) => GlobalValue::Float(*n),
            (STRING, Value::String(s)) => GlobalValue::String(s.to_str()?.to_string()),
            _ => {
                return Err(mlua::Error::runtime(format!(
                    "chaos.setGlobal(\"{key}\"): type {ty} does not match the value {} (INTEGER=1, FLOAT=2, STRING=3)",
                    value.type_name()
                )))
            }
        };
        // What the globals hold counts against the script's memory limit.
        let mut io = io.borrow_mut();
        let old = io.globals.get(&key).map_or(0, |old| global_size(&key, old));
        let total = io.globals_bytes - old + global_size(&key, &v);
        if total + lua.used_memory() > memory_limit {
            return Err(mlua::Error::runtime(format!(
                "chaos.setGlobal(\"{}\"): not enough memory: the globals would take {total} bytes \
                 of the {memory_limit}-byte memory limit",
                crate::error::clip(&key, 80)
            )));
        }
        io.globals_bytes = total;
        io.globals.insert(key, v);
        Ok(())
    })?;
    api.func("getGlobal", move |lua, io, key: String| {
        Ok(match io.borrow().globals.get(&key) {
            Some(GlobalValue::Integer(i)) => Value::Integer(*i),
            Some(GlobalValue::Float(f)) => Value::Number(*f),
            Some(GlobalValue::String(s)) => Value::String(lua.create_string(s)?),
            None => Value::Nil,
        })
    })?;
    api.func("getCurrentState", move |_lua, io, (): ()| Ok(io.borrow().world.game_state.name()))?;

    Ok(())
}
