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

    /// Arbitrary text never panics the loader.
    #[test]
    fn arbitrary_text_never_panics(text in any::<String>()) {
        let _ = load(&text);
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
        if let Ok(robot) = load(&mutated) {
            // Whatever loads evaluates without a panic or a NaN.
            let mut data = RobotData::new(&robot);
            let q = vec![0.1; robot.dof()];
            robot.forward_kinematics(&mut data, &q).unwrap();
            let mut t = vec![0.0; robot.dof()];
            robot.gravity_torque(&mut data, &mut t).unwrap();
            prop_assert!(t.iter().all(|x| x.is_finite()));
        }
    }
}
