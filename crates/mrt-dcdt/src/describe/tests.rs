use super::xml::line_column;
use super::*;
use proptest::prelude::*;

const EXAMPLE: &str = r#"<message timestamp="12.500000000">
  <object name="ball" class="Ball">
    <attribute name="distance" value="2.4" variability="0.1" reliability="0.9"/>
    <attribute name="colour" symbol="orange" variability="0" reliability="1"/>
  </object>
</message>"#;

fn example() -> SelfDescribing {
    SelfDescribing::new(Time(12_500_000_000)).with_object(
        Object::new("ball", "Ball")
            .with(Attribute::number("distance", 2.4, 0.1, 0.9))
            .with(Attribute::symbol("colour", "orange", 0.0, 1.0)),
    )
}

/// The error message `from_xml` gives for `text`, which must be rejected.
fn err(text: &str) -> String {
    match SelfDescribing::from_xml(text) {
        Ok(m) => panic!("accepted {text:?} as {m:?}"),
        Err(e) => e.to_string(),
    }
}

/// `EXAMPLE` with `from` (which must occur) replaced by `to`.
fn example_with(from: &str, to: &str) -> String {
    assert!(EXAMPLE.contains(from), "{from:?} not in the example");
    EXAMPLE.replacen(from, to, 1)
}

#[test]
fn hand_written_xml_parses_to_the_expected_message() -> Result<(), XmlError> {
    let expected = SelfDescribing {
        timestamp: Time(12_500_000_000),
        objects: vec![Object {
            name: "ball".to_owned(),
            class: "Ball".to_owned(),
            attributes: vec![
                Attribute {
                    name: "distance".to_owned(),
                    value: AttrValue::Number(2.4),
                    variability: 0.1,
                    reliability: 0.9,
                },
                Attribute {
                    name: "colour".to_owned(),
                    value: AttrValue::Symbol("orange".to_owned()),
                    variability: 0.0,
                    reliability: 1.0,
                },
            ],
        }],
    };
    assert_eq!(SelfDescribing::from_xml(EXAMPLE)?, expected);
    assert_eq!(example(), expected);
    Ok(())
}

#[test]
fn to_xml_writes_the_exact_form() {
    assert_eq!(example().to_xml(), EXAMPLE);
}

#[test]
fn module_doc_example() -> Result<(), XmlError> {
    // The module's doctest, with the scratch paths.
    let msg = example();
    let xml = msg.to_xml();
    assert_eq!(xml, EXAMPLE);
    assert_eq!(SelfDescribing::from_xml(&xml)?, msg);
    Ok(())
}

#[test]
fn empty_message_and_object_use_empty_elements() -> Result<(), XmlError> {
    let empty = SelfDescribing::default();
    assert_eq!(empty.to_xml(), r#"<message timestamp="0.000000000"/>"#);
    assert_eq!(SelfDescribing::from_xml(&empty.to_xml())?, empty);

    let msg = SelfDescribing::new(Time(1)).with_object(Object::new("a", "B"));
    let xml = msg.to_xml();
    assert_eq!(
        xml,
        "<message timestamp=\"0.000000001\">\n  <object name=\"a\" class=\"B\"/>\n</message>"
    );
    assert_eq!(SelfDescribing::from_xml(&xml)?, msg);
    Ok(())
}

#[test]
fn special_characters_are_escaped() -> Result<(), XmlError> {
    let msg = SelfDescribing::new(Time(0)).with_object(
        Object::new("a<b>&\"c'", "tab\there\nnew line")
            .with(Attribute::symbol("s", "x&y", 0.0, 1.0)),
    );
    let xml = msg.to_xml();
    assert_eq!(
        xml,
        "<message timestamp=\"0.000000000\">\n  \
             <object name=\"a&lt;b&gt;&amp;&quot;c'\" class=\"tab&#9;here&#10;new line\">\n    \
             <attribute name=\"s\" symbol=\"x&amp;y\" variability=\"0\" reliability=\"1\"/>\n  \
             </object>\n</message>"
    );
    assert_eq!(SelfDescribing::from_xml(&xml)?, msg);
    Ok(())
}

#[test]
fn lookups_and_message_identity() {
    let msg = example();
    let ball = msg.object("ball");
    assert_eq!(ball.map(|o| o.class.as_str()), Some("Ball"));
    assert!(msg.object("goal").is_none());
    assert_eq!(
        ball.and_then(|o| o.attribute("colour")).map(|a| &a.value),
        Some(&AttrValue::Symbol("orange".to_owned()))
    );
    assert!(ball.and_then(|o| o.attribute("speed")).is_none());
    assert_eq!(SelfDescribing::TYPE, MsgType(0xFFFF_0001));
    assert_eq!(SelfDescribing::NAME, "SelfDescribing");
}

#[test]
fn non_finite_numbers_round_trip() -> Result<(), XmlError> {
    let msg = SelfDescribing::new(Time(5)).with_object(
        Object::new("o", "C")
            .with(Attribute::number("nan", f64::NAN, f64::INFINITY, 0.5))
            .with(Attribute::number("inf", f64::INFINITY, 0.0, 0.5))
            .with(Attribute::number("-inf", f64::NEG_INFINITY, 0.0, 0.5)),
    );
    let xml = msg.to_xml();
    assert!(xml.contains(r#"value="NaN" variability="inf""#), "{xml}");
    assert!(xml.contains(r#"value="inf""#), "{xml}");
    assert!(xml.contains(r#"value="-inf""#), "{xml}");
    let back = SelfDescribing::from_xml(&xml)?;
    let attrs = &back.objects[0].attributes;
    assert!(matches!(attrs[0].value, AttrValue::Number(v) if v.is_nan()));
    assert_eq!(attrs[0].variability, f64::INFINITY);
    assert_eq!(attrs[1].value, AttrValue::Number(f64::INFINITY));
    assert_eq!(attrs[2].value, AttrValue::Number(f64::NEG_INFINITY));
    // Written by hand, too.
    let back = SelfDescribing::from_xml(&example_with(r#"value="2.4""#, r#"value="NaN""#))?;
    let value = &back.objects[0].attributes[0].value;
    assert!(matches!(value, AttrValue::Number(v) if v.is_nan()));
    Ok(())
}

#[test]
fn timestamps_are_exact() -> Result<(), XmlError> {
    for (text, nanos) in [
        ("12.500000000", 12_500_000_000),
        ("12.5", 12_500_000_000),
        ("12", 12_000_000_000),
        ("0.000000001", 1),
        ("007.000000010", 7_000_000_010),
        (" 3.25 ", 3_250_000_000),
        ("18446744073.709551615", u64::MAX),
    ] {
        let xml = format!(r#"<message timestamp="{text}"/>"#);
        assert_eq!(SelfDescribing::from_xml(&xml)?.timestamp, Time(nanos), "{text}");
    }
    for nanos in [0, 1, 999_999_999, 1_000_000_000, 123_456_789_012_345_678, u64::MAX] {
        let msg = SelfDescribing::new(Time(nanos));
        assert_eq!(SelfDescribing::from_xml(&msg.to_xml())?, msg);
    }
    assert_eq!(
        SelfDescribing::new(Time(u64::MAX)).to_xml(),
        r#"<message timestamp="18446744073.709551615"/>"#
    );
    Ok(())
}

#[test]
fn bad_timestamps_are_rejected() {
    for bad in [
        "-1.0",
        "+1.0",
        "1.5e3",
        "abc",
        "",
        "1.",
        ".5",
        "1.0000000001",
        "1,5",
        "NaN",
        "inf",
        "1 .5",
    ] {
        assert_eq!(
            err(&format!(r#"<message timestamp="{bad}"/>"#)),
            format!(
                "line 1, column 1: <message>: expected `timestamp` as non-negative seconds \
                     with at most 9 decimals, found {bad:?}"
            ),
        );
    }
    for bad in ["18446744073.709551616", "99999999999999999999999"] {
        assert_eq!(
            err(&format!(r#"<message timestamp="{bad}"/>"#)),
            format!(
                "line 1, column 1: <message>: expected `timestamp` of at most \
                     18446744073.709551615 seconds, found {bad:?}"
            ),
        );
    }
    assert_eq!(err("\n\n  <message/>"), "line 3, column 3: <message>: expected `timestamp`");
    assert_eq!(
        err(&example_with("timestamp=\"12.500000000\"", "timestamp=\"12.5x\"")),
        "line 1, column 1: <message>: expected `timestamp` as non-negative seconds with at \
             most 9 decimals, found \"12.5x\""
    );
}

#[test]
fn missing_reliability() {
    assert_eq!(
        err(&example_with(r#" reliability="0.9""#, "")),
        "line 3, column 5: attribute \"distance\" of object \"ball\": expected `reliability`"
    );
}

#[test]
fn reliability_out_of_range() {
    for bad in ["1.5", "-0.1", "NaN", "high"] {
        assert_eq!(
            err(&example_with(r#"reliability="1""#, &format!(r#"reliability="{bad}""#))),
            format!(
                "line 4, column 5: attribute \"colour\" of object \"ball\": expected \
                     `reliability` between 0 and 1, found {bad:?}"
            )
        );
    }
}

#[test]
fn variability_must_be_non_negative() {
    assert_eq!(
        err(&example_with(r#"variability="0.1""#, r#"variability="-0.1""#)),
        "line 3, column 5: attribute \"distance\" of object \"ball\": expected `variability` \
             to be a non-negative number, found \"-0.1\""
    );
    assert_eq!(
        err(&example_with(r#" variability="0.1""#, "")),
        "line 3, column 5: attribute \"distance\" of object \"ball\": expected `variability`"
    );
}

#[test]
fn value_xor_symbol() {
    assert_eq!(
        err(&example_with(r#"value="2.4""#, r#"value="2.4" symbol="far""#)),
        "line 3, column 5: attribute \"distance\" of object \"ball\": expected `value` or \
             `symbol`, not both"
    );
    assert_eq!(
        err(&example_with(r#" value="2.4""#, "")),
        "line 3, column 5: attribute \"distance\" of object \"ball\": expected `value` or \
             `symbol`"
    );
    assert_eq!(
        err(&example_with(r#"value="2.4""#, r#"value="far""#)),
        "line 3, column 5: attribute \"distance\" of object \"ball\": expected a number in \
             `value`, found \"far\""
    );
}

#[test]
fn missing_or_unknown_xml_attributes() {
    assert_eq!(
        err(&example_with(r#"<attribute name="distance""#, "<attribute")),
        "line 3, column 5: <attribute> of object \"ball\": expected `name`"
    );
    assert_eq!(
        err(&example_with(r#"name="ball" "#, "")),
        "line 2, column 3: <object>: expected `name`"
    );
    assert_eq!(
        err(&example_with(r#" class="Ball""#, "")),
        "line 2, column 3: object \"ball\": expected `class`"
    );
    assert_eq!(
        err(&example_with(r#"class="Ball""#, r#"class="Ball" colour="red""#)),
        "line 2, column 3: object \"ball\": expected only `name` and `class`, found `colour`"
    );
    assert_eq!(
        err(&example_with(r#"reliability="1""#, r#"reliability="1" unit="m""#)),
        "line 4, column 5: attribute \"colour\" of object \"ball\": expected only `name`, \
             `value`, `symbol`, `variability` and `reliability`, found `unit`"
    );
    assert_eq!(
        err(&example_with("<message ", "<message version=\"2\" ")),
        "line 1, column 1: <message>: expected only `timestamp`, found `version`"
    );
    assert_eq!(
        err(&example_with(r#"class="Ball""#, r#"class="Ball" name="bat""#)),
        "line 2, column 36: <object>: expected each attribute once, found a second `name`"
    );
}

#[test]
fn unknown_elements() {
    assert_eq!(
        err(&example_with(
            r#"<attribute name="colour" symbol="orange" variability="0" reliability="1"/>"#,
            "<foo/>"
        )),
        "line 4, column 5: expected <attribute>, found <foo>"
    );
    assert_eq!(
        err(&example_with("<object", "<thing")),
        "line 2, column 3: expected <object>, found <thing>"
    );
    assert_eq!(err(r#"<msg timestamp="1"/>"#), "line 1, column 1: expected <message>, found <msg>");
    assert_eq!(
        err(&format!("{EXAMPLE}\n<message timestamp=\"1\"/>")),
        "line 7, column 1: expected end of input, found <message>"
    );
    assert_eq!(
        err(&example_with("<attribute name=\"colour\"", "text <attribute name=\"colour\"")),
        "line 3, column 81: expected <attribute> or </object>, found text"
    );
}

#[test]
fn malformed_xml() {
    // An unclosed tag: the input ends inside `<object ...`.
    let cut = EXAMPLE.find(" class").unwrap_or_default();
    assert_eq!(
        err(&EXAMPLE[..cut]),
        "line 2, column 3: expected `>` to close the tag, found end of input"
    );
    // Elements left open at the end of the input.
    let cut = EXAMPLE.rfind("\n</message>").unwrap_or_default();
    assert_eq!(err(&EXAMPLE[..cut]), "line 5, column 12: expected </message>, found end of input");
    let cut = EXAMPLE.find("\n  </object>").unwrap_or_default();
    assert_eq!(err(&EXAMPLE[..cut]), "line 4, column 79: expected </object>, found end of input");
    // A mismatched end tag.
    assert_eq!(
        err(&example_with("</object>", "</objet>")),
        "line 5, column 3: expected </object>, found </objet>"
    );
    assert_eq!(err(""), "line 1, column 1: expected <message>, found end of input");
    assert_eq!(err("hello"), "line 1, column 1: expected <message>, found text");
    assert_eq!(
        err(&example_with(r#"value="2.4""#, "value=2.4")),
        "line 3, column 38: <attribute> of object \"ball\": expected a quoted attribute \
             value, found an unquoted one"
    );
    assert_eq!(
        err(&example_with(r#"symbol="orange""#, r#"symbol="&orange;""#)),
        "line 4, column 5: <attribute> of object \"ball\": in `symbol`, expected a \
             predefined entity, found `&orange;`"
    );
    assert_eq!(
        err("<!-- open\n<message/>"),
        "line 1, column 1: expected `-->` to close the comment, found end of input"
    );
}

#[test]
fn columns_count_characters() {
    assert_eq!(line_column("ab\ncd", 4), (2, 2));
    assert_eq!(line_column("é\né€x", 8), (2, 3));
    assert_eq!(line_column("abc", 99), (1, 4));
    assert_eq!(line_column("", 0), (1, 1));
    assert_eq!(
        err("<message timestamp=\"1\">\n<!--é€--><obj/>"),
        "line 2, column 10: expected <object>, found <obj>"
    );
}

#[test]
fn prolog_doctype_comments_and_open_attribute_elements_are_accepted() -> Result<(), XmlError> {
    let with_dtd = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!DOCTYPE message [\n{DTD}]>\n\
             <!-- a comment -->\n{EXAMPLE}\n<!-- the end -->\n"
    );
    assert_eq!(SelfDescribing::from_xml(&with_dtd)?, example());
    let with_system = format!("<!DOCTYPE message SYSTEM \"describe.dtd\">{EXAMPLE}");
    assert_eq!(SelfDescribing::from_xml(&with_system)?, example());
    let open = example_with(
        r#"reliability="1"/>"#,
        "reliability=\"1\">\n      <!-- nothing -->\n    </attribute>",
    );
    assert_eq!(SelfDescribing::from_xml(&open)?, example());
    assert_eq!(
        err(&format!("{EXAMPLE}<!DOCTYPE message>")),
        "line 6, column 11: expected end of input, found a doctype"
    );
    assert_eq!(
        err(&example_with(r#"reliability="1"/>"#, r#"reliability="1">x</attribute>"#)),
        "line 4, column 78: expected </attribute>, found text"
    );
    Ok(())
}

#[test]
fn postcard_round_trip() -> Result<(), postcard::Error> {
    let msg = example().with_object(
        Object::new("robot", "Robot").with(Attribute::number("x", -1e-300, 1e300, 0.0)),
    );
    let bytes = postcard::to_stdvec(&msg)?;
    let back: SelfDescribing = postcard::from_bytes(&bytes)?;
    assert_eq!(back, msg);
    Ok(())
}

fn text() -> impl Strategy<Value = String> {
    prop_oneof!["[a-zA-Z0-9 _<>&\"'\t\n\r=/;#\u{e9}\u{4e2d}\u{1F916}-]{0,12}", any::<String>(),]
}

fn number() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<f64>().prop_filter("NaN is never equal", |v| !v.is_nan()),
        -1e6..1e6f64,
        prop::sample::select(vec![
            0.0,
            -0.0,
            -2.5,
            1e300,
            -1e300,
            5e-324,
            -5e-324,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            f64::EPSILON,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ]),
    ]
}

fn attribute() -> impl Strategy<Value = Attribute> {
    let value =
        prop_oneof![number().prop_map(AttrValue::Number), text().prop_map(AttrValue::Symbol)];
    let variability = prop_oneof![0.0..1e3f64, number().prop_map(f64::abs), Just(f64::INFINITY)];
    let reliability = prop_oneof![0.0..=1.0f64, Just(0.0), Just(1.0)];
    (text(), value, variability, reliability).prop_map(|(name, value, variability, reliability)| {
        Attribute { name, value, variability, reliability }
    })
}

fn message() -> impl Strategy<Value = SelfDescribing> {
    let object = (text(), text(), prop::collection::vec(attribute(), 0..4))
        .prop_map(|(name, class, attributes)| Object { name, class, attributes });
    (any::<u64>(), prop::collection::vec(object, 0..4))
        .prop_map(|(nanos, objects)| SelfDescribing { timestamp: Time(nanos), objects })
}

fn xml_like() -> impl Strategy<Value = String> {
    "(<|</|/>|>|=|\"|'| |\n|&|&amp;|&#|;|<!--|-->|<!DOCTYPE|<\\?|\\?>|]>|message|object\
         |attribute|name|class|value|symbol|variability|reliability|timestamp|[0-9.e+-]|é|x){0,60}"
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn xml_round_trip(m in message()) {
        let xml = m.to_xml();
        let back = SelfDescribing::from_xml(&xml)
            .map_err(|e| TestCaseError::fail(format!("{e}\n{xml}")))?;
        prop_assert_eq!(back, m);
    }

    #[test]
    fn postcard_round_trip_any(m in message()) {
        let bytes = postcard::to_stdvec(&m).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let back: SelfDescribing =
            postcard::from_bytes(&bytes).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(back, m);
    }

    #[test]
    fn arbitrary_strings_never_panic(text in any::<String>()) {
        let _ = SelfDescribing::from_xml(&text);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        let _ = SelfDescribing::from_xml(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn xml_like_text_never_panics(text in xml_like()) {
        let _ = SelfDescribing::from_xml(&text);
    }

    #[test]
    fn damaged_messages_never_panic(
        m in message(),
        cut in any::<prop::sample::Index>(),
        at in any::<prop::sample::Index>(),
        insert in "[<>/=\"'&;! a-z]{0,3}",
    ) {
        let xml = m.to_xml();
        let chars: Vec<char> = xml.chars().collect();
        let cut = cut.index(chars.len() + 1);
        let truncated: String = chars[..cut].iter().collect();
        let _ = SelfDescribing::from_xml(&truncated);
        let at = at.index(chars.len() + 1);
        let mut damaged: String = chars[..at].iter().collect();
        damaged.push_str(&insert);
        damaged.extend(&chars[at..]);
        let _ = SelfDescribing::from_xml(&damaged);
    }
}
