//! Behaviors run offline against world snapshots, as `mrt behave` runs them: the `--world`
//! file (JSON: one [`WorldSnapshot`], used every cycle, or an array of them, one per cycle)
//! and the JSON line printed for each cycle. One definition for the command and for the fuzz
//! harness that feeds it hostile files.
//!
//! ```
//! use mrt_script::offline::{parse_worlds, world_at};
//!
//! let worlds = parse_worlds(r#"[{"time": 0}, {"role": "attacker"}]"#)?;
//! assert_eq!(worlds.len(), 2);
//! // A world without a time gets its cycle's; the last world is repeated after the end.
//! assert_eq!(world_at(&worlds, 5, 100).time, mrt_core::Time::from_millis(500));
//! # Ok::<(), mrt_script::offline::WorldsError>(())
//! ```

use crate::cap::Cycle;
use mrt_core::frames::seconds_from_millis;
use mrt_core::Time;
use mrt_msgs::robot::WorldSnapshot;

/// A `--world` file that is not one snapshot or an array of them.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WorldsError {
    /// Not JSON.
    #[error("{line}:{column}: {message}")]
    Syntax {
        /// Line (from 1).
        line: usize,
        /// Column (from 1).
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// JSON, but not a world snapshot.
    #[error("{}not a world snapshot: {message}", .index.map_or(String::new(), |i| format!("element {i}: ")))]
    NotASnapshot {
        /// The array element (from 0), for an array.
        index: Option<usize>,
        /// What is wrong.
        message: String,
    },
}

/// The worlds of a `--world` file (an empty array gives none: [`world_at`] then gives default
/// worlds).
pub fn parse_worlds(text: &str) -> Result<Vec<WorldSnapshot>, WorldsError> {
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| WorldsError::Syntax {
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    let parse = |index: Option<usize>, v: serde_json::Value| {
        serde_json::from_value::<WorldSnapshot>(v)
            .map_err(|e| WorldsError::NotASnapshot { index, message: e.to_string() })
    };
    let list = match value {
        serde_json::Value::Array(list) => list
            .into_iter()
            .enumerate()
            .map(|(i, v)| parse(Some(i), v))
            .collect::<Result<Vec<_>, _>>()?,
        one => vec![parse(None, one)?],
    };
    Ok(list)
}

/// The world of cycle `k`: the `k`-th of `worlds`, the last one once they run out; a world
/// without a time gets the cycle's (`k` × `period_ms`).
pub fn world_at(worlds: &[WorldSnapshot], k: u64, period_ms: u64) -> WorldSnapshot {
    let i = usize::try_from(k).unwrap_or(usize::MAX).min(worlds.len().saturating_sub(1));
    let mut w = worlds.get(i).cloned().unwrap_or_default();
    if w.time == Time::ZERO {
        w.time = Time::from_secs_f64(seconds_from_millis(k as f64 * period_ms as f64));
    }
    w
}

/// Microseconds per millisecond: `time_ms` is rounded to the microsecond, then given in ms.
const US_PER_MS: f64 = 1e3;

/// The JSON line `mrt behave` prints for cycle `k` run at `time`.
pub fn cycle_line(k: u64, time: Time, c: &Cycle) -> String {
    serde_json::json!({
        "cycle": k,
        "time_ms": (time.as_secs_f64() * 1e6).round() / US_PER_MS,
        "path": c.path,
        "behavior": c.behavior,
        "transition": c.taken.as_ref().map(|t| &t.name),
        "command": c.command,
    })
    .to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_say_where() {
        let e = parse_worlds("{\n  \"time\": ,\n}").unwrap_err();
        assert!(matches!(e, WorldsError::Syntax { line: 2, .. }), "{e}");
        let e = parse_worlds(r#"[{}, {"time": "soon"}]"#).unwrap_err();
        assert!(e.to_string().starts_with("element 1: not a world snapshot"), "{e}");
        assert_eq!(parse_worlds("[]").map(|w| w.len()).ok(), Some(0));
        assert_eq!(world_at(&[], 3, 100).time, Time::from_millis(300));
    }
}
