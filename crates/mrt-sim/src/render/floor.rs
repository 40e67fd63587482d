//! The floor's paint and the arithmetic of a row of pixels: an ideal lens (or the mirror)
//! sees an evenly stepped line of the floor along each row, so what a row shows is found as
//! spans of columns, solved for where that line crosses a painted line, the centre circle's
//! ring or the walls ([`FloorPaint`]), and filled with one colour ([`fill`]). A distorting
//! lens reads the same paint through a [`Texture`].

use mrt_world::FieldMap;
use std::ops::Range;

/// Side of a floor texel, m.
pub(super) const TEXEL: f64 = 0.02;

/// A closed interval of a row's column parameter `k` (pixel centres at integer `k`); empty
/// when its start exceeds its end.
pub(super) type Span = (f64, f64);

/// Every column.
pub(super) const ALL: Span = (f64::NEG_INFINITY, f64::INFINITY);

/// No column.
pub(super) const EMPTY: Span = (f64::INFINITY, f64::NEG_INFINITY);

/// The columns `k` where `a + b·k` lies in `[lo, hi]`.
pub(super) fn slab(a: f64, b: f64, lo: f64, hi: f64) -> Span {
    if b == 0.0 {
        return if (lo..=hi).contains(&a) { ALL } else { EMPTY };
    }
    let (k1, k2) = ((lo - a) / b, (hi - a) / b);
    (k1.min(k2), k1.max(k2))
}

/// The columns `k` where `a + b·k ≥ 0`.
pub(super) fn half_line(a: f64, b: f64) -> Span {
    if b == 0.0 {
        return if a >= 0.0 { ALL } else { EMPTY };
    }
    let k = -a / b;
    if b > 0.0 {
        (k, f64::INFINITY)
    } else {
        (f64::NEG_INFINITY, k)
    }
}

/// The columns of a row of rays `start + k·step` (horizontal parts) that point into the
/// wedge between the directions `right` and `left` ([`Shape::wedge`]): counter-clockwise of
/// the right edge and clockwise of the left one, which for a wedge of less than π is the wedge
/// alone (not its opposite too).
pub(super) fn within((right, left): ([f64; 2], [f64; 2]), start: [f64; 2], step: [f64; 2]) -> Span {
    let cross = |a: [f64; 2], v: [f64; 2]| a[0] * v[1] - a[1] * v[0];
    meet(
        half_line(cross(right, start), cross(right, step)),
        half_line(-cross(left, start), -cross(left, step)),
    )
}

/// Both spans.
pub(super) fn meet(a: Span, b: Span) -> Span {
    (a.0.max(b.0), a.1.min(b.1))
}

/// The columns `k` where `|p + k·d|² ≤ r2`.
pub(super) fn disc(p: [f64; 2], d: [f64; 2], r2: f64) -> Span {
    let a = d[0] * d[0] + d[1] * d[1];
    let b = p[0] * d[0] + p[1] * d[1];
    let c = p[0] * p[0] + p[1] * p[1] - r2;
    if a == 0.0 {
        return if c <= 0.0 { ALL } else { EMPTY };
    }
    let e = b * b - a * c;
    if e < 0.0 {
        return EMPTY;
    }
    let e = e.sqrt();
    ((-b - e) / a, (-b + e) / a)
}

/// The pixels of a row of `n` whose centres lie in `span`.
pub(super) fn pixels(span: Span, n: usize) -> Range<usize> {
    // Empty for NaN too.
    if span.0.partial_cmp(&span.1).is_none_or(|o| o == std::cmp::Ordering::Greater) {
        return 0..0;
    }
    // Clamped first (infinite ends are common), then rounded by conversion: no libm call on a
    // path taken per row, and no integer overflow.
    let limit = |v: f64| v.clamp(-1.0, n as f64 + 1.0);
    let (lo, hi) = (limit(span.0), limit(span.1));
    let ceil = |v: f64| {
        let i = v as i64;
        i + i64::from((i as f64) < v)
    };
    let floor = |v: f64| {
        let i = v as i64;
        i - i64::from((i as f64) > v)
    };
    let (lo, hi) = (ceil(lo).max(0), (floor(hi) + 1).min(n as i64));
    if lo < hi {
        lo as usize..hi as usize
    } else {
        0..0
    }
}

/// Sets the pixels `cols` of a row of RGB bytes to `colour`.
pub(super) fn fill(row: &mut [u8], cols: Range<usize>, colour: [u8; 3]) {
    let Some(part) = row.get_mut(3 * cols.start..3 * cols.end) else { return };
    // Sixteen pixels at a time: whole-word stores instead of a byte at a time.
    let mut pattern = [0u8; 48];
    for px in pattern.chunks_exact_mut(3) {
        px.copy_from_slice(&colour);
    }
    let mut chunks = part.chunks_exact_mut(48);
    for chunk in &mut chunks {
        chunk.copy_from_slice(&pattern);
    }
    let rest = chunks.into_remainder();
    rest.copy_from_slice(&pattern[..rest.len()]);
}

/// A painted field line: a segment widened to the line width, with square ends (where two
/// lines meet, the corner is filled), field frame.
#[derive(Clone, Copy, Debug)]
pub(super) struct Strip {
    pub(super) mid: [f64; 2],
    /// Unit vector along the segment.
    pub(super) along: [f64; 2],
    pub(super) half_length: f64,
    pub(super) half_width: f64,
    /// Its bounding box (min, max corners).
    pub(super) bounds: ([f64; 2], [f64; 2]),
}

/// What is painted on the floor (module doc): the field lines and the centre circle, with
/// the walls around them; one geometry for a row of pixels at a time and for single points.
#[derive(Clone, Debug)]
pub(super) struct FloorPaint {
    pub(super) strips: Vec<Strip>,
    /// The centre circle's ring, squared inner and outer radii.
    pub(super) ring: Option<(f64, f64)>,
    /// The walls: |x| ≤ wall.0, |y| ≤ wall.1.
    pub(super) wall: (f64, f64),
}

impl FloorPaint {
    pub(super) fn new(map: &FieldMap, wall: (f64, f64), line_width: f64) -> FloorPaint {
        let half_width = line_width / 2.0;
        let strips = map
            .lines()
            .into_iter()
            .filter_map(|seg| {
                let ab = seg.b - seg.a;
                let len = ab.norm();
                (len > 0.0).then(|| {
                    let mid = [(seg.a.x + seg.b.x) / 2.0, (seg.a.y + seg.b.y) / 2.0];
                    let (along, half_length) = ([ab.x / len, ab.y / len], len / 2.0 + half_width);
                    // Half the box: each half-extent projected on the axes.
                    let ex = along[0].abs() * half_length + along[1].abs() * half_width;
                    let ey = along[1].abs() * half_length + along[0].abs() * half_width;
                    let bounds = ([mid[0] - ex, mid[1] - ey], [mid[0] + ex, mid[1] + ey]);
                    Strip { mid, along, half_length, half_width, bounds }
                })
            })
            .collect();
        let r = map.centre_circle_radius;
        let ring = (r > 0.0).then(|| {
            let inner = (r - half_width).max(0.0);
            (inner * inner, (r + half_width) * (r + half_width))
        });
        FloorPaint { strips, ring, wall }
    }

    /// The columns of the floor line `p + k·d` (field frame) within the walls.
    pub(super) fn within_walls(&self, p: [f64; 2], d: [f64; 2]) -> Span {
        meet(
            slab(p[0], d[0], -self.wall.0, self.wall.0),
            slab(p[1], d[1], -self.wall.1, self.wall.1),
        )
    }

    /// Calls `paint` with the columns `k` in `0..n` of the floor line `p + k·d` (field frame)
    /// that fall on a painted line (spans may overlap, and reach beyond `0..n`). A strip whose
    /// bounding box the line's stretch misses costs four comparisons.
    pub(super) fn lines(&self, p: [f64; 2], d: [f64; 2], n: usize, mut paint: impl FnMut(Span)) {
        let end = [p[0] + n as f64 * d[0], p[1] + n as f64 * d[1]];
        let (lo, hi) = ([p[0].min(end[0]), p[1].min(end[1])], [p[0].max(end[0]), p[1].max(end[1])]);
        let misses = |(bmin, bmax): ([f64; 2], [f64; 2])| {
            hi[0] < bmin[0] || lo[0] > bmax[0] || hi[1] < bmin[1] || lo[1] > bmax[1]
        };
        for s in &self.strips {
            if misses(s.bounds) {
                continue;
            }
            let (qx, qy) = (p[0] - s.mid[0], p[1] - s.mid[1]);
            let (ux, uy) = (s.along[0], s.along[1]);
            let along =
                slab(qx * ux + qy * uy, d[0] * ux + d[1] * uy, -s.half_length, s.half_length);
            let across =
                slab(ux * qy - uy * qx, ux * d[1] - uy * d[0], -s.half_width, s.half_width);
            paint(meet(along, across));
        }
        if let Some((inner, outer)) = self.ring {
            let r = outer.sqrt();
            if misses(([-r, -r], [r, r])) {
                return;
            }
            let out = disc(p, d, outer);
            let hole = disc(p, d, inner);
            if hole.0 > hole.1 {
                paint(out);
            } else {
                paint((out.0, out.1.min(hole.0)));
                paint((out.0.max(hole.1), out.1));
            }
        }
    }

    /// Whether the floor point `p` (field frame) shows a line.
    pub(super) fn is_line(&self, p: [f64; 2]) -> bool {
        let mut line = false;
        self.lines(p, [0.0, 0.0], 1, |s| line |= !pixels(s, 1).is_empty());
        line
    }

    /// For a row of rays `r + k·dr` from the optical centre `eye` (field frame; the rays'
    /// height component `rz` is the same along a row of an ideal lens): the columns whose
    /// rays, where they leave the walls, meet a wall below its top of `height` (`true`) or
    /// pass over it into the hall (`false`) are the span returned and the rest, in the order
    /// `(span, colour of the span is the wall)`.
    pub(super) fn walls(
        &self,
        eye: [f64; 3],
        r: [f64; 2],
        dr: [f64; 2],
        rz: f64,
        height: f64,
    ) -> (Span, bool) {
        if rz == 0.0 {
            return (ALL, eye[2] <= height);
        }
        // Where the ray is at the wall's top height; it sees the wall when it leaves the
        // walls above that point (rising ray) or below it (falling ray).
        let t = (height - eye[2]) / rz;
        if t <= 0.0 {
            // A rising ray that starts above the walls, or a falling one that starts below.
            return (ALL, rz < 0.0);
        }
        let inside =
            self.within_walls([eye[0] + t * r[0], eye[1] + t * r[1]], [t * dr[0], t * dr[1]]);
        (inside, rz < 0.0)
    }
}

/// The floor's lines as a bitmap (a distorting lens's floor pass): one bit a 2 cm texel, row
/// major from the south-west corner between the walls (90 KB for the default field, which
/// stays in the cache).
#[derive(Clone, Debug)]
pub(super) struct Texture {
    pub(super) bits: Vec<u64>,
    pub(super) size: (usize, usize),
}

impl Texture {
    pub(super) fn new(paint: &FloorPaint) -> Texture {
        let wall = paint.wall;
        let size = ((2.0 * wall.0 / TEXEL).ceil() as usize, (2.0 * wall.1 / TEXEL).ceil() as usize);
        let mut bits = vec![0u64; (size.0 * size.1).div_ceil(64)];
        for j in 0..size.1 {
            for i in 0..size.0 {
                let centre =
                    [-wall.0 + (i as f64 + 0.5) * TEXEL, -wall.1 + (j as f64 + 0.5) * TEXEL];
                if paint.is_line(centre) {
                    let k = j * size.0 + i;
                    bits[k >> 6] |= 1 << (k & 63);
                }
            }
        }
        Texture { bits, size }
    }

    /// Whether the floor point `p` (field frame) shows a line; `None` beyond the walls (and
    /// for NaN: no floor).
    #[inline]
    pub(super) fn texel(&self, p: [f64; 2], wall: (f64, f64)) -> Option<bool> {
        let (tx, ty) = ((p[0] + wall.0) / TEXEL, (p[1] + wall.1) / TEXEL);
        if !(tx >= 0.0 && ty >= 0.0) {
            return None;
        }
        let (i, j) = (tx as usize, ty as usize);
        if i >= self.size.0 || j >= self.size.1 {
            return None;
        }
        let k = j * self.size.0 + i;
        Some(self.bits.get(k >> 6).is_some_and(|word| word >> (k & 63) & 1 != 0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_span_covers_the_pixels_whose_centres_it_holds() {
        assert_eq!(pixels((0.5, 2.5), 5), 1..3);
        assert_eq!(pixels((0.0, 2.0), 5), 0..3, "closed at both ends");
        assert_eq!(pixels(ALL, 5), 0..5);
        assert_eq!(pixels((-3.5, 1e300), 5), 0..5);
        assert!(pixels((4.5, 9.0), 5).is_empty(), "beyond the row");
        assert!(pixels((5.5, 7.0), 5).is_empty());
        for empty in [EMPTY, (f64::INFINITY, f64::INFINITY), (f64::NEG_INFINITY, -1.0), (3.2, 3.8)]
        {
            assert!(pixels(empty, 5).is_empty(), "{empty:?}");
        }
        assert!(pixels((f64::NAN, 3.0), 5).is_empty());
        assert!(pixels((0.0, f64::NAN), 5).is_empty());
    }

    #[test]
    fn the_floor_paint_of_a_point_is_the_paint_of_a_row_through_it() {
        let map = FieldMap::default();
        let paint = FloorPaint::new(&map, (9.5, 6.5), 0.1);
        // On the ring, in its hole, on a side line, on the carpet.
        assert!(paint.is_line([2.0, 0.0]));
        assert!(!paint.is_line([0.5, 0.5]));
        assert!(paint.is_line([3.0, 6.0 + 0.04]));
        assert!(!paint.is_line([3.0, 5.0]));
        // A row along y = 0 from x = -5.005 in 1 cm steps (no pixel centre on an edge): the
        // ring's two crossings and the half-way line, each 10 pixels as wide as the line.
        let mut spans = vec![];
        paint.lines([-5.005, 0.0], [0.01, 0.0], 1000, |s| {
            let p = pixels(s, 1000);
            if !p.is_empty() {
                spans.push(p);
            }
        });
        spans.sort_by_key(|p| p.start);
        assert_eq!(spans, vec![296..306, 496..506, 696..706], "{spans:?}");
    }
}
