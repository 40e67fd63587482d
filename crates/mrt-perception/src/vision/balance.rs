//! White balance: each image's colours corrected so that its carpet shows the colour the colour
//! classes were set for, before the lookup table classifies them (MRT's addition to ISocRob's
//! vision, ISocRob-2000 report §3.2.1, whose thresholds hold for one light only).
//!
//! A light half as bright, a warm lamp or a camera's own gain moves every colour of the image
//! the same way, channel by channel. The carpet, most of what a field camera sees, is a
//! reference that is always there: its mean colour is measured on a sparse grid of the image
//! (every [`SAMPLE_STEP`]th pixel of every [`SAMPLE_STEP`]th row, the pixels of the field's
//! hue and saturation at any value from [`CARPET_MIN_VALUE`] up), and each channel gets the
//! gain that brings that mean to the colour file's `[white_balance] carpet` (a von Kries
//! correction). A corrected level past 255 is clipped, channel by channel, where that leaves a
//! near-white pixel (saturation up to [`WHITE_SATURATION`]: a white line stays white, as an
//! overexposed camera shows it); any other pixel is scaled down as a whole, so that it keeps
//! its hue: a ball lit by a camera's headlight beside a carpet seen at a grazing angle stays
//! orange, where clipping each channel would turn it yellow. When all three gains are within [`DEAD_BAND`] of one they are left at one, so
//! that images under the light the classes were set for are classified exactly as they come;
//! an image with too little carpet ([`MIN_CARPET_SHARE`]) is left as it is too.
//!
//! ```
//! use mrt_perception::vision::balance::Gains;
//!
//! // An image under a light half as bright as the colour file's: twice the level.
//! let gains = Gains::new([2.0, 2.0, 2.0]);
//! assert_eq!(gains.apply([15, 65, 25]), [30, 130, 50]);
//! assert!(Gains::new([1.01, 0.99, 1.0]).is_unity(), "within the dead band");
//! ```

#[cfg(doc)]
use super::colors::CARPET_MIN_VALUE;
use super::colors::{rgb15_of, Lut};

/// The carpet is measured on every this many pixels of every this many rows.
pub const SAMPLE_STEP: usize = 4;
/// The share of the sampled pixels that must be carpet for an image to be balanced.
pub const MIN_CARPET_SHARE: f64 = 0.05;
/// Gains are all one when all three are within this of one.
pub const DEAD_BAND: f64 = 0.03;
/// The largest gain (and the inverse of the smallest): darker or brighter images than that
/// are corrected that far only.
pub const MAX_GAIN: f64 = 8.0;

/// A pixel that clipping each channel at 255 leaves this little saturated is clipped so;
/// a more saturated one keeps its hue.
pub const WHITE_SATURATION: f32 = 0.25;

/// One gain a channel.
#[derive(Clone, Debug)]
pub struct Gains {
    factors: [f64; 3],
}

impl Default for Gains {
    fn default() -> Self {
        Gains::new([1.0; 3])
    }
}

impl Gains {
    /// The gains `factors` (red, green, blue), each kept within `1 / MAX_GAIN ..= MAX_GAIN`
    /// and snapped to one within [`DEAD_BAND`] when all three are (a factor that is not a
    /// number is one).
    pub fn new(factors: [f64; 3]) -> Gains {
        let mut factors =
            factors.map(|f| if f.is_finite() { f.clamp(1.0 / MAX_GAIN, MAX_GAIN) } else { 1.0 });
        if factors.iter().all(|f| (f - 1.0).abs() <= DEAD_BAND) {
            factors = [1.0; 3];
        }
        Gains { factors }
    }

    /// The gains, red, green, blue.
    pub fn factors(&self) -> [f64; 3] {
        self.factors
    }

    /// Whether every gain is one (the image is classified as it comes).
    pub fn is_unity(&self) -> bool {
        self.factors == [1.0; 3]
    }

    /// A pixel, corrected: each channel times its gain, then brought into 0–255 (a colour
    /// pushed past 255 scaled down as a whole to keep its hue, unless it is near white).
    pub fn apply(&self, px: [u8; 3]) -> [u8; 3] {
        fit(std::array::from_fn(|c| f32::from(px[c]) * self.factors[c] as f32))
    }

    /// The gains that bring the mean colour of the carpet in `rgb` (an RGB888 image
    /// `width` pixels wide) to `carpet`; one where the image shows too little carpet.
    /// `is_carpet` tells a pixel of the carpet's hue and saturation by its RGB15 value.
    pub fn for_carpet(
        rgb: &[u8],
        width: usize,
        carpet: [f64; 3],
        is_carpet: impl Fn(u16) -> bool,
    ) -> Gains {
        if width == 0 {
            return Gains::default();
        }
        let (mut sum, mut count, mut sampled) = ([0u64; 3], 0u64, 0u64);
        for row in rgb.chunks_exact(3 * width).step_by(SAMPLE_STEP) {
            for px in row.chunks_exact(3).step_by(SAMPLE_STEP) {
                sampled += 1;
                if is_carpet(rgb15_of(px[0], px[1], px[2])) {
                    count += 1;
                    for (s, &v) in sum.iter_mut().zip(px) {
                        *s += u64::from(v);
                    }
                }
            }
        }
        if count == 0 || (count as f64) < MIN_CARPET_SHARE * sampled as f64 {
            return Gains::default();
        }
        let mean = sum.map(|s| (s as f64 / count as f64).max(0.5));
        Gains::new([carpet[0] / mean[0], carpet[1] / mean[1], carpet[2] / mean[2]])
    }
}

/// A corrected colour (levels from 0 up, any of them maybe past 255) as 8-bit levels: clipped
/// channel by channel where that leaves it near white, else scaled down as a whole to keep its
/// hue (see the module's doc).
#[inline]
fn fit(v: [f32; 3]) -> [u8; 3] {
    let top = v[0].max(v[1]).max(v[2]);
    let low = v[0].min(v[1]).min(v[2]);
    // Without a branch: the table's build runs this 32 768 times, on pixels of either kind.
    let keep_hue = top > 255.0 && low < 255.0 * (1.0 - WHITE_SATURATION);
    let scale = if keep_hue { 255.0 / top } else { 1.0 };
    // Levels are never negative: adding a half and truncating rounds them (a float-to-int
    // cast saturates at 255), without a call to `round`.
    v.map(|v| (v * scale + 0.5).min(255.0) as u8)
}

/// The lookup table for one image's light: the colour file's table ([`Lut`]) read through the
/// image's gains, rebuilt for each image that needs a correction (32 768 entries, cheaper than
/// correcting each pixel of a 320 × 240 image), so that classifying costs what it costs
/// without a correction.
#[derive(Clone)]
pub struct BalancedLut {
    table: Box<[u8; 1 << 15]>,
    /// The gains the table was built for (the next image under the same light reuses it).
    built_for: Option<[f64; 3]>,
    /// Each channel's 32 RGB15 cell middles times its gain.
    levels: [[f32; 32]; 3],
}

/// A cell of the table whose class is found when a pixel first falls in it: one whose
/// corrected colour keeps its hue (no class has this number).
const UNRESOLVED: u8 = u8::MAX;

impl std::fmt::Debug for BalancedLut {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BalancedLut").field("built_for", &self.built_for).finish_non_exhaustive()
    }
}

impl Default for BalancedLut {
    fn default() -> Self {
        BalancedLut { table: Box::new([0; 1 << 15]), built_for: None, levels: [[0.0; 32]; 3] }
    }
}

impl BalancedLut {
    /// Classifies an RGB888 image `width` pixels wide into `out` as [`Lut::classify`] does,
    /// after correcting its colours by the gains that bring its carpet to the colour file's
    /// `[white_balance]` (none without one), and returns those gains.
    pub fn classify(&mut self, lut: &Lut, rgb: &[u8], width: usize, out: &mut [u8]) -> Gains {
        let gains = match lut.white_balance() {
            Some(carpet) => Gains::for_carpet(rgb, width, carpet, |c| lut.is_carpet15(c)),
            None => Gains::default(),
        };
        if gains.is_unity() {
            lut.classify(rgb, out);
            return gains;
        }
        if self.built_for != Some(gains.factors) {
            self.build(lut, &gains);
        }
        for (px, o) in rgb.chunks_exact(3).zip(out.iter_mut()) {
            *o = self.class(lut, usize::from(rgb15_of(px[0], px[1], px[2])));
        }
        gains
    }

    /// The table of `lut` under `gains`: each RGB15 cell's middle colour, corrected as
    /// [`Gains::apply`] corrects it. A cell whose colour passes 255 and keeps its hue is left
    /// [`UNRESOLVED`] (most cells of a strong gain; few pixels of an image fall in them);
    /// every other cell's corrected colour is each channel's own, clipped at 255.
    fn build(&mut self, lut: &Lut, gains: &Gains) {
        self.levels = std::array::from_fn(|ch| {
            std::array::from_fn(|v| ((v << 3) | 4) as f32 * gains.factors[ch] as f32)
        });
        let white = 255.0 * (1.0 - WHITE_SATURATION);
        // A channel's RGB15 bits, and whether its level passes 255 or lies below white.
        let bits = |ch: usize, shift: u32| -> [(usize, bool, bool); 32] {
            std::array::from_fn(|v| {
                let level = self.levels[ch][v];
                (
                    usize::from((level + 0.5).min(255.0) as u8 >> 3) << shift,
                    level > 255.0,
                    level < white,
                )
            })
        };
        let (red, green, blue) = (bits(0, 10), bits(1, 5), bits(2, 0));
        let raw = lut.raw();
        for (rows, &(r, r_over, r_low)) in self.table.chunks_exact_mut(1 << 10).zip(&red) {
            for (row, &(g, g_over, g_low)) in rows.chunks_exact_mut(1 << 5).zip(&green) {
                for (slot, &(b, b_over, b_low)) in row.iter_mut().zip(&blue) {
                    let keeps_hue = (r_over | g_over | b_over) & (r_low | g_low | b_low);
                    *slot = if keeps_hue { UNRESOLVED } else { raw[r | g | b] };
                }
            }
        }
        self.built_for = Some(gains.factors);
    }

    /// The class of an RGB15 cell under the gains the table was built for.
    #[inline]
    fn class(&mut self, lut: &Lut, cell: usize) -> u8 {
        match self.table[cell] {
            UNRESOLVED => self.resolve(lut, cell),
            class => class,
        }
    }

    /// The class of an [`UNRESOLVED`] cell, kept in the table.
    #[cold]
    fn resolve(&mut self, lut: &Lut, cell: usize) -> u8 {
        let level = |ch: usize, shift: usize| self.levels[ch][(cell >> shift) & 31];
        let [r, g, b] = fit([level(0, 10), level(1, 5), level(2, 0)]);
        let class = lut.raw()[usize::from(rgb15_of(r, g, b))];
        self.table[cell] = class;
        class
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vision::colors::{ColorClass, ColorTable};

    /// A frame of carpet with an orange disc, every level scaled by `light` per channel.
    fn frame(light: [f64; 3]) -> Vec<u8> {
        let (w, h) = (64usize, 48usize);
        let mut rgb = Vec::with_capacity(w * h * 3);
        for y in 0..h {
            for x in 0..w {
                let ball = (x as f64 - 32.0).hypot(y as f64 - 24.0) < 6.0;
                let c: [f64; 3] = if ball { [250.0, 110.0, 15.0] } else { [30.0, 130.0, 50.0] };
                for (v, l) in c.iter().zip(light) {
                    rgb.push((v * l).round().min(255.0) as u8);
                }
            }
        }
        rgb
    }

    fn classes(lut: &Lut, rgb: &[u8]) -> (Vec<u8>, Gains) {
        let mut out = vec![0u8; rgb.len() / 3];
        let gains = BalancedLut::default().classify(lut, rgb, 64, &mut out);
        (out, gains)
    }

    #[test]
    fn a_dim_or_tinted_image_is_classified_as_under_the_files_light() {
        let lut = Lut::new(&ColorTable::shipped());
        let (reference, gains) = classes(&lut, &frame([1.0; 3]));
        assert!(gains.is_unity(), "the file's own light: no correction ({gains:?})");
        for light in [[0.35, 0.35, 0.35], [0.2, 0.2, 0.2], [1.0, 0.8, 0.55], [0.6, 0.7, 1.0]] {
            let (seen, gains) = classes(&lut, &frame(light));
            let same = seen.iter().zip(&reference).filter(|(a, b)| a == b).count();
            assert!(same as f64 > 0.99 * reference.len() as f64, "{light:?}: {gains:?}");
            for (g, l) in gains.factors().iter().zip(light) {
                assert!((g * l - 1.0).abs() < 0.05, "{light:?}: {gains:?}");
            }
        }
    }

    /// A headlight on the camera: the carpet, seen at a grazing angle, is dark and the ball
    /// facing the lamp bright. The gains that lift the carpet would push the ball past 255 in
    /// red and green, which clipped one by one is yellow; it keeps its orange, and a white line
    /// beside it stays white.
    #[test]
    fn a_colour_pushed_past_255_keeps_its_hue_and_white_stays_white() {
        let lut = Lut::new(&ColorTable::shipped());
        let (w, h) = (64usize, 48usize);
        let mut rgb = Vec::with_capacity(w * h * 3);
        for y in 0..h {
            for x in 0..w {
                let ball = (x as f64 - 32.0).hypot(y as f64 - 24.0) < 6.0;
                let c = match (ball, y >= 40) {
                    (true, _) => [173, 76, 10],
                    (false, true) => [70, 72, 68],
                    (false, false) => [9, 38, 15],
                };
                rgb.extend_from_slice(&c);
            }
        }
        let (seen, gains) = classes(&lut, &rgb);
        assert!(gains.factors().iter().all(|&g| g > 3.0), "{gains:?}");
        assert_eq!(seen[24 * w + 32], ColorClass::Ball as u8, "{gains:?}");
        assert_eq!(seen[44 * w + 32], ColorClass::Line as u8, "{gains:?}");
    }

    #[test]
    fn without_carpet_or_a_white_balance_nothing_is_corrected() {
        let lut = Lut::new(&ColorTable::shipped());
        let orange = [250u8, 110, 15].repeat(64 * 48);
        assert!(classes(&lut, &orange).1.is_unity(), "no carpet in view");
        let plain = ColorTable { white_balance: None, ..ColorTable::shipped() };
        let lut = Lut::new(&plain);
        let (seen, gains) = classes(&lut, &frame([0.35; 3]));
        assert!(gains.is_unity());
        assert!(!seen.contains(&(ColorClass::Field as u8)), "too dark for the field's class");
    }

    /// The table built for a light classifies random colours as correcting each pixel would,
    /// but where a pixel's corrected level falls in another RGB15 cell than its cell's middle
    /// does and that cell is of another class (95 % agree under these strong gains).
    #[test]
    fn the_balanced_table_agrees_with_correcting_each_pixel() {
        let lut = Lut::new(&ColorTable::shipped());
        let gains = Gains::new([1.7, 1.4, 0.8]);
        let mut balanced = BalancedLut::default();
        balanced.build(&lut, &gains);
        let mut state = 0x2545_f491_u32;
        let (mut same, n) = (0, 20_000);
        for _ in 0..n {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            let [r, g, b, _] = state.to_le_bytes();
            let [cr, cg, cb] = gains.apply([r, g, b]);
            let direct = lut.class(cr, cg, cb) as u8;
            same += usize::from(balanced.class(&lut, usize::from(rgb15_of(r, g, b))) == direct);
        }
        assert!(same as f64 > 0.93 * n as f64, "{same} of {n}");
    }

    #[test]
    fn gains_are_bounded_and_numbers() {
        assert_eq!(Gains::new([f64::NAN, f64::INFINITY, 1e9]).factors(), [1.0, 1.0, MAX_GAIN]);
        assert_eq!(Gains::new([0.0; 3]).factors(), [1.0 / MAX_GAIN; 3]);
        assert_eq!(Gains::new([3.0; 3]).apply([100, 0, 255]), [100, 0, 255], "kept below 255");
        assert_eq!(Gains::new([3.0; 3]).apply([170, 76, 10]), [255, 114, 15], "keeps its hue");
        assert_eq!(Gains::new([1.9, 1.6, 1.4]).apply([165, 190, 150]), [255, 255, 210], "white");
        assert!(Gains::for_carpet(&[], 0, [30.0, 130.0, 50.0], |_| true).is_unity());
    }
}
