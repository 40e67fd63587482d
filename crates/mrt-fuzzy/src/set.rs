//! Fuzzy sets (MRT manual §10.4.1, figure 10.4) and the (value, reliability) fuzzy datum.
//!
//! Membership functions follow the manual, with its open points settled as follows:
//! TRA `(a b c d)` is 1 on `[b, c]` (tested first, so `a = b` gives 1 at `a`), linear on
//! `(a, b]` and `[c, d)`, else 0; TRI `(a b c)` is TRA `(a b b c)`; REC `(b c)` is 1 on the
//! closed `[b, c]`; TOL `(a b)` is 1 up to `a`, falling to 0 at `b`; TOR `(a b)` is 0 up to `a`,
//! rising to 1 at `b`; SNG is 1 only at its value; DIV `(a b c d)`, the divided triangle for
//! wrap-around quantities such as angles, falls 1→0 on `[a, b]`, is 0 on `(b, c)`, rises 0→1 on
//! `[c, d]`, and is 0 outside `[a, d]`. A NaN input has membership 0 in every set.

/// A fuzzy set of the manual: the identifier (`TRI`, `TOL`, ...) and its parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FuzzySet {
    /// `TRI (a b c)`: triangle with its peak at `b`.
    Tri {
        /// Left foot.
        a: f64,
        /// Peak.
        b: f64,
        /// Right foot.
        c: f64,
    },
    /// `TOL (a b)`: open left triangle, 1 up to `a`, 0 from `b`.
    Tol {
        /// End of the plateau.
        a: f64,
        /// Foot.
        b: f64,
    },
    /// `TOR (a b)`: open right triangle, 0 up to `a`, 1 from `b`.
    Tor {
        /// Foot.
        a: f64,
        /// Start of the plateau.
        b: f64,
    },
    /// `DIV (a b c d)`: divided triangle for wrap-around quantities (angles).
    Div {
        /// Left end (membership 1).
        a: f64,
        /// End of the falling side.
        b: f64,
        /// Start of the rising side.
        c: f64,
        /// Right end (membership 1).
        d: f64,
    },
    /// `TRA (a b c d)`: trapezium with its plateau on `[b, c]`.
    Tra {
        /// Left foot.
        a: f64,
        /// Plateau start.
        b: f64,
        /// Plateau end.
        c: f64,
        /// Right foot.
        d: f64,
    },
    /// `REC (b c)`: rectangle, 1 on `[b, c]`.
    Rec {
        /// Start.
        b: f64,
        /// End.
        c: f64,
    },
    /// `SNG (a)`: singleton at `a`.
    Sng {
        /// The value.
        a: f64,
    },
}

/// `(x - from) / (to - from)`, or 1 when the side is vertical.
fn ramp(x: f64, from: f64, to: f64) -> f64 {
    let w = to - from;
    if w == 0.0 {
        1.0
    } else {
        ((x - from) / w).clamp(0.0, 1.0)
    }
}

impl FuzzySet {
    /// The same shape stretched by `k` (> 0) about 0: every breakpoint times `k`, so that
    /// `scaled(k).membership(k·x) = membership(x)`. A robot with other speeds keeps a
    /// behavior's labels and their meaning in units of its own.
    pub fn scaled(&self, k: f64) -> FuzzySet {
        match *self {
            FuzzySet::Tri { a, b, c } => FuzzySet::Tri { a: a * k, b: b * k, c: c * k },
            FuzzySet::Tol { a, b } => FuzzySet::Tol { a: a * k, b: b * k },
            FuzzySet::Tor { a, b } => FuzzySet::Tor { a: a * k, b: b * k },
            FuzzySet::Div { a, b, c, d } => {
                FuzzySet::Div { a: a * k, b: b * k, c: c * k, d: d * k }
            }
            FuzzySet::Tra { a, b, c, d } => {
                FuzzySet::Tra { a: a * k, b: b * k, c: c * k, d: d * k }
            }
            FuzzySet::Rec { b, c } => FuzzySet::Rec { b: b * k, c: c * k },
            FuzzySet::Sng { a } => FuzzySet::Sng { a: a * k },
        }
    }

    /// The identifier used in the files (`TRI`, `TOL`, `TOR`, `DIV`, `TRA`, `REC`, `SNG`).
    pub fn identifier(&self) -> &'static str {
        match self {
            FuzzySet::Tri { .. } => "TRI",
            FuzzySet::Tol { .. } => "TOL",
            FuzzySet::Tor { .. } => "TOR",
            FuzzySet::Div { .. } => "DIV",
            FuzzySet::Tra { .. } => "TRA",
            FuzzySet::Rec { .. } => "REC",
            FuzzySet::Sng { .. } => "SNG",
        }
    }

    /// How many parameters the identifier takes, or `None` for an unknown identifier.
    pub fn arity(identifier: &str) -> Option<usize> {
        Some(match identifier {
            "TRI" => 3,
            "TOL" | "TOR" | "REC" => 2,
            "DIV" | "TRA" => 4,
            "SNG" => 1,
            _ => return None,
        })
    }

    /// Builds a set from its identifier and parameters (`None` when they do not match).
    pub fn from_parts(identifier: &str, p: &[f64]) -> Option<FuzzySet> {
        if Some(p.len()) != FuzzySet::arity(identifier) {
            return None;
        }
        Some(match identifier {
            "TRI" => FuzzySet::Tri { a: p[0], b: p[1], c: p[2] },
            "TOL" => FuzzySet::Tol { a: p[0], b: p[1] },
            "TOR" => FuzzySet::Tor { a: p[0], b: p[1] },
            "DIV" => FuzzySet::Div { a: p[0], b: p[1], c: p[2], d: p[3] },
            "TRA" => FuzzySet::Tra { a: p[0], b: p[1], c: p[2], d: p[3] },
            "REC" => FuzzySet::Rec { b: p[0], c: p[1] },
            _ => FuzzySet::Sng { a: p[0] },
        })
    }

    /// The parameters, in file order.
    pub fn params(&self) -> Vec<f64> {
        match *self {
            FuzzySet::Tri { a, b, c } => vec![a, b, c],
            FuzzySet::Tol { a, b } | FuzzySet::Tor { a, b } => vec![a, b],
            FuzzySet::Div { a, b, c, d } | FuzzySet::Tra { a, b, c, d } => vec![a, b, c, d],
            FuzzySet::Rec { b, c } => vec![b, c],
            FuzzySet::Sng { a } => vec![a],
        }
    }

    /// Whether the parameters are in non-decreasing order, as every set needs.
    pub fn is_ordered(&self) -> bool {
        self.params().windows(2).all(|w| w[0] <= w[1])
    }

    /// The membership degree of `x`, in `[0, 1]`.
    pub fn membership(&self, x: f64) -> f64 {
        if x.is_nan() {
            return 0.0;
        }
        match *self {
            FuzzySet::Tri { a, b, c } => trapezium(x, a, b, b, c),
            FuzzySet::Tra { a, b, c, d } => trapezium(x, a, b, c, d),
            FuzzySet::Rec { b, c } => f64::from(u8::from(b <= x && x <= c)),
            FuzzySet::Tol { a, b } => {
                if x <= a {
                    1.0
                } else if x >= b {
                    0.0
                } else {
                    ramp(x, b, a)
                }
            }
            FuzzySet::Tor { a, b } => {
                if x >= b {
                    1.0
                } else if x <= a {
                    0.0
                } else {
                    ramp(x, a, b)
                }
            }
            FuzzySet::Sng { a } => f64::from(u8::from(x == a)),
            FuzzySet::Div { a, b, c, d } => {
                if x < a || x > d {
                    0.0
                } else if x <= b {
                    ramp(x, b, a)
                } else if x >= c {
                    ramp(x, c, d)
                } else {
                    0.0
                }
            }
        }
    }
}

fn trapezium(x: f64, a: f64, b: f64, c: f64, d: f64) -> f64 {
    if b <= x && x <= c {
        1.0
    } else if a < x && x < b {
        ramp(x, a, b)
    } else if c < x && x < d {
        ramp(x, d, c)
    } else {
        0.0
    }
}

/// A fuzzy datum: a membership `value` and the `reliability` of the crisp datum it came from
/// (§10.3.1). Both in `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuzzyValue {
    /// Membership degree.
    pub value: f64,
    /// Reliability.
    pub reliability: f64,
}

impl FuzzyValue {
    /// What anything missing reads as (§10.3.6): value 0, reliability 1.
    pub const MISSING: FuzzyValue = FuzzyValue { value: 0.0, reliability: 1.0 };

    /// A fuzzy value.
    pub const fn new(value: f64, reliability: f64) -> Self {
        Self { value, reliability }
    }

    /// `AND`: (min value, min reliability).
    pub fn and(self, other: FuzzyValue) -> FuzzyValue {
        FuzzyValue::new(self.value.min(other.value), self.reliability.min(other.reliability))
    }

    /// `OR`: (max value, max reliability).
    pub fn or(self, other: FuzzyValue) -> FuzzyValue {
        FuzzyValue::new(self.value.max(other.value), self.reliability.max(other.reliability))
    }

    /// A fuzzy datum with value 0 and reliability 1 carries no information and is dropped
    /// from the fuzzy data list (§10.4.1).
    pub fn is_dropped(&self) -> bool {
        self.value == 0.0 && self.reliability == 1.0
    }
}

impl std::ops::Not for FuzzyValue {
    type Output = FuzzyValue;
    /// `NOT`: (1 − value, same reliability).
    fn not(self) -> FuzzyValue {
        FuzzyValue::new(1.0 - self.value, self.reliability)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    /// Every shape, stretched by k, is the same shape in the stretched units.
    #[test]
    fn a_scaled_set_has_the_same_membership_at_the_scaled_point() {
        let sets = [
            FuzzySet::Tri { a: -1.0, b: 0.5, c: 2.0 },
            FuzzySet::Tol { a: -1.0, b: 1.0 },
            FuzzySet::Tor { a: -1.0, b: 1.0 },
            FuzzySet::Div { a: -3.0, b: -1.0, c: 1.0, d: 3.0 },
            FuzzySet::Tra { a: -2.0, b: -1.0, c: 1.0, d: 2.0 },
            FuzzySet::Rec { b: -1.0, c: 1.0 },
            FuzzySet::Sng { a: 0.5 },
        ];
        for set in sets {
            for k in [0.5, 2.0, 4.0] {
                let big = set.scaled(k);
                assert_eq!(big.identifier(), set.identifier());
                for i in -40..=40 {
                    let x = f64::from(i) * 0.1;
                    assert!(close(big.membership(k * x), set.membership(x)), "{set:?} ×{k} at {x}");
                }
            }
        }
    }

    #[test]
    fn trapezium_by_hand() {
        let s = FuzzySet::Tra { a: 40.0, b: 60.0, c: 100.0, d: 120.0 };
        for (x, m) in [
            (30.0, 0.0),
            (40.0, 0.0),
            (45.0, 0.25),
            (60.0, 1.0),
            (100.0, 1.0),
            (110.0, 0.5),
            (120.0, 0.0),
        ] {
            assert!(close(s.membership(x), m), "TRA at {x}");
        }
        // a = b: the plateau is tested first, so the left end is 1.
        let s = FuzzySet::Tra { a: 0.0, b: 0.0, c: 40.0, d: 60.0 };
        assert_eq!(s.membership(0.0), 1.0);
        assert_eq!(s.membership(-0.1), 0.0);
    }

    #[test]
    fn triangle_is_a_trapezium_with_one_peak() {
        let s = FuzzySet::Tri { a: 15.0, b: 40.0, c: 90.0 };
        for (x, m) in [(15.0, 0.0), (27.5, 0.5), (40.0, 1.0), (65.0, 0.5), (90.0, 0.0)] {
            assert!(close(s.membership(x), m), "TRI at {x}");
        }
    }

    #[test]
    fn open_triangles_rectangle_singleton() {
        let tol = FuzzySet::Tol { a: 15.0, b: 30.0 };
        for (x, m) in [(-100.0, 1.0), (15.0, 1.0), (20.0, 2.0 / 3.0), (30.0, 0.0), (31.0, 0.0)] {
            assert!(close(tol.membership(x), m), "TOL at {x}");
        }
        let tor = FuzzySet::Tor { a: 100.0, b: 120.0 };
        for (x, m) in [(0.0, 0.0), (100.0, 0.0), (110.0, 0.5), (120.0, 1.0), (1e9, 1.0)] {
            assert!(close(tor.membership(x), m), "TOR at {x}");
        }
        let rec = FuzzySet::Rec { b: 1.0, c: 2.0 };
        assert_eq!(
            [rec.membership(0.99), rec.membership(1.0), rec.membership(2.0), rec.membership(2.01)],
            [0.0, 1.0, 1.0, 0.0]
        );
        let sng = FuzzySet::Sng { a: 25.0 };
        assert_eq!([sng.membership(25.0), sng.membership(25.000001)], [1.0, 0.0]);
    }

    #[test]
    fn divided_triangle_wraps_around_angles() {
        let back = FuzzySet::Div { a: -180.0, b: -135.0, c: 135.0, d: 180.0 };
        for (x, m) in [
            (-180.0, 1.0),
            (-157.5, 0.5),
            (-135.0, 0.0),
            (0.0, 0.0),
            (135.0, 0.0),
            (157.5, 0.5),
            (180.0, 1.0),
            (181.0, 0.0),
            (-181.0, 0.0),
        ] {
            assert!(close(back.membership(x), m), "DIV at {x}");
        }
    }

    #[test]
    fn nan_belongs_to_nothing_and_infinities_to_the_open_sides() {
        let sets = [
            FuzzySet::Tri { a: 0.0, b: 1.0, c: 2.0 },
            FuzzySet::Tol { a: 0.0, b: 1.0 },
            FuzzySet::Tor { a: 0.0, b: 1.0 },
            FuzzySet::Div { a: 0.0, b: 1.0, c: 2.0, d: 3.0 },
            FuzzySet::Tra { a: 0.0, b: 1.0, c: 2.0, d: 3.0 },
            FuzzySet::Rec { b: 0.0, c: 1.0 },
            FuzzySet::Sng { a: 0.0 },
        ];
        for s in sets {
            assert_eq!(s.membership(f64::NAN), 0.0, "{}", s.identifier());
            assert_eq!(FuzzySet::from_parts(s.identifier(), &s.params()), Some(s));
        }
        assert_eq!(FuzzySet::Tol { a: 0.0, b: 1.0 }.membership(f64::NEG_INFINITY), 1.0);
        assert_eq!(FuzzySet::Tor { a: 0.0, b: 1.0 }.membership(f64::INFINITY), 1.0);
        assert_eq!(FuzzySet::from_parts("TRI", &[1.0]), None);
        assert_eq!(FuzzySet::from_parts("XYZ", &[1.0]), None);
    }

    #[test]
    fn operators_carry_reliability() {
        // §10.4.2: TargetNearest (1, 0.4) AND TargetNorth (0.9, 1) = (0.9, 0.4).
        let nearest = FuzzyValue::new(1.0, 0.4);
        let north = FuzzyValue::new(0.9, 1.0);
        assert_eq!(nearest.and(north), FuzzyValue::new(0.9, 0.4));
        assert_eq!(nearest.or(north), FuzzyValue::new(1.0, 1.0));
        assert!(close((!north).value, 0.1) && (!north).reliability == 1.0);
        assert!(FuzzyValue::MISSING.is_dropped());
        assert!(!FuzzyValue::new(0.0, 0.4).is_dropped());
    }

    proptest! {
        #[test]
        fn membership_is_always_in_unit_interval(x in proptest::num::f64::ANY, mut p in proptest::collection::vec(-1e6f64..1e6, 4)) {
            p.sort_by(f64::total_cmp);
            for id in ["TRI", "TOL", "TOR", "DIV", "TRA", "REC", "SNG"] {
                let n = FuzzySet::arity(id).unwrap_or(0);
                if let Some(s) = FuzzySet::from_parts(id, &p[..n]) {
                    let m = s.membership(x);
                    prop_assert!((0.0..=1.0).contains(&m), "{} at {}: {}", id, x, m);
                }
            }
        }
    }
}
