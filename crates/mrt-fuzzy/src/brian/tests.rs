//! The parsers of behavior lists, rule files and definitions never panic, whatever bytes or
//! tokens they are given.

use super::parse::{parse_behavior_list, parse_rules, Index, Names, Outputs};
use super::Action;
use crate::expr::parse_definitions;
use crate::lexer::{tokenize, Cursor};
use crate::set::FuzzySet;
use proptest::prelude::*;
use std::path::Path;

fn soup() -> impl Strategy<Value = String> {
    proptest::collection::vec(
        prop_oneof![
            Just("("),
            Just(")"),
            Just("AND"),
            Just("OR"),
            Just("NOT"),
            Just("D"),
            Just("P"),
            Just("level"),
            Just("1"),
            Just("-2.5"),
            Just("A"),
            Just("B"),
            Just("=>"),
            Just("="),
            Just(">"),
            Just(";"),
            Just("&DEL.Out"),
            Just("ANY"),
            Just("Out"),
            Just("HIGH"),
            Just("#x\n"),
            Just("\n"),
            Just(" ")
        ],
        0..48,
    )
    .prop_map(|v| v.concat())
}

fn try_all(text: &str) {
    let file = Path::new("x");
    let Ok(toks) = tokenize(text, file) else { return };
    let index = Index::default();
    let names = Names { inputs: &[], index: &index, file };
    let actions = [Action {
        name: "Out".into(),
        labels: vec![("HIGH".into(), 1.0)],
        sets: vec![("HIGH".into(), FuzzySet::Sng { a: 1.0 })],
        barycenter: false,
        circular: false,
        proposed: None,
        offset: 0,
    }];
    let _ = parse_rules(&mut Cursor::new(&toks, file, text), &names, &Outputs::new(&actions));
    let _ = parse_behavior_list(&mut Cursor::new(&toks, file, text));
    let _ = parse_definitions(&mut Cursor::new(&toks, file, text));
}

proptest! {
    #[test]
    fn rule_definition_and_behavior_parsers_never_panic_on_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
        try_all(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn rule_definition_and_behavior_parsers_never_panic_on_token_soup(text in soup()) {
        try_all(&text);
    }
}
