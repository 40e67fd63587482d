//! How the engine composes the proposals of its behaviors (MRT manual §10.2.4, §10.3.8,
//! §10.4.9): the weight composer ([`WeightComposer`]) weighs each proposal by its behavior's
//! weight, the float composer ([`Composer`]) combines those of one (action, label), the
//! composition ([`Composition`]) chooses between formulas 10.3 and 10.5, and [`Semantics`] how
//! reliability counts. The accumulators that a cycle fills ([`Acc`], [`Sums`]) live here too:
//! both the engine (`brian`) and its settings file (`engine`) use this module, which uses
//! neither.

/// How proposals of the same (action, label) are combined (§10.3.8, §10.4.9: the
/// `float_composer`), after each is weighted by its behavior's weight ([`WeightComposer`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Composer {
    /// The maximum (formula 10.3, `max_float_composer`): the default.
    #[default]
    Max,
    /// The mean (`average_float_composer` of §10.4.9).
    Average,
    /// The minimum (`min_float_composer` of §10.4.9).
    Min,
}

/// How one proposal is weighted by its behavior's weight (the WANT value; §10.4.9, the
/// `weight_composer`). A behavior of weight 0, or a rule that does not fire, proposes nothing
/// whichever is chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WeightComposer {
    /// The value times the weight (`mult_weight_composer`): the default.
    #[default]
    Mult,
    /// The larger of the value and the weight (`max_weight_composer`).
    Max,
    /// The smaller of the value and the weight (`min_weight_composer`).
    Min,
}

impl WeightComposer {
    /// Proposal `value` weighted by `weight`.
    pub fn apply(self, value: f64, weight: f64) -> f64 {
        match self {
            WeightComposer::Mult => value * weight,
            WeightComposer::Max => value.max(weight),
            WeightComposer::Min => value.min(weight),
        }
    }
}

/// How the proposals of the running behaviors become the outputs (§10.2.4): "Both the
/// approaches are implemented in Mr. BRIAN and it is possible to select the best one for the
/// application". `engine.txt`: `composition weighted` or `composition argmax`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Composition {
    /// Formula 10.3: every running behavior's proposals, each weighted by its behavior's
    /// weight ([`WeightComposer`]) and combined per label ([`Composer`]): the default, as in
    /// RoboCup.
    #[default]
    Weighted,
    /// Formula 10.5: for each output, only the proposals of the behavior with the largest
    /// μC · μW (CANDO value × weight) among the behaviors that propose a label of it (after
    /// `&DEL`); ties go to the behavior that runs first (lower level, then name). Opposite
    /// wishes are never averaged, at the price of pursuing one goal at a time.
    Argmax,
}

/// Which reading of reliability the engine follows: the manual's (the default) or the
/// original C++ engine's, for configurations tuned on it (`engine.txt`: `semantics manual` or
/// `semantics original`; `mrt brian eval --semantics`).
///
/// | | [`Semantics::Manual`] | [`Semantics::Original`] |
/// |---|---|---|
/// | a behavior runs when | CANDO value above the threshold (§10.3.6) | and CANDO reliability above the threshold |
/// | its weight is its WANT value when | the value is above 0.49 | and the reliability is above 0.49 |
/// | a rule proposes | precondition value × reliability, nothing under reliability 0.1 (§10.3.7) | the precondition value, whatever its reliability |
///
/// The original program filters CANDO and WANT with a filter of membership *and*
/// reliability, and its rules propose the precondition's membership: reliability decides
/// whether a behavior counts, not how much. The manual (§10.3.7) makes it scale each proposal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Semantics {
    /// As the manual describes (§10.3.6, §10.3.7): the default.
    #[default]
    Manual,
    /// As the original C++ engine measured: CANDO and WANT gated on reliability, rules blind
    /// to it.
    Original,
}

/// One (action, label) accumulator: enough for every composer and both compositions: the
/// sums of every proposal, and those of the best behavior proposing here (formula 10.5).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Acc {
    /// Every proposal's sums.
    pub(crate) all: Sums,
    /// The sums of the best behavior's proposals.
    pub(crate) best: Sums,
    /// The best behavior's μC · μW.
    pub(crate) score: f64,
    /// The best behavior (its index in run order).
    pub(crate) by: usize,
}

impl Acc {
    /// Adds proposal `v` of the behavior `by`, whose μC · μW is `score`.
    pub(crate) fn add(&mut self, v: f64, score: f64, by: usize) {
        self.all.add(v);
        if self.best.n == 0 || score > self.score {
            self.best = Sums::default();
            self.score = score;
            self.by = by;
        }
        if self.by == by {
            self.best.add(v);
        }
    }

    /// Adds what a higher level proposed: ties keep the lower level's behavior.
    pub(crate) fn merge(&mut self, o: &Acc) {
        self.all.merge(&o.all);
        if o.best.n > 0 && (self.best.n == 0 || o.score > self.score) {
            self.best = o.best;
            self.score = o.score;
            self.by = o.by;
        }
    }
}

/// Sums of the weighted proposals of one (action, label).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sums {
    max: f64,
    min: f64,
    sum: f64,
    /// How many proposals.
    pub(crate) n: u32,
}

impl Default for Sums {
    fn default() -> Self {
        Sums { max: 0.0, min: f64::INFINITY, sum: 0.0, n: 0 }
    }
}

impl Sums {
    fn add(&mut self, v: f64) {
        self.max = self.max.max(v);
        self.min = self.min.min(v);
        self.sum += v;
        self.n += 1;
    }

    fn merge(&mut self, o: &Sums) {
        self.max = self.max.max(o.max);
        self.min = self.min.min(o.min);
        self.sum += o.sum;
        self.n += o.n;
    }

    /// The proposals combined by `c`; 0 when there are none.
    pub(crate) fn weight(&self, c: Composer) -> f64 {
        match c {
            _ if self.n == 0 => 0.0,
            Composer::Max => self.max,
            Composer::Average => self.sum / f64::from(self.n),
            Composer::Min => self.min,
        }
    }
}

impl Composer {
    /// Combines weighted proposals of one (action, label); 0 when there are none.
    pub fn combine(self, weighted: &[f64]) -> f64 {
        let mut acc = Sums::default();
        weighted.iter().for_each(|v| acc.add(*v));
        acc.weight(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// §10.4.9's other composers on the same proposals: GoToTarget (weight 0.67) FAST 0.56 and
    /// 0.478, SLOW 0.968; AvoidObstacle (weight 1) SLOW 0.354. By hand:
    /// - `max_weight_composer` (max of value and weight) with the average: FAST
    ///   (0.67 + 0.67) / 2 = 0.67; SLOW (0.968 + 1) / 2 = 0.984.
    /// - `min_weight_composer` (min of value and weight) with the average: FAST
    ///   (0.56 + 0.478) / 2 = 0.519; SLOW (0.67 + 0.354) / 2 = 0.512.
    /// - `mult_weight_composer` with `min_float_composer`: FAST min(0.3752, 0.32026) =
    ///   0.32026; SLOW min(0.64856, 0.354) = 0.354.
    #[test]
    fn manual_weight_and_float_composers() {
        let (go, avoid) = (0.67, 1.0);
        let composed = |w: WeightComposer, f: Composer| {
            let fast = f.combine(&[w.apply(0.56, go), w.apply(0.478, go)]);
            let slow = f.combine(&[w.apply(0.968, go), w.apply(0.354, avoid)]);
            (fast, slow)
        };
        let close =
            |(a, b): (f64, f64), (c, d): (f64, f64)| (a - c).abs() < 1e-9 && (b - d).abs() < 1e-9;
        assert!(close(composed(WeightComposer::Max, Composer::Average), (0.67, 0.984)));
        assert!(close(composed(WeightComposer::Min, Composer::Average), (0.519, 0.512)));
        assert!(close(composed(WeightComposer::Mult, Composer::Min), (0.32026, 0.354)));
        assert!(close(composed(WeightComposer::Mult, Composer::Average), (0.34773, 0.50128)));
        assert_eq!(Composer::Min.combine(&[]), 0.0, "no proposal: 0, not infinity");
    }

    /// §10.4.9 with `mult_weight_composer` and `average_float_composer`: GoToTarget (weight
    /// 0.67) proposes FAST 0.56 and 0.478, SLOW 0.968; AvoidObstacle (weight 1) SLOW 0.354.
    /// The manual prints the first FAST proposal as 0.57 but its weighted value as 0.3752,
    /// which is 0.56 × 0.67 (0.57 × 0.67 = 0.3819): the proposal was 0.56. Then
    /// FAST = (0.3752 + 0.32026) / 2 = 0.34773 and SLOW = (0.64856 + 0.354) / 2 = 0.50128.
    #[test]
    fn manual_average_composition_with_the_typo_fixed() {
        let fast = Composer::Average.combine(&[0.56 * 0.67, 0.478 * 0.67]);
        let slow = Composer::Average.combine(&[0.968 * 0.67, 0.354 * 1.0]);
        assert!((fast - 0.34773).abs() < 1e-9, "{fast}");
        assert!((slow - 0.50128).abs() < 1e-9, "{slow}");
        let with_typo = Composer::Average.combine(&[0.57 * 0.67, 0.478 * 0.67]);
        assert!((with_typo - 0.34773).abs() > 1e-3, "0.57 would not give the manual's result");
        // The default composer takes the maximum (formula 10.3).
        assert!((Composer::Max.combine(&[0.968 * 0.67, 0.354]) - 0.64856).abs() < 1e-9);
        assert_eq!(Composer::Max.combine(&[]), 0.0);
    }
}
