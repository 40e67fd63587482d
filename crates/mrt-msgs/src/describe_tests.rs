//! The self-describing XML form (MRT manual §3.2) of every catalogue message, generated from
//! its type by `mrt_dcdt::describe`: each type's samples are described, written and read back.
//! The catalogue's `messages!` macro visits every type ([`crate::visit_catalogue`]), so a type
//! added to the catalogue without [`Samples`] here fails to compile.

use crate::*;
use mrt_core::frames::Framed;
use mrt_core::{Point2, Pose2, Time, Twist, Vec2};
use mrt_dcdt::describe::{AttrValue, SelfDescribing};
use std::collections::HashSet;

/// Values of a catalogue type to describe: its default (or its emptiest value) first.
pub(crate) trait Samples: Sized {
    fn samples() -> Vec<Self>;
}

/// What is done with each catalogue type.
pub(crate) trait Visitor {
    fn visit<M: Message + Samples>(&mut self);
}

const STAMP: Time = Time(1_500_000_000);

/// The form of `msg`, after checking that it is well made and reads back from its XML.
fn form_of<M: Message>(msg: &M) -> SelfDescribing {
    let form = match SelfDescribing::of_message(msg, STAMP) {
        Ok(form) => form,
        Err(e) => panic!("{}: {e}", M::NAME),
    };
    assert_eq!(form.timestamp, STAMP);
    let first = &form.objects[0];
    assert_eq!((first.name.as_str(), first.class.as_str()), (M::NAME, M::NAME));
    let mut names = HashSet::new();
    for object in &form.objects {
        assert!(names.insert(&object.name), "{}: two objects {}", M::NAME, object.name);
        let mut attributes = HashSet::new();
        for a in &object.attributes {
            assert!(attributes.insert(&a.name), "{}: two attributes {}", object.name, a.name);
        }
    }
    let xml = form.to_xml();
    match SelfDescribing::from_xml(&xml) {
        Ok(back) => assert_eq!(back, form, "{}:\n{xml}", M::NAME),
        Err(e) => panic!("{}: {e}\n{xml}", M::NAME),
    }
    form
}

/// `(value, variability, reliability)` of attribute `attr` of object `object`.
fn attr(form: &SelfDescribing, object: &str, attr: &str) -> (AttrValue, f64, f64) {
    let Some(a) = form.object(object).and_then(|o| o.attribute(attr)) else {
        panic!("no attribute {attr} of {object} in\n{}", form.to_xml())
    };
    (a.value.clone(), a.variability, a.reliability)
}

fn class<'a>(form: &'a SelfDescribing, object: &str) -> &'a str {
    form.object(object).map_or("", |o| o.class.as_str())
}

fn num(v: f64) -> AttrValue {
    AttrValue::Number(v)
}

fn sym(s: &str) -> AttrValue {
    AttrValue::Symbol(s.to_owned())
}

/// Every type of the catalogue: each sample's form is generated and reads back.
#[test]
fn every_catalogue_message_has_a_form() {
    struct Check(Vec<&'static str>);
    impl Visitor for Check {
        fn visit<M: Message + Samples>(&mut self) {
            let samples = M::samples();
            assert!(!samples.is_empty(), "{}", M::NAME);
            for msg in &samples {
                form_of(msg);
            }
            self.0.push(M::NAME);
        }
    }
    let mut check = Check(Vec::new());
    crate::visit_catalogue(&mut check);
    let names: Vec<&str> = crate::CATALOGUE.iter().map(|(_, name)| *name).collect();
    assert_eq!(check.0, names);
}

/// The default (nothing known) forms of a few types.
#[test]
fn default_forms() {
    let f = form_of(&ReloadRequest);
    assert_eq!(f.to_xml(), "<message timestamp=\"1.500000000\">\n  <object name=\"ReloadRequest\" class=\"ReloadRequest\"/>\n</message>");
    // A struct field is an object of its own, named by its path.
    let f = form_of(&MotorCommand::default());
    assert_eq!(f.objects.len(), 2);
    assert_eq!(attr(&f, "MotorCommand", "kick"), (sym("false"), 0.0, 1.0));
    assert_eq!(attr(&f, "twist", "vx"), (num(0.0), 0.0, 1.0));
    // Nothing seen: every LPS object has reliability 0, and so have its attributes.
    let f = form_of(&WorldSnapshot::default());
    assert_eq!(class(&f, "lps[8]"), "Lpo");
    assert_eq!(attr(&f, "lps[8]", "rho"), (num(0.0), 0.0, 0.0));
    assert_eq!(attr(&f, "lps[8]", "reliability"), (num(0.0), 0.0, 1.0));
    assert_eq!(attr(&f, "global_ball.pose", "x"), (num(0.0), 0.0, 0.0));
    assert!(f.object("job").is_none() && f.object("kickoff_pose").is_none());
}

/// A command, small enough to check its XML whole.
#[test]
fn a_robot_command_in_xml() {
    let command = RobotCommand {
        twist: Twist::new(0.3, 0.0, -0.25),
        kick: Some(2),
        needs: vec![(0, 0.8)],
        track_landmarks: false,
        behavior: Some("Score".to_owned()),
        book_ball: Some(true),
        target: Some(Target {
            pose: Framed::new(Pose2::new(1.0, -0.5, 0.5)),
            avoid: true,
            plan: false,
        }),
    };
    // Checked by hand against the rules of `mrt_dcdt::describe`: the message is the first
    // object, named and classed `RobotCommand`; its numbers in field order (`kick`'s i64 too)
    // have a `value`; `needs`, a sequence of pairs, gives `needs[0][0]` (the LPS index) and
    // `needs[0][1]` (the necessity); bools and the behavior's name are symbols; the structs
    // are the next objects: `twist`, `target`, and the target's pose, `target.pose`, of class
    // `Pose2`. No field names an uncertainty: variability 0, reliability 1 everywhere.
    let expected = r#"<message timestamp="1.500000000">
  <object name="RobotCommand" class="RobotCommand">
    <attribute name="kick" value="2" variability="0" reliability="1"/>
    <attribute name="needs[0][0]" value="0" variability="0" reliability="1"/>
    <attribute name="needs[0][1]" value="0.8" variability="0" reliability="1"/>
    <attribute name="track_landmarks" symbol="false" variability="0" reliability="1"/>
    <attribute name="behavior" symbol="Score" variability="0" reliability="1"/>
    <attribute name="book_ball" symbol="true" variability="0" reliability="1"/>
  </object>
  <object name="twist" class="Twist">
    <attribute name="vx" value="0.3" variability="0" reliability="1"/>
    <attribute name="vy" value="0" variability="0" reliability="1"/>
    <attribute name="omega" value="-0.25" variability="0" reliability="1"/>
  </object>
  <object name="target" class="Target">
    <attribute name="avoid" symbol="true" variability="0" reliability="1"/>
    <attribute name="plan" symbol="false" variability="0" reliability="1"/>
  </object>
  <object name="target.pose" class="Pose2">
    <attribute name="x" value="1" variability="0" reliability="1"/>
    <attribute name="y" value="-0.5" variability="0" reliability="1"/>
    <attribute name="theta" value="0.5" variability="0" reliability="1"/>
  </object>
</message>"#;
    assert_eq!(form_of(&command).to_xml(), expected);
    assert_eq!(SelfDescribing::from_xml(expected).ok(), Some(form_of(&command)));
}

#[test]
fn a_world_snapshot() {
    let f = form_of(&filled_snapshot());
    assert_eq!(attr(&f, "WorldSnapshot", "role"), (sym("attacker"), 0.0, 1.0));
    assert_eq!(attr(&f, "WorldSnapshot", "game_state"), (sym("Playing"), 0.0, 1.0));
    assert_eq!(attr(&f, "WorldSnapshot", "ball_vel[1]"), (num(-0.05), 0.0, 1.0));
    // The ball's LPS object: its reliability is its attributes'.
    assert_eq!(attr(&f, "lps[0]", "rho"), (num(2.4), 0.0, 0.9));
    // An estimate's quality is the reliability of its pose.
    assert_eq!(attr(&f, "my_pos.pose", "x"), (num(-1.0), 0.0, 0.8));
    assert_eq!(attr(&f, "mates[0].at.pose", "y"), (num(0.3), 0.0, 0.5));
    assert_eq!(attr(&f, "mates[0]", "keeper"), (sym("true"), 0.0, 1.0));
    // An anchored robot: `at_sigma` (of its place) is the variability of its position only.
    assert_eq!(class(&f, "robots[0]"), "AnchoredRobot");
    assert_eq!(attr(&f, "robots[0]", "class"), (sym("opponent"), 0.0, 0.6));
    assert_eq!(attr(&f, "robots[0]", "at[0]"), (num(1.5), 0.12, 0.6));
    assert_eq!(attr(&f, "robots[0]", "at[1]"), (num(-0.2), 0.12, 0.6));
    assert_eq!(attr(&f, "robots[0]", "velocity[0]"), (num(0.01), 0.0, 0.6));
    assert_eq!(attr(&f, "robots[0]", "theta"), (num(-0.1), 0.0, 0.6));
    assert_eq!(class(&f, "kickoff_pose"), "Pose2");
    assert_eq!(class(&f, "job"), "ScareJob");
    assert_eq!(attr(&f, "job", "position[1]"), (num(-2.0), 0.0, 1.0));
    assert!(f.object("job").and_then(|o| o.attribute("aim[0]")).is_none());
}

#[test]
fn a_mate_report() {
    let f = form_of(&filled_report());
    assert_eq!(attr(&f, "MateReport", "ball_sigma"), (num(0.15), 0.0, 1.0));
    // `ball_sigma` is the variability of the ball's numbers, its quality their reliability.
    assert_eq!(attr(&f, "ball.pose", "x"), (num(2.0), 0.15, 0.7));
    assert_eq!(attr(&f, "ball", "quality"), (num(0.7), 0.0, 1.0));
    assert_eq!(attr(&f, "pose.pose", "x"), (num(-1.0), 0.0, 0.8));
    assert_eq!(attr(&f, "robots[0]", "at[0]"), (num(1.5), 0.12, 1.0));
    assert_eq!(class(&f, "booking"), "BookingReport");
    assert_eq!(attr(&f, "booking", "grant[0]"), (num(2.0), 0.0, 1.0));
    assert_eq!(attr(&f, "scare", "attitudes[1]"), (num(0.25), 0.0, 1.0));
    assert_eq!(attr(&f, "scare", "doing[1]"), (num(1.0), 0.0, 1.0));
}

#[test]
fn odometry_and_camera_frames() {
    let f = form_of(&filled_odometry());
    assert_eq!(class(&f, "mice"), "MiceReadings");
    assert_eq!(attr(&f, "wheels", "dtheta"), (num(0.01), 0.0, 1.0));
    // A framed pose is its pose.
    assert_eq!(class(&f, "placed"), "Pose2");
    assert_eq!(attr(&f, "placed", "x"), (num(-4.5), 0.0, 1.0));
    // A camera image is its size, not its 640 × 480 × 3 bytes.
    let f = form_of(&filled_camera());
    assert_eq!(attr(&f, "image", "rgb"), (sym("<921600 bytes>"), 0.0, 1.0));
    assert_eq!(attr(&f, "sightings[0]", "distance"), (num(2.5), 0.0, 1.0));
    assert!(f.object("sightings[1]").is_none(), "not seen");
    assert_eq!(attr(&f, "robots[0]", "marker"), (sym("cyan"), 0.0, 1.0));
    // A pair of standard deviations is a pair of numbers.
    assert_eq!(attr(&f, "robots[0]", "sigma[1]"), (num(0.05), 0.0, 1.0));
    assert!(f.to_xml().contains(r#"symbol="&lt;921600 bytes&gt;""#));
    // No echo: an infinite range reads back.
    let f = form_of(&SonarScan { sonars: vec![Sonar::new(0.0, f64::INFINITY)] });
    assert_eq!(attr(&f, "sonars[0]", "range"), (num(f64::INFINITY), 0.0, 1.0));
}

// ---------------------------------------------------------------------------------------------
// Samples

fn filled_snapshot() -> WorldSnapshot {
    let mut w = WorldSnapshot { time: Time(12_500_000_000), ..WorldSnapshot::default() };
    w.lps[lps::BALL] = Lpo { rho: 2.4, theta: 0.1, reliability: 0.9, seen_ago: 0.0 };
    w.my_pos = Estimate { pose: Framed::new(Pose2::new(-1.0, 0.0, 0.0)), quality: 0.8 };
    w.ball_vel = Framed::new(Vec2::new(0.1, -0.05));
    w.global_ball = Estimate { pose: Framed::new(Pose2::new(2.0, 0.5, 0.0)), quality: 0.7 };
    w.mates = vec![Mate {
        id: 2,
        at: Estimate { pose: Framed::new(Pose2::new(0.0, 0.3, 1.0)), quality: 0.5 },
        keeper: true,
    }];
    w.robots = vec![AnchoredRobot {
        id: 5,
        class: RobotClass::Opponent,
        at: Framed::new(Point2::new(1.5, -0.2)),
        velocity: Framed::new(Vec2::new(0.01, 0.0)),
        at_sigma: 0.12,
        rho: 2.5,
        theta: -0.1,
        reliability: 0.6,
        seen_ago: 0.0,
    }];
    w.role = "attacker".to_owned();
    w.ball_booked = true;
    w.game_state = GameState::Playing;
    w.kickoff_pose = Some(Framed::new(Pose2::new(-0.5, 0.0, 0.0)));
    w.needs_localization = true;
    w.job = Some(ScareJob {
        activity: "BringBall".to_owned(),
        functionality: "carrier".to_owned(),
        subtask: "ReachBall".to_owned(),
        position: Some(Framed::new(Point2::new(1.0, -2.0))),
        aim: None,
        kick: true,
    });
    w
}

fn filled_report() -> MateReport {
    let mut report = MateReport::of(3, false, &filled_snapshot()).with_ball_sigma(0.15);
    report.booking = BookingReport {
        stamp: 12.5,
        claim: Some(12.0),
        grant: Some((2, 11.5)),
        echo: vec![(2, 12.4)],
    };
    report.role = "attacker".to_owned();
    report.scare = ScareReport {
        table: 77,
        attitudes: vec![0.5, 0.25],
        opportunity: vec![1.0],
        doing: Some((0, 1)),
    };
    report
}

fn filled_odometry() -> Odometry {
    Odometry {
        mice: MiceReadings::new(0.001, 0.02, -0.001, 0.021),
        wheels: Displacement::new(0.02, 0.0, 0.01),
        placed: Some(Framed::new(Pose2::new(-4.5, 0.0, 0.0))),
    }
}

fn sighting() -> Sighting {
    Sighting { distance: 2.5, bearing: -0.3 }
}

fn robot_sighting() -> RobotSighting {
    RobotSighting { sighting: sighting(), sigma: Some((0.1, 0.05)), marker: Some(Marker::Cyan) }
}

fn filled_camera() -> CameraFrame {
    let mut sightings = [None; FIELD_OBJECTS];
    sightings[sighting::BALL] = Some(sighting());
    sightings[sighting::LANDMARK0] = Some(sighting());
    CameraFrame {
        time: 3.25,
        sightings,
        robots: vec![robot_sighting()],
        image: Some(Image::new(640, 480)),
        pan: Some(0.2),
        up_image: Some(Image::new(2, 2)),
    }
}

impl Samples for WorldSnapshot {
    fn samples() -> Vec<Self> {
        vec![WorldSnapshot::default(), filled_snapshot()]
    }
}

impl Samples for RobotCommand {
    fn samples() -> Vec<Self> {
        let filled = RobotCommand {
            kick: Some(-1),
            needs: vec![(0, 1.0), (3, 0.5)],
            track_landmarks: true,
            behavior: Some("GoToBall".to_owned()),
            book_ball: Some(false),
            target: Some(Target { avoid: false, plan: true, ..Target::default() }),
            ..RobotCommand::default()
        };
        vec![RobotCommand::default(), filled]
    }
}

impl Samples for BehaviorStatus {
    fn samples() -> Vec<Self> {
        let filled = BehaviorStatus {
            path: "Attacker/Score/Align".to_owned(),
            behavior: Some("Align".to_owned()),
            reloaded: vec!["attacker.lua".to_owned()],
            errors: vec!["attacker.lua:3: <oops> & \"quotes\"".to_owned()],
            activations: vec![("Align".to_owned(), 0.75)],
        };
        vec![BehaviorStatus::default(), filled]
    }
}

impl Samples for ReloadRequest {
    fn samples() -> Vec<Self> {
        vec![ReloadRequest]
    }
}

impl Samples for BehaviorPush {
    fn samples() -> Vec<Self> {
        let filled = BehaviorPush {
            robot: 1,
            request: u64::MAX,
            file: "attacker.lua".to_owned(),
            source: "function run()\n\tsetVlin(300)\nend\n".to_owned(),
        };
        vec![BehaviorPush::default(), filled]
    }
}

impl Samples for BehaviorPushReply {
    fn samples() -> Vec<Self> {
        let filled = BehaviorPushReply {
            robot: 1,
            request: 9,
            file: "attacker.lua".to_owned(),
            installed: false,
            reloaded: Vec::new(),
            error: Some("attacker.lua:2: unexpected symbol".to_owned()),
            line: Some(2),
        };
        vec![BehaviorPushReply::default(), filled]
    }
}

impl Samples for MateReport {
    fn samples() -> Vec<Self> {
        vec![MateReport::of(0, false, &WorldSnapshot::default()), filled_report()]
    }
}

impl Samples for SonarScan {
    fn samples() -> Vec<Self> {
        let ring =
            (0..16).map(|i| Sonar::new(Sonar::ring_bearing(i, 16), 0.5 + i as f64)).collect();
        vec![SonarScan::default(), SonarScan { sonars: ring }]
    }
}

impl Samples for MotorCommand {
    fn samples() -> Vec<Self> {
        let filled = MotorCommand { twist: Twist::new(1.2, -0.3, 0.5), kick: true };
        vec![MotorCommand::default(), filled]
    }
}

impl Samples for Odometry {
    fn samples() -> Vec<Self> {
        vec![Odometry::default(), filled_odometry()]
    }
}

impl Samples for CameraFrame {
    fn samples() -> Vec<Self> {
        vec![CameraFrame::default(), filled_camera()]
    }
}

impl Samples for GameInfo {
    fn samples() -> Vec<Self> {
        let filled = GameInfo {
            state: GameState::Ready,
            attack: -1.0,
            kickoff_pose: Some(Framed::new(Pose2::new(-2.0, 1.0, 0.0))),
            marker: Some(Marker::Magenta),
        };
        vec![GameInfo::default(), filled]
    }
}

impl Samples for Localization {
    fn samples() -> Vec<Self> {
        let filled = Localization {
            pose: Framed::new(Pose2::new(1.0, -2.0, 0.5)),
            sigma_xy: 0.1,
            sigma_theta: 0.05,
            quality: 0.9,
            counts: FilterCounts { mice: 100, corrections: 7, ..FilterCounts::default() },
            ball: Some(BallBelief {
                at: Framed::new(Point2::new(2.0, 0.5)),
                velocity: None,
                seen_ago: 0.2,
            }),
        };
        vec![Localization::default(), filled]
    }
}

impl Samples for Percepts {
    fn samples() -> Vec<Self> {
        let mut filled = Percepts { time: 3.25, ..Percepts::default() };
        filled.sightings[sighting::BALL] = Some(sighting());
        filled.sigmas[sighting::BALL] = Some((0.02, 0.01));
        filled.pixels[sighting::BALL] = 120;
        filled.line_points =
            vec![Framed::new(Point2::new(1.0, 0.5)), Framed::new(Point2::new(1.2, 0.5))];
        filled.robots = vec![robot_sighting()];
        let post =
            PostSighting { sighting: sighting(), sigma: (0.1, 0.02), east: true, pixels: 40 };
        filled.posts = vec![post];
        filled.goal_corners = vec![post];
        filled.pan = Some(0.0);
        let at = |kind, x, y, w, h| ImageDetection { kind, x, y, w, h };
        filled.detections = Some(ImageDetections {
            width: 320,
            height: 240,
            items: vec![
                at(DetectionKind::Ball, 160.5, 200.0, 12.0, 12.0),
                at(DetectionKind::Post, 40.0, 100.0, 6.0, 30.0),
                at(DetectionKind::Line, 8.5, 230.0, 0.0, 0.0),
            ],
        });
        vec![Percepts::default(), filled]
    }
}

impl Samples for HfsmStructure {
    fn samples() -> Vec<Self> {
        let state = |name: &str, runs: Option<&str>| HfsmState {
            name: name.to_owned(),
            runs: runs.map(str::to_owned),
        };
        let filled = HfsmStructure {
            file: "player.hfsm.lua".to_owned(),
            root: "Player".to_owned(),
            machines: vec![
                HfsmMachine {
                    name: "Player".to_owned(),
                    initial: "Wait".to_owned(),
                    states: vec![state("Wait", None), state("Attack", Some("Attack"))],
                    transitions: vec![HfsmTransition {
                        name: "Go".to_owned(),
                        from: "Wait".to_owned(),
                        to: "Attack".to_owned(),
                        priority: 0.0,
                        test: "chaos.getCurrentState() == PLAYING".to_owned(),
                    }],
                },
                HfsmMachine {
                    name: "Attack".to_owned(),
                    initial: "GoToBall".to_owned(),
                    states: vec![state("GoToBall", None)],
                    transitions: Vec::new(),
                },
            ],
        };
        vec![HfsmStructure::default(), filled]
    }
}

impl Samples for PlanRequest {
    fn samples() -> Vec<Self> {
        vec![PlanRequest::default(), PlanRequest { to: Framed::new(Pose2::new(3.0, 0.0, 0.0)) }]
    }
}

impl Samples for PlannedPath {
    fn samples() -> Vec<Self> {
        let filled = PlannedPath {
            to: Framed::new(Pose2::new(3.0, 0.0, 0.0)),
            poses: vec![Framed::new(Pose2::identity()), Framed::new(Pose2::new(0.25, 0.0, 0.0))],
            length: 0.25,
            error: String::new(),
        };
        vec![PlannedPath::default(), filled]
    }
}

#[test]
fn localization_sigmas() {
    let f = form_of(&Localization::samples()[1]);
    assert_eq!(attr(&f, "pose", "x"), (num(1.0), 0.1, 0.9));
    assert_eq!(attr(&f, "pose", "theta"), (num(0.5), 0.05, 0.9));
    // `sigma_xy` is of the pose's `x` and `y` alone; the quality reaches the ball too.
    assert_eq!(attr(&f, "ball", "at[0]"), (num(2.0), 0.0, 0.9));
}
