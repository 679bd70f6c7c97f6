//! Every bad routing input is a typed error whose message names the file, the cable and the
//! field at fault; no text, however malformed, makes loading panic.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use sinew_testkit::cdhrm5;
use sinew_testkit::one_joint::HEADER;

use proptest::prelude::*;
use sinew_robot::{ChainSettings, Robot, RobotData};
use sinew_routing::{
    JointProblem, Order, Routing, RoutingData, RoutingError, compute_cable_geometry,
};

const FILE: &str = "test/cables.toml";

/// An explicit routing: the header then the given cables.
fn explicit(cables: &str) -> String {
    format!("{HEADER}{cables}")
}

/// A valid explicit cable of joint 1 (0-based), through the discs of joints 0 and 1.
const GOOD_CABLE: &str = r#"
[[cable]]
name = "good"
holes = [
  { link = "base_link", point = [0.02, 0.0, 0.0] },
  { link = "link1", point = [0.02, 0.0, 0.0] },
  { link = "link1_distal", point = [0.02, 0.0, 0.0] },
  { link = "link2", point = [0.02, 0.0, 0.0] },
]
"#;

/// The pattern with `{MODEL}`, `{PROXIMAL}`, `{DISTAL}` placeholders.
const PATTERN: &str = r#"
[pattern]
model = "routed"
radius = 0.022
theta0 = 0.3
joint_offset = 0.4
proximal_discs = {PROXIMAL}
distal_discs = {DISTAL}
"#;

const PROXIMAL: &str =
    r#"["base_link", "link1_distal", "link2_distal", "link3_distal", "link4_distal"]"#;
const DISTAL: &str = r#"["link1", "link2", "link3", "link4", "link5"]"#;

fn pattern(proximal: &str, distal: &str) -> String {
    format!("{HEADER}{}", PATTERN.replace("{PROXIMAL}", proximal).replace("{DISTAL}", distal))
}

fn load(text: &str) -> Result<Routing, RoutingError> {
    Routing::from_toml_str(text, FILE, &cdhrm5::robot())
}

/// The error of loading `text`, checked to name the file and every given word.
fn error(text: &str, words: &[&str]) -> RoutingError {
    let err = load(text).expect_err("expected an error");
    let message = err.to_string();
    assert!(message.contains(FILE), "message does not name the file: {message}");
    for word in words {
        assert!(message.contains(word), "message does not name `{word}`: {message}");
    }
    err
}

#[test]
fn the_templates_are_valid() {
    let routing = load(&explicit(GOOD_CABLE)).unwrap();
    assert_eq!(routing.cable_joints(), [1]);
    let routing = load(&pattern(PROXIMAL, DISTAL)).unwrap();
    assert_eq!(routing.cable_count(), 15);
}

#[test]
fn missing_file() {
    let robot = cdhrm5::robot();
    let err = sinew_routing::load("/nonexistent/robot", &robot).unwrap_err();
    assert!(matches!(err, RoutingError::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("/nonexistent/robot"), "{err}");
}

#[test]
fn unknown_link() {
    let text = explicit(&GOOD_CABLE.replace(r#"link = "link1_distal""#, r#"link = "link9""#));
    let err = error(&text, &["good", "cable[0].holes[2].link", "link9"]);
    assert!(
        matches!(&err, RoutingError::UnknownLink { cable, field, link, .. }
            if cable == "good" && field == "cable[0].holes[2].link" && link == "link9"),
        "{err:?}"
    );
    // In the pattern: the first cable that uses the disc, and the disc's entry.
    let distal = DISTAL.replace("link3", "linkX");
    let err = error(&pattern(PROXIMAL, &distal), &["j3c1", "pattern.distal_discs[2]", "linkX"]);
    assert!(matches!(err, RoutingError::UnknownLink { .. }), "{err:?}");
}

#[test]
fn hole_off_the_chain() {
    // A hole on link3 (body 6) for a cable anchored on link2 (body 4).
    let text = explicit(&GOOD_CABLE.replace(r#"link = "link1_distal""#, r#"link = "link3""#));
    let err = error(&text, &["good", "cable[0].holes[2].link", "link3"]);
    assert!(
        matches!(&err, RoutingError::HoleOffChain { cable, body: 6, anchor_body: 4, .. } if cable == "good"),
        "{err:?}"
    );
    // The pattern with joint 1's proximal disc on link3, beyond its anchor on link2.
    let proximal = PROXIMAL.replace("link1_distal", "link3");
    let err = error(&pattern(&proximal, DISTAL), &["j2c1", "pattern.proximal_discs[1]", "link3"]);
    assert!(matches!(err, RoutingError::HoleOffChain { .. }), "{err:?}");
}

#[test]
fn too_few_holes() {
    for holes in [r#"[{ link = "link1", point = [0.02, 0.0, 0.0] }]"#, "[]"] {
        let text = explicit(&format!("[[cable]]\nname = \"short\"\nholes = {holes}\n"));
        let err = error(&text, &["short", "cable[0].holes"]);
        assert!(
            matches!(&err, RoutingError::TooFewHoles { cable, .. } if cable == "short"),
            "{err:?}"
        );
    }
}

#[test]
fn zero_length_segment() {
    // The same hole twice.
    let text = explicit(&GOOD_CABLE.replace(
        r#"{ link = "link1_distal", point = [0.02, 0.0, 0.0] }"#,
        r#"{ link = "link1", point = [0.02, 0.0, 0.0] }"#,
    ));
    let err =
        error(&text, &["good", "segment 1", "cable[0].holes[1].link", "cable[0].holes[2].link"]);
    assert!(
        matches!(&err, RoutingError::ZeroLengthSegment { cable, segment: 1, length, .. } if cable == "good" && *length == 0.0),
        "{err:?}"
    );
    // Two links of one body, the same point: link1 at z = 0.22 is link1_distal's origin.
    let text = explicit(&GOOD_CABLE.replace(
        r#"{ link = "link1", point = [0.02, 0.0, 0.0] }"#,
        r#"{ link = "link1", point = [0.02, 0.0, 0.22] }"#,
    ));
    let err = error(&text, &["good", "segment 1"]);
    assert!(matches!(err, RoutingError::ZeroLengthSegment { .. }), "{err:?}");
}

#[test]
fn non_physical_material() {
    for (from, to, field) in [
        ("youngs_modulus = 12.5e9", "youngs_modulus = 0.0", "material.youngs_modulus"),
        ("youngs_modulus = 12.5e9", "youngs_modulus = -1.0", "material.youngs_modulus"),
        ("youngs_modulus = 12.5e9", "youngs_modulus = nan", "material.youngs_modulus"),
        ("diameter = 1.0e-3", "diameter = 0.0", "material.diameter"),
        ("diameter = 1.0e-3", "diameter = -1e-3", "material.diameter"),
        ("diameter = 1.0e-3", "area = 0.0", "material.area"),
        ("diameter = 1.0e-3", "area = -1e-6", "material.area"),
        ("diameter = 1.0e-3", "area = inf", "material.area"),
        ("diameter = 1.0e-3", "diameter = 1.0e-3\narea = 1e-6", "material.area"),
        ("diameter = 1.0e-3", "", "material.area"),
    ] {
        let text = explicit(GOOD_CABLE).replace(from, to);
        let err = error(&text, &[field, "every cable"]);
        assert!(
            matches!(&err, RoutingError::InvalidMaterial { field: f, .. } if *f == field),
            "{to}: {err:?}"
        );
    }
}

#[test]
fn bad_tension_limits() {
    for limits in ["[600.0, 20.0]", "[20.0, 20.0]", "[-1.0, 600.0]", "[20.0, inf]", "[nan, 600.0]"]
    {
        let text = explicit(GOOD_CABLE).replace("[20.0, 600.0]", limits);
        let err = error(&text, &["tension_limits", "every cable"]);
        assert!(matches!(err, RoutingError::InvalidTensionLimits { .. }), "{limits}: {err:?}");
    }
}

#[test]
fn malformed_toml() {
    for text in [
        "tension_limits = [20.0, ".to_owned(),
        "this is not toml".to_owned(),
        explicit(GOOD_CABLE).replace("name = \"good\"", "name = 3"),
        explicit(GOOD_CABLE).replace("name = \"good\"", "name = \"good\"\ncolour = \"red\""),
        explicit(GOOD_CABLE).replace("tension_limits = [20.0, 600.0]", ""),
        explicit(GOOD_CABLE).replace("point = [0.02, 0.0, 0.0] }", "point = [0.02, 0.0] }"),
        explicit(GOOD_CABLE).replace("name = \"good\"", "name = \"good\"\njoint = -1"),
        pattern(PROXIMAL, DISTAL).replace("\"routed\"", "\"tangled\""),
    ] {
        let err = error(&text, &["invalid routing file"]);
        assert!(matches!(err, RoutingError::Parse { .. }), "{text}: {err:?}");
    }
    // The parser's message points at the offending key.
    let text = explicit(GOOD_CABLE).replace("name = \"good\"", "name = \"good\"\ncolour = \"red\"");
    error(&text, &["colour"]);
}

#[test]
fn duplicate_cable() {
    let text = explicit(&format!("{GOOD_CABLE}{GOOD_CABLE}"));
    let err = error(&text, &["good", "cable[1]"]);
    assert!(matches!(err, RoutingError::DuplicateCable { .. }), "{err:?}");
}

#[test]
fn wrong_joint() {
    // A joint the robot does not have.
    let text = explicit(&GOOD_CABLE.replace("name = \"good\"", "name = \"good\"\njoint = 7"));
    let err = error(&text, &["good", "cable[0].joint", "joint 7"]);
    assert!(
        matches!(
            err,
            RoutingError::WrongJoint { problem: JointProblem::NoSuchJoint { joint: 7, .. }, .. }
        ),
        "{err:?}"
    );
    // A joint other than the one the anchor's body is moved by.
    let text = explicit(&GOOD_CABLE.replace("name = \"good\"", "name = \"good\"\njoint = 0"));
    let err = error(&text, &["good", "cable[0].holes[3].link"]);
    assert!(
        matches!(
            err,
            RoutingError::WrongJoint {
                problem: JointProblem::AnchorElsewhere { joint: 0, .. },
                ..
            }
        ),
        "{err:?}"
    );
    // Anchored on the base.
    let text = explicit(
        "[[cable]]\nname = \"flat\"\nholes = [{ link = \"base_link\", point = [0.0, 0.0, 0.0] }, { link = \"base_link\", point = [0.02, 0.0, 0.0] }]\n",
    );
    let err = error(&text, &["flat", "cable[0].holes[1].link", "base body"]);
    assert!(
        matches!(err, RoutingError::WrongJoint { problem: JointProblem::AnchorOnBase, .. }),
        "{err:?}"
    );
    // Not crossing its joint: both holes beyond joint 0's proximal disc, anchored on link1.
    let text = explicit(
        "[[cable]]\nname = \"inside\"\nholes = [{ link = \"cross1\", point = [0.0, 0.0, 0.0] }, { link = \"link1\", point = [0.02, 0.0, 0.0] }]\n",
    );
    let err = error(&text, &["inside", "cable[0].holes", "does not cross"]);
    assert!(
        matches!(
            err,
            RoutingError::WrongJoint {
                problem: JointProblem::NotCrossing { joint: 0, proximal: 0 },
                ..
            }
        ),
        "{err:?}"
    );
}

#[test]
fn cable_form() {
    let both = format!("{}{GOOD_CABLE}", pattern(PROXIMAL, DISTAL));
    let err = error(&both, &["not both"]);
    assert!(matches!(err, RoutingError::CableForm { .. }), "{err:?}");
    let err = error(HEADER, &["no cables"]);
    assert!(matches!(err, RoutingError::CableForm { .. }), "{err:?}");
}

#[test]
fn pattern_values() {
    // Wrong number of discs.
    let err = error(&pattern(r#"["base_link"]"#, DISTAL), &["pattern.proximal_discs", "1 entries"]);
    assert!(matches!(err, RoutingError::PatternSize { expected: 5, got: 1, .. }), "{err:?}");
    // Non-positive radius, per joint.
    let text = pattern(PROXIMAL, DISTAL)
        .replace("radius = 0.022", "radius = [0.02, 0.02, 0.0, 0.02, 0.02]");
    let err = error(&text, &["pattern.radius[2]"]);
    assert!(matches!(err, RoutingError::InvalidValue { .. }), "{err:?}");
    // No radius at all.
    let text = pattern(PROXIMAL, DISTAL).replace("radius = 0.022", "distal_radius = 0.02");
    let err = error(&text, &["pattern.proximal_radius"]);
    assert!(matches!(err, RoutingError::InvalidValue { .. }), "{err:?}");
    // A non-finite angle.
    let text = pattern(PROXIMAL, DISTAL).replace("theta0 = 0.3", "theta0 = inf");
    let err = error(&text, &["pattern.theta0"]);
    assert!(matches!(err, RoutingError::InvalidValue { .. }), "{err:?}");
    // Separate radii are used.
    let text = pattern(PROXIMAL, DISTAL).replace(
        "radius = 0.022",
        "proximal_radius = 0.02\ndistal_radius = [0.021, 0.022, 0.023, 0.024, 0.025]",
    );
    let routing = load(&text).unwrap();
    let cable = &routing.cables()[14];
    let r = |h: usize| cable.holes[h].point.xy().norm();
    assert!(
        (r(0) - 0.02).abs() < 1e-15 && (r(1) - 0.021).abs() < 1e-15 && (r(9) - 0.025).abs() < 1e-15
    );
}

#[test]
fn bad_numbers_in_cables() {
    let text = explicit(&GOOD_CABLE.replace(
        "point = [0.02, 0.0, 0.0] },\n  { link = \"link1\"",
        "point = [nan, 0.0, 0.0] },\n  { link = \"link1\"",
    ));
    let err = error(&text, &["good", "cable[0].holes[0].point"]);
    assert!(matches!(err, RoutingError::InvalidValue { .. }), "{err:?}");
    let text =
        explicit(&GOOD_CABLE.replace("name = \"good\"", "name = \"good\"\nfree_length = -0.5"));
    let err = error(&text, &["good", "cable[0].free_length"]);
    assert!(matches!(err, RoutingError::InvalidValue { .. }), "{err:?}");
    let text = explicit(GOOD_CABLE).replace("free_length = 1.0", "free_length = [1.0, 1.0]");
    let err = error(&text, &["free_length", "2 entries"]);
    assert!(matches!(err, RoutingError::PatternSize { .. }), "{err:?}");
    // Far-away holes: finite, but the cable Hessians' products of lever arms overflow (a
    // proptest case of `mutated_valid_files_never_panic` found it through the pattern's
    // radius). Refused at the point, or the radius, beyond `MAX_HOLE_OFFSET`.
    for far in ["1e308", "1001.0", "-2e3"] {
        let text = explicit(&GOOD_CABLE.replace(
            "point = [0.02, 0.0, 0.0] },\n  { link = \"link1\"",
            &format!("point = [{far}, 0.0, 0.0] }},\n  {{ link = \"link1\""),
        ));
        let err = error(&text, &["good", "cable[0].holes[0].point", "1 km"]);
        assert!(matches!(err, RoutingError::InvalidValue { .. }), "{err:?}");
    }
    let near = explicit(&GOOD_CABLE.replace(
        "point = [0.02, 0.0, 0.0] },\n  { link = \"link1\"",
        "point = [999.0, 0.0, 0.0] },\n  { link = \"link1\"",
    ));
    assert!(load(&near).is_ok(), "a hole within the bound loads");
    for far in ["1e308", "1001.0"] {
        let text = pattern(PROXIMAL, DISTAL).replace("radius = 0.022", &format!("radius = {far}"));
        let err = error(&text, &["pattern.radius", "1 km"]);
        assert!(matches!(err, RoutingError::InvalidValue { .. }), "{err:?}");
    }
}

#[test]
fn pattern_needs_universal_joints() {
    // One revolute joint: a 1-DOF joint, which explicit cables can drive but the three-cable
    // pattern cannot.
    let urdf = r#"<robot name="one"><link name="base"/><link name="tip"/>
      <joint name="j" type="revolute"><parent link="base"/><child link="tip"/>
      <axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"#;
    let settings =
        ChainSettings { tip_link: "tip".to_owned(), gravity: nalgebra::Vector3::zeros() };
    let robot = Robot::from_urdf_str(urdf, "one.urdf", &settings).unwrap();
    assert_eq!(robot.joint_groups().len(), 1);
    assert_eq!(robot.joint_groups()[0], 0..1);
    let text = pattern(r#"["base"]"#, r#"["tip"]"#);
    let err = Routing::from_toml_str(&text, FILE, &robot).unwrap_err();
    assert!(matches!(err, RoutingError::NotUniversal { dof: 1, .. }), "{err:?}");
    assert!(err.to_string().contains(FILE));
    assert!(err.to_string().contains("[[cable]]"), "{err}");
    let cables = "[[cable]]\nname = \"a\"\nholes = [{ link = \"base\", point = [0.0, 0.02, 0.0] }, { link = \"tip\", point = [0.0, 0.02, 0.1] }]\n";
    let routing = Routing::from_toml_str(&explicit(cables), FILE, &robot).unwrap();
    assert_eq!(routing.cable_joints(), &[0]);
    assert_eq!(routing.cable_joint_span(0), Some(0..1));
}

/// Load `text`; when it loads, evaluate it at Q = 0 and at a bent configuration. Nothing may
/// panic, and a routing that loads has finite, positive stiffness.
fn load_and_evaluate(robot: &Robot, text: &str) {
    let routing = match Routing::from_toml_str(text, "<prop>", robot) {
        Ok(routing) => routing,
        Err(err) => {
            // A rejected file: a non-empty headline that names it, on one line; only a TOML
            // parse error adds lines (the parser's quoted excerpt, which the CLI folds into
            // one line, see crates/sinew-cli's `one_line`).
            let message = err.to_string();
            let headline = message.lines().next().unwrap_or_default();
            assert!(headline.starts_with("<prop>: ") && headline.len() > 8, "{message:?}");
            if !matches!(err, RoutingError::Parse { .. }) {
                assert!(!message.contains('\n'), "{message:?}");
            }
            return;
        }
    };
    assert!(routing.cable_stiffness().iter().all(|k| k.is_finite() && *k > 0.0));
    let mut rdata = RobotData::new(robot);
    let mut data = RoutingData::new(&routing);
    let n = robot.dof();
    let mut hessian = faer::Mat::zeros(n, n);
    for q in [0.0, 0.4] {
        let q = vec![q; n];
        match compute_cable_geometry(&routing, robot, &mut rdata, &mut data, &q, Order::Hessians) {
            Ok(()) => {
                // Whatever evaluates is finite: lengths, J_c, every cable's Hessian.
                assert!(data.lengths().unwrap().iter().all(|l| l.is_finite()));
                let j = data.jacobian().unwrap();
                assert!((0..n).all(|d| (0..j.nrows()).all(|c| j[(c, d)].is_finite())));
                for c in 0..routing.cable_count() {
                    data.cable_hessian(&routing, c, hessian.as_mut()).unwrap();
                    assert!(
                        (0..n).all(|a| (0..n).all(|b| hessian[(a, b)].is_finite())),
                        "cable {c}: non-finite Hessian"
                    );
                }
            }
            Err(err) => {
                // A configuration the routing cannot take: one line naming the cable.
                let message = err.to_string();
                assert!(!message.contains('\n') && message.contains("cable `"), "{message:?}");
            }
        }
    }
}

/// The valid files the mutations start from: both cdhrm5 files and an explicit one.
fn valid_files() -> Vec<String> {
    vec![
        std::fs::read_to_string(cdhrm5::dir().join(sinew_routing::ROUTING_FILE)).unwrap(),
        std::fs::read_to_string(cdhrm5::dir().join(sinew_routing::ROUTED_ROUTING_FILE)).unwrap(),
        explicit(GOOD_CABLE),
    ]
}

/// A mutation of a text: replace a byte range by one of a set of troublesome snippets.
fn mutate(text: &str, start: usize, len: usize, snippet: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let start = start % (chars.len() + 1);
    let end = (start + len).min(chars.len());
    let mut out: String = chars[..start].iter().collect();
    out.push_str(snippet);
    out.extend(&chars[end..]);
    out
}

const SNIPPETS: &[&str] = &[
    "",
    "0",
    "-1",
    "0.0",
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "-inf",
    "1e-320",
    "[",
    "]",
    "{",
    "}",
    "\"",
    "=",
    ",",
    "\n",
    "[[cable]]",
    "[pattern]",
    "link1",
    "base_link",
    "\"link9\"",
    "[]",
    "18446744073709551615",
    "99",
    "routed",
    "decoupled",
    "radius = 0.0",
    "joint = 4",
    "holes = []",
    "model = \"routed\"",
    "x = 1",
    "#",
];

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_text_never_panics(text in any::<String>()) {
        load_and_evaluate(&cdhrm5::robot(), &text);
    }

    #[test]
    fn toml_like_text_never_panics(text in "[a-z_\\[\\]=\". 0-9,{}\\n-]{0,200}") {
        load_and_evaluate(&cdhrm5::robot(), &text);
    }

    #[test]
    fn mutated_valid_files_never_panic(
        file in 0usize..3,
        edits in proptest::collection::vec((any::<usize>(), 0usize..12, 0..SNIPPETS.len()), 1..4),
    ) {
        let mut text = valid_files()[file].clone();
        for (start, len, snippet) in edits {
            text = mutate(&text, start, len, SNIPPETS[snippet]);
        }
        load_and_evaluate(&cdhrm5::robot(), &text);
    }
}
