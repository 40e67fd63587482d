use super::*;
use proptest::prelude::*;
use std::collections::BTreeMap;

/// Whether two forms are equal, a NaN equal to a NaN.
fn same(a: &SelfDescribing, b: &SelfDescribing) -> bool {
    let number = |x: f64, y: f64| x == y || (x.is_nan() && y.is_nan());
    a.timestamp == b.timestamp
        && a.objects.len() == b.objects.len()
        && a.objects.iter().zip(&b.objects).all(|(o, p)| {
            o.name == p.name
                && o.class == p.class
                && o.attributes.len() == p.attributes.len()
                && o.attributes.iter().zip(&p.attributes).all(|(x, y)| {
                    x.name == y.name
                        && number(x.variability, y.variability)
                        && number(x.reliability, y.reliability)
                        && match (&x.value, &y.value) {
                            (AttrValue::Number(u), AttrValue::Number(v)) => number(*u, *v),
                            (u, v) => u == v,
                        }
                })
        })
}

/// The form of `value` as `name`, checked to read back from its XML.
fn form<T: Serialize + ?Sized>(name: &str, value: &T) -> SelfDescribing {
    let form = match describe(name, value, Time(7)) {
        Ok(form) => form,
        Err(e) => panic!("{e}"),
    };
    let xml = form.to_xml();
    match SelfDescribing::from_xml(&xml) {
        Ok(back) => assert!(same(&back, &form), "{xml}"),
        Err(e) => panic!("{e}\n{xml}"),
    }
    form
}

/// `(name, value or symbol, variability, reliability)` of each attribute of object `name`.
fn attrs(form: &SelfDescribing, name: &str) -> Vec<(String, String, f64, f64)> {
    let Some(object) = form.object(name) else { panic!("no object {name}") };
    object
        .attributes
        .iter()
        .map(|a| {
            let value = match &a.value {
                AttrValue::Number(v) => v.to_string(),
                AttrValue::Symbol(s) => format!("'{s}'"),
            };
            (a.name.clone(), value, a.variability, a.reliability)
        })
        .collect()
}

fn row(name: &str, value: &str, variability: f64, reliability: f64) -> (String, String, f64, f64) {
    (name.to_owned(), value.to_owned(), variability, reliability)
}

fn objects(form: &SelfDescribing) -> Vec<(&str, &str)> {
    form.objects.iter().map(|o| (o.name.as_str(), o.class.as_str())).collect()
}

#[derive(Serialize, Clone, Debug, Default)]
struct Pose {
    x: f64,
    y: f64,
    theta: f64,
}

#[derive(Serialize, Clone, Debug)]
enum Kind {
    Ball,
    Robot(u32),
    Post { east: bool, at: Pose },
    Pair(f32, i64),
}

#[derive(Serialize, Clone, Debug)]
struct Thing {
    name: String,
    kind: Kind,
    pose: Pose,
    sigma: f64,
    quality: f64,
    tags: Vec<char>,
}

#[derive(Serialize, Clone, Debug)]
struct Scene {
    time: u64,
    things: Vec<Thing>,
    grid: [u8; 3],
    image: Vec<u8>,
    table: BTreeMap<String, f64>,
    by_id: BTreeMap<u16, Pose>,
    pair: (i8, Option<bool>),
    unit: (),
    variability: f64,
    pose_sigma: f64,
    pose: Option<Pose>,
}

#[test]
fn nested_structs_are_objects_named_by_path() {
    let thing = |name: &str, kind| Thing {
        name: name.to_owned(),
        kind,
        pose: Pose { x: 1.0, y: 2.0, theta: 0.5 },
        sigma: 0.25,
        quality: 0.75,
        tags: vec!['a', '<'],
    };
    let scene = Scene {
        time: 3,
        things: vec![
            thing("ball", Kind::Ball),
            thing("mate", Kind::Robot(4)),
            thing("post", Kind::Post { east: true, at: Pose::default() }),
            thing("pair", Kind::Pair(1.5, -2)),
        ],
        grid: [1, 2, 3],
        image: vec![9; 1_000_000],
        table: BTreeMap::from([("b".to_owned(), 2.0), ("a".to_owned(), 1.0)]),
        by_id: BTreeMap::from([(7, Pose::default())]),
        pair: (-1, None),
        unit: (),
        variability: 0.5,
        pose_sigma: 0.125,
        pose: Some(Pose { x: 3.0, y: 4.0, theta: -1.0 }),
    };
    let form = form("scene", &scene);
    assert_eq!(
        objects(&form),
        [
            ("scene", "Scene"),
            ("things[0]", "Thing"),
            ("things[0].pose", "Pose"),
            ("things[1]", "Thing"),
            ("things[1].kind", "Robot"),
            ("things[1].pose", "Pose"),
            ("things[2]", "Thing"),
            ("things[2].kind", "Post"),
            ("things[2].kind.at", "Pose"),
            ("things[2].pose", "Pose"),
            ("things[3]", "Thing"),
            ("things[3].kind", "Pair"),
            ("things[3].pose", "Pose"),
            ("by_id.7", "Pose"),
            ("pose", "Pose"),
        ]
    );
    // `variability` gives every other number of the scene 0.5 and reaches nested
    // objects; `pose_sigma` gives the field `pose` 0.125 instead.
    assert_eq!(
        attrs(&form, "scene"),
        [
            row("time", "3", 0.5, 1.0),
            row("grid[0]", "1", 0.5, 1.0),
            row("grid[1]", "2", 0.5, 1.0),
            row("grid[2]", "3", 0.5, 1.0),
            row("image", "'<1000000 bytes>'", 0.0, 1.0),
            row("table.a", "1", 0.5, 1.0),
            row("table.b", "2", 0.5, 1.0),
            row("pair[0]", "-1", 0.5, 1.0),
            row("variability", "0.5", 0.0, 1.0),
            row("pose_sigma", "0.125", 0.0, 1.0),
        ]
    );
    assert_eq!(
        attrs(&form, "pose"),
        [row("x", "3", 0.125, 1.0), row("y", "4", 0.125, 1.0), row("theta", "-1", 0.125, 1.0)]
    );
    assert_eq!(attrs(&form, "by_id.7")[0], row("x", "0", 0.5, 1.0));
    // `quality` is the reliability of a thing's attributes and of its pose's; `sigma` the
    // variability of the pose's x and y, the scene's `variability` that of the rest.
    assert_eq!(
        attrs(&form, "things[0]"),
        [
            row("name", "'ball'", 0.0, 0.75),
            row("kind", "'Ball'", 0.0, 0.75),
            row("sigma", "0.25", 0.0, 1.0),
            row("quality", "0.75", 0.0, 1.0),
            row("tags[0]", "'a'", 0.0, 0.75),
            row("tags[1]", "'<'", 0.0, 0.75),
        ]
    );
    assert_eq!(
        attrs(&form, "things[0].pose"),
        [row("x", "1", 0.25, 0.75), row("y", "2", 0.25, 0.75), row("theta", "0.5", 0.5, 0.75)]
    );
    // Variants with data.
    assert_eq!(attrs(&form, "things[1].kind"), [row("0", "4", 0.5, 0.75)]);
    assert_eq!(attrs(&form, "things[2].kind"), [row("east", "'true'", 0.0, 0.75)]);
    assert_eq!(
        attrs(&form, "things[3].kind"),
        [row("0", "1.5", 0.5, 0.75), row("1", "-2", 0.5, 0.75)]
    );
}

#[test]
fn named_sigmas_reach_nested_attributes() {
    #[derive(Serialize)]
    struct Estimate {
        pose: Pose,
        sigma_xy: f64,
        sigma_theta: f64,
        quality: f64,
    }
    let form = form(
        "Estimate",
        &Estimate { pose: Pose::default(), sigma_xy: 0.1, sigma_theta: 0.05, quality: 0.5 },
    );
    assert_eq!(
        attrs(&form, "pose"),
        [row("x", "0", 0.1, 0.5), row("y", "0", 0.1, 0.5), row("theta", "0", 0.05, 0.5)]
    );
}

#[test]
fn uncertainty_is_made_valid() {
    #[derive(Serialize)]
    struct Odd {
        v: f64,
        reliability: f64,
        variability: f64,
    }
    for (reliability, variability, r, v) in [
        (f64::NAN, f64::NAN, 0.0, f64::INFINITY),
        (2.0, -3.0, 1.0, 3.0),
        (-1.0, f64::NEG_INFINITY, 0.0, f64::INFINITY),
        (0.5, -0.0, 0.5, 0.0),
    ] {
        let form = form("odd", &Odd { v: f64::NAN, reliability, variability });
        let v_attr = &form.objects[0].attributes[0];
        assert_eq!((v_attr.variability, v_attr.reliability), (v, r));
        assert!(matches!(v_attr.value, AttrValue::Number(x) if x.is_nan()));
    }
    // Non-finite numbers as values read back.
    let form = form("numbers", &[f64::INFINITY, f64::NEG_INFINITY, f64::NAN, -0.0, 5e-324]);
    assert!(form.to_xml().contains(r#"name="[0]" value="inf""#), "{}", form.to_xml());
    assert!(form.to_xml().contains(r#"name="[1]" value="-inf""#));
    assert!(form.to_xml().contains(r#"name="[2]" value="NaN""#));
}

#[test]
fn values_that_are_not_structs() {
    assert_eq!(attrs(&form("n", &2.5), "n"), [row("value", "2.5", 0.0, 1.0)]);
    assert_eq!(objects(&form("n", &2.5)), [("n", "n")]);
    assert_eq!(attrs(&form("s", "hi"), "s"), [row("value", "'hi'", 0.0, 1.0)]);
    assert!(attrs(&form("none", &None::<f64>), "none").is_empty());
    assert!(attrs(&form("empty", &Vec::<f64>::new()), "empty").is_empty());
    let seq = form("poses", &vec![Pose::default(); 2]);
    assert_eq!(objects(&seq), [("poses", "poses"), ("[0]", "Pose"), ("[1]", "Pose")]);
    let map = form("m", &BTreeMap::from([('k', Pose::default())]));
    assert_eq!(objects(&map), [("m", "m"), ("k", "Pose")]);
    assert_eq!(objects(&form("k", &Kind::Robot(1))), [("k", "Robot")]);
    #[derive(Serialize)]
    struct Unit;
    #[derive(Serialize)]
    struct Wrapper(Pose);
    #[derive(Serialize)]
    struct Meters(f64);
    #[derive(Serialize)]
    struct Pair(f64, Unit);
    assert_eq!(objects(&form("u", &Unit)), [("u", "Unit")]);
    assert_eq!(objects(&form("w", &Wrapper(Pose::default()))), [("w", "Wrapper")]);
    assert_eq!(attrs(&form("w", &Wrapper(Pose::default())), "w").len(), 3);
    assert_eq!(attrs(&form("m", &Meters(2.0)), "m"), [row("value", "2", 0.0, 1.0)]);
    assert_eq!(objects(&form("p", &Pair(1.0, Unit))), [("p", "Pair"), ("1", "Unit")]);
    // u128, i128, chars, bools.
    assert_eq!(
        attrs(&form("t", &(u128::MAX, i128::MIN, 'x', false)), "t"),
        [
            row("[0]", &(u128::MAX as f64).to_string(), 0.0, 1.0),
            row("[1]", &(i128::MIN as f64).to_string(), 0.0, 1.0),
            row("[2]", "'x'", 0.0, 1.0),
            row("[3]", "'false'", 0.0, 1.0),
        ]
    );
}

/// `serialize_bytes` (what `serde_bytes` calls) gives one attribute.
struct Bytes(Vec<u8>);

impl Serialize for Bytes {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_bytes(&self.0)
    }
}

#[test]
fn byte_arrays_are_one_attribute() {
    #[derive(Serialize)]
    struct Image {
        raw: Bytes,
        rgb: Vec<u8>,
        empty: Bytes,
        small: [u8; 2],
        mixed: Vec<Option<u8>>,
    }
    let image = Image {
        raw: Bytes(vec![1; 5]),
        rgb: vec![0; 921_600],
        empty: Bytes(Vec::new()),
        small: [7, 8],
        mixed: vec![None, Some(3)],
    };
    assert_eq!(
        attrs(&form("image", &image), "image"),
        [
            row("raw", "'<5 bytes>'", 0.0, 1.0),
            row("rgb", "'<921600 bytes>'", 0.0, 1.0),
            row("empty", "'<0 bytes>'", 0.0, 1.0),
            row("small[0]", "7", 0.0, 1.0),
            row("small[1]", "8", 0.0, 1.0),
            row("mixed[1]", "3", 0.0, 1.0),
        ]
    );
    // Optional bytes and newtypes of bytes are numbers.
    #[derive(Serialize)]
    struct Level(u8);
    assert_eq!(
        attrs(&form("v", &vec![Some(1), Some(2)]), "v"),
        [row("[0]", "1", 0.0, 1.0), row("[1]", "2", 0.0, 1.0)]
    );
    assert_eq!(attrs(&form("v", &vec![Level(3)]), "v"), [row("[0]", "3", 0.0, 1.0)]);
    // Bytes followed by something else are numbers after all.
    assert_eq!(attrs(&form("v", &vec![Some(4), None]), "v"), [row("[0]", "4", 0.0, 1.0)]);
}

#[test]
fn errors_are_typed() {
    let bad_key = BTreeMap::from([((1, 2), 3.0)]);
    assert!(matches!(
        describe("m", &bad_key, Time(0)),
        Err(DescribeError::MapKey { found: "a sequence" })
    ));
    struct Failing;
    impl Serialize for Failing {
        fn serialize<S: serde::Serializer>(&self, _: S) -> Result<S::Ok, S::Error> {
            Err(serde::ser::Error::custom("no camera"))
        }
    }
    let err = describe("f", &vec![Failing], Time(0)).err().map(|e| e.to_string());
    assert_eq!(err.as_deref(), Some("the value could not be serialized: no camera"));
    #[derive(Serialize)]
    struct Chain(Option<Box<Chain>>);
    let mut chain = Chain(None);
    for _ in 0..MAX_DEPTH {
        chain = Chain(Some(Box::new(chain)));
    }
    assert!(matches!(describe("c", &chain, Time(0)), Err(DescribeError::TooDeep)));
    let mut shallow = Chain(None);
    for _ in 0..MAX_DEPTH / 3 {
        shallow = Chain(Some(Box::new(shallow)));
    }
    assert!(describe("c", &shallow, Time(0)).is_ok());
}

fn number() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<f64>(),
        -1e4..1e4f64,
        prop::sample::select(vec![0.0, -0.0, 1.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY]),
    ]
}

fn pose() -> impl Strategy<Value = Pose> {
    (number(), number(), number()).prop_map(|(x, y, theta)| Pose { x, y, theta })
}

fn kind() -> impl Strategy<Value = Kind> {
    prop_oneof![
        Just(Kind::Ball),
        any::<u32>().prop_map(Kind::Robot),
        (any::<bool>(), pose()).prop_map(|(east, at)| Kind::Post { east, at }),
        (any::<f32>(), any::<i64>()).prop_map(|(a, b)| Kind::Pair(a, b)),
    ]
}

fn thing() -> impl Strategy<Value = Thing> {
    (
        any::<String>(),
        kind(),
        pose(),
        number(),
        number(),
        prop::collection::vec(any::<char>(), 0..3),
    )
        .prop_map(|(name, kind, pose, sigma, quality, tags)| Thing {
            name,
            kind,
            pose,
            sigma,
            quality,
            tags,
        })
}

fn scene() -> impl Strategy<Value = Scene> {
    (
        (any::<u64>(), prop::collection::vec(thing(), 0..3), any::<[u8; 3]>()),
        prop::collection::vec(any::<u8>(), 0..40),
        prop::collection::btree_map(any::<String>(), number(), 0..3),
        prop::collection::btree_map(any::<u16>(), pose(), 0..3),
        (any::<i8>(), any::<Option<bool>>()),
        (number(), number(), prop::option::of(pose())),
    )
        .prop_map(|((time, things, grid), image, table, by_id, pair, rest)| Scene {
            time,
            things,
            grid,
            image,
            table,
            by_id,
            pair,
            unit: (),
            variability: rest.0,
            pose_sigma: rest.1,
            pose: rest.2,
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Any value gives a form, whose XML reads back as the form.
    #[test]
    fn any_value_reads_back(scene in scene(), nanos in any::<u64>()) {
        let form = describe("scene", &scene, Time(nanos))
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        let xml = form.to_xml();
        let back = SelfDescribing::from_xml(&xml)
            .map_err(|e| TestCaseError::fail(format!("{e}\n{xml}")))?;
        prop_assert!(same(&back, &form), "{}", xml);
        prop_assert_eq!(form.objects.len(), 1 + scene.things.iter().map(|t| match t.kind {
            Kind::Ball => 2,
            Kind::Post { .. } => 4,
            _ => 3,
        }).sum::<usize>() + scene.by_id.len() + usize::from(scene.pose.is_some()));
    }

    #[test]
    fn any_thing_reads_back(things in prop::collection::vec(thing(), 0..4)) {
        let form = describe("things", &things, Time(1))
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        let back = SelfDescribing::from_xml(&form.to_xml())
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert!(same(&back, &form));
    }
}
