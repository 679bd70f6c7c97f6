//! The structure of the routing and of its derivatives: block diagonal (decoupled) and block
//! lower-triangular (routed) `J_c`, exact zeros, `K_l`, the two file forms, the printed view.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::fmt::Write as _;

use faer::Mat;
use sinew_robot::{Robot, RobotData, UniformChain};
use sinew_routing::{
    Order, PatternModel, PerJoint, Routing, RoutingData, RoutingError, RoutingModel,
    compute_cable_geometry, compute_cable_geometry_from_kinematics,
};
use sinew_testkit::cdhrm5;
use sinew_testkit::config::{random_q, rng};

/// The least moment arm counted as "non-zero": a hole radius of 22 mm gives arms of that order.
const NONZERO: f64 = 1e-4;

#[test]
fn cables_are_ordered_by_joint_three_each() {
    for (name, robot, routing) in cdhrm5::cases(50) {
        let n = robot.dof() / 2;
        assert_eq!(routing.cable_count(), 3 * n, "{name}");
        let expected: Vec<usize> = (0..3 * n).map(|c| c / 3).collect();
        assert_eq!(routing.cable_joints(), expected.as_slice(), "{name}");
        for (c, cable) in routing.cables().iter().enumerate() {
            assert_eq!(cable.name, format!("j{}c{}", c / 3 + 1, c % 3 + 1), "{name}");
            let holes = match routing.model() {
                RoutingModel::Decoupled => 2,
                _ => 2 * (cable.joint + 1),
            };
            assert_eq!(cable.holes.len(), holes, "{name}: {}", cable.name);
        }
    }
}

/// `check(name, robot, routing, data)` at 100 random configurations (seeded with `seed`) of
/// every case of `model`, after the geometry with Hessians.
fn at_random_configurations(
    model: RoutingModel,
    seed: u64,
    mut check: impl FnMut(&str, &Robot, &Routing, &RoutingData),
) {
    for (name, robot, routing) in cdhrm5::cases(50) {
        if routing.model() != model {
            continue;
        }
        let mut rdata = RobotData::new(&robot);
        let mut data = RoutingData::new(&routing);
        let mut rng = rng(seed);
        for _ in 0..100 {
            let q = random_q(&robot, &mut rng);
            compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &q, Order::Hessians)
                .unwrap();
            check(&name, &robot, &routing, &data);
        }
    }
}

/// The Hessian of cable `c` is exactly zero at every `(i, k)` where `zero(i, k)`.
fn assert_hessian_zero_where(
    name: &str,
    routing: &Routing,
    data: &RoutingData,
    c: usize,
    zero: impl Fn(usize, usize) -> bool,
) {
    let n = data.jacobian().unwrap().ncols();
    let mut h = Mat::<f64>::zeros(n, n);
    data.cable_hessian(routing, c, h.as_mut()).unwrap();
    let cable = &routing.cables()[c].name;
    for i in 0..n {
        for k in 0..n {
            if zero(i, k) {
                assert_eq!(h[(i, k)], 0.0, "{name}: H of {cable} at ({i}, {k})");
            }
        }
    }
}

#[test]
fn decoupled_jacobian_is_block_diagonal() {
    at_random_configurations(RoutingModel::Decoupled, 21, |name, robot, routing, data| {
        let jacobian = data.jacobian().unwrap();
        for (c, cable) in routing.cables().iter().enumerate() {
            let own = 2 * cable.joint..2 * cable.joint + 2;
            assert_eq!(cable.dofs, own, "{name}: {}", cable.name);
            for k in 0..robot.dof() {
                if own.contains(&k) {
                    continue;
                }
                assert_eq!(jacobian[(c, k)], 0.0, "{name}: J[{}, {k}]", cable.name);
            }
            let arm = jacobian[(c, own.start)].abs() + jacobian[(c, own.start + 1)].abs();
            assert!(arm > NONZERO, "{name}: {} has no moment arm on its joint", cable.name);
            assert_hessian_zero_where(name, routing, data, c, |i, k| {
                !(own.contains(&i) && own.contains(&k))
            });
        }
    });
}

#[test]
fn routed_jacobian_is_block_lower_triangular_with_proximal_blocks() {
    at_random_configurations(RoutingModel::Routed, 22, |name, robot, routing, data| {
        let jacobian = data.jacobian().unwrap();
        for (c, cable) in routing.cables().iter().enumerate() {
            let j = cable.joint;
            assert_eq!(cable.dofs, 0..2 * j + 2, "{name}: {}", cable.name);
            for k in 2 * j + 2..robot.dof() {
                assert_eq!(jacobian[(c, k)], 0.0, "{name}: J[{}, {k}]", cable.name);
            }
            // Every joint up to its own carries it: non-zero blocks, proximal ones included.
            for p in 0..=j {
                let arm = jacobian[(c, 2 * p)].abs() + jacobian[(c, 2 * p + 1)].abs();
                assert!(
                    arm > NONZERO,
                    "{name}: {} has no moment arm on joint {p} ({arm:.2e})",
                    cable.name
                );
            }
            // Each segment crosses one universal joint: H_c is block diagonal in 2 × 2
            // blocks over the joints 0..=j.
            assert_hessian_zero_where(name, routing, data, c, |i, k| i / 2 != k / 2 || i / 2 > j);
        }
    });
}

#[test]
fn cable_stiffness_is_ea_over_elastic_length() {
    for (name, robot, routing) in cdhrm5::cases(50) {
        let mut rdata = RobotData::new(&robot);
        let mut data = RoutingData::new(&routing);
        let zero = vec![0.0; robot.dof()];
        compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &zero, Order::Lengths)
            .unwrap();
        let ea = routing.youngs_modulus() * routing.area();
        assert_eq!(routing.youngs_modulus(), 12.5e9, "{name}");
        assert!((routing.area() - std::f64::consts::PI * 0.25e-6).abs() < 1e-20, "{name}");
        let m = routing.cable_count();
        let mut k_l = Mat::<f64>::zeros(m, m);
        routing.fill_stiffness_matrix(k_l.as_mut()).unwrap();
        for (c, cable) in routing.cables().iter().enumerate() {
            let routed = data.lengths().unwrap()[c];
            assert!((cable.routed_length - routed).abs() < 1e-12, "{name}: {}", cable.name);
            // Both models give every cable the same elastic length: the free length (cdhrm5's
            // calibrated one, 3.6 m for the generated chain) + 0.25 m per link before its joint
            // + its 30 mm crossing.
            let free = cdhrm5::FREE_LENGTH;
            let expected_l = free + 0.25 * cable.joint as f64 + 0.03;
            assert!(
                (cable.elastic_length - expected_l).abs() < 1e-12,
                "{name}: {} has l = {}, expected {expected_l}",
                cable.name,
                cable.elastic_length
            );
            let k = ea / (cable.free_length + routed);
            assert!((routing.cable_stiffness()[c] - k).abs() <= 1e-12 * k, "{name}");
            for d in 0..m {
                assert_eq!(k_l[(c, d)], if c == d { routing.cable_stiffness()[c] } else { 0.0 });
            }
        }
    }
}

#[test]
fn cdhrm5_inherent_stiffness_at_zero_is_table_ii_order() {
    // The free length was chosen so that joint 1's inherent stiffness J_cᵀ K_l J_c at Q = 0 is
    // inside Table II's K_x = [1.92, 1.98] N m/rad (robots/cdhrm5/README.md).
    let robot = cdhrm5::robot();
    let routing = cdhrm5::routing(&robot, PatternModel::Decoupled);
    let mut rdata = RobotData::new(&robot);
    let mut data = RoutingData::new(&routing);
    compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &[0.0; 10], Order::Jacobian)
        .unwrap();
    let j = data.jacobian().unwrap();
    let k = routing.cable_stiffness();
    let kxx: f64 = (0..3).map(|c| k[c] * j[(c, 0)] * j[(c, 0)]).sum();
    let kyy: f64 = (0..3).map(|c| k[c] * j[(c, 1)] * j[(c, 1)]).sum();
    assert!((1.92..=1.98).contains(&kxx), "K_x = {kxx}");
    assert!((kxx - kyy).abs() < 1e-9, "K_x = {kxx}, K_y = {kyy}");
}

#[test]
fn cdhrm5_files_match_the_generated_pattern() {
    let robot = cdhrm5::robot();
    let (d1, d2) = cdhrm5::D1_D2;
    let chain = UniformChain { d1, d2, ..cdhrm5::uniform_chain(5) };
    for model in [PatternModel::Decoupled, PatternModel::Routed] {
        let from_file = cdhrm5::routing(&robot, model);
        let mut spec = cdhrm5::chain_routing_spec(&chain, model);
        let pitch = d1 + d2 + chain.link_length;
        spec.free_length = Some(match model {
            PatternModel::Decoupled => {
                PerJoint::Each((0..5).map(|i| cdhrm5::FREE_LENGTH + i as f64 * pitch).collect())
            }
            PatternModel::Routed => PerJoint::Uniform(cdhrm5::FREE_LENGTH),
        });
        let pattern = spec.pattern.as_mut().unwrap();
        pattern.radius = Some(PerJoint::Uniform(cdhrm5::HOLE_RADIUS));
        pattern.theta0 = cdhrm5::THETA0;
        let generated = Routing::new(&robot, &spec, "<gen>").unwrap();
        assert_eq!(from_file.cables(), generated.cables(), "{model:?}");
        assert_eq!(from_file.segments(), generated.segments(), "{model:?}");
    }
}

#[test]
fn cdhrm5_holes_are_distinct_and_inside_the_link() {
    let robot = cdhrm5::robot();
    let routing = cdhrm5::routing(&robot, PatternModel::Routed);
    let mut anchors = Vec::new();
    for cable in routing.cables() {
        for hole in &cable.holes {
            let r = (hole.point.x.powi(2) + hole.point.y.powi(2)).sqrt();
            assert!(
                (r - cdhrm5::HOLE_RADIUS).abs() < 1e-15 && r < 0.03,
                "{}: radius {r}",
                cable.name
            );
            assert_eq!(hole.point.z, 0.0);
        }
        let p = cable.holes[cable.holes.len() - 1].point;
        anchors.push(p.y.atan2(p.x));
    }
    // 15 distinct angles, 24° apart.
    anchors.sort_by(f64::total_cmp);
    for w in anchors.windows(2) {
        assert!((w[1] - w[0] - 24f64.to_radians()).abs() < 1e-12, "{anchors:?}");
    }
}

/// The explicit form of a routing, written from its printed (JSON) view.
fn explicit_toml(routing: &Routing) -> String {
    let view: serde_json::Value = serde_json::from_str(&routing.to_json().unwrap()).unwrap();
    let limits = &view["tension_limits"];
    let mut s = String::new();
    writeln!(
        s,
        "tension_limits = [{:?}, {:?}]",
        limits[0].as_f64().unwrap(),
        limits[1].as_f64().unwrap()
    )
    .unwrap();
    writeln!(
        s,
        "[material]\nyoungs_modulus = {:?}\narea = {:?}",
        view["youngs_modulus"].as_f64().unwrap(),
        view["area"].as_f64().unwrap()
    )
    .unwrap();
    for cable in view["cables"].as_array().unwrap() {
        writeln!(
            s,
            "[[cable]]\nname = {}\njoint = {}\nfree_length = {:?}\nholes = [",
            cable["name"],
            cable["joint"],
            cable["free_length"].as_f64().unwrap()
        )
        .unwrap();
        for hole in cable["holes"].as_array().unwrap() {
            let p: Vec<f64> =
                hole["point"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            writeln!(
                s,
                "  {{ link = {}, point = [{:?}, {:?}, {:?}] }},",
                hole["link"], p[0], p[1], p[2]
            )
            .unwrap();
        }
        writeln!(s, "]").unwrap();
    }
    s
}

#[test]
fn explicit_and_pattern_forms_give_the_same_routing() {
    for (name, robot, routing) in cdhrm5::cases(50) {
        let text = explicit_toml(&routing);
        let explicit = Routing::from_toml_str(&text, "<explicit>", &robot).unwrap();
        assert_eq!(explicit.model(), RoutingModel::Explicit);
        assert_eq!(explicit.cables(), routing.cables(), "{name}");
        assert_eq!(explicit.segments(), routing.segments(), "{name}");
        // And so the same numbers.
        let mut rdata = RobotData::new(&robot);
        let (mut a, mut b) = (RoutingData::new(&routing), RoutingData::new(&explicit));
        let q = random_q(&robot, &mut rng(5));
        compute_cable_geometry(&routing, &robot, &mut rdata, &mut a, &q, Order::Hessians).unwrap();
        compute_cable_geometry_from_kinematics(&explicit, &robot, &rdata, &mut b, Order::Hessians)
            .unwrap();
        assert_eq!(a.lengths().unwrap(), b.lengths().unwrap(), "{name}");
        assert_eq!(a.jacobian().unwrap(), b.jacobian().unwrap(), "{name}");
    }
}

#[test]
fn explicit_cables_derive_their_joint_and_are_sorted() {
    let robot = cdhrm5::robot();
    // Given out of order, without `joint`: derived from the anchor and sorted (stable).
    let text = r#"
tension_limits = [20.0, 600.0]
free_length = [1.0, 2.0, 3.0, 4.0, 5.0]
[material]
youngs_modulus = 1e9
area = 1e-6
[[cable]]
name = "late"
holes = [{ link = "link2_distal", point = [0.02, 0.0, 0.0] }, { link = "link3", point = [0.02, 0.0, 0.0] }]
[[cable]]
name = "early"
free_length = 0.5
holes = [{ link = "base_link", point = [0.0, 0.02, 0.0] }, { link = "link1", point = [0.0, 0.02, 0.0] }]
[[cable]]
name = "late2"
holes = [{ link = "link2_distal", point = [0.0, 0.02, 0.0] }, { link = "link3", point = [0.0, 0.02, 0.0] }]
"#;
    let routing = Routing::from_toml_str(text, "<t>", &robot).unwrap();
    let names: Vec<&str> = routing.cables().iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["early", "late", "late2"]);
    assert_eq!(routing.cable_joints(), [0, 2, 2]);
    assert_eq!(routing.cables()[0].free_length, 0.5);
    assert_eq!(routing.cables()[1].free_length, 3.0);
    assert_eq!(routing.cable_index("late2"), Some(2));
    assert!((routing.cable_stiffness()[0] - 1e3 / (0.5 + 0.03)).abs() < 1e-9);
}

#[test]
fn printed_view_lists_every_hole() {
    let robot = cdhrm5::robot();
    let routing = cdhrm5::routing(&robot, PatternModel::Routed);
    let view: serde_json::Value = serde_json::from_str(&routing.to_json().unwrap()).unwrap();
    assert_eq!(view["model"], "routed");
    assert_eq!(view["robot"], "cdhrm5");
    let cables = view["cables"].as_array().unwrap();
    assert_eq!(cables.len(), 15);
    let j3c2 = &cables[7];
    assert_eq!(j3c2["name"], "j3c2");
    assert_eq!(j3c2["joint"], 2);
    assert_eq!(j3c2["f_min"], 20.0);
    assert_eq!(j3c2["f_max"], 600.0);
    let links: Vec<&str> =
        j3c2["holes"].as_array().unwrap().iter().map(|h| h["link"].as_str().unwrap()).collect();
    assert_eq!(links, ["base_link", "link1", "link1_distal", "link2", "link2_distal", "link3"]);
    let k = j3c2["stiffness"].as_f64().unwrap();
    assert!((k - routing.cable_stiffness()[7]).abs() < 1e-9);
}

#[test]
fn evaluation_errors_are_typed() {
    let robot = cdhrm5::robot();
    let routing = cdhrm5::routing(&robot, PatternModel::Decoupled);
    let mut rdata = RobotData::new(&robot);
    let mut data = RoutingData::new(&routing);

    // Nothing computed yet.
    assert!(matches!(data.lengths(), Err(RoutingError::NotComputed { .. })));
    // Wrong length of Q.
    let err =
        compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &[0.0; 3], Order::Lengths)
            .unwrap_err();
    assert!(
        matches!(err, RoutingError::Robot(sinew_robot::RobotError::DimensionMismatch { .. })),
        "{err:?}"
    );
    // Hessians not computed by a Jacobian-order evaluation.
    compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &[0.1; 10], Order::Jacobian)
        .unwrap();
    let mut h = Mat::<f64>::zeros(10, 10);
    let err = data.cable_hessian(&routing, 0, h.as_mut()).unwrap_err();
    assert!(matches!(err, RoutingError::NotComputed { needed: Order::Hessians, .. }), "{err:?}");
    // Wrong sizes and indices.
    compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &[0.1; 10], Order::Hessians)
        .unwrap();
    let err = data.cable_hessian(&routing, 15, h.as_mut()).unwrap_err();
    assert!(matches!(err, RoutingError::NoSuchCable { cable: 15, cables: 15 }), "{err:?}");
    let mut small = Mat::<f64>::zeros(9, 10);
    let err = data.add_weighted_hessians(&routing, &[1.0; 15], small.as_mut()).unwrap_err();
    assert!(matches!(err, RoutingError::DimensionMismatch { .. }), "{err:?}");
    let err = data.add_weighted_hessians(&routing, &[1.0; 14], h.as_mut()).unwrap_err();
    assert!(
        matches!(err, RoutingError::DimensionMismatch { expected: 15, got: 14, .. }),
        "{err:?}"
    );
    // A routing for another robot, a workspace for another routing.
    let (chain, chain_routing) = cdhrm5::chain(50, PatternModel::Decoupled);
    let mut chain_rdata = RobotData::new(&chain);
    let err = compute_cable_geometry(
        &routing,
        &chain,
        &mut chain_rdata,
        &mut data,
        &[0.0; 100],
        Order::Lengths,
    )
    .unwrap_err();
    assert!(matches!(err, RoutingError::RobotMismatch { .. }), "{err:?}");
    let mut chain_data = RoutingData::new(&chain_routing);
    let err = compute_cable_geometry(
        &routing,
        &robot,
        &mut rdata,
        &mut chain_data,
        &[0.0; 10],
        Order::Lengths,
    )
    .unwrap_err();
    assert!(matches!(err, RoutingError::WorkspaceMismatch { .. }), "{err:?}");
    assert!(chain_data.computed().is_none());
}

#[test]
fn a_segment_that_collapses_is_an_error_not_a_nan() {
    // A hole on the base at (0, 0.01, d1) and one on the cross of joint 1 (frame at the joint
    // centre, z = d1 = 0.03 m on cdhrm5) at (0, 0, 0.01): they meet at q_11 = −π/2.
    let robot = cdhrm5::robot();
    let text = r#"
tension_limits = [20.0, 600.0]
[material]
youngs_modulus = 1e9
area = 1e-6
[[cable]]
name = "folding"
holes = [
  { link = "base_link", point = [0.0, 0.01, 0.03] },
  { link = "cross1", point = [0.0, 0.0, 0.01] },
  { link = "link1", point = [0.02, 0.0, 0.0] },
]
"#;
    let routing = Routing::from_toml_str(text, "<t>", &robot).unwrap();
    let mut rdata = RobotData::new(&robot);
    let mut data = RoutingData::new(&routing);
    let mut q = [0.0; 10];
    compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &q, Order::Hessians).unwrap();
    q[0] = -std::f64::consts::FRAC_PI_2;
    let err = compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &q, Order::Hessians)
        .unwrap_err();
    assert!(
        matches!(&err, RoutingError::DegenerateSegment { cable, segment: 0, .. } if cable == "folding"),
        "{err:?}"
    );
    assert!(err.to_string().contains("folding"), "{err}");
    assert!(data.computed().is_none());
}

#[test]
fn hessian_at_zero_is_minus_d1_d2_over_d1_plus_d2() {
    // At Q = 0 a crossing segment runs along z; bending either axis shortens it by
    // d1·d2/(d1 + d2)·q²/2 whatever the hole's radius and angle (robots/cdhrm5/README.md).
    for (d1, d2) in [(0.015, 0.015), (0.01, 0.025), (0.0, 0.03)] {
        let chain = UniformChain { d1, d2, ..cdhrm5::uniform_chain(5) };
        let robot = chain.build().unwrap();
        let spec = cdhrm5::chain_routing_spec(&chain, PatternModel::Decoupled);
        let routing = Routing::new(&robot, &spec, "<gen>").unwrap();
        let mut rdata = RobotData::new(&robot);
        let mut data = RoutingData::new(&routing);
        compute_cable_geometry(
            &routing,
            &robot,
            &mut rdata,
            &mut data,
            &[0.0; 10],
            Order::Hessians,
        )
        .unwrap();
        let expected = -d1 * d2 / (d1 + d2);
        let mut h = Mat::<f64>::zeros(10, 10);
        for (c, cable) in routing.cables().iter().enumerate() {
            data.cable_hessian(&routing, c, h.as_mut()).unwrap();
            for k in [2 * cable.joint, 2 * cable.joint + 1] {
                assert!((h[(k, k)] - expected).abs() < 1e-15, "{}: {}", cable.name, h[(k, k)]);
            }
        }
    }
}
