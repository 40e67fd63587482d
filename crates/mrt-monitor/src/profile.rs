//! How much of a match a recording keeps: every message
//! with every digit ([`RecordProfile::Full`], the default, what `mrt replay --robot` needs to
//! re-run a robot's behaviors exactly), or the bulky high-rate types at a lower rate per topic
//! on the simulated clock and every float with fewer digits ([`RecordProfile::Compact`],
//! `mrt sim --record FILE --compact`).

use serde::{Deserialize, Serialize};

/// How much a recording keeps (module doc). Recorded in the `/match` topic's
/// [`MatchInfo`](crate::MatchInfo) and in the file's `mrt` metadata record, so that a reader
/// knows.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum RecordProfile {
    /// Every message, every float with all the digits of its `f64`.
    #[default]
    Full,
    /// Every topic, but the world model's, the vision's and the drivers' high-rate types at
    /// [`COMPACT_INTERVAL_NS`] (2 Hz) per topic, the scene at [`COMPACT_SCENE_INTERVAL_NS`],
    /// the rest (commands, statuses, game info, logs, `/truth`) at their own rate; every float
    /// rounded to [`COMPACT_PRECISION`].
    Compact,
}

/// The types a compact recording keeps at most once every [`COMPACT_INTERVAL_NS`] on each of
/// their topics: the bulky ones that come every control cycle (per type, of the default
/// match's 100 MB with zstd: `WorldSnapshot` 45 MB, `Percepts` 23, `MateReport` 8.8,
/// `Localization` 5.6, `SonarScan` 4.8, `Odometry` 3.6), the camera's and the distributed
/// devices' frames, and the believed poses derived from `Localization`.
pub const COMPACT_DECIMATED: &[&str] = &[
    "WorldSnapshot",
    "Percepts",
    "MateReport",
    "SonarScan",
    "Odometry",
    "Localization",
    "CameraFrame",
    "foxglove.FrameTransform",
];

/// The interval of [`COMPACT_DECIMATED`]'s types in a compact recording: 0.5 s (2 Hz).
pub const COMPACT_INTERVAL_NS: u64 = 500_000_000;

/// The interval of `/scene` (`foxglove.SceneUpdate`, drawn from `/truth`) in a compact
/// recording: 0.2 s (5 Hz). `/truth` itself stays at every cycle.
pub const COMPACT_SCENE_INTERVAL_NS: u64 = 200_000_000;

/// How floats are written in a compact recording: 4 decimals and at most 6 significant
/// digits. In the units of MRT's messages that is 0.1 mm for metres and m/s, 0.01 mm and
/// 0.01 mm/s for millimetres under 10 m, 0.0001 rad (0.006°) for radians, 0.0001° for
/// degrees, 0.1 ms for seconds, 0.0001 for qualities and reliabilities: far below any sensor's
/// noise (docs/monitor.md, "Size and cost").
pub const COMPACT_PRECISION: Precision = Precision { decimals: 4, significant: 6 };

/// How the Foxglove views drawn from other messages (`/scene`, `/field`, `/<robot>/pose`)
/// write their floats, whatever the profile: they are for looking at, and the exact values are
/// in the messages they are drawn from (`/truth`, `Localization`).
pub const VIEW_PRECISION: Precision = COMPACT_PRECISION;

/// The zstd level of a compact recording's chunks ([`RecordProfile::zstd_level`]).
pub const COMPACT_ZSTD_LEVEL: u32 = 9;

/// How many digits of a float are kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Precision {
    /// At most this many digits after the decimal point.
    pub decimals: i32,
    /// At most this many significant digits.
    pub significant: i32,
}

impl Precision {
    /// `x` rounded to this precision: to [`Precision::decimals`] decimals, or fewer when
    /// that would keep more than [`Precision::significant`] digits. Zero, infinities and
    /// NaN are kept; −0 becomes 0.
    pub fn round(self, x: f64) -> f64 {
        if x == 0.0 || !x.is_finite() {
            return if x == 0.0 { 0.0 } else { x };
        }
        let magnitude = x.abs().log10().floor() as i32;
        let d = (self.significant - 1 - magnitude).min(self.decimals);
        let r = if d >= 0 {
            let s = 10f64.powi(d);
            (x * s).round() / s
        } else {
            let s = 10f64.powi(-d);
            (x / s).round() * s
        };
        if r == 0.0 {
            0.0
        } else {
            r
        }
    }

    /// `json` with every float (a number with a `.` or an exponent) rounded ([`Precision::round`])
    /// and written in its shortest form, into `out`. Integers (times in nanoseconds, counts)
    /// and strings are copied as they are.
    pub fn round_json(self, json: &[u8], out: &mut Vec<u8>) {
        use std::io::Write as _;
        out.reserve(json.len());
        let n = json.len();
        let mut i = 0;
        while i < n {
            let c = json[i];
            if c == b'"' {
                let start = i;
                i += 1;
                while i < n {
                    match json[i] {
                        b'\\' => i += 2,
                        b'"' => {
                            i += 1;
                            break;
                        }
                        _ => i += 1,
                    }
                }
                out.extend_from_slice(&json[start..i.min(n)]);
            } else if c == b'-' || c.is_ascii_digit() {
                let start = i;
                i += 1;
                while i < n && matches!(json[i], b'0'..=b'9' | b'.' | b'e' | b'E' | b'+' | b'-') {
                    i += 1;
                }
                let token = &json[start..i];
                let float = token.iter().any(|b| matches!(b, b'.' | b'e' | b'E'));
                let parsed = std::str::from_utf8(token).ok().and_then(|s| s.parse::<f64>().ok());
                match parsed {
                    Some(x) if float => {
                        // Writing into a Vec does not fail.
                        let _ = write!(out, "{:?}", self.round(x));
                    }
                    _ => out.extend_from_slice(token),
                }
            } else {
                out.push(c);
                i += 1;
            }
        }
    }
}

impl RecordProfile {
    /// Its name, as `MatchInfo` and the metadata write it (`full`, `compact`).
    pub fn name(self) -> &'static str {
        match self {
            RecordProfile::Full => "full",
            RecordProfile::Compact => "compact",
        }
    }

    /// The least time between two kept messages of a topic whose schema is `schema`, ns;
    /// `None` keeps every message.
    pub fn interval(self, schema: &str) -> Option<u64> {
        match self {
            RecordProfile::Full => None,
            RecordProfile::Compact if schema == "foxglove.SceneUpdate" => {
                Some(COMPACT_SCENE_INTERVAL_NS)
            }
            RecordProfile::Compact => {
                COMPACT_DECIMATED.contains(&schema).then_some(COMPACT_INTERVAL_NS)
            }
        }
    }

    /// How floats are written; `None`: with every digit.
    pub fn precision(self) -> Option<Precision> {
        match self {
            RecordProfile::Full => None,
            RecordProfile::Compact => Some(COMPACT_PRECISION),
        }
    }

    /// The size of the file's chunks before compression, bytes (the `mcap` crate's default,
    /// 768 KiB).
    pub fn chunk_size(self) -> Option<u64> {
        Some(768 * 1024)
    }

    /// The zstd level of the file's chunks (0: the library's default, 3). Compact uses 9:
    /// on the default match's rounded messages it writes 22 % fewer bytes than 3 (a tenth
    /// for the full profile's, at a fifth more time; docs/monitor.md, "Size and cost").
    pub fn zstd_level(self) -> u32 {
        match self {
            RecordProfile::Full => 0,
            RecordProfile::Compact => COMPACT_ZSTD_LEVEL,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rounded(json: &str) -> String {
        let mut out = Vec::new();
        COMPACT_PRECISION.round_json(json.as_bytes(), &mut out);
        String::from_utf8(out).unwrap()
    }

    /// Values worked out by hand: 4 decimals, at most 6 significant digits.
    #[test]
    fn floats_are_rounded_to_four_decimals_and_six_digits() {
        let p = COMPACT_PRECISION;
        assert_eq!(p.round(1.23456789), 1.2346);
        assert_eq!(p.round(-0.612345678), -0.6123);
        assert_eq!(p.round(4500.123456), 4500.12);
        assert_eq!(p.round(123456789.0), 123457000.0);
        assert_eq!(p.round(0.00004999), 0.0);
        assert_eq!(p.round(-2.7755575615628914e-17).to_bits(), 0.0f64.to_bits());
        assert_eq!(p.round(f64::INFINITY), f64::INFINITY);
        assert_eq!(
            rounded(
                r#"{"x":1.23456789,"t":8100000000,"s":"a1.23456\"b2.5","v":[-0.0001234,1e-7,3.0,-2.5e3]}"#
            ),
            r#"{"x":1.2346,"t":8100000000,"s":"a1.23456\"b2.5","v":[-0.0001,0.0,3.0,-2500.0]}"#
        );
        assert_eq!(rounded("[null,true,-7]"), "[null,true,-7]");
    }

    /// Full keeps everything; compact decimates the bulky types and the scene only.
    #[test]
    fn compact_decimates_the_bulky_types_only() {
        assert_eq!(RecordProfile::default(), RecordProfile::Full);
        assert_eq!(RecordProfile::Full.interval("WorldSnapshot"), None);
        assert_eq!(RecordProfile::Compact.interval("WorldSnapshot"), Some(500_000_000));
        assert_eq!(RecordProfile::Compact.interval("foxglove.SceneUpdate"), Some(200_000_000));
        for kept in ["RobotCommand", "GameInfo", "BehaviorStatus", "Truth", "foxglove.Log"] {
            assert_eq!(RecordProfile::Compact.interval(kept), None, "{kept}");
        }
        assert_eq!(serde_json::to_string(&RecordProfile::Compact).unwrap(), "\"compact\"");
    }
}
