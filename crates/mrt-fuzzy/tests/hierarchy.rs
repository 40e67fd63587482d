//! The hierarchy rules of Mr. BRIAN, one test each, on a tiny two-level configuration:
//! weights apply once; `&DEL` removes lower levels' proposals (one label or `ANY`), never its own
//! level's; a level above 1 sees what the levels below propose as a crisp `Proposed<Action>`
//! datum (reliability 1), re-fuzzified and read by `PredicateActions.ini`.

#![allow(clippy::unwrap_used)]

use mrt_fuzzy::brian::Brian;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Out: LOW 0, MID 50, HIGH 100. Input X in [0, 1] gives `On` = X (TOR 0 1).
/// Level 1 `Base` (WANT `Six`) proposes HIGH when On. Level 2 `Top` runs when On and
/// proposes/deletes what `top_rule` says; `SawHigh` is true when level 1 proposed ≥ 90.
fn config(top_rule: &str, top_want: &str) -> PathBuf {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let d = std::env::temp_dir().join(format!("mrt-hier-{}-{n}", std::process::id()));
    std::fs::create_dir_all(d.join("b")).unwrap();
    for (f, t) in [
        ("shape_ctof.txt", "(S (TOR (ON 0 1)))\n(P (TOR (HIGHISH 80 90)))\n(W (TRI (SIX 0.5 0.6 0.7)) (TOR (ALL 0.9 1)))"),
        ("ctof.txt", "(X S)\n(ProposedOut P)\n(Want W)"),
        ("Predicate.ini", "On = (D X ON);\nSix = (D Want SIX);\nAll = (D Want ALL);"),
        ("PredicateActions.ini", "SawHigh = (D ProposedOut HIGHISH);"),
        ("Cando.ini", "Base = (P On);\nTop = (P On);"),
        ("want.txt", &format!("Base = (P Six);\nTop = {top_want};")),
        ("behavior.txt", "(level 1 Base b/Base.rul)\n( level 2 Top b/Top.rul )"),
        ("b/Base.rul", "(On) => (Out HIGH);"),
        ("b/Top.rul", top_rule),
        ("s_shape.txt", "(OUT (SNG (LOW 0)) (SNG (MID 50)) (SNG (HIGH 100)))"),
        ("s_ftoc.txt", "(Out OUT)"),
    ] {
        std::fs::write(d.join(f), t).unwrap();
    }
    d
}

fn out(top_rule: &str, top_want: &str) -> Option<f64> {
    let dir = config(top_rule, top_want);
    let mut b = Brian::from_dir(&dir).unwrap();
    // Want = 0.6 is the peak of SIX (so `Six` = 1) and below ALL (so `All` = 0).
    let r = b.run(&[("X", 1.0, 1.0), ("Want", 0.6, 1.0)]).get("Out").copied();
    std::fs::remove_dir_all(&dir).unwrap();
    r
}

#[test]
fn weights_apply_once_across_levels() {
    // Base proposes HIGH with weight Six = 1 (Want 0.6 is SIX's peak); Top proposes LOW with
    // weight 1. Max per label, then (100·1 + 0·1) / 2 = 50: the level-1 weight is not applied
    // again at level 2.
    assert_eq!(out("(On) => (Out LOW);", "(P On)"), Some(50.0));
}

#[test]
fn del_any_removes_the_lower_levels_proposals_only() {
    // Top deletes every Out proposal of level 1 and proposes MID itself: only MID is left.
    assert_eq!(out("(On) => (&DEL.Out ANY) (Out MID);", "(P On)"), Some(50.0));
    // Deleting a label that level 1 did not propose changes nothing.
    assert_eq!(out("(On) => (&DEL.Out LOW) (Out MID);", "(P On)"), Some(75.0));
    // Deleting HIGH (what level 1 proposed) leaves only Top's LOW.
    assert_eq!(out("(On) => (&DEL.Out HIGH) (Out LOW);", "(P On)"), Some(0.0));
}

#[test]
fn del_never_removes_its_own_levels_proposals() {
    // The same rule proposes LOW and deletes LOW: the deletion is about lower levels only.
    assert_eq!(out("(On) => (Out LOW) (&DEL.Out LOW);", "(P On)"), Some(50.0));
}

#[test]
fn a_higher_level_reads_what_the_lower_ones_propose() {
    // Level 1 proposes HIGH alone: ProposedOut = 100, so SawHigh is 1 and Top answers LOW.
    assert_eq!(out("(SawHigh) => (Out LOW);", "(P On)"), Some(50.0));
    // A Top that reads SawHigh negated proposes nothing: Out stays 100.
    assert_eq!(out("(NOT (SawHigh)) => (Out LOW);", "(P On)"), Some(100.0));
}

#[test]
fn a_behavior_without_enough_want_proposes_nothing() {
    // Top's WANT is `All` = 0 (Want 0.6): weight 0, so its LOW does not count.
    assert_eq!(out("(On) => (Out LOW);", "(P All)"), Some(100.0));
}

#[test]
fn del_applies_when_the_rule_fires_even_at_weight_0() {
    // Top runs (CANDO On) with weight 0: its MID does not count, but its deletion does, so
    // nothing is left and the action is absent.
    assert_eq!(out("(On) => (&DEL.Out ANY) (Out MID);", "(P All)"), None);
}
