//! Colour classes and the lookup table (ISocRob-2000 report §3.2.1, eqs 12–15).
//!
//! A class is a box in HSV space, `⟨H_min, H_max, S_min, V_min⟩` as in the report, with hue in
//! degrees (the report's sextant units × 60) and saturation and value in `[0, 1]`. Fixed from
//! the report: hue wraps through red when `hue_min > hue_max` (oranges and reds straddle 0°);
//! a grey pixel has hue 0 and saturation 0, a black one saturation 0. **MRT adds** `sat_max`
//! and `val_max` (default 1): the report's four numbers cannot tell white lines (low
//! saturation, high value) or dark robots (low value) from anything else.
//!
//! Pixels are looked up by their RGB15 value (five bits a channel, eq. 12): the table has
//! 2¹⁵ = 32 768 entries, built once from the classes ([`Lut::new`]); classifying an RGB888
//! frame is one table read per pixel ([`Lut::classify`]).
//!
//! The classes come from a COLORS.toml file ([`ColorTable::from_toml`], `configs/vision/`):
//! one table per class, `[ball]`, `[ball_shade]`, `[goal_yellow]`, `[goal_blue]`,
//! `[marker_magenta]`, `[marker_cyan]`, `[robot]`, `[line]`, `[field]`, each with `hue_min`, `hue_max` (degrees, 0 to 360), `sat_min`, `val_min` and
//! optionally `sat_max`, `val_max` (0 to 1). A pixel that fits several classes takes the first
//! in that order of precedence: ball, ball_shade, goal_yellow, goal_blue, marker_magenta,
//! marker_cyan, robot, line, field. **MRT adds** `[ball_shade]`, the ball's side in shade (of
//! the ball's hue, what the ball's class does not take, darker or a little less saturated: it
//! joins a ball it touches and is never a ball alone), and `[white_balance] carpet`, the carpet's colour under the light the classes were
//! set for, to which each image is corrected first ([`super::balance`]).

use mrt_core::FileError;
use serde::{Deserialize, Serialize};

/// What a pixel is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum ColorClass {
    /// None of the classes.
    #[default]
    Unknown = 0,
    /// The orange ball.
    Ball = 1,
    /// The yellow goal.
    GoalYellow = 2,
    /// The blue goal.
    GoalBlue = 3,
    /// A robot (dark).
    Robot = 4,
    /// A white field line.
    Line = 5,
    /// The green carpet.
    Field = 6,
    /// A magenta robot marker (one team's colour).
    MarkerMagenta = 7,
    /// A cyan robot marker (the other team's).
    MarkerCyan = 8,
    /// The ball's shaded side (MRT's addition): of the ball's hue, what the ball's class does
    /// not take (darker, or a little less saturated); it joins a ball blob it touches and never
    /// makes a ball on its own
    /// ([`super::blobs::find_ball`]).
    BallShade = 9,
}

impl ColorClass {
    /// How many byte values name a class, `Unknown` included (`class as usize` is below it).
    pub const COUNT: usize = 10;

    /// The classes in their order of precedence.
    pub const ALL: [ColorClass; 9] = [
        ColorClass::Ball,
        ColorClass::BallShade,
        ColorClass::GoalYellow,
        ColorClass::GoalBlue,
        ColorClass::MarkerMagenta,
        ColorClass::MarkerCyan,
        ColorClass::Robot,
        ColorClass::Line,
        ColorClass::Field,
    ];

    /// The class of a table entry (`Unknown` for anything else).
    pub fn from_u8(v: u8) -> ColorClass {
        match v {
            1 => ColorClass::Ball,
            2 => ColorClass::GoalYellow,
            3 => ColorClass::GoalBlue,
            4 => ColorClass::Robot,
            5 => ColorClass::Line,
            6 => ColorClass::Field,
            7 => ColorClass::MarkerMagenta,
            8 => ColorClass::MarkerCyan,
            9 => ColorClass::BallShade,
            _ => ColorClass::Unknown,
        }
    }

    /// The name used in COLORS.toml and in `mrt vision`'s output.
    pub fn name(self) -> &'static str {
        match self {
            ColorClass::Unknown => "unknown",
            ColorClass::Ball => "ball",
            ColorClass::GoalYellow => "goal_yellow",
            ColorClass::GoalBlue => "goal_blue",
            ColorClass::Robot => "robot",
            ColorClass::Line => "line",
            ColorClass::Field => "field",
            ColorClass::MarkerMagenta => "marker_magenta",
            ColorClass::MarkerCyan => "marker_cyan",
            ColorClass::BallShade => "ball_shade",
        }
    }
}

/// One class's box in HSV space (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Thresholds {
    /// Lowest hue, degrees (above `hue_max`: the range wraps through 0°).
    pub hue_min: f64,
    /// Highest hue, degrees.
    pub hue_max: f64,
    /// Lowest saturation, 0 to 1.
    pub sat_min: f64,
    /// Lowest value (brightness), 0 to 1.
    pub val_min: f64,
    /// Highest saturation, 0 to 1 (MRT's addition; default 1).
    #[serde(default = "one")]
    pub sat_max: f64,
    /// Highest value, 0 to 1 (MRT's addition; default 1).
    #[serde(default = "one")]
    pub val_max: f64,
}

fn one() -> f64 {
    1.0
}

impl Thresholds {
    /// Whether a colour of hue `h` (degrees in `[0, 360)`), saturation `s` and value `v` is in
    /// the box (eq. 15, with the hue wrap-around).
    pub fn contains(&self, h: f64, s: f64, v: f64) -> bool {
        let hue = if self.hue_min <= self.hue_max {
            self.hue_min <= h && h <= self.hue_max
        } else {
            h >= self.hue_min || h <= self.hue_max
        };
        hue && s >= self.sat_min && s <= self.sat_max && v >= self.val_min && v <= self.val_max
    }

    fn check(&self, class: &str) -> Result<(), String> {
        let deg = [("hue_min", self.hue_min), ("hue_max", self.hue_max)];
        for (name, v) in deg {
            if !(0.0..=360.0).contains(&v) {
                return Err(format!("{class}.{name} must be 0 to 360 degrees, not {v}"));
            }
        }
        let unit = [
            ("sat_min", self.sat_min),
            ("val_min", self.val_min),
            ("sat_max", self.sat_max),
            ("val_max", self.val_max),
        ];
        for (name, v) in unit {
            if !(0.0..=1.0).contains(&v) {
                return Err(format!("{class}.{name} must be 0 to 1, not {v}"));
            }
        }
        Ok(())
    }
}

/// The classes of a COLORS.toml file (module doc); a class left out matches nothing.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColorTable {
    /// The ball.
    pub ball: Option<Thresholds>,
    /// The yellow goal.
    pub goal_yellow: Option<Thresholds>,
    /// The blue goal.
    pub goal_blue: Option<Thresholds>,
    /// Robots.
    pub robot: Option<Thresholds>,
    /// Field lines.
    pub line: Option<Thresholds>,
    /// The carpet.
    pub field: Option<Thresholds>,
    /// Magenta robot markers.
    #[serde(default)]
    pub marker_magenta: Option<Thresholds>,
    /// Cyan robot markers.
    #[serde(default)]
    pub marker_cyan: Option<Thresholds>,
    /// The ball's shaded side, second in precedence (MRT's addition; module doc).
    #[serde(default)]
    pub ball_shade: Option<Thresholds>,
    /// The carpet's colour under the light the classes were set for (MRT's addition): each
    /// image is corrected so that its carpet shows this colour before it is classified
    /// ([`super::balance`]). Without it images are classified as they come.
    #[serde(default)]
    pub white_balance: Option<WhiteBalance>,
}

/// What an image's colours are corrected to before classification ([`super::balance`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WhiteBalance {
    /// The carpet's red, green and blue (0–255) under the light the classes were set for.
    pub carpet: [f64; 3],
}

impl ColorTable {
    /// Parses a COLORS.toml; `file` names it in errors (with line and column for syntax).
    pub fn from_toml(text: &str, file: &str) -> Result<ColorTable, FileError> {
        let t: ColorTable = toml::from_str(text)
            .map_err(|e| FileError::parse(file, text, e.span().map(|s| s.start), e.message()))?;
        t.check().map_err(|message| FileError::Invalid { file: file.to_string(), message })?;
        Ok(t)
    }

    /// Checks every class's thresholds (a table embedded in another file, such as a robot
    /// file's `[vision.colors]`, is read without [`ColorTable::from_toml`]).
    pub fn check(&self) -> Result<(), String> {
        for class in ColorClass::ALL {
            if let Some(th) = self.get(class) {
                th.check(class.name())?;
            }
        }
        if let Some(wb) = &self.white_balance {
            if !wb.carpet.iter().all(|c| (1.0..=255.0).contains(c)) {
                return Err(format!(
                    "white_balance.carpet must be three levels of 1 to 255, not {:?}",
                    wb.carpet
                ));
            }
            if self.field.is_none() {
                return Err("white_balance needs a [field] class to find the carpet".into());
            }
        }
        Ok(())
    }

    /// The shipped `configs/vision/colors.toml`, tuned for the simulator's images (built into
    /// the program).
    pub fn shipped() -> ColorTable {
        const SHIPPED: &str = include_str!("../../../../configs/vision/colors.toml");
        // The file is checked by a test: it parses.
        ColorTable::from_toml(SHIPPED, "configs/vision/colors.toml").unwrap_or_default()
    }

    /// Reads a COLORS.toml file.
    pub fn from_file(path: impl AsRef<std::path::Path>) -> Result<ColorTable, FileError> {
        let (text, file) = mrt_core::FileError::read(path.as_ref())?;
        ColorTable::from_toml(&text, &file)
    }

    /// A class's thresholds, if the table has them.
    pub fn get(&self, class: ColorClass) -> Option<&Thresholds> {
        match class {
            ColorClass::Unknown => None,
            ColorClass::Ball => self.ball.as_ref(),
            ColorClass::GoalYellow => self.goal_yellow.as_ref(),
            ColorClass::GoalBlue => self.goal_blue.as_ref(),
            ColorClass::Robot => self.robot.as_ref(),
            ColorClass::Line => self.line.as_ref(),
            ColorClass::Field => self.field.as_ref(),
            ColorClass::MarkerMagenta => self.marker_magenta.as_ref(),
            ColorClass::MarkerCyan => self.marker_cyan.as_ref(),
            ColorClass::BallShade => self.ball_shade.as_ref(),
        }
    }

    /// The class of a colour (first match in the order of precedence), from its HSV.
    pub fn classify_hsv(&self, h: f64, s: f64, v: f64) -> ColorClass {
        ColorClass::ALL
            .into_iter()
            .find(|c| self.get(*c).is_some_and(|t| t.contains(h, s, v)))
            .unwrap_or(ColorClass::Unknown)
    }
}

/// Packs five bits a channel (eq. 12): `0rrrrrgg gggbbbbb`.
pub fn rgb15(r5: u16, g5: u16, b5: u16) -> u16 {
    ((r5 & 31) << 10) | ((g5 & 31) << 5) | (b5 & 31)
}

/// The RGB15 value of an RGB888 pixel (the top five bits of each channel).
#[inline]
pub fn rgb15_of(r: u8, g: u8, b: u8) -> u16 {
    (u16::from(r >> 3) << 10) | (u16::from(g >> 3) << 5) | u16::from(b >> 3)
}

/// An RGB15 word as the report's camera sends it: two bytes, most significant first (eq. 12).
pub fn rgb15_from_bytes(bytes: [u8; 2]) -> u16 {
    u16::from_be_bytes(bytes) & 0x7FFF
}

/// Hue (degrees in `[0, 360)`), saturation and value (both 0 to 1) of an RGB15 colour, by the
/// report's eq. 13 (Foley et al.) with its flags fixed: hue in sextants × 60, negative hues
/// wrapped, grey (Δ = 0) has hue 0, black (M = 0) saturation 0.
pub fn hsv_of_rgb15(c: u16) -> (f64, f64, f64) {
    let (r, g, b) = (f64::from((c >> 10) & 31), f64::from((c >> 5) & 31), f64::from(c & 31));
    let (max, min) = (r.max(g).max(b), r.min(g).min(b));
    let delta = max - min;
    let sextant = if delta == 0.0 {
        0.0
    } else if r == max {
        (g - b) / delta
    } else if g == max {
        2.0 + (b - r) / delta
    } else {
        4.0 + (r - g) / delta
    };
    let hue = (sextant * 60.0).rem_euclid(360.0);
    let sat = if max == 0.0 { 0.0 } else { delta / max };
    (hue, sat, max / 31.0)
}

/// The colour lookup table: RGB15 → class, 32 768 entries (module doc), with what the white
/// balance needs ([`super::balance`]).
#[derive(Clone)]
pub struct Lut {
    table: Box<[u8; 1 << 15]>,
    /// Of the field's hue and saturation, at any value from [`CARPET_MIN_VALUE`] up.
    carpet: Box<[bool; 1 << 15]>,
    white_balance: Option<[f64; 3]>,
}

/// The darkest value a pixel of the carpet's hue and saturation is measured at by the white
/// balance (two levels of 31).
pub const CARPET_MIN_VALUE: f64 = 2.0 / 31.0;

impl std::fmt::Debug for Lut {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Lut").finish_non_exhaustive()
    }
}

impl Lut {
    /// The table of `colors`, every RGB15 value classified once.
    pub fn new(colors: &ColorTable) -> Lut {
        let mut table = Box::new([0u8; 1 << 15]);
        let mut carpet = Box::new([false; 1 << 15]);
        let field =
            colors.field.map(|f| Thresholds { val_min: CARPET_MIN_VALUE, val_max: 1.0, ..f });
        for (c, (slot, carpet)) in table.iter_mut().zip(carpet.iter_mut()).enumerate() {
            let (h, s, v) = hsv_of_rgb15(c as u16);
            *slot = colors.classify_hsv(h, s, v) as u8;
            *carpet = field.is_some_and(|f| f.contains(h, s, v));
        }
        Lut { table, carpet, white_balance: colors.white_balance.map(|w| w.carpet) }
    }

    /// The carpet's colour the images are balanced to, if the colour file gives one.
    pub fn white_balance(&self) -> Option<[f64; 3]> {
        self.white_balance
    }

    /// Whether an RGB15 value has the field's hue and saturation (at any value from
    /// [`CARPET_MIN_VALUE`] up).
    #[inline]
    pub fn is_carpet15(&self, c: u16) -> bool {
        self.carpet[usize::from(c & 0x7FFF)]
    }

    /// The whole table: the class byte of every RGB15 value.
    pub(crate) fn raw(&self) -> &[u8; 1 << 15] {
        &self.table
    }

    /// The class of an RGB15 value.
    #[inline]
    pub fn class15(&self, c: u16) -> ColorClass {
        ColorClass::from_u8(self.table[usize::from(c & 0x7FFF)])
    }

    /// The class of an RGB888 pixel.
    #[inline]
    pub fn class(&self, r: u8, g: u8, b: u8) -> ColorClass {
        self.class15(rgb15_of(r, g, b))
    }

    /// Classifies an RGB888 frame (`rgb`: 3 bytes a pixel, row after row) into `out` (one
    /// class byte a pixel, `ColorClass as u8`). Pixels beyond the shorter of the two are left
    /// alone.
    pub fn classify(&self, rgb: &[u8], out: &mut [u8]) {
        for (px, o) in rgb.chunks_exact(3).zip(out.iter_mut()) {
            *o = self.table[usize::from(rgb15_of(px[0], px[1], px[2]))];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn shipped() -> ColorTable {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../configs/vision/colors.toml");
        let table = ColorTable::from_file(path).unwrap();
        assert_eq!(ColorTable::shipped(), table, "the built-in table is the file's");
        assert!(ColorClass::ALL.iter().all(|&c| table.get(c).is_some()));
        table
    }

    /// An independent HSV: the textbook formula on channels scaled to [0, 1], in degrees.
    fn reference_hsv(c: u16) -> (f64, f64, f64) {
        let ch = |shift: u16| f64::from((c >> shift) & 31) / 31.0;
        let (r, g, b) = (ch(10), ch(5), ch(0));
        let max = r.max(g).max(b);
        let min = r.min(g).min(b);
        let d = max - min;
        let h = if d == 0.0 {
            0.0
        } else if max == r {
            60.0 * ((g - b) / d).rem_euclid(6.0)
        } else if max == g {
            60.0 * ((b - r) / d + 2.0)
        } else {
            60.0 * ((r - g) / d + 4.0)
        };
        (h % 360.0, if max == 0.0 { 0.0 } else { d / max }, max)
    }

    /// Every one of the 32 768 RGB15 values: the table agrees with a direct classification by
    /// an independent HSV formula (except exactly on a threshold, where rounding may differ).
    #[test]
    fn the_table_agrees_with_direct_hsv_classification_on_every_rgb15_value() {
        let colors = shipped();
        let lut = Lut::new(&colors);
        let edges: Vec<f64> = ColorClass::ALL
            .into_iter()
            .filter_map(|c| colors.get(c))
            .flat_map(|t| [t.hue_min, t.hue_max, t.sat_min, t.sat_max, t.val_min, t.val_max])
            .collect();
        let on_edge = |x: f64| edges.iter().any(|e| (x - e).abs() < 1e-9);
        let mut on_a_threshold = 0;
        for c in 0..(1u16 << 15) {
            let (h, s, v) = reference_hsv(c);
            let direct = colors.classify_hsv(h, s, v);
            if lut.class15(c) != direct {
                // Only where rounding can tip a value that sits exactly on a threshold.
                assert!(on_edge(h) || on_edge(s) || on_edge(v), "rgb15 {c:#06x}: {direct:?}");
                on_a_threshold += 1;
            }
        }
        // 102 with the shipped colours: ratios such as s = 1/5 or h = 40° that the two formulas
        // round to either side of a threshold set exactly there.
        assert!(on_a_threshold < 256, "{on_a_threshold} disagreements on thresholds");
    }

    #[test]
    fn class_bytes_round_trip() {
        for c in ColorClass::ALL {
            assert_eq!(ColorClass::from_u8(c as u8), c);
            assert!((c as usize) < ColorClass::COUNT);
        }
        assert_eq!(ColorClass::ALL.len() + 1, ColorClass::COUNT, "every class and Unknown");
        assert_eq!(ColorClass::from_u8(0), ColorClass::Unknown);
        assert_eq!(ColorClass::from_u8(200), ColorClass::Unknown);
    }

    #[test]
    fn hsv_by_hand_and_the_reports_flags() {
        // Pure red, green, blue; grey; black.
        assert_eq!(hsv_of_rgb15(rgb15(31, 0, 0)), (0.0, 1.0, 1.0));
        assert_eq!(hsv_of_rgb15(rgb15(0, 31, 0)).0, 120.0);
        assert_eq!(hsv_of_rgb15(rgb15(0, 0, 31)).0, 240.0);
        assert_eq!(hsv_of_rgb15(rgb15(16, 16, 16)), (0.0, 0.0, 16.0 / 31.0), "grey: hue 0");
        assert_eq!(hsv_of_rgb15(0), (0.0, 0.0, 0.0), "black: saturation 0");
        // R = max, G < B: the report's H is negative (−1/3 sextant): wrapped to 340°.
        let (h, _, _) = hsv_of_rgb15(rgb15(31, 0, 10));
        assert!((h - (360.0 - 60.0 * 10.0 / 31.0)).abs() < 1e-9, "{h}");
        // eq. 12: two bytes, most significant first, top bit unused.
        assert_eq!(rgb15_from_bytes([0b1111_1100, 0b0001_1111]), rgb15(31, 0, 31));
        assert_eq!(rgb15_of(255, 128, 7), rgb15(31, 16, 0));
    }

    #[test]
    fn the_shipped_colours_classify_the_simulators_palette() {
        let lut = Lut::new(&shipped());
        assert_eq!(lut.class(255, 120, 0), ColorClass::Ball, "orange");
        assert_eq!(lut.class(230, 200, 20), ColorClass::GoalYellow);
        assert_eq!(lut.class(20, 60, 220), ColorClass::GoalBlue);
        assert_eq!(lut.class(245, 245, 245), ColorClass::Line, "white");
        assert_eq!(lut.class(30, 140, 40), ColorClass::Field, "carpet green");
        assert_eq!(lut.class(25, 25, 25), ColorClass::Robot, "black");
        // A wrapping hue range: the ball's orange-red reaches across 0°.
        assert_eq!(lut.class(255, 20, 40), ColorClass::Ball, "red-orange, hue ≈ 355°");
    }

    #[test]
    fn a_frame_is_classified_pixel_by_pixel() {
        let lut = Lut::new(&shipped());
        let rgb = [255, 120, 0, 30, 140, 40, 245, 245, 245, 128, 0, 255];
        let mut out = [9u8; 4];
        lut.classify(&rgb, &mut out);
        let classes: Vec<ColorClass> = out.iter().map(|c| ColorClass::from_u8(*c)).collect();
        assert_eq!(
            classes,
            [ColorClass::Ball, ColorClass::Field, ColorClass::Line, ColorClass::Unknown]
        );
    }

    #[test]
    fn bad_colour_files_say_where() {
        let e =
            ColorTable::from_toml("[ball]\nhue_min = 10\nhue_max = 40\n", "c.toml").unwrap_err();
        assert!(e.to_string().starts_with("c.toml:1:1: missing field `sat_min`"), "{e}");
        let text = "[ball]\nhue_min = 10\nhue_max = 400\nsat_min = 0.5\nval_min = 0.3\n";
        let e = ColorTable::from_toml(text, "c.toml").unwrap_err();
        assert_eq!(e.to_string(), "c.toml: ball.hue_max must be 0 to 360 degrees, not 400");
        let e = ColorTable::from_toml("[blob]\n", "c.toml").unwrap_err();
        assert!(e.to_string().contains("unknown field `blob`"), "{e}");
    }

    proptest! {
        /// Random text never panics the parser.
        #[test]
        fn random_colour_files_are_parsed_or_refused(text in "\\PC{0,200}") {
            let _ = ColorTable::from_toml(&text, "fuzz.toml");
        }

        /// Random thresholds: accepted only in range, and then a table builds.
        #[test]
        fn random_thresholds(hmin in -10.0f64..400.0, hmax in -10.0f64..400.0,
                             s in -0.5f64..1.5, v in -0.5f64..1.5) {
            let text = format!("[ball]\nhue_min = {hmin:?}\nhue_max = {hmax:?}\nsat_min = {s:?}\nval_min = {v:?}\n");
            if let Ok(t) = ColorTable::from_toml(&text, "p.toml") {
                let b = t.ball.unwrap();
                prop_assert!((0.0..=360.0).contains(&b.hue_min) && (0.0..=1.0).contains(&b.sat_min));
                let _ = Lut::new(&t);
            }
        }

        /// Random bytes of any length classify without panicking.
        #[test]
        fn random_frames_classify(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
            let lut = Lut::new(&ColorTable::default());
            let mut out = vec![0u8; bytes.len() / 3];
            lut.classify(&bytes, &mut out);
            prop_assert!(out.iter().all(|c| *c == ColorClass::Unknown as u8));
        }
    }
}
