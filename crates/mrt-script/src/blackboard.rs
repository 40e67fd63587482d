//! `bb.*`: the robot's blackboard (ISocRob's, `mrt-blackboard`) from Lua behaviors.
//!
//! | function | does |
//! |---|---|
//! | `bb.get(symbol)` | the latest value of a `var` symbol (integer, number, boolean or string), `nil` if it is not on the blackboard (a malformed symbol is an error) |
//! | `bb.set(symbol, value)` | binds a value: a Lua integer is an `Int`, a float a `Float`, a boolean a `Bool`, a string a `String` |
//! | `bb.age(symbol)` | seconds since the value was set (or arrived from another robot), `nil` if unknown |
//! | `bb.push(symbol, value)` / `bb.pop(symbol)` | append to / take the oldest of a `talk` queue (`nil` when empty) |
//!
//! A malformed symbol, a value of another type than the one stored, or a `var`/`talk`
//! mix-up is a Lua error with the script's file and line. `bb` is `nil` when the behavior
//! Member was given no blackboard.

use crate::runtime::LuaRuntime;
use crate::ScriptError;
use mlua::{Lua, Value as LuaValue};
use mrt_blackboard::{BbError, Blackboard, Value};

fn to_lua(lua: &Lua, v: Value) -> mlua::Result<LuaValue> {
    Ok(match v {
        Value::Int(i) => LuaValue::Integer(i),
        Value::Float(x) => LuaValue::Number(x),
        Value::Bool(b) => LuaValue::Boolean(b),
        Value::String(s) => LuaValue::String(lua.create_string(&s)?),
    })
}

fn from_lua(fname: &str, v: LuaValue) -> mlua::Result<Value> {
    Ok(match v {
        LuaValue::Integer(i) => Value::Int(i),
        LuaValue::Number(x) => Value::Float(x),
        LuaValue::Boolean(b) => Value::Bool(b),
        LuaValue::String(s) => Value::String(s.to_str()?.to_string()),
        other => {
            return Err(mlua::Error::runtime(format!(
                "bb.{fname}: a value is an integer, a number, a boolean or a string, not {}",
                other.type_name()
            )))
        }
    })
}

fn lua_err(fname: &str, e: BbError) -> mlua::Error {
    mlua::Error::runtime(format!("bb.{fname}: {e}"))
}

/// `nil` for a well-formed symbol that is not on the blackboard; an error for a malformed one
/// (a typo must not read as "not set yet").
fn absent<T>(fname: &str, symbol: &str) -> mlua::Result<Option<T>> {
    mrt_blackboard::Symbol::parse(symbol).map_err(|e| lua_err(fname, e.into()))?;
    Ok(None)
}

/// Installs `bb.*` in the runtime, bound to `bb`.
pub fn install(rt: &LuaRuntime, bb: Blackboard) -> Result<(), ScriptError> {
    install_inner(&rt.lua, bb).map_err(ScriptError::setup)
}

fn install_inner(lua: &Lua, bb: Blackboard) -> mlua::Result<()> {
    let t = lua.create_table()?;
    let b = bb.clone();
    t.set(
        "get",
        lua.create_function(move |lua, symbol: String| match b.get_stamped(&symbol) {
            Ok(s) => Ok(Some(to_lua(lua, s.value)?)),
            Err(BbError::Unknown(_)) => absent("get", &symbol),
            Err(e) => Err(lua_err("get", e)),
        })?,
    )?;
    let b = bb.clone();
    t.set(
        "age",
        lua.create_function(move |_, symbol: String| match b.get_stamped(&symbol) {
            Ok(s) => Ok(Some(b.now().saturating_since(s.time).as_secs_f64())),
            Err(BbError::Unknown(_)) => absent("age", &symbol),
            Err(e) => Err(lua_err("age", e)),
        })?,
    )?;
    let b = bb.clone();
    t.set(
        "set",
        lua.create_function(move |_, (symbol, value): (String, LuaValue)| {
            b.set(&symbol, from_lua("set", value)?).map_err(|e| lua_err("set", e))
        })?,
    )?;
    let b = bb.clone();
    t.set(
        "push",
        lua.create_function(move |_, (symbol, value): (String, LuaValue)| {
            b.push(&symbol, from_lua("push", value)?).map_err(|e| lua_err("push", e))
        })?,
    )?;
    t.set(
        "pop",
        lua.create_function(move |lua, symbol: String| match bb.pop(&symbol) {
            Ok(Some(s)) => Ok(Some(to_lua(lua, s.value)?)),
            Ok(None) => Ok(None),
            Err(BbError::Unknown(_)) => absent("pop", &symbol),
            Err(e) => Err(lua_err("pop", e)),
        })?,
    )?;
    lua.globals().set("bb", t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runtime::Sandbox;
    use std::sync::Arc;

    fn setup() -> (LuaRuntime, Blackboard) {
        let rt = LuaRuntime::new(Sandbox::default()).unwrap();
        let bb = Blackboard::new(1, Arc::new(mrt_core::SimClock::new()));
        install(&rt, bb.clone()).unwrap();
        (rt, bb)
    }

    #[test]
    fn behaviors_read_and_write_typed_values() {
        let (rt, bb) = setup();
        bb.set("local.var.machine.config.def.near-ball", 0.8).unwrap();
        rt.lua
            .load(
                r#"
                assert(bb.get("local.var.machine.config.def.near-ball") == 0.8)
                assert(bb.get("local.var.nothing") == nil)
                bb.set("local.var.machine.role", "defender")
                bb.set("*.var.team.cost", 3)
                bb.set("local.var.kicker.kick", true)
                bb.set("local.var.machine.speed", 1.5)
                assert(bb.age("local.var.machine.role") == 0)
                bb.push("local.talk.log", "a"); bb.push("local.talk.log", "b")
                assert(bb.pop("local.talk.log") == "a")
            "#,
            )
            .set_name("@behaviors/test.lua")
            .exec()
            .unwrap();
        assert_eq!(bb.get::<String>("local.var.machine.role").unwrap(), "defender");
        assert_eq!(bb.get::<i64>("*.var.team.cost").unwrap(), 3);
        assert!(bb.get::<bool>("local.var.kicker.kick").unwrap());
        assert_eq!(bb.get::<f64>("local.var.machine.speed").unwrap(), 1.5);
        assert_eq!(bb.pop("local.talk.log").unwrap().unwrap().value, Value::from("b"));
    }

    #[test]
    fn mistakes_are_lua_errors_with_file_and_line() {
        let (rt, bb) = setup();
        bb.set("local.var.machine.role", "defender").unwrap();
        let err = |code: &str| {
            rt.lua.load(code).set_name("@behaviors/bad.lua").exec().unwrap_err().to_string()
        };
        let e = err("\nbb.set('local.var.machine.role', 2)");
        assert!(e.contains("bad.lua:2:") && e.contains("holds a String, not a Int"), "{e}");
        let e = err("bb.get('local.vr.x')");
        assert!(e.contains("bad.lua:1:") && e.contains("the kind (level 2)"), "{e}");
        let e = err("bb.set('local.var.t', {})");
        assert!(e.contains("not table"), "{e}");
        let e = err("bb.push('local.var.machine.role', 'x')");
        assert!(e.contains("is a var symbol"), "{e}");
        assert_eq!(bb.get::<String>("local.var.machine.role").unwrap(), "defender");
    }

    #[test]
    fn a_behavior_counts_its_cycles_on_the_blackboard_from_load_on() {
        let dir = std::env::temp_dir().join(format!("mrt-bb-lua-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // hbm.lua runs at load: bb is there already. The behavior reads a tuning value and
        // counts its cycles.
        std::fs::write(dir.join("hbm.lua"), "bb.set('local.var.behavior.loaded', true)\n").unwrap();
        std::fs::write(
            dir.join("count.lua"),
            "local n = bb.get('local.var.behavior.cycles') or 0\n\
             bb.set('local.var.behavior.cycles', n + 1)\n\
             chaos.setVlin(bb.get('local.var.behavior.config.speed'))\n",
        )
        .unwrap();
        let bb = Blackboard::new(1, Arc::new(mrt_core::SimClock::new()));
        bb.set("local.var.behavior.config.speed", 250.0).unwrap();
        let mut cap =
            crate::ThinkingCap::load_behavior(&dir, "count", Sandbox::default(), Some(bb.clone()))
                .unwrap();
        assert!(bb.get::<bool>("local.var.behavior.loaded").unwrap());
        for _ in 0..3 {
            let c = cap.cycle(mrt_msgs::robot::WorldSnapshot::default());
            assert!(c.errors.is_empty(), "{:?}", c.errors);
            assert_eq!(c.command.vlin(), 250.0);
        }
        assert_eq!(bb.get::<i64>("local.var.behavior.cycles").unwrap(), 3);
        // Without a blackboard, `bb` is nil: the script fails with its file and line.
        let plain = crate::ThinkingCap::with_behavior(&dir, "count", Sandbox::default());
        let e = plain.err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains("hbm.lua:1"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
