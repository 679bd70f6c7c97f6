//! The routing file's friction keys (defaults, overrides, frames), every bad friction input as
//! a typed error naming the file and the cable, the one-hole capstan ratio in closed form, and
//! the friction stages' own errors.
#![allow(clippy::unwrap_used, clippy::expect_used, non_snake_case)]

use nalgebra::{Point3, Vector3};
use sinew_robot::{ErrorKind, Robot, RobotData};
use sinew_routing::{
    FrictionData, FrictionModel, Order, Routing, RoutingData, RoutingError, Slip,
    compute_cable_geometry, compute_capstan_weights, compute_friction_geometry,
};
use sinew_testkit::cdhrm5;
use sinew_testkit::config::random_qs;
use sinew_testkit::one_joint::{HEADER, eq1, one_hole_routing};
use sinew_testkit::random_chain::RandomChain;

const FILE: &str = "test/cables.toml";

const PATTERN: &str = r#"
[pattern]
model = "decoupled"
radius = 0.022
proximal_discs = ["base_link", "link1_distal", "link2_distal", "link3_distal", "link4_distal"]
distal_discs = ["link1", "link2", "link3", "link4", "link5"]
"#;

/// An explicit cable of joint 1 with extra keys.
fn explicit_cable(keys: &str) -> String {
    format!(
        r#"
[[cable]]
name = "good"
{keys}
holes = [
  {{ link = "base_link", point = [0.02, 0.0, 0.0] }},
  {{ link = "link1", point = [0.02, 0.0, 0.0] }},
  {{ link = "link1_distal", point = [0.02, 0.0, 0.0] }},
  {{ link = "link2", point = [0.02, 0.0, 0.0] }},
]
"#
    )
}

fn load(text: &str) -> Result<Routing, RoutingError> {
    Routing::from_toml_str(text, FILE, &cdhrm5::robot())
}

#[test]
fn existing_files_have_no_friction_and_enter_along_plus_z() {
    for model in cdhrm5::MODELS {
        let (_, routing) = cdhrm5::robot_and_routing(model);
        assert_eq!(routing.friction_coefficient(), 0.0);
        assert!(!routing.has_friction());
        for cable in routing.cables() {
            assert_eq!(cable.friction_coefficient, 0.0);
            assert_eq!(cable.entry_direction, Vector3::z());
            assert_eq!(cable.entry_direction_in_body(), Vector3::z());
        }
    }
}

#[test]
fn per_cable_keys_override_the_routing_wide_coefficient() {
    let text = format!(
        "friction_coefficient = 0.1\n{HEADER}{PATTERN}\n[pattern.cable.j2c3]\nfriction_coefficient = 0.25\nentry_direction = [0.0, 3.0, 4.0]\n[pattern.cable.j4c1]\nentry_direction = [1e300, 0.0, 1e300]\n"
    );
    let routing = load(&text).unwrap();
    assert_eq!(routing.friction_coefficient(), 0.1);
    assert!(routing.has_friction());
    for cable in routing.cables() {
        let (mu, entry) = match cable.name.as_str() {
            "j2c3" => (0.25, Vector3::new(0.0, 0.6, 0.8)),
            "j4c1" => (0.1, Vector3::new(1.0, 0.0, 1.0) / 2f64.sqrt()),
            _ => (0.1, Vector3::z()),
        };
        assert_eq!(cable.friction_coefficient, mu, "{}", cable.name);
        assert!((cable.entry_direction - entry).norm() <= 1e-16, "{}", cable.name);
    }
    // The explicit form: keys on the cable; a subnormal direction still normalises.
    let routing = load(&format!(
        "{HEADER}{}",
        explicit_cable("friction_coefficient = 0.3\nentry_direction = [5e-324, 0.0, 0.0]")
    ))
    .unwrap();
    let cable = &routing.cables()[0];
    assert_eq!((routing.friction_coefficient(), cable.friction_coefficient), (0.0, 0.3));
    assert_eq!(cable.entry_direction, Vector3::x());
    // The model can override every cable's μ (a front end's --friction) and keeps the entries.
    let model = FrictionModel::new(&routing);
    assert_eq!(model.friction_coefficients(), &[0.3]);
    assert_eq!(model.with_friction_coefficient(0.0).unwrap().friction_coefficients(), &[0.0]);
}

/// The friction example of docs/cli.md, added to cdhrm5's pattern file, loads as it says.
#[test]
fn the_friction_example_of_the_cli_docs_loads() {
    let root = cdhrm5::workspace_root();
    let doc = std::fs::read_to_string(root.join("docs/cli.md")).unwrap();
    let block = doc
        .split("```toml\n")
        .skip(1)
        .map(|b| b.split("```").next().unwrap())
        .find(|b| b.contains("[pattern.cable.j2c1]"))
        .expect("the friction example");
    // Its top-level key goes before the file's tables, its table after them.
    let (top, table) = block.split_at(block.find('[').unwrap());
    let file = std::fs::read_to_string(cdhrm5::dir().join("cables.toml")).unwrap();
    let routing = load(&format!("{top}\n{file}\n{table}")).unwrap();
    assert_eq!(routing.friction_coefficient(), 0.1);
    let j2c1 = &routing.cables()[routing.cable_index("j2c1").unwrap()];
    assert_eq!(j2c1.friction_coefficient, 0.2);
    assert!((j2c1.entry_direction - Vector3::new(0.0, 0.1, 1.0).normalize()).norm() <= 1e-16);
}

#[test]
fn the_entry_direction_is_given_in_the_first_holes_link_frame() {
    // Random chains: the disc links have random rpy in their bodies, so +z of the link is not
    // +z of the body; the body-frame direction is the link's rotation applied to it.
    let chain = RandomChain::new(3, 7);
    let robot = chain.robot();
    let routing =
        chain.routing(&robot, &chain.pattern_spec(sinew_routing::PatternModel::Decoupled));
    let mut turned = 0;
    for cable in routing.cables() {
        let link = robot.link(&cable.holes[0].link).unwrap();
        let expected = link.body_m_link.rotation * Vector3::z();
        assert!((cable.entry_direction_in_body() - expected).norm() <= 1e-15, "{}", cable.name);
        turned += usize::from((expected - Vector3::z()).norm() > 1e-3);
    }
    assert!(turned > 0, "no link frame turned in its body: nothing checked");
}

#[test]
fn bad_friction_input_is_a_typed_error_naming_the_file_and_the_cable() {
    let pattern = |table: &str| format!("{HEADER}{PATTERN}\n{table}\n");
    let cases: Vec<(String, &str, &str)> = vec![
        (format!("friction_coefficient = -0.1\n{HEADER}{PATTERN}"), "", "friction_coefficient"),
        (format!("friction_coefficient = inf\n{HEADER}{PATTERN}"), "", "friction_coefficient"),
        (
            format!("{HEADER}{}", explicit_cable("friction_coefficient = nan")),
            "good",
            "cable[0].friction_coefficient",
        ),
        (
            pattern("[pattern.cable.j2c1]\nfriction_coefficient = -1e-9"),
            "j2c1",
            "pattern.cable.j2c1.friction_coefficient",
        ),
        (
            format!("{HEADER}{}", explicit_cable("entry_direction = [0.0, 0.0, 0.0]")),
            "good",
            "cable[0].entry_direction",
        ),
        (
            format!("{HEADER}{}", explicit_cable("entry_direction = [nan, 0.0, 1.0]")),
            "good",
            "cable[0].entry_direction",
        ),
        (
            pattern("[pattern.cable.j5c3]\nentry_direction = [0.0, inf, 1.0]"),
            "j5c3",
            "pattern.cable.j5c3.entry_direction",
        ),
        (pattern("[pattern.cable.j6c1]\nfriction_coefficient = 0.1"), "j6c1", "pattern.cable.j6c1"),
    ];
    for (text, cable, field) in cases {
        let err = load(&text).unwrap_err();
        let message = err.to_string();
        match (&err, cable) {
            (RoutingError::InvalidFrictionCoefficient { cable: c, field: f, .. }, _)
            | (RoutingError::InvalidEntryDirection { cable: c, field: f, .. }, _)
            | (RoutingError::UnknownCable { cable: c, field: f, .. }, _) => {
                assert_eq!((c.as_str(), f.as_str()), (cable, field), "{message}");
            }
            _ => panic!("{field}: unexpected {err:?}"),
        }
        assert_eq!(err.kind(), ErrorKind::Input);
        assert!(message.starts_with(FILE), "{message}");
        assert!(message.contains(field), "{message}");
        if cable.is_empty() {
            assert!(message.contains("applies to every cable"), "{message}");
        } else {
            assert!(message.contains(&format!("`{cable}`")), "{message}");
        }
        println!("{message}");
    }
    // Each variant is reached.
    let variant = |text: String| std::mem::discriminant(&load(&text).unwrap_err());
    let kinds: std::collections::HashSet<_> = [
        variant(format!("friction_coefficient = -1.0\n{HEADER}{PATTERN}")),
        variant(format!("{HEADER}{}", explicit_cable("entry_direction = [0.0, 0.0, 0.0]"))),
        variant(pattern("[pattern.cable.x]\nfriction_coefficient = 0.1")),
    ]
    .into_iter()
    .collect();
    assert_eq!(kinds.len(), 3);
    // A front end's override is checked the same way.
    let routing = load(&format!("{HEADER}{PATTERN}")).unwrap();
    for mu in [-0.5, f64::NAN, f64::INFINITY] {
        let err = FrictionModel::new(&routing).with_friction_coefficient(mu).unwrap_err();
        assert!(matches!(err, RoutingError::InvalidFrictionCoefficient { .. }), "{err:?}");
        assert!(err.to_string().starts_with(FILE), "{err}");
    }
}

#[test]
fn one_hole_matches_the_closed_form_capstan_ratio() {
    // One universal joint; a cable from a hole on the base disc to its anchor on the distal
    // disc, arriving at the hole tilted by α from the arm's axis. θ is the angle between the
    // entry direction and the segment, from eq. (1) alone; T_1 / T_0 = e^{∓μθ}.
    let chain = cdhrm5::uniform_chain(1);
    let robot: Robot = chain.build().unwrap();
    let (rho, alpha, mu) = (0.02, 0.3_f64, 0.35);
    let entry = Vector3::new(alpha.sin(), 0.0, alpha.cos());
    let text = one_hole_routing(rho, mu, &entry);
    let routing = Routing::from_toml_str(&text, FILE, &robot).unwrap();
    let model = FrictionModel::new(&routing);
    let mut rdata = RobotData::new(&robot);
    let mut routing_data = RoutingData::new(&routing);
    let mut data = FrictionData::new(&model);
    let mut qs = random_qs(&robot, 21, 50);
    qs.push(vec![0.0, 0.0]);
    let mut worst: f64 = 0.0;
    for q in &qs {
        compute_cable_geometry(&routing, &robot, &mut rdata, &mut routing_data, q, Order::Lengths)
            .unwrap();
        compute_friction_geometry(&model, &routing, &routing_data, &mut data).unwrap();
        let r = Vector3::new(rho, 0.0, 0.0);
        let u = (eq1(chain.d1, chain.d2, [q[0], q[1]]) * Point3::from(r)).coords - r;
        let theta = entry.cross(&u).norm().atan2(entry.dot(&u));
        let angles = data.wrap_angles(&model, 0).unwrap();
        assert_eq!(angles.len(), 1);
        worst = worst.max((angles[0] - theta).abs());
        for (slip, sign) in [(Slip::Pull, -1.0), (Slip::Release, 1.0)] {
            compute_capstan_weights(&model, &mut data, slip).unwrap();
            let w = data.weights(&model, 0).unwrap();
            let closed = (sign * mu * theta).exp();
            assert_eq!(w[0], 1.0);
            assert!(
                (w[1] - closed).abs() <= 1e-14 * closed,
                "{slip:?} at {q:?}: {} vs {closed}",
                w[1]
            );
            // J̃ = w_1 J_1: the one segment's row, scaled.
            let j = routing_data_jacobian(&routing, &robot, q);
            let jt = data.effective_jacobian().unwrap();
            for i in 0..2 {
                assert!((jt[(0, i)] - w[1] * j[i]).abs() <= 1e-15 * j[i].abs().max(1e-3));
            }
        }
    }
    // At Q = 0 the segment is the arm's axis: θ = α exactly as given.
    assert!((data.wrap_angles(&model, 0).unwrap()[0] - alpha).abs() <= 1e-15);
    println!("one hole: worst |θ − closed form| = {worst:.2e} rad");
    assert!(worst <= 1e-15);
}

/// `J_c`'s one row at `q`.
fn routing_data_jacobian(routing: &Routing, robot: &Robot, q: &[f64]) -> Vec<f64> {
    let mut rdata = RobotData::new(robot);
    let mut data = RoutingData::new(routing);
    compute_cable_geometry(routing, robot, &mut rdata, &mut data, q, Order::Jacobian).unwrap();
    let j = data.jacobian().unwrap();
    (0..robot.dof()).map(|i| j[(0, i)]).collect()
}

#[test]
fn the_friction_stages_refuse_what_they_cannot_compute() {
    let (robot, routing) = cdhrm5::robot_and_routing(sinew_routing::PatternModel::Routed);
    let model = FrictionModel::new(&routing);
    let mut data = FrictionData::new(&model);
    let routing_data = RoutingData::new(&routing);
    // Before the routing geometry, before the friction geometry, before the weights.
    let err = compute_friction_geometry(&model, &routing, &routing_data, &mut data).unwrap_err();
    assert!(matches!(err, RoutingError::NotComputed { .. }), "{err:?}");
    let err = compute_capstan_weights(&model, &mut data, Slip::Pull).unwrap_err();
    assert!(matches!(err, RoutingError::FrictionNotComputed { .. }), "{err}");
    assert!(err.to_string().contains("compute_friction_geometry"), "{err}");
    assert!(matches!(data.lengths(&model, 0), Err(RoutingError::FrictionNotComputed { .. })));
    let mut rdata = RobotData::new(&robot);
    let mut routing_data = RoutingData::new(&routing);
    let q = random_qs(&robot, 1, 1).remove(0);
    compute_cable_geometry(&routing, &robot, &mut rdata, &mut routing_data, &q, Order::Lengths)
        .unwrap();
    compute_friction_geometry(&model, &routing, &routing_data, &mut data).unwrap();
    let err = data.weights(&model, 0).unwrap_err();
    assert!(err.to_string().contains("compute_capstan_weights"), "{err}");
    assert!(data.effective_jacobian().is_err());
    assert_eq!(data.slip(), None);
    compute_capstan_weights(&model, &mut data, Slip::Release).unwrap();
    assert_eq!(data.slip(), Some(Slip::Release));
    // Out-of-range cables, segments and holes.
    let m = routing.cable_count();
    let holes = routing.cables()[0].holes.len();
    assert!(matches!(data.weights(&model, m), Err(RoutingError::NoSuchCable { .. })));
    assert!(data.segment_jacobian(&model, 0, holes).is_err());
    assert!(data.wrap_gradient(&model, 0, holes - 1).is_err(), "the anchor has no wrap angle");
    assert!(data.wrap_gradient(&model, 0, holes - 2).is_ok());
    // A model, workspace or routing workspace of another routing.
    let (_, other) = cdhrm5::robot_and_routing(sinew_routing::PatternModel::Decoupled);
    let other_model = FrictionModel::new(&other);
    let mut other_data = FrictionData::new(&other_model);
    assert!(matches!(
        compute_friction_geometry(&other_model, &routing, &routing_data, &mut data),
        Err(RoutingError::WorkspaceMismatch { .. })
    ));
    assert!(matches!(
        compute_friction_geometry(&model, &routing, &routing_data, &mut other_data),
        Err(RoutingError::WorkspaceMismatch { .. })
    ));
    assert!(matches!(
        compute_capstan_weights(&model, &mut other_data, Slip::Pull),
        Err(RoutingError::WorkspaceMismatch { .. })
    ));
}
