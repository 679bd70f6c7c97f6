//! Every malformed input is a distinct typed error whose message names the element at fault.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::Vector3;
use proptest::prelude::*;
use sinew_robot::{ChainSettings, Robot, RobotData, RobotError, UniformChain};
use sinew_testkit::cdhrm5;

fn settings() -> ChainSettings {
    ChainSettings { tip_link: "tip".to_owned(), gravity: Vector3::new(0.0, 0.0, -9.81) }
}

/// A two-joint chain `base → j1 → l1 → j2 → tip`, with `{J1}`, `{J2}`, `{EXTRA}` and `{MASS}`
/// placeholders for the cases below.
const TEMPLATE: &str = r#"<?xml version="1.0"?>
<robot name="two">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0 0 0.1"/><mass value="{MASS}"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-4"/></inertial></link>
  <link name="tip"/>
  <joint name="j1" type="{J1}"><parent link="{P1}"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><axis xyz="{AXIS}"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="tip"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  {EXTRA}
</robot>"#;

fn urdf(j1: &str, p1: &str, axis: &str, mass: &str, extra: &str) -> String {
    TEMPLATE
        .replace("{J1}", j1)
        .replace("{P1}", p1)
        .replace("{AXIS}", axis)
        .replace("{MASS}", mass)
        .replace("{EXTRA}", extra)
}

fn load(text: &str) -> Result<Robot, RobotError> {
    Robot::from_urdf_str(text, "test.urdf", &settings())
}

fn valid() -> String {
    urdf("revolute", "base", "1 0 0", "0.5", "")
}

#[test]
fn the_template_is_valid() {
    let robot = load(&valid()).unwrap();
    assert_eq!(robot.dof(), 2);
    assert_eq!(robot.joints()[0].name, "j1");
}

#[test]
fn missing_file() {
    let err = sinew_robot::load("/nonexistent/robot").unwrap_err();
    assert!(matches!(err, RobotError::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("/nonexistent/robot"), "{err}");
}

#[test]
fn missing_urdf_named_by_a_description() {
    let dir = std::env::temp_dir().join(format!("sinew-missing-urdf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("robot.toml"),
        "urdf = \"gone.urdf\"\ntip_link = \"tip\"\ngravity = [0.0, 0.0, -9.81]\n",
    )
    .unwrap();
    let err = sinew_robot::load(&dir).unwrap_err();
    assert!(matches!(err, RobotError::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("gone.urdf"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn invalid_description() {
    let dir = std::env::temp_dir().join(format!("sinew-bad-description-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("robot.toml"), "urdf = \"x.urdf\"\ngravity = \"down\"\n").unwrap();
    let err = sinew_robot::load(&dir).unwrap_err();
    assert!(matches!(err, RobotError::InvalidDescription { .. }), "{err:?}");
    assert!(err.to_string().contains("robot.toml"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn invalid_xml() {
    let err = load("<robot name=\"x\"><link name=\"a\"></robot").unwrap_err();
    assert!(matches!(err, RobotError::InvalidUrdf { .. }), "{err:?}");
    assert!(err.to_string().contains("test.urdf"), "{err}");
}

#[test]
fn unknown_parent_link() {
    let err = load(&urdf("revolute", "nowhere", "1 0 0", "0.5", "")).unwrap_err();
    assert!(
        matches!(err, RobotError::UnknownLink { ref joint, ref link, .. } if joint == "j1" && link == "nowhere"),
        "{err:?}"
    );
    assert!(err.to_string().contains("`nowhere`") && err.to_string().contains("`j1`"), "{err}");
}

#[test]
fn kinematic_loop() {
    // A third joint makes `base` the child of `tip`: every link has a parent.
    let extra =
        r#"<joint name="back" type="fixed"><parent link="tip"/><child link="base"/></joint>"#;
    let err = load(&urdf("revolute", "base", "1 0 0", "0.5", extra)).unwrap_err();
    assert!(matches!(err, RobotError::KinematicLoop { .. }), "{err:?}");
    assert!(err.to_string().contains("loop through link"), "{err}");
}

#[test]
fn link_with_two_parents_is_a_loop() {
    let extra =
        r#"<joint name="again" type="fixed"><parent link="base"/><child link="tip"/></joint>"#;
    let err = load(&urdf("revolute", "base", "1 0 0", "0.5", extra)).unwrap_err();
    assert!(matches!(err, RobotError::KinematicLoop { ref link, .. } if link == "tip"), "{err:?}");
}

#[test]
fn prismatic_joint() {
    let err = load(&urdf("prismatic", "base", "1 0 0", "0.5", "")).unwrap_err();
    assert!(
        matches!(err, RobotError::UnsupportedJoint { ref joint, ref kind, .. } if joint == "j1" && kind == "prismatic"),
        "{err:?}"
    );
    assert!(err.to_string().contains("`j1` is prismatic"), "{err}");
}

#[test]
fn negative_mass() {
    let err = load(&urdf("revolute", "base", "1 0 0", "-0.5", "")).unwrap_err();
    assert!(
        matches!(err, RobotError::InvalidMass { ref link, mass, .. } if link == "l1" && mass == -0.5),
        "{err:?}"
    );
    assert!(err.to_string().contains("`l1`"), "{err}");
}

#[test]
fn zero_joint_axis() {
    let err = load(&urdf("revolute", "base", "0 0 0", "0.5", "")).unwrap_err();
    assert!(matches!(err, RobotError::ZeroAxis { ref joint, .. } if joint == "j1"), "{err:?}");
    assert!(err.to_string().contains("`j1` has a zero axis"), "{err}");
}

#[test]
fn branching_chain() {
    let extra = r#"<link name="side"/><joint name="j3" type="revolute"><parent link="base"/><child link="side"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>"#;
    let err = load(&urdf("revolute", "base", "1 0 0", "0.5", extra)).unwrap_err();
    assert!(
        matches!(err, RobotError::BranchingChain { ref link, .. } if link == "base"),
        "{err:?}"
    );
}

#[test]
fn fixed_side_branch_is_folded_not_an_error() {
    let extra = r#"<link name="camera"/><joint name="cam" type="fixed"><parent link="l1"/><child link="camera"/>
        <origin xyz="0.03 0 0"/></joint>"#;
    let robot = load(&urdf("revolute", "base", "1 0 0", "0.5", extra)).unwrap();
    assert_eq!(robot.link("camera").unwrap().body, 1);
}

#[test]
fn two_roots() {
    let extra = r#"<link name="floating"/>"#;
    let err = load(&urdf("revolute", "base", "1 0 0", "0.5", extra)).unwrap_err();
    assert!(matches!(err, RobotError::MultipleRoots { .. }), "{err:?}");
    assert!(err.to_string().contains("`floating`"), "{err}");
}

#[test]
fn duplicate_link() {
    let extra = r#"<link name="l1"/>"#;
    let err = load(&urdf("revolute", "base", "1 0 0", "0.5", extra)).unwrap_err();
    assert!(matches!(err, RobotError::DuplicateLink { ref link, .. } if link == "l1"), "{err:?}");
}

#[test]
fn duplicate_joint() {
    let extra = r#"<link name="l2"/><joint name="j2" type="fixed"><parent link="tip"/><child link="l2"/></joint>"#;
    let err = load(&urdf("revolute", "base", "1 0 0", "0.5", extra)).unwrap_err();
    assert!(
        matches!(err, RobotError::DuplicateJoint { ref joint, .. } if joint == "j2"),
        "{err:?}"
    );
    assert_eq!(err.to_string(), "test.urdf: joint `j2` is defined twice");
}

#[test]
fn non_finite_urdf_values_name_the_element_and_field() {
    // A joint origin.
    let text = valid().replacen(r#"<origin xyz="0 0 0.2"/>"#, r#"<origin xyz="0 0 inf"/>"#, 1);
    let err = load(&text).unwrap_err();
    assert!(
        matches!(err, RobotError::NonFinite { ref element, ref field, .. } if element == "joint `j2`" && field == "origin"),
        "{err:?}"
    );
    assert_eq!(err.to_string(), "test.urdf: joint `j2`: `origin` is not finite (or beyond ±1e9)");
    // A joint axis.
    let err = load(&urdf("revolute", "base", "nan 0 1", "0.5", "")).unwrap_err();
    assert_eq!(err.to_string(), "test.urdf: joint `j1`: `axis` is not finite (or beyond ±1e9)");
    // A link's inertia and its inertial origin.
    let err = load(&valid().replacen(r#"ixx="1e-3""#, r#"ixx="NaN""#, 1)).unwrap_err();
    assert!(matches!(err, RobotError::NonFinite { .. }), "{err:?}");
    assert_eq!(
        err.to_string(),
        "test.urdf: link `l1` inertial: `inertia` is not finite (or beyond ±1e9)"
    );
    let err = load(&valid().replacen(r#"xyz="0 0 0.1"/><mass"#, r#"xyz="0 -inf 0.1"/><mass"#, 1))
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "test.urdf: link `l1` inertial: `origin` is not finite (or beyond ±1e9)"
    );
    // Finite but absurd: a torque of 1e308 m × 0.5 kg × 9.81 m/s² overflows (proptest found
    // `xyz="0 01e308 0.1"`, which loaded and gave an infinite gravity torque).
    let err = load(&valid().replacen(r#"xyz="0 0 0.1"/><mass"#, r#"xyz="0 1e308 0.1"/><mass"#, 1))
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "test.urdf: link `l1` inertial: `origin` is not finite (or beyond ±1e9)"
    );
    assert!(
        load(&valid().replacen(r#"xyz="0 0 0.1"/><mass"#, r#"xyz="0 1e9 0.1"/><mass"#, 1)).is_ok()
    );
    let err = load(&urdf("revolute", "base", "1 0 0", "2e9", "")).unwrap_err();
    assert!(matches!(err, RobotError::InvalidMass { mass, .. } if mass == 2e9), "{err:?}");
}

#[test]
fn non_finite_gravity_in_the_description() {
    let dir = std::env::temp_dir().join(format!("sinew-nan-gravity-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("robot.toml"),
        "urdf = \"x.urdf\"\ntip_link = \"tip\"\ngravity = [0.0, 0.0, nan]\n",
    )
    .unwrap();
    let err = sinew_robot::RobotDescription::read(&dir).unwrap_err();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(
        matches!(err, RobotError::InvalidGravity { gravity, .. } if gravity[2].is_nan()),
        "{err:?}"
    );
    let message = err.to_string();
    assert!(message.contains("robot.toml") && message.contains("gravity"), "{message}");
}

#[test]
fn a_body_index_the_robot_does_not_have() {
    let robot = load(&valid()).unwrap();
    let mut data = RobotData::new(&robot);
    robot.forward_kinematics(&mut data, &[0.0, 0.0]).unwrap();
    let bodies = robot.bodies().len();
    let point = sinew_robot::BodyPoint { body: bodies + 7, point: Vector3::zeros() };
    let err = robot.point_position(&data, &point).unwrap_err();
    assert!(matches!(err, RobotError::NoSuchBody { body, .. } if body == bodies + 7), "{err:?}");
    assert_eq!(
        err.to_string(),
        format!("body index {} is out of range: the robot has {bodies} bodies", bodies + 7)
    );
}

#[test]
fn a_wrong_size_output_names_what_was_passed() {
    let robot = load(&valid()).unwrap();
    let mut data = RobotData::new(&robot);
    robot.forward_kinematics(&mut data, &[0.0, 0.0]).unwrap();
    let err = robot.forward_kinematics(&mut data, &[0.0; 3]).unwrap_err();
    assert!(err.to_string().ends_with("expected 2 entries, got 3"), "{err}");
    let mut t = vec![0.0; 5];
    let err = robot.gravity_torque(&mut data, &mut t).unwrap_err();
    assert!(matches!(err, RobotError::DimensionMismatch { expected: 2, got: 5, .. }), "{err:?}");
    assert!(err.to_string().ends_with("expected 2 entries, got 5"), "{err}");
}

#[test]
fn inverted_limits() {
    let text = valid().replacen(r#"lower="-1" upper="1""#, r#"lower="1" upper="-1""#, 1);
    let err = load(&text).unwrap_err();
    assert!(matches!(err, RobotError::InvalidLimits { ref joint, .. } if joint == "j1"), "{err:?}");
}

#[test]
fn unknown_tip_link() {
    let settings = ChainSettings { tip_link: "hand".to_owned(), gravity: Vector3::zeros() };
    let err = Robot::from_urdf_str(&valid(), "test.urdf", &settings).unwrap_err();
    assert!(matches!(err, RobotError::NoSuchLink { ref link, .. } if link == "hand"), "{err:?}");
}

#[test]
fn no_revolute_joint() {
    let err = UniformChain { joints: 0, ..cdhrm5::uniform_chain(0) }.build().unwrap_err();
    assert!(matches!(err, RobotError::NoJoints { .. }), "{err:?}");
}

#[test]
fn wrong_configuration_length_nan_and_out_of_limits() {
    let robot = load(&valid()).unwrap();
    let mut data = RobotData::new(&robot);
    let err = robot.forward_kinematics(&mut data, &[0.0; 3]).unwrap_err();
    assert!(matches!(err, RobotError::DimensionMismatch { expected: 2, got: 3, .. }), "{err:?}");
    let err = robot.forward_kinematics(&mut data, &[0.0, f64::NAN]).unwrap_err();
    assert!(
        matches!(err, RobotError::NonFiniteAngle { ref joint, .. } if joint == "j2"),
        "{err:?}"
    );
    let err = robot.check_limits(&[1.5, 0.0]).unwrap_err();
    assert!(
        matches!(err, RobotError::OutOfLimits { ref joint, position, .. } if joint == "j1" && position == 1.5),
        "{err:?}"
    );
    assert!(err.to_string().contains("`j1`"), "{err}");
    robot.check_limits(&[0.5, -0.5]).unwrap();
}

#[test]
fn workspace_of_another_robot() {
    let robot = load(&valid()).unwrap();
    let other = cdhrm5::robot();
    let mut data = RobotData::new(&other);
    let err = robot.forward_kinematics(&mut data, &[0.0, 0.0]).unwrap_err();
    assert!(matches!(err, RobotError::WorkspaceMismatch { data_dof: 10, robot_dof: 2 }), "{err:?}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// Arbitrary text never panics the loader; what it rejects it names in one line.
    #[test]
    fn arbitrary_text_never_panics(text in any::<String>()) {
        match load(&text) {
            Err(err) => assert_one_line_naming_the_source(&err),
            Ok(robot) => assert_evaluates_finitely(&robot),
        }
    }

    /// URDF-looking text: the valid file with a slice cut out and a token spliced in.
    #[test]
    fn mutated_urdf_never_panics(
        start in 0usize..2000,
        len in 0usize..200,
        token in prop::sample::select(vec!["", "<", ">", "/>", "\"", "nan", "-1", "inf", "1e308", "<link name=\"l1\"/>",
            "type=\"planar\"", "<joint name=\"j\" type=\"fixed\"><parent link=\"tip\"/><child link=\"base\"/></joint>"]),
    ) {
        let text = valid();
        let mut start = start.min(text.len());
        while !text.is_char_boundary(start) { start -= 1; }
        let mut end = (start + len).min(text.len());
        while !text.is_char_boundary(end) { end -= 1; }
        let mutated = format!("{}{}{}", &text[..start], token, &text[end..]);
        match load(&mutated) {
            Err(err) => assert_one_line_naming_the_source(&err),
            Ok(robot) => assert_evaluates_finitely(&robot),
        }
    }
}

/// A loader error is one non-empty line that names the file (`test.urdf`), or, for a tip link
/// the chain does not have, the robot and the link asked for.
fn assert_one_line_naming_the_source(err: &RobotError) {
    let message = err.to_string();
    assert!(!message.trim().is_empty() && !message.contains('\n'), "{message:?}");
    match err {
        RobotError::NoSuchLink { link, .. } => {
            assert!(message.contains(&format!("`{link}`")), "{message}");
        }
        _ => assert!(message.starts_with("test.urdf: "), "{message}"),
    }
}

/// Whatever loads evaluates without a panic or a NaN: positions, the tip Jacobian, the
/// gravity torque and its derivative.
fn assert_evaluates_finitely(robot: &Robot) {
    let n = robot.dof();
    let mut data = RobotData::new(robot);
    let q = vec![0.1; n];
    robot.forward_kinematics(&mut data, &q).unwrap();
    let mut t = vec![0.0; n];
    robot.gravity_torque(&mut data, &mut t).unwrap();
    assert!(t.iter().all(|x| x.is_finite()), "{t:?}");
    let mut j = faer::Mat::zeros(6, n);
    robot.point_jacobian(&data, &robot.tip_point(), j.as_mut()).unwrap();
    let mut k = faer::Mat::zeros(n, n);
    robot.gravity_torque_derivative(&mut data, k.as_mut()).unwrap();
    for m in [&j, &k] {
        assert!((0..m.ncols()).all(|c| (0..m.nrows()).all(|r| m[(r, c)].is_finite())));
    }
}

#[test]
fn a_description_from_its_text_is_the_one_read_from_its_folder() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/cdhrm5");
    let read = sinew_robot::RobotDescription::read(&dir).unwrap();
    let text = std::fs::read_to_string(dir.join("robot.toml")).unwrap();
    let parsed =
        sinew_robot::RobotDescription::from_toml_str(&text, dir.join("robot.toml")).unwrap();
    assert_eq!(parsed, read);
    // The robot built from the two texts alone (no file read) is the one loaded from the folder.
    let urdf = std::fs::read_to_string(&read.urdf).unwrap();
    let name = read.urdf.display().to_string();
    let robot = Robot::from_urdf_str(&urdf, &name, &parsed.settings).unwrap();
    assert_eq!(robot, sinew_robot::load(&dir).unwrap());
    // A bad text names the path it was given.
    let err = sinew_robot::RobotDescription::from_toml_str("gravity = 1", "pickled/robot.toml")
        .unwrap_err();
    assert!(matches!(err, RobotError::InvalidDescription { .. }), "{err:?}");
    assert!(err.to_string().contains("pickled/robot.toml"), "{err}");
    let nan = "urdf = \"x.urdf\"\ntip_link = \"tip\"\ngravity = [0.0, nan, 0.0]\n";
    let err = sinew_robot::RobotDescription::from_toml_str(nan, "r.toml").unwrap_err();
    assert!(matches!(err, RobotError::InvalidGravity { .. }), "{err:?}");
}
