//! One cycle of the engine: the inputs set, fuzzified and evaluated level by level, the
//! behaviors the CANDO filter lets run proposing their actions, and the outputs composed and
//! defuzzified ([`Brian::step`], [`Brian::run`]).

use super::{
    Action, Brian, CandoFilter, Commands, Proposals, RuleAction, Semantics, Situation,
    ThresholdFilter, MIN_RELIABILITY, WANT_THRESHOLD,
};
use crate::compose::{Acc, Composer, Composition};
use crate::set::FuzzyValue;
use crate::shapes::{barycenter, defuzzify};
use std::sync::Arc;

impl Brian {
    /// The slot of a crisp input, for [`set_input`](Self::set_input).
    pub fn input_slot(&self, name: &str) -> Option<usize> {
        self.names.inputs.get(name).copied()
    }

    /// Sets an input for the next [`step`](Self::step). Reliability is clamped to `[0, 1]`; a
    /// NaN reliability counts as 0 (the datum is not trusted at all).
    pub fn set_input(&mut self, slot: usize, value: f64, reliability: f64) {
        let reliability = if reliability.is_nan() { 0.0 } else { reliability.clamp(0.0, 1.0) };
        if let Some(i) = self.inputs.get_mut(slot) {
            i.now = Some((value, reliability));
        }
    }

    /// Forgets every input set since the last step (missing inputs read as value 0,
    /// reliability 1, or as the previous cycle's output of the same name).
    pub fn clear_inputs(&mut self) {
        self.inputs.iter_mut().for_each(|i| i.now = None);
    }

    /// The output action names, in `s_ftoc.txt` order (the order of [`output`](Self::output)).
    pub fn output_names(&self) -> impl Iterator<Item = &str> {
        self.actions.iter().map(|a| a.name.as_str())
    }

    /// Output `i` of the last step; `None` when every weight of that action was 0.
    pub fn output(&self, i: usize) -> Option<f64> {
        self.outputs.get(i).copied().flatten()
    }

    /// Runs one cycle on the inputs set with [`set_input`](Self::set_input), then clears them.
    /// Allocates nothing.
    pub fn step(&mut self) {
        self.cycle();
        self.clear_inputs();
    }

    /// Runs one cycle on `(name, value, reliability)` inputs. Unknown names are ignored; a
    /// missing input reads as value 0, reliability 1 for every label, unless the previous
    /// cycle produced an output of that name (then that value with reliability 1). A NaN value
    /// belongs to no fuzzy set.
    pub fn run(&mut self, inputs: &[(&str, f64, f64)]) -> Commands {
        self.clear_inputs();
        for (name, v, r) in inputs {
            if let Some(slot) = self.input_slot(name) {
                self.set_input(slot, *v, *r);
            }
        }
        self.step();
        // Reuses the shared buffer when no caller still holds the previous cycle's commands.
        Arc::make_mut(&mut self.shared_outputs).copy_from_slice(&self.outputs);
        Commands { names: self.sorted_names.clone(), values: self.shared_outputs.clone() }
    }

    fn fuzzify(&mut self, slot: usize) {
        let input = &self.inputs[slot];
        let crisp = input.now.or(input.previous.map(|v| (v, 1.0)));
        for (k, (_, set)) in input.shape.sets.iter().enumerate() {
            self.data[input.offset + k] = match crisp {
                Some((v, r)) => FuzzyValue::new(set.membership(v), r),
                None => FuzzyValue::MISSING,
            };
        }
    }

    fn cycle(&mut self) {
        self.traced.clear();
        for slot in 0..self.inputs.len() {
            if self.is_proposed[slot] {
                self.inputs[slot].now = None;
                self.inputs[slot].previous = None;
            }
            self.fuzzify(slot);
        }
        for i in 0..self.predicates.len() {
            self.pred_values[i] = self.predicates[i].1.eval(&self.data, &self.pred_values, &[]);
        }
        self.lower.iter_mut().for_each(|v| *v = Acc::default());
        let mut b = 0;
        let mut first = true;
        while b < self.behaviors.len() {
            let level = self.behaviors[b].level;
            if !first {
                self.feed_proposals();
            }
            first = false;
            for i in 0..self.predicate_actions.len() {
                self.act_values[i] = self.predicate_actions[i].1.eval(
                    &self.data,
                    &self.pred_values,
                    &self.act_values,
                );
            }
            self.level_acc.iter_mut().for_each(|v| *v = Acc::default());
            while b < self.behaviors.len() && self.behaviors[b].level == level {
                self.run_behavior(b);
                b += 1;
            }
            for (l, v) in self.lower.iter_mut().zip(&self.level_acc) {
                l.merge(v);
            }
        }
        for (ai, a) in self.actions.iter().enumerate() {
            self.outputs[ai] = self.crisp(a, self.composer, self.composition);
        }
        // The previous cycle's outputs come back as inputs of the same name (§10.5).
        for (input, fb) in self.inputs.iter_mut().zip(&self.feedback) {
            input.previous = fb.and_then(|ai| self.outputs[ai]);
        }
    }

    /// Defuzzifies one action from the accumulated proposals.
    fn crisp(&self, a: &Action, c: Composer, composition: Composition) -> Option<f64> {
        let w = &self.lower[a.offset..a.offset + a.labels.len()];
        // Formula 10.5: the behavior of largest μC · μW among those proposing for this action
        // (ties: the first to run).
        let mut best: Option<(f64, usize)> = None;
        if composition == Composition::Argmax {
            for acc in w.iter().filter(|acc| acc.best.n > 0) {
                if best.is_none_or(|(s, by)| acc.score > s || (acc.score == s && acc.by < by)) {
                    best = Some((acc.score, acc.by));
                }
            }
        }
        let weight = |acc: &Acc| match best {
            None => acc.all.weight(c),
            Some((_, by)) if acc.best.n > 0 && acc.by == by => acc.best.weight(c),
            Some(_) => 0.0,
        };
        if a.barycenter {
            barycenter(a.sets.iter().zip(w).map(|((_, s), w)| (s, weight(w))), a.circular)
        } else {
            defuzzify(a.labels.iter().zip(w).map(|((_, s), w)| (*s, weight(w))), a.circular)
        }
    }

    /// Defuzzifies what the lower levels propose into `Proposed<Action>` data and fuzzifies it.
    fn feed_proposals(&mut self) {
        for ai in 0..self.actions.len() {
            let a = &self.actions[ai];
            let Some(slot) = a.proposed else { continue };
            // What lower levels propose is composed by max per label, whatever
            // composer and composition the outputs use.
            let crisp = self.crisp(a, Composer::Max, Composition::Weighted);
            self.inputs[slot].now = crisp.map(|v| (v, 1.0));
            self.fuzzify(slot);
        }
    }

    fn run_behavior(&mut self, b: usize) {
        let beh = &self.behaviors[b];
        // No CANDO entry reads as missing, (0, 1): the behavior never runs (the checker warns).
        let cando = beh.cando.as_ref().map_or(FuzzyValue::MISSING, |e| {
            e.eval(&self.data, &self.pred_values, &self.act_values)
        });
        let passes = match &self.cando_filter {
            Some(filter) => filter.0.can_do(&beh.name, cando),
            None => ThresholdFilter { threshold: self.threshold }.can_do(&beh.name, cando),
        };
        // The original engine also gates CANDO and WANT on their reliability (Semantics).
        let original = self.semantics == Semantics::Original;
        if !passes || (original && cando.reliability <= self.threshold) {
            self.activity[b] = None;
            return;
        }
        let want = beh.want.as_ref().map_or(FuzzyValue::MISSING, |e| {
            e.eval(&self.data, &self.pred_values, &self.act_values)
        });
        self.activity[b] = Some((cando, want));
        let reliable = !original || want.reliability > WANT_THRESHOLD;
        let weight = if want.value > WANT_THRESHOLD && reliable { want.value } else { 0.0 };
        // μC · μW, by which formula 10.5 chooses.
        let score = cando.value * weight;
        if self.behaviors[b].code.is_some() {
            self.run_code(b, weight, score);
            return;
        }
        for r in 0..self.behaviors[b].rules.len() {
            let rule = &self.behaviors[b].rules[r];
            let p = rule.precondition.eval(&self.data, &self.pred_values, &self.act_values);
            let value = match self.semantics {
                Semantics::Manual if p.reliability < MIN_RELIABILITY => continue,
                Semantics::Manual => p.value * p.reliability,
                Semantics::Original => p.value,
            };
            for k in 0..rule.actions.len() {
                let act = self.behaviors[b].rules[r].actions[k];
                self.apply(b, act, value, weight, score);
            }
        }
    }

    /// Runs a code behavior: its proposals are applied as a rule's.
    fn run_code(&mut self, b: usize, weight: f64, score: f64) {
        let code = self.behaviors[b].code.as_ref().and_then(|c| c.behavior.clone());
        let Some(code) = code else { return };
        let mut out = std::mem::take(&mut self.code_out);
        out.clear();
        code.0.run(
            &Situation { brian: self, behavior: b },
            &mut Proposals { brian: self, out: &mut out },
        );
        for &(act, value) in &out {
            self.apply(b, act, value, weight, score);
        }
        self.code_out = out;
    }

    /// One action of behavior `b`, from a rule of value `value` (or a code behavior), the
    /// behavior weighing `weight` with μC · μW = `score`.
    fn apply(&mut self, b: usize, act: RuleAction, value: f64, weight: f64, score: f64) {
        match act {
            // A rule that does not fire (value 0), or a behavior of weight 0, proposes
            // nothing: it must not count in the average composer's mean.
            RuleAction::Propose(slot) if weight * value > 0.0 => {
                let weighted = self.weight_composer.apply(value, weight);
                self.level_acc[slot].add(weighted, score, b);
                if self.tracing {
                    // Actions are in offset order: the last one starting at or before `slot`
                    // holds it.
                    let ai = self.actions.partition_point(|a| a.offset <= slot).saturating_sub(1);
                    let label = slot - self.actions[ai].offset;
                    self.traced.push((b, ai, Some(label), Some(weighted)));
                }
            }
            RuleAction::Propose(_) => {}
            // `&DEL` applies when the rule fires (value > 0), whatever the behavior's weight:
            // a running behavior (CANDO above the threshold) may suppress lower levels even
            // while its WANT gives its own proposals no weight. This is what the shared
            // conformance data (brian40-hier) require.
            RuleAction::Delete { action, label } if value > 0.0 => {
                if self.tracing {
                    self.traced.push((b, action, label, None));
                }
                let a = &self.actions[action];
                match label {
                    Some(k) => self.lower[a.offset + k] = Acc::default(),
                    None => self.lower[a.offset..a.offset + a.labels.len()]
                        .iter_mut()
                        .for_each(|v| *v = Acc::default()),
                }
            }
            RuleAction::Delete { .. } => {}
        }
    }
}
