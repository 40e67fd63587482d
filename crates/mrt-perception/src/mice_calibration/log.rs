//! The log of a calibration's readings (MRT manual §4.2): what the mice counted on each run of
//! the procedure, as CSV text.
//!
//! ```text
//! # two-mice calibration (MRT manual §4.2): 500 mm straight runs, 360° CCW turns
//! kind,run,mouse,x,y
//! straight,1,left,3937,6819
//! straight,1,right,-12,7872
//! turn,1,left,-8242,-4382
//! turn,1,right,4947,-18
//! ```
//!
//! - UTF-8 text, one record a line (`\n` or `\r\n`); blank lines and lines whose first
//!   non-blank character is `#` are ignored.
//! - The first other line is the header `kind,run,mouse,x,y`.
//! - Then one record a line, five fields separated by commas (blanks around a field are
//!   ignored): `kind` is `straight` (a run of the translational measurement) or `turn` (of the
//!   rotational one); `run` numbers the run within its kind (a whole number from 1 to
//!   1 000 000; gaps are allowed, the order of the lines is not significant); `mouse` is `left`
//!   or `right` (or `l`, `r`); `x` and `y` are the mouse's counts `x̄` (across it, positive to
//!   its right) and `ȳ` (along it, positive towards its buttons): whole numbers, signed. A USB
//!   mouse reports y positive towards its back: the logger writes `y = −REL_Y`.
//! - Several lines of the same run and mouse add up: a logger may write one line per sampling
//!   period rather than the run's totals.
//! - Every run has lines of both mice.
//!
//! Errors name the file, the line and the column ([`CalibrationError::Syntax`]).

use super::{calibrate, CalibrationError, Counts, MiceCalibration, Mouse, Procedure, Run, RunKind};
use mrt_core::frames::millimetres;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// The header line of the log format.
pub const HEADER: &str = "kind,run,mouse,x,y";

/// The largest run number.
pub const MAX_RUN: u32 = 1_000_000;

/// The readings of one calibration: the runs of each kind, in the order of their numbers.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CalibrationLog {
    /// The translational measurement's runs.
    pub straight: Vec<Run>,
    /// The rotational measurement's runs.
    pub turns: Vec<Run>,
}

/// One run's sums while parsing: counts of the left and right mouse, when seen.
type Sums = [Option<(i64, i64)>; 2];

/// A syntax error at `column` (characters, from 1) of line `line`.
fn syntax(file: &str, line: usize, column: usize, message: String) -> CalibrationError {
    CalibrationError::Syntax { file: file.to_string(), line, column, message }
}

/// The character column (from 1) of byte `offset` of `line`.
fn column(line: &str, offset: usize) -> usize {
    line.get(..offset).map_or(1, |s| s.chars().count() + 1)
}

impl CalibrationLog {
    /// Parses a log (module doc) read from `file` (its name for the errors).
    pub fn parse(file: &str, bytes: &[u8]) -> Result<CalibrationLog, CalibrationError> {
        let text = match std::str::from_utf8(bytes) {
            Ok(t) => t,
            Err(e) => {
                let good = &bytes[..e.valid_up_to()];
                let line = good.iter().filter(|&&b| b == b'\n').count() + 1;
                let start = good.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
                let col = std::str::from_utf8(&good[start..]).map_or(1, |s| s.chars().count() + 1);
                return Err(syntax(file, line, col, "not UTF-8 text".into()));
            }
        };
        let mut runs: BTreeMap<(RunKind, u32), Sums> = BTreeMap::new();
        let mut header = false;
        for (k, raw) in text.split('\n').enumerate() {
            let n = k + 1;
            let line = raw.strip_suffix('\r').unwrap_or(raw);
            let trimmed = line.trim();
            if trimmed.is_empty() || trimmed.starts_with('#') {
                continue;
            }
            // The fields with the byte offset where each starts (after its blanks).
            let mut fields = Vec::with_capacity(5);
            let mut at = 0;
            for f in line.split(',') {
                let lead = f.len() - f.trim_start().len();
                fields.push((f.trim(), at + lead));
                at += f.len() + 1;
            }
            if !header {
                let names: Vec<&str> = fields.iter().map(|f| f.0).collect();
                if names.join(",") != HEADER {
                    let col = column(line, line.len() - line.trim_start().len());
                    return Err(syntax(file, n, col, format!("expected the header `{HEADER}`")));
                }
                header = true;
                continue;
            }
            if fields.len() != 5 {
                let col = column(line, line.len());
                let msg = format!("expected 5 fields ({HEADER}), found {}", fields.len());
                return Err(syntax(file, n, col, msg));
            }
            let err = |i: usize, msg: String| syntax(file, n, column(line, fields[i].1), msg);
            let kind = match fields[0].0 {
                "straight" => RunKind::Straight,
                "turn" => RunKind::Turn,
                other => {
                    return Err(err(
                        0,
                        format!("unknown run kind `{other}`: expected straight or turn"),
                    ))
                }
            };
            let run = match fields[1].0.parse::<u32>() {
                Ok(r) if (1..=MAX_RUN).contains(&r) => r,
                _ => {
                    let msg = format!(
                        "run `{}`: expected a whole number from 1 to {MAX_RUN}",
                        fields[1].0
                    );
                    return Err(err(1, msg));
                }
            };
            let mouse = match fields[2].0 {
                "left" | "l" => Mouse::Left,
                "right" | "r" => Mouse::Right,
                other => {
                    return Err(err(2, format!("unknown mouse `{other}`: expected left or right")))
                }
            };
            let count = |i: usize| {
                fields[i].0.parse::<i64>().map_err(|_| {
                    let axis = if i == 3 { "x" } else { "y" };
                    err(i, format!("{axis} `{}`: expected a whole number of counts", fields[i].0))
                })
            };
            let (x, y) = (count(3)?, count(4)?);
            let slot = &mut runs.entry((kind, run)).or_default()[mouse as usize];
            let (sx, sy) = slot.unwrap_or((0, 0));
            match (sx.checked_add(x), sy.checked_add(y)) {
                (Some(sx), Some(sy)) => *slot = Some((sx, sy)),
                _ => return Err(err(3, "the run's counts overflow".into())),
            }
        }
        if !header {
            return Err(syntax(file, 1, 1, format!("empty log: expected the header `{HEADER}`")));
        }
        let mut log = CalibrationLog::default();
        for ((kind, run), sums) in runs {
            let counts = |m: Mouse| {
                sums[m as usize].map(|(x, y)| Counts::new(x as f64, y as f64)).ok_or_else(|| {
                    let message =
                        format!("{} run {run} has no line of the {} mouse", kind.name(), m.name());
                    CalibrationError::Log { file: file.to_string(), message }
                })
            };
            let r = Run { left: counts(Mouse::Left)?, right: counts(Mouse::Right)? };
            match kind {
                RunKind::Straight => log.straight.push(r),
                RunKind::Turn => log.turns.push(r),
            }
        }
        Ok(log)
    }

    /// Reads and parses the log file at `path`.
    pub fn read(path: &Path) -> Result<CalibrationLog, CalibrationError> {
        let file = path.display().to_string();
        match mrt_core::read_bounded(path, mrt_core::MAX_LOG_BYTES) {
            Ok(bytes) => {
                CalibrationLog::parse(&file, bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(&bytes))
            }
            Err(source) => Err(CalibrationError::Io { file, source }),
        }
    }

    /// The log as text (module doc), each run's totals on one line per mouse, counts rounded
    /// to whole counts, after a comment naming `procedure`.
    pub fn to_text(&self, procedure: &Procedure) -> String {
        let mut out = format!(
            "# two-mice calibration (MRT manual §4.2): {} mm straight runs, {}° turns in place\n{HEADER}\n",
            millimetres(procedure.length),
            procedure.turn.to_degrees()
        );
        for (kind, runs) in [(RunKind::Straight, &self.straight), (RunKind::Turn, &self.turns)] {
            for (i, r) in runs.iter().enumerate() {
                for (name, c) in [("left", r.left), ("right", r.right)] {
                    let _ = writeln!(
                        out,
                        "{},{},{name},{:.0},{:.0}",
                        kind.name(),
                        i + 1,
                        c.x.round(),
                        c.y.round()
                    );
                }
            }
        }
        out
    }

    /// The calibration these readings give ([`calibrate`]).
    pub fn calibrate(&self, procedure: &Procedure) -> Result<MiceCalibration, CalibrationError> {
        calibrate(&self.straight, &self.turns, procedure)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn parse(text: &str) -> Result<CalibrationLog, CalibrationError> {
        CalibrationLog::parse("cal.csv", text.as_bytes())
    }

    fn syntax_at(text: &str) -> (usize, usize, String) {
        match parse(text) {
            Err(CalibrationError::Syntax { file, line, column, message }) => {
                assert_eq!(file, "cal.csv");
                (line, column, message)
            }
            other => panic!("expected a syntax error, got {other:?}"),
        }
    }

    #[test]
    fn a_log_is_read_and_lines_add_up() {
        let log = parse(
            "# a comment\n\nkind, run ,mouse,x,y\r\nstraight,2,left,3937,6819\n straight , 2 , r , -1 , 7000 \n\
             straight,1,l,3900,6800\nstraight,1,right,0,3000\nstraight,1,right,2,4000\n  # more\n\
             turn,7,left,-8242,-4382\nturn,7,right,4947,-18\n",
        )
        .unwrap();
        assert_eq!(log.straight.len(), 2);
        // Runs in the order of their numbers; run 1's right mouse wrote two lines.
        assert_eq!(log.straight[0].left, Counts::new(3900.0, 6800.0));
        assert_eq!(log.straight[0].right, Counts::new(2.0, 7000.0));
        assert_eq!(log.straight[1].right, Counts::new(-1.0, 7000.0));
        assert_eq!(
            log.turns,
            vec![Run { left: Counts::new(-8242.0, -4382.0), right: Counts::new(4947.0, -18.0) }]
        );
        // Written and read again: the same runs.
        let again = parse(&log.to_text(&Procedure::default())).unwrap();
        assert_eq!(again, log);
        assert!(log.to_text(&Procedure::default()).starts_with("# two-mice calibration"));
    }

    #[test]
    fn errors_name_the_file_line_and_column() {
        let h = "kind,run,mouse,x,y\n";
        assert_eq!(syntax_at("").0, 1);
        assert_eq!(
            syntax_at("# only a comment\n").2,
            "empty log: expected the header `kind,run,mouse,x,y`"
        );
        let (line, col, _) = syntax_at("\n  run,kind\n");
        assert_eq!((line, col), (2, 3));
        let (line, col, msg) = syntax_at(&format!("{h}straight,1,left,1,2\nwalk,1,left,1,2\n"));
        assert_eq!((line, col), (3, 1));
        assert!(msg.contains("unknown run kind `walk`"), "{msg}");
        let (line, col, msg) = syntax_at(&format!("{h}turn, 0,left,1,2\n"));
        assert_eq!((line, col), (2, 7));
        assert!(msg.contains("run `0`"), "{msg}");
        let (_, col, msg) = syntax_at(&format!("{h}turn,1,middle,1,2\n"));
        assert_eq!(col, 8);
        assert!(msg.contains("unknown mouse `middle`"), "{msg}");
        // Columns count characters, not bytes.
        let (_, col, msg) = syntax_at(&format!("{h}turn,1,left,1,2.5\n"));
        assert_eq!(col, 15);
        assert!(msg.contains("y `2.5`"), "{msg}");
        let (_, col, _) = syntax_at(&format!("{h}turn,1,left,é,2\n"));
        assert_eq!(col, 13);
        let (_, col, msg) = syntax_at(&format!("{h}turn,1,left,1\n"));
        assert_eq!(col, 14);
        assert!(msg.contains("found 4"), "{msg}");
        let (line, col, msg) =
            syntax_at(&format!("{h}turn,1,left,9223372036854775807,0\nturn,1,left,1,0\n"));
        assert_eq!((line, col), (3, 13));
        assert!(msg.contains("overflow"), "{msg}");
        // Bytes that are not UTF-8: where they start.
        let mut bytes = format!("{h}turn,1,lé").into_bytes();
        bytes.push(0xff);
        match CalibrationLog::parse("cal.csv", &bytes) {
            Err(CalibrationError::Syntax { line: 2, column: 10, .. }) => {}
            other => panic!("{other:?}"),
        }
        // A run without one mouse.
        match parse(&format!("{h}turn,3,left,1,2\n")) {
            Err(e @ CalibrationError::Log { .. }) => {
                assert_eq!(e.to_string(), "cal.csv: turn run 3 has no line of the right mouse");
            }
            other => panic!("{other:?}"),
        }
        let e = parse(&format!("{h}walk,1,left,1,2\n")).err().map(|e| e.to_string());
        assert_eq!(
            e.as_deref(),
            Some("cal.csv:2:1: unknown run kind `walk`: expected straight or turn")
        );
        let missing = CalibrationLog::read(Path::new("/nonexistent/cal.csv"));
        assert!(matches!(missing, Err(CalibrationError::Io { .. })));
    }

    proptest! {
        /// Any bytes: an answer, never a panic; an error's line and column lie in the input.
        #[test]
        fn random_bytes_do_not_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            if let Err(CalibrationError::Syntax { line, column, .. }) =
                CalibrationLog::parse("x", &bytes)
            {
                prop_assert!(line >= 1 && column >= 1);
                prop_assert!(line <= bytes.iter().filter(|&&b| b == b'\n').count() + 1);
            }
        }

        /// Random lines after the header, of the format's words and numbers: no panic.
        #[test]
        fn random_records_do_not_panic(lines in proptest::collection::vec(
            (prop_oneof![Just("straight"), Just("turn"), Just("x"), Just("")],
             -3i64..5, prop_oneof![Just("left"), Just("r"), Just("?")],
             any::<i64>(), any::<i64>(), 3usize..7), 0..30)) {
            let mut text = format!("{HEADER}\n");
            for (k, run, m, x, y, n) in lines {
                let f = [k.to_string(), run.to_string(), m.to_string(), x.to_string(), y.to_string(), "1".into()];
                text.push_str(&f[..n.min(6)].join(","));
                text.push('\n');
            }
            let _ = parse(&text);
        }
    }
}
