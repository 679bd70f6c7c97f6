//! The slip regimes' statics (spec §9, #27): the torque on `J̃`, the actuator-tension limits,
//! the equilibrium set in the actuator tensions, the paper's levels on them and the dead band;
//! μ = 0 bit for bit.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use rand::Rng;
use sinew_robot::{ErrorKind, Robot, RobotData};
use sinew_routing::{
    FrictionData, FrictionModel, Order, Routing, RoutingData, Slip, compute_cable_geometry,
    compute_capstan_weights, compute_friction_geometry,
};
use sinew_statics::{
    CableLayout, EquilibriumSet, StaticsError, TensionInterval, TensionLimits, TensionPolicy,
    actuator_limits, cable_torques, dead_band, distribute_tensions, distribute_with_policy,
    slip_equilibrium_set, slip_levels, slip_torques,
};
use sinew_testkit::cdhrm5;
use sinew_testkit::config::{random_qs, rng};
use sinew_testkit::random_chain::RandomChain;

fn cases() -> Vec<(String, Robot, Routing)> {
    let mut out: Vec<_> = cdhrm5::MODELS
        .iter()
        .map(|&m| {
            let (robot, routing) = cdhrm5::robot_and_routing(m);
            (format!("cdhrm5 {m:?}"), robot, routing)
        })
        .collect();
    let chain = RandomChain::new(3, 7);
    let robot = chain.robot();
    for model in cdhrm5::MODELS {
        let routing = chain.routing(&robot, &chain.pattern_spec(model));
        out.push((format!("{} {model:?}", chain.name), robot.clone(), routing));
    }
    out
}

fn evaluate(
    robot: &Robot,
    routing: &Routing,
    model: &FrictionModel,
    q: &[f64],
) -> (RoutingData, FrictionData) {
    let mut rdata = RobotData::new(robot);
    let mut geometry = RoutingData::new(routing);
    compute_cable_geometry(routing, robot, &mut rdata, &mut geometry, q, Order::Jacobian).unwrap();
    let mut friction = FrictionData::new(model);
    compute_friction_geometry(model, routing, &geometry, &mut friction).unwrap();
    (geometry, friction)
}

#[test]
fn mu_zero_is_the_frictionless_statics_bit_for_bit() {
    for (case, robot, routing) in cases() {
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.0).unwrap();
        let (m, n) = (routing.cable_count(), routing.dof());
        let q = &random_qs(&robot, 21, 1)[0];
        let (geometry, mut friction) = evaluate(&robot, &routing, &model, q);
        let mut r = rng(22);
        let f: Vec<f64> = (0..m).map(|_| r.random_range(30.0..100.0)).collect();
        for slip in [Slip::Pull, Slip::Release] {
            compute_capstan_weights(&model, &mut friction, slip).unwrap();
            let (mut tau, mut today) = (vec![0.0; n], vec![0.0; n]);
            slip_torques(&friction, &f, &mut tau).unwrap();
            cable_torques(geometry.jacobian().unwrap(), &f, &mut today).unwrap();
            assert_eq!(tau, today, "{case}");
            let mut limits = vec![[0.0; 2]; m];
            actuator_limits(&model, &friction, routing.cable_limits(), &mut limits).unwrap();
            assert_eq!(limits, routing.cable_limits(), "{case}");
            let mut band = vec![[0.0; 2]; m];
            dead_band(&model, &friction, &f, &mut band).unwrap();
            assert!(band.iter().zip(&f).all(|(b, f)| b[0] == *f && b[1] == *f), "{case}");
            let t0 = today.clone();
            let groups = routing.joint_groups();
            let set = slip_equilibrium_set(&model, &friction, &t0, routing.cable_limits(), groups)
                .unwrap();
            let frictionless = EquilibriumSet::new(
                geometry.jacobian().unwrap(),
                &t0,
                routing.cable_limits(),
                groups,
            )
            .unwrap();
            assert_eq!(set, frictionless, "{case}");
        }
    }
}

#[test]
fn the_dead_band_ends_reproduce_the_pull_and_release_distributions() {
    for (case, robot, routing) in cases() {
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.2).unwrap();
        let m = routing.cable_count();
        for q in random_qs(&robot, 23, 3) {
            let (_, mut friction) = evaluate(&robot, &routing, &model, &q);
            let anchor: Vec<f64> = (0..m).map(|c| 40.0 + c as f64).collect();
            let mut band = vec![[0.0; 2]; m];
            dead_band(&model, &friction, &anchor, &mut band).unwrap();
            for (c, b) in band.iter().enumerate() {
                let total: f64 = friction.wrap_angles(&model, c).unwrap().iter().sum();
                assert!(total > 0.0 && b[0] < anchor[c] && anchor[c] < b[1], "{case}: cable {c}");
                // Closed form: the band's ends are T_a e^{∓μΘ}.
                let ratio = b[1] / b[0];
                let exact = (2.0 * 0.2 * total).exp();
                assert!(
                    (ratio / exact - 1.0).abs() <= 1e-14,
                    "{case}: cable {c}: {ratio} vs {exact}"
                );
            }
            for (slip, end) in [(Slip::Release, 0), (Slip::Pull, 1)] {
                compute_capstan_weights(&model, &mut friction, slip).unwrap();
                for c in 0..m {
                    let w = friction.weights(&model, c).unwrap();
                    let reached = band[c][end] * w[w.len() - 1];
                    let err = (reached - anchor[c]).abs() / anchor[c];
                    assert!(err <= 4.0 * f64::EPSILON, "{case}: {slip:?} cable {c}: {err:.1e}");
                }
            }
        }
    }
}

#[test]
fn the_slip_statics_keep_every_segment_within_its_limits() {
    for (case, robot, routing) in cases() {
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.1).unwrap();
        let (m, n) = (routing.cable_count(), routing.dof());
        let names: Vec<String> = routing.cables().iter().map(|c| c.name.clone()).collect();
        for (k, q) in random_qs(&robot, 24, 2).iter().enumerate() {
            let (_, mut friction) = evaluate(&robot, &routing, &model, q);
            for slip in [Slip::Pull, Slip::Release] {
                compute_capstan_weights(&model, &mut friction, slip).unwrap();
                let mut limits = vec![[0.0; 2]; m];
                actuator_limits(&model, &friction, routing.cable_limits(), &mut limits).unwrap();
                for (c, (l, cable)) in limits.iter().zip(routing.cable_limits()).enumerate() {
                    let w = friction.weights(&model, c).unwrap();
                    // Each end puts some segment exactly on its limit, the rest inside.
                    let lo: Vec<f64> = w.iter().map(|w| l[0] * w).collect();
                    let hi: Vec<f64> = w.iter().map(|w| l[1] * w).collect();
                    let (min, max) = (
                        lo.iter().copied().fold(f64::INFINITY, f64::min),
                        hi.iter().copied().fold(0.0, f64::max),
                    );
                    assert!((min - cable[0]).abs() <= 1e-13 * cable[0], "{case}: {slip:?} {c}");
                    assert!((max - cable[1]).abs() <= 1e-13 * cable[1], "{case}: {slip:?} {c}");
                    // Pull: the anchor binds f_min, the actuator f_max; release the reverse.
                    let (anchor, first) = (w[w.len() - 1], w[0]);
                    match slip {
                        Slip::Pull => {
                            assert!(anchor < 1.0 && l[0] > cable[0] && l[1] == cable[1] / first)
                        }
                        Slip::Release => {
                            assert!(anchor > 1.0 && l[0] == cable[0] && l[1] < cable[1])
                        }
                    }
                }
                // A load the cables hold: the torque of tensions inside the actuator limits.
                let mut r = rng(25 + k as u64);
                let t: Vec<f64> = limits
                    .iter()
                    .map(|l| r.random_range(l[0] + 0.3 * (l[1] - l[0])..l[0] + 0.5 * (l[1] - l[0])))
                    .collect();
                let mut tau = vec![0.0; n];
                slip_torques(&friction, &t, &mut tau).unwrap();
                let t0 = tau.clone();
                let set = slip_equilibrium_set(
                    &model,
                    &friction,
                    &t0,
                    routing.cable_limits(),
                    routing.joint_groups(),
                )
                .unwrap();
                let mut chosen = vec![0.0; m];
                distribute_with_policy(
                    &set,
                    TensionPolicy::LeastTotal,
                    routing.joint_groups(),
                    &names,
                    &mut chosen,
                )
                .unwrap();
                slip_torques(&friction, &chosen, &mut tau).unwrap();
                for (a, b) in tau.iter().zip(&t0) {
                    assert!(
                        (a - b).abs() <= 1e-8 * b.abs().max(1.0),
                        "{case}: {slip:?}: unbalanced: {a} vs {b}"
                    );
                }
                for (c, &t_0) in chosen.iter().enumerate() {
                    let [f_min, f_max] = routing.cable_limits()[c];
                    for w in friction.weights(&model, c).unwrap() {
                        let t_s = t_0 * w;
                        let slack = 1e-7 * (f_max - f_min);
                        assert!(
                            t_s >= f_min - slack && t_s <= f_max + slack,
                            "{case}: cable {c}: {t_s}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn a_capstan_ratio_beyond_the_limits_is_a_typed_refusal() {
    let (robot, routing) = cdhrm5::robot_and_routing(cdhrm5::MODELS[1]);
    let model = FrictionModel::new(&routing).with_friction_coefficient(0.5).unwrap();
    let q = &random_qs(&robot, 26, 1)[0];
    let (_, mut friction) = evaluate(&robot, &routing, &model, q);
    compute_capstan_weights(&model, &mut friction, Slip::Pull).unwrap();
    let m = routing.cable_count();
    let mut out = vec![[0.0; 2]; m];
    let tight = vec![[20.0, 20.5]; m];
    let e = actuator_limits(&model, &friction, &tight, &mut out).unwrap_err();
    let StaticsError::EmptyActuatorInterval { cable, limits, ratio } = e else { panic!("{e}") };
    assert!(ratio > 20.5 / 20.0 && limits == [20.0, 20.5], "{cable}: {ratio}");
    assert_eq!(e.kind(), ErrorKind::Infeasible);
    let e = actuator_limits(&model, &friction, &tight[1..], &mut out).unwrap_err();
    assert!(matches!(e, StaticsError::DimensionMismatch { .. }));
}

// The paper's tension levels in the slip regimes ([`slip_levels`]): they balance the load
// through `J̃`, keep each cable within its own actuator limits, put level 0 and 1 on them, agree
// with the least-total policy where the joints are independent, are the frictionless closed form
// at μ = 0, and name a joint's true torque when they refuse.

/// The friction data at `q` with `slip`'s weights, and the routing's common limits.
fn weights(
    robot: &Robot,
    routing: &Routing,
    model: &FrictionModel,
    q: &[f64],
    slip: Slip,
) -> (RoutingData, FrictionData, TensionLimits) {
    let (geometry, mut friction) = evaluate(robot, routing, model, q);
    compute_capstan_weights(model, &mut friction, slip).unwrap();
    let [f_min, f_max] = routing.cable_limits()[0];
    (geometry, friction, TensionLimits { f_min, f_max })
}

/// A load the cables hold: the torque of actuator tensions in the middle of their limits.
fn load(friction: &FrictionData, limits: &[[f64; 2]], seed: u64) -> Vec<f64> {
    let mut r = rng(seed);
    let t: Vec<f64> = limits
        .iter()
        .map(|l| r.random_range(l[0] + 0.3 * (l[1] - l[0])..l[0] + 0.6 * (l[1] - l[0])))
        .collect();
    let mut t0 = vec![0.0; friction.effective_jacobian().unwrap().ncols()];
    slip_torques(friction, &t, &mut t0).unwrap();
    t0
}

#[test]
fn the_levels_balance_the_load_within_each_cables_actuator_limits() {
    for (case, robot, routing) in cases() {
        let layout = CableLayout::new(&routing).unwrap();
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.2).unwrap();
        let (m, joints) = (routing.cable_count(), layout.joints());
        let names: Vec<String> = routing.cables().iter().map(|c| c.name.clone()).collect();
        let mut answered = 0;
        for (k, q) in random_qs(&robot, 32, 2).iter().enumerate() {
            for slip in [Slip::Pull, Slip::Release] {
                let (_, friction, common) = weights(&robot, &routing, &model, q, slip);
                let cable_limits = routing.cable_limits();
                let mut limits = vec![[0.0; 2]; m];
                actuator_limits(&model, &friction, cable_limits, &mut limits).unwrap();
                let t0 = load(&friction, &limits, 33 + k as u64);
                // In the routed model the closed form fixes the distal joints first, and their
                // levels may overload a proximal joint (the frictionless levels refuse so too):
                // such a refusal is a result there, never in the decoupled model.
                let at = |levels: &[f64]| {
                    let mut t = vec![0.0; m];
                    let closed_form = (&layout, common);
                    match slip_levels(
                        &model,
                        &friction,
                        closed_form,
                        cable_limits,
                        &t0,
                        levels,
                        &mut t,
                    ) {
                        Ok(()) => Some(t),
                        Err(StaticsError::Infeasible { .. }) if !routing.is_decoupled() => None,
                        Err(e) => panic!("{case} {slip:?} {levels:?}: {e}"),
                    }
                };
                let mut r = rng(34 + k as u64);
                let random: Vec<f64> = (0..joints).map(|_| r.random_range(0.0..1.0)).collect();
                let (low, high) = (at(&vec![0.0; joints]), at(&vec![1.0; joints]));
                let answers = [low.clone(), at(&vec![0.5; joints]), high.clone(), at(&random)];
                for t in answers.iter().flatten() {
                    answered += 1;
                    let mut tau = vec![0.0; t0.len()];
                    slip_torques(&friction, t, &mut tau).unwrap();
                    let scale = t0.iter().fold(1.0_f64, |s, x| s.max(x.abs()));
                    for (a, b) in tau.iter().zip(&t0) {
                        assert!((a - b).abs() <= 1e-10 * scale, "{case} {slip:?}: {a} vs {b}");
                    }
                    for (c, (t, l)) in t.iter().zip(&limits).enumerate() {
                        assert!(l[0] <= *t && *t <= l[1], "{case} {slip:?}: cable {c}: {t} {l:?}");
                    }
                }
                // Level 0 and level 1 are the ends of each joint's interval: some cable on one of
                // its own actuator limits (in force closure, level 0 on a least tension and
                // level 1 on a greatest; without it, a cable may meet the other limit).
                for i in 0..joints {
                    let own = 3 * i..3 * i + 3;
                    let gap = |t: &[f64]| {
                        own.clone()
                            .flat_map(|c| limits[c].map(|l| (t[c] - l).abs() / l))
                            .fold(f64::INFINITY, f64::min)
                    };
                    for (level, t) in [(0, &low), (1, &high)] {
                        if let Some(t) = t {
                            assert!(gap(t) <= 1e-12, "{case} {slip:?}: joint {i} at level {level}");
                        }
                    }
                }
                // Where the joints are independent, level 0 is the least total tension and
                // level ½ the middle of the two ends.
                if routing.is_decoupled() {
                    let set = slip_equilibrium_set(
                        &model,
                        &friction,
                        &t0,
                        cable_limits,
                        routing.joint_groups(),
                    )
                    .unwrap();
                    let mut least = vec![0.0; m];
                    let groups = routing.joint_groups();
                    let policy = TensionPolicy::LeastTotal;
                    distribute_with_policy(&set, policy, groups, &names, &mut least).unwrap();
                    let half = at(&vec![0.5; joints]).unwrap();
                    let (low, high) = (low.unwrap(), high.unwrap());
                    for c in 0..m {
                        let scale = limits[c][1];
                        assert!((least[c] - low[c]).abs() <= 1e-8 * scale, "{case}: cable {c}");
                        let mid = 0.5 * (low[c] + high[c]);
                        assert!((half[c] - mid).abs() <= 1e-10 * scale, "{case}: cable {c}");
                    }
                }
            }
        }
        // Two poses × two slips × four level sets; the routed refusals are a minority.
        assert!(answered >= 12, "{case}: {answered} of 16 answered");
    }
}

#[test]
fn at_mu_zero_the_levels_are_the_frictionless_closed_form() {
    for (case, robot, routing) in cases() {
        let layout = CableLayout::new(&routing).unwrap();
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.0).unwrap();
        let (m, joints) = (routing.cable_count(), layout.joints());
        let q = &random_qs(&robot, 35, 1)[0];
        let (geometry, friction, common) = weights(&robot, &routing, &model, q, Slip::Pull);
        let t0 = load(&friction, routing.cable_limits(), 36);
        let levels: Vec<f64> = (0..joints).map(|i| (i as f64 + 0.5) / joints as f64).collect();
        let mut slip = vec![0.0; m];
        let closed_form = (&layout, common);
        let cable_limits = routing.cable_limits();
        slip_levels(&model, &friction, closed_form, cable_limits, &t0, &levels, &mut slip).unwrap();
        let mut intervals = vec![placeholder(common); joints];
        let mut today = vec![0.0; m];
        let jacobian = geometry.jacobian().unwrap();
        distribute_tensions(&layout, jacobian, common, &t0, &levels, &mut intervals, &mut today)
            .unwrap();
        for (c, (a, b)) in slip.iter().zip(&today).enumerate() {
            assert!((a - b).abs() <= 1e-12 * b, "{case}: cable {c}: {a} vs {b}");
        }
    }
}

#[test]
fn a_load_beyond_the_limits_names_the_joint_and_its_true_torque() {
    for (case, robot, routing) in cases().into_iter().filter(|(_, _, r)| r.is_decoupled()) {
        let layout = CableLayout::new(&routing).unwrap();
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.2).unwrap();
        let (m, joints) = (routing.cable_count(), layout.joints());
        let q = &random_qs(&robot, 37, 1)[0];
        let (_, friction, common) = weights(&robot, &routing, &model, q, Slip::Release);
        let mut limits = vec![[0.0; 2]; m];
        actuator_limits(&model, &friction, routing.cable_limits(), &mut limits).unwrap();
        let mut t0 = load(&friction, &limits, 38);
        // The last joint overloaded: the joints before it are solved and hold.
        let last = joints - 1;
        t0[2 * last] *= 1e3;
        t0[2 * last + 1] *= 1e3;
        let mut t = vec![0.0; m];
        let closed_form = (&layout, common);
        let levels = vec![0.5; joints];
        let e = slip_levels(
            &model,
            &friction,
            closed_form,
            routing.cable_limits(),
            &t0,
            &levels,
            &mut t,
        )
        .unwrap_err();
        let StaticsError::Infeasible { joint, torque, limits: reported, .. } = e else {
            panic!("{case}: {e}")
        };
        assert_eq!(joint, last, "{case}");
        for k in 0..2 {
            let want = t0[2 * last + k];
            assert!((torque[k] - want).abs() <= 1e-9 * want.abs(), "{case}: {torque:?}");
        }
        let own = &limits[3 * last..3 * last + 3];
        let lo = own.iter().map(|l| l[0]).fold(f64::INFINITY, f64::min);
        let hi = own.iter().map(|l| l[1]).fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(reported, [lo, hi], "{case}");
    }
}

fn placeholder(limits: TensionLimits) -> TensionInterval {
    TensionInterval {
        joint: 0,
        particular: Default::default(),
        null: Default::default(),
        lambda_min: 0.0,
        lambda_max: 0.0,
        limits,
        limiting: [0, 0],
    }
}
