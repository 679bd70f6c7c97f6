//! The text `to_mjcf` writes, parsed back: every convention of the crate docs checked on
//! cdhrm5 (both models), against the robot and routing it was written from.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use roxmltree::{Document, Node};
use sinew_mjcf::{CableModel, MIN_MASS, MjcfError, MjcfOptions, Split, State, to_mjcf};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, PatternModel, Routing, RoutingData, compute_cable_geometry};
use sinew_testkit::cdhrm5::{LOADED_POSE, robot_and_routing};

const WRENCH: [f64; 6] = [0.0, 5.0, 0.0, 0.0, 0.0, 0.0];

fn nums(node: Node<'_, '_>, attr: &str) -> Vec<f64> {
    let text = node
        .attribute(attr)
        .unwrap_or_else(|| panic!("<{}> has no {attr}", node.tag_name().name()));
    text.split_whitespace().map(|t| t.parse().unwrap()).collect()
}

fn elements<'a, 'i>(doc: &'a Document<'i>, tag: &str) -> Vec<Node<'a, 'i>> {
    doc.descendants().filter(|n| n.has_tag_name(tag)).collect()
}

fn lengths(robot: &Robot, routing: &Routing, q: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let mut rd = RobotData::new(robot);
    let mut data = RoutingData::new(routing);
    compute_cable_geometry(routing, robot, &mut rd, &mut data, q, Order::Lengths).unwrap();
    (data.lengths().unwrap().to_vec(), data.segment_lengths().unwrap().to_vec())
}

fn export(
    model: PatternModel,
    tensions: &[f64],
    options: &MjcfOptions,
) -> (Robot, Routing, String) {
    let (robot, routing) = robot_and_routing(model);
    let state = State { q: &LOADED_POSE, tensions, wrench: WRENCH, segment_tensions: None };
    let text = to_mjcf(&robot, &routing, &state, options).unwrap();
    (robot, routing, text)
}

/// Tensions alternating between the low and the high end, so both spring forms appear.
fn mixed_tensions(m: usize) -> Vec<f64> {
    (0..m).map(|c| if c % 2 == 0 { 20.0 } else { 150.0 + c as f64 }).collect()
}

#[test]
fn springs_give_each_cable_its_tension_at_the_pose_in_both_forms() {
    for model in [PatternModel::Decoupled, PatternModel::Routed] {
        let f = mixed_tensions(15);
        let (robot, routing, text) = export(model, &f, &MjcfOptions::default());
        let doc = Document::parse(&text).unwrap();
        let (l, _) = lengths(&robot, &routing, &LOADED_POSE);
        let spatial = elements(&doc, "spatial");
        assert_eq!(spatial.len(), 15);
        let (mut dead_band, mut negative) = (0, 0);
        for (c, (t, cable)) in spatial.iter().zip(routing.cables()).enumerate() {
            assert_eq!(t.attribute("name"), Some(cable.name.as_str()), "routing order");
            let k = nums(*t, "stiffness")[0];
            assert_eq!(k, cable.stiffness, "K_l = E A / l_c, written exactly");
            let sl = nums(*t, "springlength");
            let rest = l[c] - f[c] / k;
            if rest >= 0.0 {
                assert_eq!(sl, vec![0.0, rest], "{}: tension-only form 0 L_u", cable.name);
                dead_band += 1;
            } else {
                assert_eq!(sl, vec![rest, rest], "{}: L_u L_u when L_u < 0", cable.name);
                negative += 1;
            }
            // The tension MuJoCo's spring gives at the pose: k (L − L_u) = f.
            let upper = *sl.last().unwrap();
            assert!((k * (l[c] - upper) - f[c]).abs() <= 1e-9 * f[c], "{}", cable.name);
        }
        match model {
            // The decoupled tendon is the 30 mm crossing; K_l counts the free length:
            // 20 N leaves L_u > 0, above ≈ 91 N it is negative.
            PatternModel::Decoupled => assert_eq!((dead_band, negative), (8, 7)),
            // Routed: the tendon is the whole routed length, L_u > 0 at every tension here.
            PatternModel::Routed => assert!(dead_band >= 8, "{dead_band}"),
        }
        assert!(elements(&doc, "motor").is_empty());
        let key = elements(&doc, "key");
        assert_eq!(nums(key[0], "qpos"), LOADED_POSE.to_vec());
        assert!(key[0].attribute("ctrl").is_none());
    }
}

#[test]
fn motors_pull_with_gear_minus_one_and_the_keyframe_holds_pose_and_tensions() {
    let f: Vec<f64> = (0..15).map(|c| 30.0 + 7.0 * c as f64).collect();
    let options = MjcfOptions { cables: CableModel::Motors, ..MjcfOptions::default() };
    let (_, routing, text) = export(PatternModel::Routed, &f, &options);
    let doc = Document::parse(&text).unwrap();
    for t in elements(&doc, "spatial") {
        assert!(t.attribute("stiffness").is_none() && t.attribute("springlength").is_none());
    }
    let motors = elements(&doc, "motor");
    assert_eq!(motors.len(), 15);
    for (m, cable) in motors.iter().zip(routing.cables()) {
        assert_eq!(m.attribute("tendon"), Some(cable.name.as_str()));
        assert_eq!(nums(*m, "gear"), vec![-1.0]);
        assert_eq!(nums(*m, "ctrlrange"), vec![20.0, 600.0]);
    }
    let key = elements(&doc, "key");
    assert_eq!(nums(key[0], "qpos"), LOADED_POSE.to_vec());
    assert_eq!(nums(key[0], "ctrl"), f);
    let forces = elements(&doc, "actuatorfrc");
    assert_eq!(forces.len(), 15);
    assert_eq!(
        forces[3].attribute("actuator"),
        Some(format!("{}_motor", routing.cables()[3].name).as_str())
    );
}

#[test]
fn a_universal_joint_is_two_hinges_x_then_y_and_the_massless_cross_is_merged() {
    let (robot, _, text) = export(PatternModel::Decoupled, &[20.0; 15], &MjcfOptions::default());
    let doc = Document::parse(&text).unwrap();
    let bodies = elements(&doc, "body");
    // cdhrm5: five links; the five crosses (massless, no hole) are merged, not given mass.
    assert_eq!(bodies.len(), 5);
    assert!(bodies.iter().all(|b| !b.attribute("name").unwrap().starts_with("cross")));
    assert!(!text.contains(&format!("mass=\"{MIN_MASS:?}\"")));
    for (i, body) in bodies.iter().enumerate() {
        let hinges: Vec<Node<'_, '_>> =
            body.children().filter(|n| n.has_tag_name("joint")).collect();
        assert_eq!(hinges.len(), 2, "joint {}", i + 1);
        assert_eq!(hinges[0].attribute("name"), Some(format!("joint{}_x", i + 1).as_str()));
        assert_eq!(nums(hinges[0], "axis"), vec![1.0, 0.0, 0.0]);
        assert_eq!(nums(hinges[1], "axis"), vec![0.0, 1.0, 0.0]);
        assert!(hinges.iter().all(|h| h.attribute("pos").is_none()), "both at the body origin");
        let joint = &robot.joints()[2 * i];
        assert_eq!(nums(hinges[0], "range"), vec![joint.lower, joint.upper]);
        assert!((joint.upper - std::f64::consts::PI / 6.0).abs() < 1e-15);
        // The stated damping, on every hinge.
        assert_eq!(nums(hinges[1], "damping"), vec![sinew_mjcf::DEFAULT_DAMPING]);
        // The body sits d1 beyond the previous disc (0.25 m per link), with the link's inertial.
        let expect_z = if i == 0 { 0.03 } else { 0.25 };
        let pos = nums(*body, "pos");
        assert_eq!(pos[..2], [0.0, 0.0]);
        assert!((pos[2] - expect_z).abs() < 1e-15, "{pos:?}");
        let inertial = body.children().find(|n| n.has_tag_name("inertial")).unwrap();
        assert_eq!(nums(inertial, "mass"), vec![robot.bodies()[2 * i + 2].mass]);
        let comment = format!("cross{}", i + 1);
        assert!(
            body.children().any(|n| n.is_comment() && n.text().unwrap_or("").contains(&comment))
        );
    }
    let contacts: Vec<_> = elements(&doc, "geom")
        .into_iter()
        .filter(|g| g.parent().unwrap().has_tag_name("default"))
        .collect();
    assert_eq!(contacts[0].attribute("contype"), Some("0"));
    assert_eq!(contacts[0].attribute("conaffinity"), Some("0"));
    let option = elements(&doc, "option");
    assert_eq!(nums(option[0], "gravity"), vec![0.0, 9.81, 0.0]);
    let compiler = elements(&doc, "compiler");
    assert_eq!(compiler[0].attribute("angle"), Some("radian"));
    assert_eq!(compiler[0].attribute("autolimits"), Some("true"));
}

#[test]
fn a_massless_cross_that_carries_a_hole_keeps_a_body_with_the_least_mass() {
    let (robot, _) = robot_and_routing(PatternModel::Decoupled);
    let text = r#"
tension_limits = [20.0, 600.0]
free_length = 1.0
[material]
youngs_modulus = 12.5e9
diameter = 1.0e-3
[[cable]]
name = "through_cross"
holes = [
  { link = "base_link", point = [0.02, 0.0, 0.0] },
  { link = "cross1", point = [0.02, 0.0, 0.0] },
  { link = "link1", point = [0.02, 0.0, 0.01] },
]
"#;
    let routing = Routing::from_toml_str(text, "through_cross.toml", &robot).unwrap();
    let q = [0.1; 10];
    let state = State { q: &q, tensions: &[50.0], wrench: [0.0; 6], segment_tensions: None };
    let xml = to_mjcf(&robot, &routing, &state, &MjcfOptions::default()).unwrap();
    let doc = Document::parse(&xml).unwrap();
    let bodies = elements(&doc, "body");
    // cross1 stays (it carries a hole), the other four crosses are merged.
    assert_eq!(bodies.len(), 6);
    let cross = bodies.iter().find(|b| b.attribute("name") == Some("cross1")).unwrap();
    let inertial = cross.children().find(|n| n.has_tag_name("inertial")).unwrap();
    assert_eq!(nums(inertial, "mass"), vec![MIN_MASS]);
    assert!(cross.children().any(|n| n.is_comment() && n.text().unwrap().contains("massless")));
    let hinges: Vec<_> = cross.children().filter(|n| n.has_tag_name("joint")).collect();
    assert_eq!(hinges.len(), 1);
    // Its child, pivot1, holds joint1_y alone.
    let pivot = cross.children().find(|n| n.has_tag_name("body")).unwrap();
    assert_eq!(pivot.attribute("name"), Some("pivot1"));
    assert_eq!(pivot.children().filter(|n| n.has_tag_name("joint")).count(), 1);
    let site = cross.children().find(|n| n.has_tag_name("site")).unwrap();
    assert_eq!(site.attribute("name"), Some("through_cross_h1"));
    assert_eq!(nums(site, "pos"), vec![0.02, 0.0, 0.0]);
}

#[test]
fn one_site_per_hole_in_its_body_frame_a_tip_site_and_tendons_through_them_in_order() {
    let (robot, routing, text) = export(PatternModel::Routed, &[40.0; 15], &MjcfOptions::default());
    let doc = Document::parse(&text).unwrap();
    let sites: Vec<_> =
        elements(&doc, "site").into_iter().filter(|s| s.attribute("name").is_some()).collect();
    let holes: usize = routing.cables().iter().map(|c| c.holes.len()).sum();
    assert_eq!(sites.len(), holes + 1);
    for cable in routing.cables() {
        for (h, hole) in cable.holes.iter().enumerate() {
            let name = format!("{}_h{h}", cable.name);
            let site = sites.iter().find(|s| s.attribute("name") == Some(name.as_str())).unwrap();
            assert_eq!(nums(*site, "pos"), hole.body_point.point.as_slice().to_vec(), "{name}");
            let parent = site.parent().unwrap();
            let body = &robot.bodies()[hole.body_point.body];
            match hole.body_point.body {
                0 => assert!(parent.has_tag_name("worldbody")),
                _ => assert_eq!(parent.attribute("name"), Some(body.name.as_str()), "{name}"),
            }
        }
    }
    let tip = sites.iter().find(|s| s.attribute("name") == Some("tip")).unwrap();
    assert_eq!(nums(*tip, "pos"), robot.tip_point().point.as_slice().to_vec());
    assert_eq!(
        tip.parent().unwrap().attribute("name"),
        Some(robot.bodies()[robot.tip_point().body].name.as_str())
    );
    for (t, cable) in elements(&doc, "spatial").iter().zip(routing.cables()) {
        let refs: Vec<&str> = t
            .children()
            .filter(|n| n.has_tag_name("site"))
            .map(|n| n.attribute("site").unwrap())
            .collect();
        let expect: Vec<String> =
            (0..cable.holes.len()).map(|h| format!("{}_h{h}", cable.name)).collect();
        assert_eq!(refs, expect, "{}: holes base first", cable.name);
    }
    let sensors = elements(&doc, "tendonpos");
    assert_eq!(sensors.len(), 15);
    assert_eq!(sensors[0].attribute("tendon"), Some(routing.cables()[0].name.as_str()));
    assert!(elements(&doc, "actuatorfrc").is_empty());
    let custom = elements(&doc, "numeric");
    assert_eq!(nums(custom[0], "data"), WRENCH.to_vec());
}

#[test]
fn split_segments_is_one_spring_per_segment_with_stiffness_ea_over_its_length() {
    let f = mixed_tensions(15);
    let options = MjcfOptions { split: Split::Segments, ..MjcfOptions::default() };
    let (robot, routing, text) = export(PatternModel::Routed, &f, &options);
    let doc = Document::parse(&text).unwrap();
    let (_, seg) = lengths(&robot, &routing, &LOADED_POSE);
    let spatial = elements(&doc, "spatial");
    assert_eq!(spatial.len(), routing.segments().len());
    for (t, (s, segment)) in spatial.iter().zip(routing.segments().iter().enumerate()) {
        let cable = &routing.cables()[segment.cable];
        assert_eq!(
            t.attribute("name"),
            Some(format!("{}_s{}", cable.name, segment.index).as_str())
        );
        let ea = cable.stiffness * cable.elastic_length;
        let k = nums(*t, "stiffness")[0];
        assert!((k - ea / seg[s]).abs() <= 1e-12 * k);
        let sl = nums(*t, "springlength");
        assert_eq!(sl[0], 0.0, "ℓ_s (1 − f/EA) > 0");
        assert!((k * (seg[s] - sl[1]) - f[segment.cable]).abs() <= 1e-9 * f[segment.cable]);
        let refs: Vec<&str> = t
            .children()
            .filter(|n| n.has_tag_name("site"))
            .map(|n| n.attribute("site").unwrap())
            .collect();
        let i = segment.index;
        assert_eq!(
            refs,
            vec![format!("{}_h{i}", cable.name), format!("{}_h{}", cable.name, i + 1)]
        );
    }
}

#[test]
fn bad_input_is_a_typed_error_naming_what_is_wrong() {
    let (robot, routing) = robot_and_routing(PatternModel::Decoupled);
    let o = MjcfOptions::default();
    let ok = [40.0; 15];
    let run = |q: &[f64], f: &[f64], w: [f64; 6], o: &MjcfOptions| {
        to_mjcf(&robot, &routing, &State { q, tensions: f, wrench: w, segment_tensions: None }, o)
    };
    let mut q = LOADED_POSE;
    q[4] = 0.6;
    let e = run(&q, &ok, WRENCH, &o).unwrap_err();
    assert!(matches!(e, MjcfError::Robot(_)) && e.to_string().contains("joint3_x"), "{e}");
    // A routing of another robot (a 2-joint chain's cables on cdhrm5): the routing's error.
    let (_, other) = sinew_testkit::cdhrm5::chain(2, PatternModel::Decoupled);
    let e = to_mjcf(
        &robot,
        &other,
        &State { q: &LOADED_POSE, tensions: &ok[..6], wrench: WRENCH, segment_tensions: None },
        &o,
    )
    .unwrap_err();
    assert!(matches!(e, MjcfError::Routing(_)), "{e:?}");
    let e = run(&LOADED_POSE, &ok[..14], WRENCH, &o).unwrap_err();
    assert!(matches!(e, MjcfError::TensionCount { expected: 15, got: 14 }), "{e}");
    let mut f = ok;
    f[2] = 10.0;
    let e = run(&LOADED_POSE, &f, WRENCH, &o).unwrap_err();
    assert!(e.to_string().contains("j1c3") && e.to_string().contains("[20, 600]"), "{e}");
    f[2] = f64::NAN;
    assert!(matches!(run(&LOADED_POSE, &f, WRENCH, &o), Err(MjcfError::Tension { .. })));
    let e = run(&LOADED_POSE, &ok, [0.0, f64::INFINITY, 0.0, 0.0, 0.0, 0.0], &o).unwrap_err();
    assert!(matches!(e, MjcfError::Wrench { index: 1, .. }), "{e}");
    let bad = MjcfOptions { cables: CableModel::Motors, split: Split::Segments, ..o.clone() };
    assert!(matches!(
        run(&LOADED_POSE, &ok, WRENCH, &bad),
        Err(MjcfError::Option { option: "split", .. })
    ));
    let bad = MjcfOptions { damping: -1.0, ..o.clone() };
    assert!(matches!(
        run(&LOADED_POSE, &ok, WRENCH, &bad),
        Err(MjcfError::Option { option: "damping", .. })
    ));
    assert_eq!(
        run(&LOADED_POSE, &ok, WRENCH, &bad).unwrap_err().kind(),
        sinew_robot::ErrorKind::Input
    );
}

/// The stick regime after a pull or a release: each segment its own tension, its spring
/// length set so that it pulls with it; refused without split segments, with the wrong count,
/// or outside the cable's limits.
#[test]
fn segment_tensions_give_each_segment_its_own_tension() {
    let (robot, routing) = robot_and_routing(PatternModel::Routed);
    let f = mixed_tensions(15);
    let own: Vec<f64> =
        routing.segments().iter().map(|s| f[s.cable] * (1.0 + 0.01 * s.index as f64)).collect();
    let segments = MjcfOptions { split: Split::Segments, ..MjcfOptions::default() };
    fn state<'a>(f: &'a [f64], t: &'a [f64]) -> State<'a> {
        State { q: &LOADED_POSE, tensions: f, wrench: WRENCH, segment_tensions: Some(t) }
    }
    let text = to_mjcf(&robot, &routing, &state(&f, &own), &segments).unwrap();
    let doc = Document::parse(&text).unwrap();
    let (_, seg) = lengths(&robot, &routing, &LOADED_POSE);
    let spatial = elements(&doc, "spatial");
    assert_eq!(spatial.len(), own.len());
    for (s, t) in spatial.iter().enumerate() {
        let k = nums(*t, "stiffness")[0];
        let rest = nums(*t, "springlength")[1];
        assert!((k * (seg[s] - rest) - own[s]).abs() <= 1e-9 * own[s], "segment {s}");
    }
    // Refusals.
    let e = to_mjcf(&robot, &routing, &state(&f, &own), &MjcfOptions::default()).unwrap_err();
    assert!(matches!(e, MjcfError::Option { option: "segment_tensions", .. }), "{e}");
    let e = to_mjcf(&robot, &routing, &state(&f, &own[1..]), &segments).unwrap_err();
    let n = own.len();
    assert!(
        matches!(e, MjcfError::SegmentTensionCount { expected, got } if expected == n && got == n - 1),
        "{e}"
    );
    assert_eq!(e.kind(), sinew_robot::ErrorKind::Input);
    let mut low = own.clone();
    low[n - 1] = 5.0;
    let e = to_mjcf(&robot, &routing, &state(&f, &low), &segments).unwrap_err();
    let cable = &routing.cables()[routing.segments()[n - 1].cable].name;
    assert!(
        matches!(&e, MjcfError::Tension { cable: c, tension, .. } if c == cable && *tension == 5.0),
        "{e}"
    );
}
