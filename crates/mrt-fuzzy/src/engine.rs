//! The behavior engine's settings file, `engine.txt` (optional): what the manual sets by
//! choosing C++ classes and calling methods (§10.3.6 `threshold_filter` and `set_threshold`,
//! §10.4.9 the weight and float composers), written as a file of the configuration so that a team
//! changes them without code. One setting a line, the manual's names, `#` comments:
//!
//! ```text
//! # engine.txt
//! threshold_filter 0.5                     # a behavior runs when its CANDO is above it
//! weight_composer mult_weight_composer     # (the default), max_ or min_weight_composer
//! float_composer average_float_composer    # max_ (the default) or min_float_composer
//! composition argmax                       # weighted (the default, formula 10.3) or argmax (10.5)
//! semantics original                       # manual (the default) or original (the C++ engine's)
//! ```
//!
//! `composition` chooses between the two ways of §10.2.4 ("both the approaches are
//! implemented in Mr. BRIAN and it is possible to select the best one for the application"):
//! the weighted composition of formula 10.3 or the best behavior's actions of formula 10.5
//! ([`Composition`]). `semantics` chooses how reliability counts ([`Semantics`]): as the
//! manual says, or as the original C++ engine did, for configurations tuned on it. Both are
//! properties of a configuration (its rules and WANTs were written for one of them), hence
//! settings of its directory rather than of a program.
//!
//! Why a file of its own: the manual's nine files have fixed grammars that the original
//! engine's tools read, and adding keys to one of them would break those tools; a missing
//! `engine.txt` leaves the manual's defaults (threshold 0.49, the maximum).
//!
//! ```
//! use mrt_fuzzy::brian::Composer;
//! use mrt_fuzzy::engine::parse_engine;
//!
//! let s = parse_engine("threshold_filter 0.5\nfloat_composer average_float_composer\n", "engine.txt".as_ref())?;
//! assert_eq!((s.threshold, s.composer), (Some(0.5), Some(Composer::Average)));
//! # Ok::<(), mrt_fuzzy::BrianError>(())
//! ```

use crate::compose::{Composer, Composition, Semantics, WeightComposer};
use crate::lexer::Span;
use crate::BrianError;
use std::path::Path;

/// The settings an `engine.txt` gives (`None`: the default stays).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EngineSettings {
    /// The CANDO threshold (`threshold_filter`), in [0, 1].
    pub threshold: Option<f64>,
    /// How the proposals for one output label are composed (`float_composer`).
    pub composer: Option<Composer>,
    /// How a proposal is weighted by its behavior's weight (`weight_composer`).
    pub weight_composer: Option<WeightComposer>,
    /// How proposals become outputs (`composition`: formula 10.3 or 10.5).
    pub composition: Option<Composition>,
    /// How reliability counts (`semantics`: the manual's or the original engine's).
    pub semantics: Option<Semantics>,
}

/// The compositions by name.
const COMPOSITIONS: [(&str, Composition); 2] =
    [("weighted", Composition::Weighted), ("argmax", Composition::Argmax)];

/// The semantics by name.
const SEMANTICS: [(&str, Semantics); 2] =
    [("manual", Semantics::Manual), ("original", Semantics::Original)];

/// The semantics named `value` (`manual` or `original`), for command lines.
pub fn semantics_by_name(value: &str) -> Result<Semantics, String> {
    choice(value, &SEMANTICS)
}

/// The float composers by the manual's class names.
const FLOAT_COMPOSERS: [(&str, Composer); 3] = [
    ("max_float_composer", Composer::Max),
    ("average_float_composer", Composer::Average),
    ("min_float_composer", Composer::Min),
];

/// The weight composers by the manual's class names.
const WEIGHT_COMPOSERS: [(&str, WeightComposer); 3] = [
    ("mult_weight_composer", WeightComposer::Mult),
    ("max_weight_composer", WeightComposer::Max),
    ("min_weight_composer", WeightComposer::Min),
];

/// The option named `value` among `options`, or what was expected instead.
fn choice<T: Copy>(value: &str, options: &[(&str, T)]) -> Result<T, String> {
    if let Some(&(_, t)) = options.iter().find(|(name, _)| *name == value) {
        return Ok(t);
    }
    let names: Vec<&str> = options.iter().map(|(name, _)| *name).collect();
    Err(format!("one of {}, not `{value}`", names.join(", ")))
}

/// Reads `engine.txt` (module doc); `file` names it in errors.
///
/// # Errors
/// [`BrianError::At`] with the line and column of an unknown setting, a missing or extra
/// value, a threshold that is not a number in [0, 1], an unknown composer, or a setting given
/// twice.
pub fn parse_engine(text: &str, file: &Path) -> Result<EngineSettings, BrianError> {
    let mut s = EngineSettings::default();
    for (k, line) in text.lines().enumerate() {
        let code = line.split('#').next().unwrap_or("");
        // Each word with its column (from 1, in characters). One pass over the line: a
        // 64 KiB line of words took seconds when each word was cut from the line's start.
        let mut words = Vec::new();
        let mut start = None;
        let ends = code.char_indices().chain(std::iter::once((code.len(), ' ')));
        for (col, (byte, c)) in ends.enumerate() {
            match (c.is_whitespace(), start) {
                (false, None) => start = Some((byte, col)),
                (true, Some((from, from_col))) => {
                    words
                        .push((code.get(from..byte).unwrap_or_default().to_string(), from_col + 1));
                    start = None;
                }
                _ => {}
            }
        }
        let at = |column: usize, message: String| {
            BrianError::at(file, Span { line: k + 1, column }, message)
        };
        let Some((key, key_col)) = words.first() else { continue };
        let value = words.get(1);
        if let Some((extra, col)) = words.get(2) {
            return Err(at(*col, format!("one value after `{key}`, found `{extra}` too")));
        }
        let Some((value, col)) = value else {
            return Err(at(*key_col + key.chars().count(), format!("a value after `{key}`")));
        };
        match key.as_str() {
            "threshold_filter" => {
                let t: f64 = value
                    .parse()
                    .ok()
                    .filter(|t: &f64| (0.0..=1.0).contains(t))
                    .ok_or_else(|| at(*col, format!("a threshold in [0, 1], not `{value}`")))?;
                if s.threshold.replace(t).is_some() {
                    return Err(at(*key_col, "threshold_filter is set twice".into()));
                }
            }
            "float_composer" => {
                let c = choice(value, &FLOAT_COMPOSERS).map_err(|m| at(*col, m))?;
                if s.composer.replace(c).is_some() {
                    return Err(at(*key_col, "float_composer is set twice".into()));
                }
            }
            "weight_composer" => {
                let c = choice(value, &WEIGHT_COMPOSERS).map_err(|m| at(*col, m))?;
                if s.weight_composer.replace(c).is_some() {
                    return Err(at(*key_col, "weight_composer is set twice".into()));
                }
            }
            "composition" => {
                let c = choice(value, &COMPOSITIONS).map_err(|m| at(*col, m))?;
                if s.composition.replace(c).is_some() {
                    return Err(at(*key_col, "composition is set twice".into()));
                }
            }
            "semantics" => {
                let c = choice(value, &SEMANTICS).map_err(|m| at(*col, m))?;
                if s.semantics.replace(c).is_some() {
                    return Err(at(*key_col, "semantics is set twice".into()));
                }
            }
            other => {
                return Err(at(
                    *key_col,
                    format!(
                        "threshold_filter, weight_composer, float_composer, composition or \
                         semantics, not `{other}`"
                    ),
                ))
            }
        }
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn err(text: &str) -> String {
        parse_engine(text, Path::new("engine.txt")).map(|_| ()).unwrap_err().to_string()
    }

    #[test]
    fn settings_comments_and_blank_lines_are_read() {
        let s = parse_engine(
            "# the engine\n\n  threshold_filter   0.3  # lower\nfloat_composer max_float_composer\n",
            Path::new("engine.txt"),
        )
        .unwrap();
        let want = EngineSettings {
            threshold: Some(0.3),
            composer: Some(Composer::Max),
            ..EngineSettings::default()
        };
        assert_eq!(s, want);
        let s = parse_engine(
            "weight_composer min_weight_composer\nfloat_composer min_float_composer\n",
            Path::new("e"),
        )
        .unwrap();
        assert_eq!(
            (s.weight_composer, s.composer),
            (Some(WeightComposer::Min), Some(Composer::Min))
        );
        assert_eq!(parse_engine("", Path::new("e")).unwrap(), EngineSettings::default());
        let s =
            parse_engine("composition argmax\nsemantics original # C++\n", Path::new("e")).unwrap();
        assert_eq!(
            (s.composition, s.semantics),
            (Some(Composition::Argmax), Some(Semantics::Original))
        );
        let s = parse_engine("composition weighted\nsemantics manual\n", Path::new("e")).unwrap();
        assert_eq!(
            (s.composition, s.semantics),
            (Some(Composition::Weighted), Some(Semantics::Manual))
        );
    }

    #[test]
    fn every_mistake_is_placed_by_line_and_column() {
        assert!(
            err("threshold_filter 1.5\n").ends_with("engine.txt:1:18"),
            "{}",
            err("threshold_filter 1.5\n")
        );
        assert!(err("\nthreshold_filter\n").contains("at line 2: a value after `threshold_filter`"));
        assert!(err("\nthreshold_filter\n").ends_with("engine.txt:2:17"));
        assert!(err("float_composer min\n").contains("not `min`"));
        assert!(err("weight_composer sum_weight_composer\n").ends_with("engine.txt:1:17"));
        assert!(err("speed 3\n").ends_with("engine.txt:1:1"));
        assert!(err("threshold_filter 0.2 0.3\n").ends_with("engine.txt:1:22"));
        assert!(err("threshold_filter 0.2\nthreshold_filter 0.3\n").contains("set twice"));
        assert!(err("threshold_filter NaN\n").contains("not `NaN`"));
        assert!(
            err("\ncomposition  best\n").contains("at line 2: one of weighted, argmax, not `best`"),
            "{}",
            err("\ncomposition  best\n")
        );
        assert!(err("\ncomposition  best\n").ends_with("engine.txt:2:14"));
        assert!(err("semantics C++\n").ends_with("engine.txt:1:11"));
        assert!(err("semantics manual\nsemantics original\n").ends_with("engine.txt:2:1"));
        assert!(err("semantics\n").contains("a value after `semantics`"));
    }

    /// Found by the fuzzer (target `brian`, seed 23, input 14162): a 64 KiB mutant of the
    /// harvester's `engine.txt` took 9 s, each word being cut from the start of its line. A
    /// line of 20 000 words is now refused at once, at the second value's column.
    #[test]
    fn a_long_line_is_read_in_linear_time() {
        let line = format!("threshold_filter {}\n", "0.5 ".repeat(20_000));
        let start = std::time::Instant::now();
        assert!(err(&line).ends_with("engine.txt:1:22"), "{}", err(&line));
        assert!(start.elapsed() < std::time::Duration::from_secs(1), "{:?}", start.elapsed());
        // Columns count characters: two no-break spaces (blanks), then a word of three é.
        let wide = format!("# é\nsemantics{}ééé\n", "\u{a0}".repeat(2));
        assert!(err(&wide).contains("not `ééé`"), "{}", err(&wide));
        assert!(err(&wide).ends_with("engine.txt:2:12"), "{}", err(&wide));
    }

    proptest! {
        #[test]
        fn any_text_is_read_or_refused_without_panic(text in ".{0,200}") {
            let _ = parse_engine(&text, Path::new("engine.txt"));
        }
    }
}
