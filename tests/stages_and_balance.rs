//! Stages out of order (`StaticsError::NoPose`, `StiffnessError::StageMissing`) and given
//! tensions that do not balance the load (`StaticsError::NotBalanced`), in every layer that
//! returns them: the statics and the arm stiffness (the CLI takes no given tensions; the
//! Python bindings' `tensions=` is tested in their pytest suite).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::Vector6;
use sinew::robot::RobotData;
use sinew::routing::{Order, PatternModel, RoutingData, compute_cable_geometry};
use sinew::statics::{ArmStatics, NotBalanced, StaticsError, TensionChoice};
use sinew::stiffness::{ArmStiffness, ArmStiffnessData, StiffnessError};
use sinew_testkit::cdhrm5;

#[test]
fn a_tension_stage_before_a_pose_stage_is_a_typed_error() {
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Decoupled);
    let statics = ArmStatics::new(&routing);
    let cables = RoutingData::new(&routing);
    let mut data = statics.data(&robot);
    for choice in [
        TensionChoice::Default,
        TensionChoice::Levels(&[0.0; 5]),
        TensionChoice::Given(&[30.0; 15]),
    ] {
        let e = statics.set_tensions(&cables, &mut data, choice);
        assert!(matches!(e, Err(StaticsError::NoPose)), "{e:?}");
    }
    let e = statics.equilibrium_set(&cables, &mut data).map(|_| ());
    assert!(matches!(e, Err(StaticsError::NoPose)), "{e:?}");
    assert!(StaticsError::NoPose.to_string().contains("no pose"));

    let arm = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&arm);
    let e = arm.set_tensions(&mut data, TensionChoice::Default).unwrap_err();
    assert!(
        matches!(e, StiffnessError::StageMissing { needs: "set_pose", missing: "pose" }),
        "{e:?}"
    );
    assert_eq!(e.to_string(), "set_pose first: the workspace has no pose yet");
    let e = arm.solve_end(&mut data).unwrap_err();
    assert!(matches!(e, StiffnessError::StageMissing { .. }), "{e:?}");
}

#[test]
fn given_tensions_that_do_not_balance_are_refused_in_the_statics_and_the_arm() {
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Decoupled);
    let q = cdhrm5::LOADED_POSE;
    let load = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    let statics = ArmStatics::new(&routing);
    let mut rdata = RobotData::new(&robot);
    let mut cables = RoutingData::new(&routing);
    compute_cable_geometry(&routing, &robot, &mut rdata, &mut cables, &q, Order::Jacobian).unwrap();
    let mut data = statics.data(&robot);
    statics
        .solve_with(&robot, &mut rdata, &cables, &mut data, &load, TensionChoice::Default)
        .unwrap();
    let good = data.tensions.clone();
    // The balancing tensions are accepted as given; 1 N more on one cable is not.
    statics.set_tensions(&cables, &mut data, TensionChoice::Given(&good)).unwrap();
    let mut off = good.clone();
    off[4] += 1.0;
    let Err(StaticsError::NotBalanced(NotBalanced::Residual { residual, t0 })) =
        statics.set_tensions(&cables, &mut data, TensionChoice::Given(&off))
    else {
        panic!("unbalanced tensions accepted");
    };
    // |T0 + J_cᵀ f| is then |J_c row 4| · 1 N.
    let j = cables.jacobian().unwrap();
    let row: f64 = (0..10).map(|d| j[(4, d)] * j[(4, d)]).sum::<f64>().sqrt();
    assert!((residual - row).abs() <= 1e-9 * row, "{residual} vs {row}");
    let t0_norm = data.t0.iter().map(|v| v * v).sum::<f64>().sqrt();
    assert!((t0 - t0_norm).abs() <= 1e-12 * t0_norm);
    let mut outside = good.clone();
    outside[7] = 700.0;
    let e = statics.set_tensions(&cables, &mut data, TensionChoice::Given(&outside)).unwrap_err();
    let name = routing.cables()[7].name.clone();
    let StaticsError::NotBalanced(NotBalanced::OutsideLimits { cable, tension, limits }) = &e
    else {
        panic!("{e:?}");
    };
    assert_eq!((cable, *tension, *limits), (&name, 700.0, [20.0, 600.0]));
    assert!(e.to_string().contains(&format!("`{name}`")), "{e}");
    let mut nan = good.clone();
    nan[0] = f64::NAN;
    assert!(matches!(
        statics.set_tensions(&cables, &mut data, TensionChoice::Given(&nan)),
        Err(StaticsError::NotBalanced(NotBalanced::OutsideLimits { .. }))
    ));

    // The arm: the same refusal, wrapped.
    let arm = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&arm);
    arm.evaluate_joints(&mut data, &q, &load, TensionChoice::Given(&good)).unwrap();
    for bad in [&off, &outside] {
        let e = arm.evaluate_joints(&mut data, &q, &load, TensionChoice::Given(bad)).unwrap_err();
        assert!(matches!(e, StiffnessError::Statics(StaticsError::NotBalanced(_))), "{e:?}");
        assert!(e.to_string().contains("balance") || e.to_string().contains("limits"), "{e}");
    }
}

#[test]
fn a_routing_with_a_cable_duplicated_through_the_same_holes_is_answered_by_every_policy() {
    // ua3x4 with a copy of its first cable (another name, the same holes): J_c has two equal
    // rows, the set one more dimension. The least-norm tensions split the pair's share equally,
    // and the pair carries together what the cable carries alone under least norm.
    use sinew::routing::{Routing, RoutingSpec};
    use sinew::statics::TensionPolicy;
    let dir = cdhrm5::workspace_root().join("robots/ua3x4");
    let robot = sinew::robot::load(&dir).unwrap();
    let text = std::fs::read_to_string(dir.join("cables.toml")).unwrap();
    let mut spec = RoutingSpec::from_toml_str(&text, "cables.toml").unwrap();
    let mut twin = spec.cables[0].clone();
    twin.name = format!("{}_twin", twin.name);
    spec.cables.insert(1, twin);
    let routing = Routing::new(&robot, &spec, "<ua3x4 with a twin>").unwrap();
    let original = sinew::routing::load(&dir, &robot).unwrap();
    let q = [0.2, -0.3, 0.25, 0.1, -0.15, 0.3];
    let load = Vector6::new(0.0, 2.0, 0.0, 0.0, 0.0, 0.0);
    let solve = |routing: &Routing, policy| {
        let statics = ArmStatics::new(routing);
        let mut rdata = RobotData::new(&robot);
        let mut cables = RoutingData::new(routing);
        compute_cable_geometry(routing, &robot, &mut rdata, &mut cables, &q, Order::Jacobian)
            .unwrap();
        let mut data = statics.data(&robot);
        statics
            .solve_with(
                &robot,
                &mut rdata,
                &cables,
                &mut data,
                &load,
                TensionChoice::Policy(policy),
            )
            .unwrap();
        let dim = statics.equilibrium_set(&cables, &mut data).unwrap().dimension();
        (data.tensions.clone(), dim)
    };
    for policy in TensionPolicy::ALL {
        let (f, dim) = solve(&routing, policy);
        let (g, dim0) = solve(&original, policy);
        assert_eq!(dim, dim0 + 1, "{policy:?}");
        assert!(f.iter().all(|v| v.is_finite() && (20.0..=600.0).contains(v)), "{policy:?}: {f:?}");
        if policy == TensionPolicy::LeastNorm {
            assert!((f[0] - f[1]).abs() <= 1e-9 * f[0], "{f:?}");
        }
        if policy == TensionPolicy::LeastTotal {
            // Σ f: the pair costs what the single cable did, at least 2 f_min.
            let (total, total0) = (f.iter().sum::<f64>(), g.iter().sum::<f64>());
            assert!(total >= total0 - 1e-9 * total0, "{policy:?}: {total} < {total0}");
        }
    }
}
