//! Help for tuning a colour file: for each class, the
//! hue, saturation and value of the pixels it takes, so that a person sees what a threshold
//! lets in and where it cuts. The pixels nobody takes ([`ColorClass::Unknown`]) are counted as
//! well: a class whose colour shows up there is too narrow.
//!
//! HSV is computed the way the lookup table computes it (from the pixel's RGB15 value, eq. 13
//! of the ISocRob-2000 report), so the histograms show exactly what the thresholds are compared with.
//!
//! ```
//! use mrt_perception::vision::calibrate::Histograms;
//! use mrt_perception::vision::colors::{ColorClass, ColorTable, Lut};
//!
//! let lut = Lut::new(&ColorTable::shipped());
//! let mut h = Histograms::default();
//! h.add(&lut, &[255, 120, 0, 30, 140, 40]); // an orange pixel and a green one
//! assert_eq!(h.class(ColorClass::Ball).pixels, 1);
//! assert_eq!(h.class(ColorClass::Field).pixels, 1);
//! ```

use super::colors::{hsv_of_rgb15, rgb15_of, ColorClass, Lut};

/// Hue bins, 10° each.
pub const HUE_BINS: usize = 36;
/// Saturation and value bins, 0.05 each.
pub const LEVEL_BINS: usize = 20;

/// The HSV histograms of the pixels of one class.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ClassHistogram {
    /// Pixels counted.
    pub pixels: u64,
    /// Hue, `HUE_BINS` bins of 10° from 0°.
    pub hue: [u64; HUE_BINS],
    /// Saturation, `LEVEL_BINS` bins of 0.05 from 0.
    pub sat: [u64; LEVEL_BINS],
    /// Value, `LEVEL_BINS` bins of 0.05 from 0.
    pub val: [u64; LEVEL_BINS],
}

impl Default for ClassHistogram {
    fn default() -> Self {
        ClassHistogram { pixels: 0, hue: [0; HUE_BINS], sat: [0; LEVEL_BINS], val: [0; LEVEL_BINS] }
    }
}

fn level_bin(x: f64) -> usize {
    ((x * LEVEL_BINS as f64) as usize).min(LEVEL_BINS - 1)
}

impl ClassHistogram {
    fn add(&mut self, h: f64, s: f64, v: f64) {
        self.pixels += 1;
        self.hue[((h / 10.0) as usize).min(HUE_BINS - 1)] += 1;
        self.sat[level_bin(s)] += 1;
        self.val[level_bin(v)] += 1;
    }

    /// The range of bins holding all but `tail` of the pixels at each end (e.g. 0.02: the 2nd
    /// to the 98th percentile), as the lower edge of the first bin and the upper edge of the
    /// last, in the histogram's units (`bin_width` per bin). `None` for no pixels. Hue is not
    /// unwrapped: a class around 0° spans the whole circle here.
    pub fn central_range(bins: &[u64], bin_width: f64, tail: f64) -> Option<(f64, f64)> {
        let total: u64 = bins.iter().sum();
        if total == 0 {
            return None;
        }
        let cut = (total as f64 * tail).floor() as u64;
        let mut seen = 0;
        let mut lo = 0;
        for (i, &n) in bins.iter().enumerate() {
            seen += n;
            if seen > cut {
                lo = i;
                break;
            }
        }
        let mut seen = 0;
        let mut hi = bins.len() - 1;
        for (i, &n) in bins.iter().enumerate().rev() {
            seen += n;
            if seen > cut {
                hi = i;
                break;
            }
        }
        Some((lo as f64 * bin_width, (hi + 1) as f64 * bin_width))
    }
}

/// The histograms of every class and of the pixels no class takes, over any number of images.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Histograms {
    /// Indexed by `ColorClass as usize` (`Unknown` first).
    classes: [ClassHistogram; ColorClass::COUNT],
}

impl Histograms {
    /// Adds the pixels of an RGB888 buffer (3 bytes a pixel), each under the class the table
    /// gives it.
    pub fn add(&mut self, lut: &Lut, rgb: &[u8]) {
        for px in rgb.chunks_exact(3) {
            let c = rgb15_of(px[0], px[1], px[2]);
            let (h, s, v) = hsv_of_rgb15(c);
            self.classes[lut.class15(c) as usize].add(h, s, v);
        }
    }

    /// The histograms of one class (`Unknown`: the pixels no class takes).
    pub fn class(&self, class: ColorClass) -> &ClassHistogram {
        &self.classes[class as usize]
    }

    /// All pixels counted.
    pub fn pixels(&self) -> u64 {
        self.classes.iter().map(|c| c.pixels).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vision::colors::ColorTable;

    #[test]
    fn every_pixel_is_counted_once_under_the_class_the_table_gives_it() {
        let lut = Lut::new(&ColorTable::shipped());
        // Every RGB15 colour once (at the low end of its RGB888 cell).
        let mut rgb = Vec::with_capacity(3 << 15);
        for c in 0u16..1 << 15 {
            rgb.extend_from_slice(&[
                ((c >> 10) as u8 & 31) << 3,
                ((c >> 5) as u8 & 31) << 3,
                (c as u8 & 31) << 3,
            ]);
        }
        let mut h = Histograms::default();
        h.add(&lut, &rgb);
        assert_eq!(h.pixels(), 1 << 15);
        let mut by_class = [0u64; ColorClass::COUNT];
        for c in 0u16..1 << 15 {
            by_class[lut.class15(c) as usize] += 1;
        }
        for class in std::iter::once(ColorClass::Unknown).chain(ColorClass::ALL) {
            let hist = h.class(class);
            assert_eq!(hist.pixels, by_class[class as usize], "{}", class.name());
            assert_eq!(hist.hue.iter().sum::<u64>(), hist.pixels);
            assert_eq!(hist.sat.iter().sum::<u64>(), hist.pixels);
            assert_eq!(hist.val.iter().sum::<u64>(), hist.pixels);
        }
    }

    #[test]
    fn a_class_histogram_lies_inside_its_thresholds() {
        let colors = ColorTable::shipped();
        let lut = Lut::new(&colors);
        let mut rgb = Vec::new();
        for r in (0..=255u16).step_by(5) {
            for g in (0..=255u16).step_by(5) {
                for b in (0..=255u16).step_by(5) {
                    rgb.extend_from_slice(&[r as u8, g as u8, b as u8]);
                }
            }
        }
        let mut h = Histograms::default();
        h.add(&lut, &rgb);
        let ball = colors.get(ColorClass::Ball).copied().unwrap_or_else(|| unreachable!());
        let hist = h.class(ColorClass::Ball);
        assert!(hist.pixels > 0);
        // Saturation and value bins below the class's minimum are empty (bins are 0.05 wide).
        for (i, &n) in hist.sat.iter().enumerate() {
            if (i + 1) as f64 * 0.05 <= ball.sat_min {
                assert_eq!(n, 0, "saturation bin {i} below sat_min {}", ball.sat_min);
            }
        }
        for (i, &n) in hist.val.iter().enumerate() {
            if (i + 1) as f64 * 0.05 <= ball.val_min {
                assert_eq!(n, 0, "value bin {i} below val_min {}", ball.val_min);
            }
        }
    }

    #[test]
    fn the_central_range_drops_the_tails() {
        let mut bins = [0u64; 20];
        bins[2] = 1; // an outlier
        bins[8] = 50;
        bins[9] = 48;
        bins[15] = 1; // another
        assert_eq!(ClassHistogram::central_range(&bins, 0.05, 0.02), Some((0.4, 0.5)));
        let (lo, hi) = ClassHistogram::central_range(&bins, 0.05, 0.0).unwrap_or_default();
        assert!((lo - 0.1).abs() < 1e-12 && (hi - 0.8).abs() < 1e-12, "{lo} {hi}");
        assert_eq!(ClassHistogram::central_range(&[0; 5], 1.0, 0.02), None);
    }
}
