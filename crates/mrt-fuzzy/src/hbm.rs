//! The fuzzy core of ThinkingCap's Hierarchical Behavior Module (HBM) and its Context-Dependent
//! Blending (CDB), ThinkingCap/TeamChaos report §4.1.
//!
//! A low-level behavior is a set of rules `if <predicate> then <action> <LABEL>`: each firing
//! rule asserts the label of a control variable (`go`, `turn`, `strafe`, `kick`...) at the
//! predicate's truth value. A complex behavior uses meta-rules `if <predicate> then use
//! <behavior>` that run a sub-behavior at an **activation** level; everything the sub-behavior
//! asserts is clipped at that level (Mamdani's `min`), and assertions of the same label are
//! joined by `max`. Since the union of one label's set clipped at `d1` and at `d2` is the set
//! clipped at `max(d1, d2)`, the whole blended output of one control variable is one degree per
//! label: [`Blender`] keeps exactly that, allocation-free, through any depth of hierarchy.
//! Fusion is per control variable, independently, as the seed says.
//!
//! The crisp output of a variable is then ([`Defuzzification`]):
//! - `Centroid`: standard Mamdani, the centroid of `max_i min(d_i, μ_i(x))` over the variable's
//!   range, computed exactly (the function is piecewise linear; no sampling);
//! - `Singleton`: each label stands for the centre of its core, weighted by its degree
//!   (formula 10.6 of the MRT manual, shared with Mr. BRIAN: [`crate::shapes::defuzzify`]);
//! - `Choice`: a discrete decision such as the kick to apply: the value of the label with the
//!   largest degree, if that degree reaches 0.5.
//!
//! Perceptual rules `if <predicate> then need <OBJECT>` go through [`Blender::need`]: a need is
//! clipped by the asserting behavior's activation and needs combine by `max` over the active
//! behaviors (§4.1).
//!
//! ```
//! use mrt_fuzzy::hbm::{Blender, ControlVariable, Defuzzification};
//! use mrt_fuzzy::FuzzySet;
//!
//! let strafe = ControlVariable::new("strafe", -200.0, 200.0, Defuzzification::Singleton)
//!     .label("LEFT", FuzzySet::Sng { a: 200.0 })
//!     .label("NONE", FuzzySet::Sng { a: 0.0 })
//!     .label("RIGHT", FuzzySet::Sng { a: -200.0 });
//! let mut cdb = Blender::new(vec![strafe], 3);
//! cdb.begin_cycle();
//! cdb.fire(0, 2, 0.75); // if posLeft (0.75) then strafe RIGHT
//! cdb.fire(0, 1, 0.25); // if posAhead (0.25) then strafe NONE
//! assert_eq!(cdb.output(0), Some(-150.0)); // (0.75·-200 + 0.25·0) / 1
//! ```

use crate::set::FuzzySet;
use crate::shapes::defuzzify;

/// How a control variable's blended labels become one crisp value.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Defuzzification {
    /// Mamdani: the centroid of the union of the clipped label sets (ThinkingCap/TeamChaos report §4.1).
    #[default]
    Centroid,
    /// Weighted mean of the labels' core centres.
    Singleton,
    /// The core centre of the strongest label, when its degree is at least 0.5.
    Choice,
}

/// A control variable of the HBM output space (`go`, `turn`, `strafe`, `kick`, ...) with its
/// fuzzy labels.
#[derive(Clone, Debug, PartialEq)]
pub struct ControlVariable {
    /// Its name in the rules.
    pub name: String,
    /// The lower end of its range (the centroid's universe).
    pub min: f64,
    /// The upper end of its range.
    pub max: f64,
    /// The labels, in the order given (the Lua `variable{}` sorts them by name); the first of
    /// equally strong labels wins a `Choice`.
    pub labels: Vec<(String, FuzzySet)>,
    /// How it is defuzzified.
    pub defuzzification: Defuzzification,
}

impl ControlVariable {
    /// A variable with no labels yet.
    pub fn new(name: &str, min: f64, max: f64, defuzzification: Defuzzification) -> Self {
        Self { name: name.to_string(), min, max, labels: Vec::new(), defuzzification }
    }

    /// Adds a label (builder style).
    pub fn label(mut self, name: &str, set: FuzzySet) -> Self {
        self.labels.push((name.to_string(), set));
        self
    }

    /// The index of a label.
    pub fn label_index(&self, name: &str) -> Option<usize> {
        self.labels.iter().position(|(n, _)| n == name)
    }

    /// The crisp value for these label degrees (one per label), or `None` when no label is
    /// asserted (the variable is absent: the caller keeps its default).
    pub fn defuzzify(&self, degrees: &[f64]) -> Option<f64> {
        let sets = self.labels.iter().map(|(_, s)| s);
        match self.defuzzification {
            Defuzzification::Singleton => {
                defuzzify(sets.map(core_centre).zip(degrees.iter().copied()), false)
            }
            Defuzzification::Choice => {
                let (best, d) = degrees
                    .iter()
                    .copied()
                    .enumerate()
                    .fold((0, 0.0), |acc, (i, d)| if d > acc.1 { (i, d) } else { acc });
                (d >= 0.5).then(|| core_centre(&self.labels[best].1))
            }
            Defuzzification::Centroid => {
                let parts: Vec<(FuzzySet, f64)> =
                    sets.copied().zip(degrees.iter().copied()).filter(|(_, d)| *d > 0.0).collect();
                centroid(&parts, self.min, self.max)
            }
        }
    }
}

/// The centre of a set's core (where its membership is 1): the value a label stands for in
/// singleton defuzzification. For `TOL`/`TOR` it is the end of the plateau, for `DIV` its left
/// end.
pub fn core_centre(set: &FuzzySet) -> f64 {
    match *set {
        FuzzySet::Tri { b, .. } => b,
        FuzzySet::Tol { a, .. } => a,
        FuzzySet::Tor { b, .. } => b,
        FuzzySet::Tra { b, c, .. } | FuzzySet::Rec { b, c } => (b + c) / 2.0,
        FuzzySet::Sng { a } => a,
        FuzzySet::Div { a, .. } => a,
    }
}

/// Mamdani centroid of `μ(x) = max_i min(d_i, μ_i(x))` on `[lo, hi]`, exact.
///
/// `μ` is piecewise linear. Its breakpoints are the sets' parameters, the points where a set
/// crosses its clip level, and the points where two clipped sets cross; between them `μ` is
/// linear, and `∫μ` and `∫xμ` are summed in closed form. `None` when the area is 0 (only
/// singletons, or nothing asserted).
pub fn centroid(parts: &[(FuzzySet, f64)], lo: f64, hi: f64) -> Option<f64> {
    if parts.is_empty() || lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
        return None;
    }
    let clipped = |i: usize, x: f64| parts[i].1.min(parts[i].0.membership(x));
    // Values of a piece just inside an interval's ends, extrapolated to the ends: each set is
    // linear on the open interval, even where it jumps at an end (REC, vertical sides).
    let ends = |f: &dyn Fn(f64) -> f64, a: f64, b: f64| {
        let e = (b - a) * 1e-7;
        let (fa, fb) = (f(a + e), f(b - e));
        let slope = (fb - fa) / (b - a - 2.0 * e);
        (fa - slope * e, fb + slope * e)
    };
    let mut xs: Vec<f64> = vec![lo, hi];
    for (set, _) in parts {
        xs.extend(set.params().into_iter().filter(|p| *p > lo && *p < hi));
    }
    let sort = |xs: &mut Vec<f64>| {
        xs.sort_by(f64::total_cmp);
        xs.dedup();
    };
    sort(&mut xs);
    // Pass 1: where a set meets its clip level. Pass 2: where two clipped sets meet.
    for pass in 0..2 {
        let mut extra = Vec::new();
        for w in xs.windows(2) {
            let (a, b) = (w[0], w[1]);
            let mut lines = Vec::with_capacity(parts.len());
            for (i, (set, d)) in parts.iter().enumerate() {
                if pass == 0 {
                    let (ma, mb) = ends(&|x| set.membership(x), a, b);
                    if let Some(x) = crossing(a, b, ma - d, mb - d) {
                        extra.push(x);
                    }
                } else {
                    lines.push(ends(&|x| clipped(i, x), a, b));
                }
            }
            for (i, li) in lines.iter().enumerate() {
                for lj in &lines[i + 1..] {
                    if let Some(x) = crossing(a, b, li.0 - lj.0, li.1 - lj.1) {
                        extra.push(x);
                    }
                }
            }
        }
        xs.extend(extra);
        sort(&mut xs);
    }
    let (mut area, mut moment) = (0.0, 0.0);
    for w in xs.windows(2) {
        let (a, b) = (w[0], w[1]);
        let mu = |x: f64| (0..parts.len()).map(|i| clipped(i, x)).fold(0.0, f64::max);
        let (ya, yb) = ends(&mu, a, b);
        let h = b - a;
        area += h * (ya + yb) / 2.0;
        // ∫ x·μ over a linear piece: h/6 · (ya·(2a + b) + yb·(a + 2b)).
        moment += h / 6.0 * (ya * (2.0 * a + b) + yb * (a + 2.0 * b));
    }
    (area > 1e-12).then(|| moment / area)
}

/// Where a linear function with values `fa` at `a` and `fb` at `b` crosses 0 strictly inside.
fn crossing(a: f64, b: f64, fa: f64, fb: f64) -> Option<f64> {
    if (fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0) {
        let x = a + (b - a) * fa / (fa - fb);
        (x > a && x < b).then_some(x)
    } else {
        None
    }
}

/// Context-Dependent Blending of one HBM cycle: the label degrees of every control variable,
/// the perceptual needs, and the stack of behavior activations (§4.1).
#[derive(Clone, Debug)]
pub struct Blender {
    variables: Vec<ControlVariable>,
    /// `degrees[v][l]`: the degree of label `l` of variable `v` this cycle.
    degrees: Vec<Vec<f64>>,
    needs: Vec<f64>,
    /// Activation of the behaviors being run, outermost first; the current one is the last.
    activations: Vec<f64>,
}

impl Blender {
    /// A blender for these variables and `objects` perceptual objects (needs).
    pub fn new(variables: Vec<ControlVariable>, objects: usize) -> Self {
        let degrees = variables.iter().map(|v| vec![0.0; v.labels.len()]).collect();
        Self { variables, degrees, needs: vec![0.0; objects], activations: Vec::with_capacity(16) }
    }

    /// The variables.
    pub fn variables(&self) -> &[ControlVariable] {
        &self.variables
    }

    /// The index of a variable.
    pub fn variable_index(&self, name: &str) -> Option<usize> {
        self.variables.iter().position(|v| v.name == name)
    }

    /// Starts a cycle: nothing asserted, top-level activation 1.
    pub fn begin_cycle(&mut self) {
        self.degrees.iter_mut().for_each(|d| d.fill(0.0));
        self.needs.fill(0.0);
        self.activations.clear();
    }

    /// The activation of the behavior running now (1 at top level).
    pub fn activation(&self) -> f64 {
        self.activations.last().copied().unwrap_or(1.0)
    }

    /// How deep the running behavior is (0 at top level).
    pub fn depth(&self) -> usize {
        self.activations.len()
    }

    /// Enters a sub-behavior used at degree `degree` (`use`): its activation is
    /// `min(degree, current activation)`. Returns it; a caller may skip the sub-behavior when it
    /// is 0. Pair with [`Blender::leave`].
    pub fn enter(&mut self, degree: f64) -> f64 {
        let a = clamp01(degree).min(self.activation());
        self.activations.push(a);
        a
    }

    /// Leaves the sub-behavior entered last.
    pub fn leave(&mut self) {
        self.activations.pop();
    }

    /// A rule fired: label `label` of variable `variable` at truth `degree`, clipped by the
    /// current activation and joined by max. Out-of-range indices are ignored.
    pub fn fire(&mut self, variable: usize, label: usize, degree: f64) {
        let d = clamp01(degree).min(self.activation());
        if let Some(slot) = self.degrees.get_mut(variable).and_then(|v| v.get_mut(label)) {
            *slot = slot.max(d);
        }
    }

    /// A perceptual rule fired: object `object` is needed at `degree`, clipped by the current
    /// activation and joined by max over the active behaviors.
    pub fn need(&mut self, object: usize, degree: f64) {
        let d = clamp01(degree).min(self.activation());
        if let Some(slot) = self.needs.get_mut(object) {
            *slot = slot.max(d);
        }
    }

    /// The label degrees of a variable this cycle.
    pub fn degrees(&self, variable: usize) -> &[f64] {
        self.degrees.get(variable).map_or(&[], Vec::as_slice)
    }

    /// The crisp output of a variable, `None` when no rule asserted it this cycle.
    pub fn output(&self, variable: usize) -> Option<f64> {
        let v = self.variables.get(variable)?;
        v.defuzzify(&self.degrees[variable])
    }

    /// The needs of this cycle, indexed by object.
    pub fn needs(&self) -> &[f64] {
        &self.needs
    }
}

/// A truth value forced into `[0, 1]`; NaN counts as false.
fn clamp01(x: f64) -> f64 {
    if x.is_nan() {
        0.0
    } else {
        x.clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() < tol
    }

    /// Numerical centroid by a fine midpoint rule, the independent check of the exact one.
    fn sampled(parts: &[(FuzzySet, f64)], lo: f64, hi: f64) -> f64 {
        let n = 200_000;
        let h = (hi - lo) / n as f64;
        let (mut a, mut m) = (0.0, 0.0);
        for k in 0..n {
            let x = lo + (k as f64 + 0.5) * h;
            let mu = parts.iter().map(|(s, d)| d.min(s.membership(x))).fold(0.0, f64::max);
            a += mu;
            m += x * mu;
        }
        m / a
    }

    /// By hand: TRI(0 100 200) clipped at 0.5 is the trapezium (0, 50, 150, 200) at height 0.5,
    /// symmetric about 100, so its centroid is 100.
    #[test]
    fn centroid_of_a_symmetric_clipped_triangle() {
        let t = FuzzySet::Tri { a: 0.0, b: 100.0, c: 200.0 };
        assert!(close(centroid(&[(t, 0.5)], -500.0, 500.0).unwrap(), 100.0, 1e-6));
    }

    /// By hand: A = TRI(0 0 100) (right triangle falling from 1 at 0 to 0 at 100) at degree 1
    /// and B = REC(100 200) at degree 0.5. Area A = 50, its centroid is 100/3; area B = 50, its
    /// centroid 150. Total centroid = (50·33.333 + 50·150) / 100 = 91.6667.
    #[test]
    fn centroid_of_two_labels_by_hand() {
        let a = FuzzySet::Tri { a: 0.0, b: 0.0, c: 100.0 };
        let b = FuzzySet::Rec { b: 100.0, c: 200.0 };
        let got = centroid(&[(a, 1.0), (b, 0.5)], 0.0, 300.0).unwrap();
        assert!(close(got, (50.0 * 100.0 / 3.0 + 50.0 * 150.0) / 100.0, 1e-6), "{got}");
    }

    /// Overlapping labels: the max of the two clipped sets, checked against sampling.
    #[test]
    fn centroid_of_overlapping_labels_matches_sampling() {
        let slow = FuzzySet::Tri { a: 0.0, b: 100.0, c: 200.0 };
        let fast = FuzzySet::Tra { a: 100.0, b: 250.0, c: 300.0, d: 300.0 };
        let back = FuzzySet::Tol { a: -200.0, b: 0.0 };
        let parts = [(slow, 0.8), (fast, 0.3), (back, 0.1)];
        let exact = centroid(&parts, -300.0, 300.0).unwrap();
        assert!(close(exact, sampled(&parts, -300.0, 300.0), 1e-3), "{exact}");
    }

    #[test]
    fn singletons_have_no_area_and_nothing_asserted_is_absent() {
        assert_eq!(centroid(&[(FuzzySet::Sng { a: 3.0 }, 1.0)], 0.0, 10.0), None);
        assert_eq!(centroid(&[], 0.0, 10.0), None);
        let v = ControlVariable::new("go", 0.0, 1.0, Defuzzification::Centroid)
            .label("A", FuzzySet::Tri { a: 0.0, b: 0.5, c: 1.0 });
        assert_eq!(v.defuzzify(&[0.0]), None);
    }

    /// The gkcutb strafe example (ThinkingCap/TeamChaos report §4.1) in both modes, by hand: posLeft 0.6 → RIGHT,
    /// posAhead 0.4 → NONE. Labels RIGHT = TRI(-300 -200 -100), NONE = TRI(-100 0 100),
    /// LEFT = TRI(100 200 300). Singleton: (0.6·-200 + 0.4·0) / 1.0 = -120. Centroid: two
    /// disjoint symmetric trapezia; RIGHT clipped at 0.6 has area 200·0.6·(1 − 0.6/2) = 84 at
    /// -200, NONE at 0.4 has area 200·0.4·0.8 = 64 at 0: (84·-200) / 148 = -113.5135.
    #[test]
    fn gkcutb_strafe_in_both_modes() {
        let tri = |b: f64| FuzzySet::Tri { a: b - 100.0, b, c: b + 100.0 };
        let mk = |mode| {
            ControlVariable::new("strafe", -300.0, 300.0, mode)
                .label("LEFT", tri(200.0))
                .label("NONE", tri(0.0))
                .label("RIGHT", tri(-200.0))
        };
        let degrees = [0.0, 0.4, 0.6];
        let s = mk(Defuzzification::Singleton).defuzzify(&degrees).unwrap();
        assert!(close(s, -120.0, 1e-9), "{s}");
        let c = mk(Defuzzification::Centroid).defuzzify(&degrees).unwrap();
        assert!(close(c, -200.0 * 84.0 / 148.0, 1e-6), "{c}");
    }

    #[test]
    fn choice_takes_the_strongest_label_from_half_up() {
        let kick = ControlVariable::new("kick", 0.0, 10.0, Defuzzification::Choice)
            .label("NOKICK", FuzzySet::Sng { a: 0.0 })
            .label("FRONTKICK", FuzzySet::Sng { a: 1.0 })
            .label("HEADKICK", FuzzySet::Sng { a: 2.0 });
        assert_eq!(kick.defuzzify(&[0.2, 0.7, 0.6]), Some(1.0));
        assert_eq!(kick.defuzzify(&[0.0, 0.3, 0.4]), None, "nothing reaches 0.5");
    }

    /// CDB: two sub-behaviors used at 0.3 and 0.7 that each assert one label fully give the
    /// activation-weighted mean in singleton mode; nested activations multiply by min; needs
    /// are clipped by activation and joined by max.
    #[test]
    fn blending_weights_sub_behaviors_by_activation() {
        let turn = ControlVariable::new("turn", -90.0, 90.0, Defuzzification::Singleton)
            .label("LEFT", FuzzySet::Sng { a: 90.0 })
            .label("RIGHT", FuzzySet::Sng { a: -90.0 });
        let mut cdb = Blender::new(vec![turn], 3);
        cdb.begin_cycle();
        assert_eq!(cdb.enter(0.3), 0.3);
        cdb.fire(0, 0, 1.0);
        cdb.need(1, 0.9);
        cdb.leave();
        assert_eq!(cdb.enter(0.7), 0.7);
        cdb.fire(0, 1, 1.0);
        assert_eq!(cdb.enter(0.5), 0.5, "nested: min(0.5, 0.7)");
        assert_eq!(cdb.enter(0.9), 0.5, "deeper: still bounded by 0.5");
        cdb.need(1, 1.0);
        cdb.leave();
        cdb.leave();
        cdb.leave();
        assert_eq!(cdb.depth(), 0);
        let out = cdb.output(0).unwrap();
        assert!(close(out, (0.3 * 90.0 - 0.7 * 90.0) / 1.0, 1e-9), "{out}");
        assert_eq!(cdb.needs(), &[0.0, 0.5, 0.0], "max(min(0.9, 0.3), min(1, 0.5))");
        cdb.begin_cycle();
        assert_eq!((cdb.output(0), cdb.needs()[1]), (None, 0.0));
    }

    #[test]
    fn bad_degrees_and_indices_are_harmless() {
        let mut cdb = Blender::new(vec![], 1);
        cdb.begin_cycle();
        cdb.fire(5, 5, 1.0);
        cdb.need(9, 1.0);
        cdb.need(0, f64::NAN);
        assert_eq!(cdb.needs(), &[0.0]);
        assert_eq!(cdb.output(3), None);
        assert_eq!(cdb.enter(f64::INFINITY), 1.0);
    }
}
