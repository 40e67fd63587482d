//! Shape files and association files (MRT manual §10.4.1 and §10.4.6): `shape_ctof.txt` and
//! `s_shape.txt` define shapes (named lists of labelled fuzzy sets); `ctof.txt` and
//! `s_ftoc.txt` associate a crisp datum or an action with a shape.
//!
//! ```text
//! (Distance
//!  (TRA (NEAREST 0 0.1 40 60))
//!  (TRA (NEAR 40 60 100 120))
//!  (TOR (FAR 100 120))
//! )
//! (TargetDistance Distance)
//! ```

use crate::error::BrianError;
use crate::lexer::{tokenize, Cursor, Span, Tok};
use crate::set::{FuzzySet, FuzzyValue};
use std::collections::{HashMap, HashSet};
use std::path::Path;

/// A shape: a named list of labelled fuzzy sets.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    /// Its name.
    pub name: String,
    /// Its fuzzy sets, in file order.
    pub sets: Vec<(String, FuzzySet)>,
    /// Where it is defined.
    pub span: Span,
}

impl Shape {
    /// Fuzzifies a crisp datum (§10.3.1): one fuzzy value per set, each with the datum's
    /// reliability. Values with membership 0 and reliability 1 are dropped by the caller
    /// ([`FuzzyValue::is_dropped`]).
    pub fn fuzzify(
        &self,
        crisp: f64,
        reliability: f64,
    ) -> impl Iterator<Item = (&str, FuzzyValue)> + '_ {
        self.sets.iter().map(move |(label, set)| {
            (label.as_str(), FuzzyValue::new(set.membership(crisp), reliability))
        })
    }

    /// The set with this label.
    pub fn set(&self, label: &str) -> Option<&FuzzySet> {
        self.sets.iter().find(|(l, _)| l == label).map(|(_, s)| s)
    }
}

/// An association line `(<data_or_action_name> <shape_name>)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Association {
    /// The crisp datum (or action) name.
    pub name: String,
    /// The shape's name.
    pub shape: String,
    /// Where it is written.
    pub span: Span,
}

/// Parses a shape file.
pub fn parse_shapes(text: &str, file: &Path) -> Result<Vec<Shape>, BrianError> {
    let toks = tokenize(text, file)?;
    let mut c = Cursor::new(&toks, file, text);
    let mut shapes: Vec<Shape> = Vec::new();
    // Hash tables for the duplicate checks: linear time however many shapes and labels.
    let mut defined: HashMap<String, Span> = HashMap::new();
    while !c.at_end() {
        c.punct(Tok::Open, "`(` to start a shape")?;
        let (name, span) = c.word("a shape name")?;
        if let Some(prev) = defined.get(&name) {
            return Err(BrianError::at(
                file,
                span,
                format!("shape `{name}` is already defined at line {}", prev.line),
            ));
        }
        defined.insert(name.clone(), span);
        let mut sets: Vec<(String, FuzzySet)> = Vec::new();
        let mut labels: HashSet<String> = HashSet::new();
        while c.peek() == Some(&Tok::Open) {
            c.punct(Tok::Open, "`(`")?;
            let id_span = c.span();
            let (id, _) = c.word("a fuzzy set identifier (TRI, TOL, TOR, DIV, TRA, REC or SNG)")?;
            let Some(arity) = FuzzySet::arity(&id) else {
                return Err(BrianError::at(
                    file,
                    id_span,
                    format!("expected a fuzzy set identifier (TRI, TOL, TOR, DIV, TRA, REC or SNG), found `{id}`"),
                ));
            };
            c.punct(Tok::Open, "`(` before the fuzzy set's label")?;
            let (label, label_span) = c.word("a fuzzy set label")?;
            let mut params = Vec::with_capacity(arity);
            for k in 0..arity {
                params.push(c.number(&format!(
                    "value {} of {} of {id} `{label}` ({id} takes {arity})",
                    k + 1,
                    arity
                ))?);
            }
            c.punct(Tok::Close, &format!("`)` after the {arity} values of {id} `{label}`"))?;
            c.punct(Tok::Close, "`)` to close the fuzzy set")?;
            let set = FuzzySet::from_parts(&id, &params).ok_or_else(|| {
                BrianError::at(file, id_span, format!("{id} takes {arity} values"))
            })?;
            if !set.is_ordered() {
                return Err(BrianError::at(
                    file,
                    label_span,
                    format!("the values of {id} `{label}` must not decrease: {params:?}"),
                ));
            }
            // Each side's width (b − a, ...) must be a number: a difference that overflows
            // to ∞ would make memberships NaN.
            if params.windows(2).any(|w| !(w[1] - w[0]).is_finite()) {
                return Err(BrianError::at(
                    file,
                    label_span,
                    format!("the values of {id} `{label}` are too far apart: {params:?}"),
                ));
            }
            if !labels.insert(label.clone()) {
                return Err(BrianError::at(
                    file,
                    label_span,
                    format!("label `{label}` appears twice in shape `{name}`"),
                ));
            }
            sets.push((label, set));
        }
        c.punct(Tok::Close, &format!("`(` for another fuzzy set or `)` to close shape `{name}`"))?;
        shapes.push(Shape { name, sets, span });
    }
    Ok(shapes)
}

/// Parses an association file.
pub fn parse_associations(text: &str, file: &Path) -> Result<Vec<Association>, BrianError> {
    let toks = tokenize(text, file)?;
    let mut c = Cursor::new(&toks, file, text);
    let mut out: Vec<Association> = Vec::new();
    let mut defined: HashMap<String, Span> = HashMap::new();
    while !c.at_end() {
        c.punct(Tok::Open, "`(` to start an association")?;
        let (name, span) = c.word("a datum or action name")?;
        let (shape, _) = c.word(&format!("the name of the shape for `{name}`"))?;
        c.punct(Tok::Close, "`)` to close the association")?;
        if let Some(prev) = defined.get(&name) {
            return Err(BrianError::at(
                file,
                span,
                format!("`{name}` is already associated at line {}", prev.line),
            ));
        }
        defined.insert(name.clone(), span);
        out.push(Association { name, shape, span });
    }
    Ok(out)
}

/// Resolves associations against shapes: the index of each association's shape.
pub fn resolve(
    assocs: &[Association],
    shapes: &[Shape],
    file: &Path,
) -> Result<Vec<usize>, BrianError> {
    let by_name: HashMap<&str, usize> =
        shapes.iter().enumerate().map(|(i, s)| (s.name.as_str(), i)).collect();
    assocs
        .iter()
        .map(|a| {
            by_name.get(a.shape.as_str()).copied().ok_or_else(|| {
                let known: Vec<&str> = shapes.iter().map(|s| s.name.as_str()).collect();
                BrianError::at(
                    file,
                    a.span,
                    format!(
                        "unknown shape `{}` for `{}` (known shapes: {})",
                        a.shape,
                        a.name,
                        known.join(", ")
                    ),
                )
            })
        })
        .collect()
}

/// Singleton defuzzification (formula 10.6): `Σ(w·v) / Σw` over the labels of one action, where
/// `v` is the label's singleton. `None` when every weight is 0 (the action is absent).
///
/// With `circular`, values are angles in degrees averaged on the circle (for actions whose name
/// contains `Angle`), giving `[0, 360)`.
pub fn defuzzify(weighted: impl IntoIterator<Item = (f64, f64)>, circular: bool) -> Option<f64> {
    let (mut sw, mut swv, mut sx, mut sy) = (0.0, 0.0, 0.0, 0.0);
    for (value, weight) in weighted {
        if weight.is_nan() || weight <= 0.0 || !value.is_finite() {
            continue;
        }
        sw += weight;
        if circular {
            let r = value.to_radians();
            sx += weight * r.cos();
            sy += weight * r.sin();
        } else {
            swv += weight * value;
        }
    }
    if sw <= 0.0 {
        return None;
    }
    if circular {
        // Opposite proposals of equal weight cancel out and the mean direction is undefined:
        // the output is 0° then, still a number in [0, 360). The sums are tested against a
        // tolerance: cos 90° is not exactly 0 in floating point, and the rounding left over
        // from 90° against 270° would otherwise point anywhere (180° for that pair).
        if sx.hypot(sy) <= 1e-9 * sw {
            return Some(0.0);
        }
        let deg = sy.atan2(sx).to_degrees();
        let deg = if deg < 0.0 { deg + 360.0 } else { deg };
        Some(if deg >= 360.0 { 0.0 } else { deg })
    } else {
        Some(swv / sw)
    }
}

/// One piece of a polygon set: up to four vertices `(x, membership)`, left to right.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Piece {
    vertices: [(f64, f64); 4],
    len: usize,
}

impl Piece {
    fn new(v: &[(f64, f64)]) -> Piece {
        let mut vertices = [(0.0, 0.0); 4];
        let len = v.len().min(4);
        vertices[..len].copy_from_slice(&v[..len]);
        Piece { vertices, len }
    }

    /// `(area, moment)` of the piece's membership clipped at `mu` (min(membership, mu)):
    /// `∫ min(m(x), mu) dx` and `∫ x · min(m(x), mu) dx`.
    fn clipped(&self, mu: f64) -> (f64, f64) {
        let (mut area, mut moment) = (0.0, 0.0);
        for w in self.vertices[..self.len].windows(2) {
            let ((x0, y0), (x1, y1)) = (w[0], w[1]);
            if x1 <= x0 {
                continue; // a vertical side has no area
            }
            // Split the side where it crosses the height `mu`.
            let crosses = (y0 < mu && mu < y1) || (y1 < mu && mu < y0);
            let parts: [(f64, f64, f64, f64); 2] = if crosses {
                let xm = x0 + (mu - y0) / (y1 - y0) * (x1 - x0);
                [(x0, y0.min(mu), xm, mu), (xm, mu, x1, y1.min(mu))]
            } else {
                [(x0, y0.min(mu), x1, y1.min(mu)), (x1, 0.0, x1, 0.0)]
            };
            for (u0, h0, u1, h1) in parts {
                // A trapezium of heights h0, h1 on [u0, u1].
                let dx = u1 - u0;
                area += (h0 + h1) / 2.0 * dx;
                moment += dx * (h0 * (2.0 * u0 + u1) + h1 * (u0 + 2.0 * u1)) / 6.0;
            }
        }
        (area, moment)
    }
}

/// The pieces of a polygon set (see [`is_polygon`]); the second is for DIV only.
fn pieces(set: &FuzzySet) -> Option<(Piece, Option<Piece>)> {
    Some(match *set {
        FuzzySet::Tri { a, b, c } => (Piece::new(&[(a, 0.0), (b, 1.0), (c, 0.0)]), None),
        FuzzySet::Tra { a, b, c, d } => {
            (Piece::new(&[(a, 0.0), (b, 1.0), (c, 1.0), (d, 0.0)]), None)
        }
        // The vertical sides have no area: the top is the whole piece.
        FuzzySet::Rec { b, c } => (Piece::new(&[(b, 1.0), (c, 1.0)]), None),
        FuzzySet::Div { a, b, c, d } => {
            (Piece::new(&[(a, 1.0), (b, 0.0)]), Some(Piece::new(&[(c, 0.0), (d, 1.0)])))
        }
        FuzzySet::Tol { .. } | FuzzySet::Tor { .. } | FuzzySet::Sng { .. } => return None,
    })
}

/// Whether barycenter defuzzification can use the set (§10.3.9): a triangle (TRI), a divided
/// triangle (DIV), a trapezium (TRA) or a rectangle (REC). SNG has no area; TOL and TOR are
/// open on one side, so their area is infinite.
pub fn is_polygon(set: &FuzzySet) -> bool {
    pieces(set).is_some()
}

/// The areas under a polygon set clipped at `mu` ("the intersections between the membership
/// values of the actions and the fuzzy sets", §10.3.9, figure 10.8), one per piece, each as
/// `(centroid, area)`: two pieces for DIV, one for the others. Pieces of no area are left out,
/// and so is everything of a set that is not a polygon.
pub fn clipped_areas(set: &FuzzySet, mu: f64) -> impl Iterator<Item = (f64, f64)> {
    let mu = if mu.is_nan() { 0.0 } else { mu.clamp(0.0, 1.0) };
    let (first, second) = match pieces(set) {
        Some((p, q)) => (Some(p), q),
        None => (None, None),
    };
    first.into_iter().chain(second).filter_map(move |p| {
        let (area, moment) = p.clipped(mu);
        (area > 0.0).then(|| (moment / area, area))
    })
}

/// Barycenter defuzzification (formula 10.7, corrected): each label's polygon set clipped at
/// the label's weight (its composed action value), and the crisp value is the barycenter of
/// the clipped areas, `Σ(Aₖ · x̄ₖ) / Σ Aₖ`, where `Aₖ` is the clipped area of label `k` and
/// `x̄ₖ` its centroid. `None` when no weight is above 0 (the action is absent).
///
/// The manual prints formula 10.7 as `Σ Areas / Σ weight`: an area divided by a membership
/// degree, which is a width, not a position. A triangle TRI (100 110 120) with weight 1 would
/// give 10 (its area) instead of 110 (its barycenter), and the result would move when the set
/// moves nowhere else. The barycenter of figure 10.8 weighs each area's centroid by the area:
/// that is the formula here, and it is formula 10.6 applied to the clipped areas (weight = area,
/// value = centroid), as the manual says the two methods are "very similar".
///
/// With `circular` (actions whose name contains `Angle`), each piece's centroid is an angle in
/// degrees averaged on the circle with its area as weight, as [`defuzzify`] does for
/// singletons: DIV (0 30 330 360), the divided triangle around 0°, gives 0°, not 180°.
pub fn barycenter<'a>(
    weighted: impl IntoIterator<Item = (&'a FuzzySet, f64)>,
    circular: bool,
) -> Option<f64> {
    defuzzify(
        weighted.into_iter().filter(|(_, w)| *w > 0.0).flat_map(|(set, w)| clipped_areas(set, w)),
        circular,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const DISTANCE: &str = "(Distance\n (TRA (NEAREST 0 0.1 40 60))\n (TRA (NEAR 40 60 100 120))\n (TOR (FAR 100 120))\n )\n";

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    /// MRT manual §10.4.1, the Distance shape fed `<TargetDistance, 45, 1>`. The manual prints
    /// NEAREST 0.25 and NEAR 0.75: swapped. The shape decides: NEAREST = TRA(0 0.1 40 60) falls
    /// from 1 at 40 to 0 at 60, so at 45 it is (60 − 45)/20 = 0.75; NEAR = TRA(40 60 100 120)
    /// rises from 0 at 40 to 1 at 60, so (45 − 40)/20 = 0.25.
    #[test]
    fn manual_fuzzification_of_45_with_the_typo_fixed() {
        let shapes = parse_shapes(DISTANCE, Path::new("shape_ctof.txt")).unwrap();
        let got: Vec<(&str, FuzzyValue)> = shapes[0].fuzzify(45.0, 1.0).collect();
        assert_eq!(got[0].0, "NEAREST");
        assert!(close(got[0].1.value, 0.75));
        assert!(close(got[1].1.value, 0.25));
        assert_eq!(got[2], ("FAR", FuzzyValue::new(0.0, 1.0)));
        assert!(got[2].1.is_dropped(), "FAR 0 with reliability 1 is not pushed");
        assert!(!got[0].1.is_dropped() && !got[1].1.is_dropped());
    }

    /// §10.4.1 second example: `<TargetDistance, 80, 0.4>` gives NEAREST 0, NEAR 1, FAR 0, all
    /// with reliability 0.4 and all kept (their reliability is not 1).
    #[test]
    fn manual_fuzzification_of_80_with_reliability_0_4() {
        let shapes = parse_shapes(DISTANCE, Path::new("shape_ctof.txt")).unwrap();
        let got: Vec<(&str, FuzzyValue)> = shapes[0].fuzzify(80.0, 0.4).collect();
        assert_eq!(
            got,
            vec![
                ("NEAREST", FuzzyValue::new(0.0, 0.4)),
                ("NEAR", FuzzyValue::new(1.0, 0.4)),
                ("FAR", FuzzyValue::new(0.0, 0.4))
            ]
        );
        assert!(got.iter().all(|(_, v)| !v.is_dropped()));
    }

    /// §10.4.6: VERY_FAST 0.8, FAST 0.6, SLOW 0.9 on SPEEDMODULE give
    /// (100·0.8 + 75·0.6 + 25·0.9) / (0.8 + 0.6 + 0.9) = 147.5 / 2.3 = 64.1304 cm/s.
    /// The manual cites "Formula 10.7" there, which is the barycenter formula; the singleton
    /// default it computes is formula 10.6.
    #[test]
    fn manual_defuzzification_64_13() {
        let text = "(SPEEDMODULE\n(SNG (STEADY 0))\n(SNG (VERY_SLOW 10))\n(SNG (SLOW 25))\n(SNG (FAST 75))\n(SNG (VERY_FAST 100))\n)\n";
        let shapes = parse_shapes(text, Path::new("s_shape.txt")).unwrap();
        let s = &shapes[0];
        let sng = |l: &str| match s.set(l) {
            Some(FuzzySet::Sng { a }) => *a,
            _ => f64::NAN,
        };
        let out =
            defuzzify([(sng("VERY_FAST"), 0.8), (sng("FAST"), 0.6), (sng("SLOW"), 0.9)], false)
                .unwrap();
        assert!((out - 64.130_434_782_6).abs() < 1e-9, "{out}");
        assert!((out - 147.5 / 2.3).abs() < 1e-12);
        assert_eq!(defuzzify([(25.0, 0.0)], false), None, "all weights 0: absent, not 0");
    }

    /// Barycenter defuzzification (§10.3.9, formula 10.7 corrected), checked by hand.
    ///
    /// SPEED has SLOW = TRA (0 10 30 40) and FAST = TRI (60 80 100); the composer gives SLOW
    /// 0.5 and FAST 1.
    /// - SLOW clipped at 0.5 is a trapezium of height 0.5, bottom [0, 40] and top [5, 35]:
    ///   area 0.5 × (40 + 30) / 2 = 17.5, centroid 20 (it is symmetric about 20).
    /// - FAST at 1 is the whole triangle: area 40 × 1 / 2 = 20, centroid 80.
    /// - Barycenter: (17.5 × 20 + 20 × 80) / (17.5 + 20) = (350 + 1600) / 37.5 = 52.
    ///
    /// The manual's printed formula 10.7, Σ Areas / Σ weight, gives 37.5 / 1.5 = 25, a speed
    /// between nothing the composer asked for; for FAST alone it gives 20 / 1 = 20, not 80:
    /// the typo (the numerator lacks the centroids, the denominator must be the areas).
    #[test]
    fn barycenter_of_clipped_polygons_52() {
        let slow = FuzzySet::Tra { a: 0.0, b: 10.0, c: 30.0, d: 40.0 };
        let fast = FuzzySet::Tri { a: 60.0, b: 80.0, c: 100.0 };
        let s: Vec<(f64, f64)> = clipped_areas(&slow, 0.5).collect();
        assert_eq!(s.len(), 1);
        assert!((s[0].0 - 20.0).abs() < 1e-6 && (s[0].1 - 17.5).abs() < 1e-6, "{s:?}");
        let out = barycenter([(&slow, 0.5), (&fast, 1.0)], false).unwrap();
        assert!((out - 52.0).abs() < 1e-6, "{out}");
        let printed: f64 = (17.5 + 20.0) / (0.5 + 1.0);
        assert!((printed - 25.0).abs() < 1e-9 && (out - printed).abs() > 1.0);
        let fast_alone = barycenter([(&fast, 1.0), (&slow, 0.0)], false).unwrap();
        assert!((fast_alone - 80.0).abs() < 1e-6, "{fast_alone}");
        assert_eq!(barycenter([(&fast, 0.0)], false), None, "all weights 0: absent");
    }

    /// An asymmetric triangle cut by its weight. TRI (0 10 40) clipped at 0.5 rises to 0.5 at
    /// x = 5, stays at 0.5 until the falling side (40 − x) / 30 = 0.5, x = 25, and falls to 0
    /// at 40. By pieces (area, centroid, moment):
    /// - [0, 5], triangle 0 → 0.5: 1.25 at 2/3 × 5 = 10/3, moment 25/6;
    /// - [5, 25], rectangle 0.5: 10 at 15, moment 150;
    /// - [25, 40], triangle 0.5 → 0: 3.75 at 25 + 15/3 = 30, moment 112.5.
    ///
    /// Area 15, moment 25/6 + 262.5 = 1600/6, centroid 1600 / 90 = 160/9 = 17.777…; a
    /// rectangle REC (20 40) at 0.3 has area 6 at 30. Both: (15 × 160/9 + 6 × 30) / 21 =
    /// (800/3 + 180) / 21 = 1340 / 63 = 21.2698…
    #[test]
    fn barycenter_of_an_asymmetric_triangle_and_a_rectangle() {
        let tri = FuzzySet::Tri { a: 0.0, b: 10.0, c: 40.0 };
        let rec = FuzzySet::Rec { b: 20.0, c: 40.0 };
        let t: Vec<(f64, f64)> = clipped_areas(&tri, 0.5).collect();
        assert!((t[0].0 - 160.0 / 9.0).abs() < 1e-6 && (t[0].1 - 15.0).abs() < 1e-6, "{t:?}");
        let r: Vec<(f64, f64)> = clipped_areas(&rec, 0.3).collect();
        assert!((r[0].0 - 30.0).abs() < 1e-6 && (r[0].1 - 6.0).abs() < 1e-6, "{r:?}");
        let out = barycenter([(&tri, 0.5), (&rec, 0.3)], false).unwrap();
        assert!((out - 1340.0 / 63.0).abs() < 1e-6, "{out}");
        // Weights above 1 are clipped at 1: the whole set.
        let whole: Vec<(f64, f64)> = clipped_areas(&tri, 2.0).collect();
        assert!((whole[0].0 - 50.0 / 3.0).abs() < 1e-6 && (whole[0].1 - 20.0).abs() < 1e-6);
    }

    /// The divided triangle DIV (0 30 330 360), "FRONT" around 0°, at weight 1: two pieces, the
    /// triangle on [0, 30] falling from 1 (area 15, centroid 10) and the one on [330, 360]
    /// rising to 1 (area 15, centroid 350). On a straight line their barycenter is 180, the
    /// heading opposite to FRONT; on the circle (an `Angle` action) it is 0. With LEFT = TRI
    /// (60 90 120) at 1 too (area 30, centroid 90): on the circle, unit vectors at 10° and
    /// 350° (15 each) and 90° (30): x = 30 cos 10°, y = 30; atan2(30, 30 cos 10°) = 45.43°.
    #[test]
    fn barycenter_of_a_divided_triangle() {
        let front = FuzzySet::Div { a: 0.0, b: 30.0, c: 330.0, d: 360.0 };
        let p: Vec<(f64, f64)> = clipped_areas(&front, 1.0).collect();
        assert_eq!(p.len(), 2);
        assert!((p[0].0 - 10.0).abs() < 1e-6 && (p[1].0 - 350.0).abs() < 1e-6, "{p:?}");
        assert!((p[0].1 - 15.0).abs() < 1e-6 && (p[1].1 - 15.0).abs() < 1e-6);
        assert!((barycenter([(&front, 1.0)], false).unwrap() - 180.0).abs() < 1e-6);
        assert_eq!(barycenter([(&front, 1.0)], true), Some(0.0));
        let left = FuzzySet::Tri { a: 60.0, b: 90.0, c: 120.0 };
        let out = barycenter([(&front, 1.0), (&left, 1.0)], true).unwrap();
        let expect = 30f64.atan2(30.0 * 10f64.to_radians().cos()).to_degrees();
        assert!((out - expect).abs() < 1e-6 && (out - 45.43).abs() < 0.01, "{out}");
        for set in [FuzzySet::Sng { a: 1.0 }, FuzzySet::Tol { a: 0.0, b: 1.0 }] {
            assert!(!is_polygon(&set) && clipped_areas(&set, 1.0).next().is_none());
        }
    }

    #[test]
    fn angles_average_on_the_circle() {
        let out = defuzzify([(350.0, 1.0), (10.0, 1.0)], true).unwrap();
        assert!(out.abs() < 1e-9 || (out - 360.0).abs() < 1e-9, "{out}");
        let out = defuzzify([(340.0, 1.0), (20.0, 3.0)], true).unwrap();
        // Unit vectors at −20° (w 1) and 20° (w 3): atan2(3 sin20 − sin20, 4 cos20).
        let expect =
            (2.0 * 20f64.to_radians().sin()).atan2(4.0 * 20f64.to_radians().cos()).to_degrees();
        assert!((out - expect).abs() < 1e-9, "{out} vs {expect}");
        let out = defuzzify([(270.0, 1.0)], true).unwrap();
        assert!((out - 270.0).abs() < 1e-9);
        // Exactly opposite and equally weighted: undefined, 0° (not the rounding's 180°).
        assert_eq!(defuzzify([(90.0, 0.49), (270.0, 0.49)], true), Some(0.0));
        assert_eq!(defuzzify([(0.0, 0.3), (180.0, 0.3)], true), Some(0.0));
    }

    #[test]
    fn associations_resolve_or_say_which_shapes_exist() {
        let shapes = parse_shapes(DISTANCE, Path::new("shape_ctof.txt")).unwrap();
        let ok = parse_associations("(TargetDistance Distance) # comment\n", Path::new("ctof.txt"))
            .unwrap();
        assert_eq!(resolve(&ok, &shapes, Path::new("ctof.txt")).unwrap(), vec![0]);
        let bad = parse_associations("\n  (TargetAngle Angle)\n", Path::new("ctof.txt")).unwrap();
        let e = resolve(&bad, &shapes, Path::new("ctof.txt")).unwrap_err().to_string();
        assert_eq!(e, "error in file ctof.txt at line 2: unknown shape `Angle` for `TargetAngle` (known shapes: Distance)\n  --> ctof.txt:2:4");
    }

    #[test]
    fn syntax_errors_name_file_line_and_column() {
        let cases = [
            ("(Distance\n (TRX (A 1 2 3)))", "at line 2: expected a fuzzy set identifier (TRI, TOL, TOR, DIV, TRA, REC or SNG), found `TRX`\n  --> s.txt:2:3"),
            ("(Distance\n (TRI (A 1 2)))", "at line 2: expected value 3 of 3 of TRI `A` (TRI takes 3), found `)`\n  --> s.txt:2:13"),
            ("(Distance\n (TRI (A 1 2 3 4)))", "at line 2: expected `)` after the 3 values of TRI `A`, found the number `4`\n  --> s.txt:2:16"),
            ("(Distance\n (TRI (A 3 2 1)))", "at line 2: the values of TRI `A` must not decrease: [3.0, 2.0, 1.0]\n  --> s.txt:2:8"),
            ("(Distance\n (SNG (A 1))\n (SNG (A 2)))", "at line 3: label `A` appears twice in shape `Distance`\n  --> s.txt:3:8"),
            ("(D (SNG (A 1)))\n(D (SNG (B 1)))", "at line 2: shape `D` is already defined at line 1\n  --> s.txt:2:2"),
            ("(Distance\n (SNG (A 1))", "at line 2: expected `(` for another fuzzy set or `)` to close shape `Distance`, found end of file\n  --> s.txt:2:13"),
            ("Distance", "at line 1: expected `(` to start a shape, found `Distance`\n  --> s.txt:1:1"),
        ];
        for (text, want) in cases {
            let e = parse_shapes(text, Path::new("s.txt")).unwrap_err().to_string();
            assert_eq!(e, format!("error in file s.txt {want}"), "{text:?}");
        }
    }

    #[test]
    fn the_brian40_shapes_parse() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/brian/brian40");
        for (shapes, assoc) in [("shape_ctof.txt", "ctof.txt"), ("s_shape.txt", "s_ftoc.txt")] {
            let sp = dir.join(shapes);
            let ap = dir.join(assoc);
            let s = parse_shapes(&std::fs::read_to_string(&sp).unwrap(), &sp).unwrap();
            let a = parse_associations(&std::fs::read_to_string(&ap).unwrap(), &ap).unwrap();
            resolve(&a, &s, &ap).unwrap();
            assert!(!s.is_empty() && !a.is_empty());
        }
    }

    proptest! {
        #[test]
        fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..256)) {
            let text = String::from_utf8_lossy(&bytes);
            let _ = parse_shapes(&text, Path::new("x"));
            let _ = parse_associations(&text, Path::new("x"));
        }

        /// The barycenter lies within the supports of the sets it weighs, and weights out of
        /// [0, 1] (or NaN) neither panic nor leave that range.
        #[test]
        fn barycenter_stays_within_the_sets(
            params in proptest::collection::vec((-1e3f64..1e3, 0.0f64..50.0, 0.0f64..50.0, 0.0f64..50.0, 0u8..4), 1..6),
            weights in proptest::collection::vec(prop_oneof![-1.0f64..2.0, Just(f64::NAN)], 6),
        ) {
            let sets: Vec<FuzzySet> = params
                .iter()
                .map(|&(a, w1, w2, w3, kind)| match kind {
                    0 => FuzzySet::Tri { a, b: a + w1, c: a + w1 + w2 + 1.0 },
                    1 => FuzzySet::Tra { a, b: a + w1, c: a + w1 + w2, d: a + w1 + w2 + w3 + 1.0 },
                    2 => FuzzySet::Rec { b: a, c: a + w1 + 1.0 },
                    _ => FuzzySet::Div { a, b: a + w1 + 1.0, c: a + w1 + 1.0 + w2, d: a + w1 + w2 + w3 + 2.0 },
                })
                .collect();
            let out = barycenter(sets.iter().zip(weights.iter().copied()), false);
            let used: Vec<&FuzzySet> =
                sets.iter().zip(&weights).filter(|(_, w)| **w > 0.0).map(|(s, _)| s).collect();
            match out {
                None => prop_assert!(used.is_empty()),
                Some(x) => {
                    let lo = used.iter().map(|s| s.params()[0]).fold(f64::INFINITY, f64::min);
                    let hi = used.iter().map(|s| *s.params().last().unwrap_or(&0.0)).fold(f64::NEG_INFINITY, f64::max);
                    prop_assert!(lo - 1e-6 <= x && x <= hi + 1e-6, "{x} not in [{lo}, {hi}]");
                }
            }
        }

        #[test]
        fn token_soup_never_panics(parts in proptest::collection::vec(prop_oneof![
            Just("("), Just(")"), Just("TRI"), Just("SNG"), Just("TRA"), Just("DIV"), Just("A"),
            Just("1"), Just("-2.5"), Just("#c\n"), Just("\n"), Just(" "), Just("="), Just(";")], 0..40)) {
            let text = parts.concat();
            let _ = parse_shapes(&text, Path::new("x"));
            let _ = parse_associations(&text, Path::new("x"));
        }
    }
}
