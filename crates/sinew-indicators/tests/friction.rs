//! The joint probe and the sweep with friction at the holes (spec §9, #27): μ = 0 is the paper's
//! probe bit for bit; with friction the interval's ends are the ends of the feasible actuator
//! tensions (balanced by the segment tensions, every segment within the limits, one on a
//! limit); stick after `equal` keeps the frictionless tensions and is stiffer; bad input is
//! refused by name.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::Matrix2;
use sinew_indicators::{AngleGrid, IndicatorError, JointProbe, sweep_joint, sweep_probe};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{
    FrictionData, FrictionModel, Order, PatternModel, Routing, RoutingData, Slip,
    compute_cable_geometry, compute_capstan_weights, compute_friction_geometry,
};
use sinew_stiffness::{
    FrictionRegime, FrictionStiffnessData, History, StiffnessError, joint_block, slip_stiffness,
    stick_stiffness,
};
use sinew_testkit::cdhrm5;

const SLIPS: [Slip; 2] = [Slip::Pull, Slip::Release];

/// Angles of the other joints that bend the arm (every hole wraps), within the limits.
fn bent(dof: usize) -> Vec<f64> {
    (0..dof).map(|k| 0.12 * ((k as f64) * 1.3 + 0.4).sin()).collect()
}

fn friction(routing: &Routing, mu: f64) -> FrictionModel {
    FrictionModel::new(routing).with_friction_coefficient(mu).unwrap()
}

fn probe(robot: &Robot, routing: &Routing, joint: usize) -> JointProbe {
    let mut probe = JointProbe::new(robot, routing, joint).unwrap();
    probe.set_configuration(&bent(robot.dof())).unwrap();
    probe
}

#[test]
fn at_mu_zero_a_slip_regime_is_the_papers_probe_bit_for_bit() {
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        for joint in [0, 2, 4] {
            for slip in SLIPS {
                let mut plain = probe(&robot, &routing, joint);
                let mut with = probe(&robot, &routing, joint)
                    .with_friction(&routing, friction(&routing, 0.0), FrictionRegime::Slip(slip))
                    .unwrap();
                for (q, tau) in [([0.1, -0.2], [-1.0, 0.5]), ([-0.3, 0.05], [0.4, 2.0])] {
                    let a = plain.evaluate(&robot, &routing, q, tau).unwrap();
                    let b = with.evaluate(&robot, &routing, q, tau).unwrap();
                    assert_eq!(a, b, "{model:?}, joint {joint}, {slip:?}, q {q:?}");
                }
            }
        }
    }
}

/// The segment tensions `T_0 w_s` of cable `c` after `slip` (or equal along it for `None`).
fn segment_tensions(
    model: &FrictionModel,
    data: &FrictionData,
    c: usize,
    t_0: f64,
    slip: Option<Slip>,
) -> Vec<f64> {
    match slip {
        Some(_) => data.weights(model, c).unwrap().iter().map(|w| t_0 * w).collect(),
        None => vec![t_0; data.lengths(model, c).unwrap().len()],
    }
}

#[test]
fn with_friction_the_ends_are_those_of_the_feasible_actuator_tensions() {
    let mu = 0.15;
    for pattern in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(pattern);
        let [f_min, f_max] = routing.tension_limits();
        let model = friction(&routing, mu);
        for joint in [0, 3, 4] {
            for regime in [
                FrictionRegime::Slip(Slip::Pull),
                FrictionRegime::Slip(Slip::Release),
                FrictionRegime::Stick(History::Pull),
                FrictionRegime::Stick(History::Equal),
            ] {
                let slip = match regime {
                    FrictionRegime::Slip(s) => Some(s),
                    FrictionRegime::Stick(h) => h.slip(),
                };
                let mut probe =
                    probe(&robot, &routing, joint).with_friction(&routing, model.clone(), regime);
                let probe = probe.as_mut().unwrap();
                let (q, tau) = ([0.2, -0.15], [1.5, -0.8]);
                let range = probe.evaluate(&robot, &routing, q, tau).unwrap();
                // The friction geometry at the same pose, computed here.
                let mut full = bent(robot.dof());
                (full[2 * joint], full[2 * joint + 1]) = (q[0], q[1]);
                let (mut rdata, mut g) = (RobotData::new(&robot), RoutingData::new(&routing));
                compute_cable_geometry(
                    &routing,
                    &robot,
                    &mut rdata,
                    &mut g,
                    &full,
                    Order::Hessians,
                )
                .unwrap();
                let mut data = FrictionData::new(&model);
                compute_friction_geometry(&model, &routing, &g, &mut data).unwrap();
                if let Some(slip) = slip {
                    compute_capstan_weights(&model, &mut data, slip).unwrap();
                }
                let own = routing.cables_of_joint(joint);
                let what = format!("{pattern:?}, joint {joint}, {regime:?}");
                let mut on_limit = [false; 2];
                for (end, t) in range.tensions.iter().enumerate() {
                    // Balance by the segment tensions: τ = −Σ_c Σ_s T_{c,s} J_{c,s} on the
                    // joint's two DOF.
                    let mut torque = [0.0; 2];
                    for (r, c) in own.clone().enumerate() {
                        let tensions = segment_tensions(&model, &data, c, t[r], slip);
                        for (s, t_s) in tensions.iter().enumerate() {
                            let j_s = data.segment_jacobian(&model, c, s).unwrap();
                            for (v, d) in j_s.values.iter().zip(j_s.dofs.clone()) {
                                if d / 2 == joint {
                                    torque[d % 2] -= t_s * v;
                                }
                            }
                        }
                        // Every segment within the limits; one of them on a limit at each end.
                        for t_s in tensions {
                            assert!(
                                t_s >= f_min * (1.0 - 1e-12) && t_s <= f_max * (1.0 + 1e-12),
                                "{what}, end {end}, cable {c}: segment tension {t_s}"
                            );
                            let tight = ((t_s - f_min).abs()).min((t_s - f_max).abs());
                            on_limit[end] |= tight <= 1e-9 * f_max;
                        }
                    }
                    for k in 0..2 {
                        assert!(
                            (torque[k] - tau[k]).abs() <= 1e-9 * (1.0 + tau[k].abs()),
                            "{what}, end {end}: torque {torque:?} against {tau:?}"
                        );
                    }
                }
                assert_eq!(on_limit, [true, true], "{what}: the ends are on a limit");
                // The stiffness at each end: the regime's whole-arm K_q at those tensions (the
                // joint's cables only), its joint block.
                let mut out = FrictionStiffnessData::new(&model);
                for (end, k) in [range.k_at_min, range.k_at_max].into_iter().enumerate() {
                    let mut t = vec![0.0; routing.cable_count()];
                    t[own.clone()].copy_from_slice(range.tensions[end].as_slice());
                    match regime {
                        FrictionRegime::Slip(s) => {
                            slip_stiffness(&model, &routing, &g, &data, s, &t, &mut out).unwrap()
                        }
                        FrictionRegime::Stick(h) => {
                            stick_stiffness(&model, &routing, &g, &data, h, &t, &mut out).unwrap()
                        }
                    }
                    let direct = joint_block(out.stiffness().unwrap(), joint).unwrap();
                    assert!(
                        (k - direct).norm() <= 1e-12 * direct.norm(),
                        "{what}: {k} against {direct}"
                    );
                }
                let totals = range.tensions.map(|t| t.sum());
                assert!(totals[0] < totals[1] - 1.0, "{what}: least total first, {totals:?}");
            }
        }
    }
}

#[test]
fn stick_after_equal_keeps_the_frictionless_tensions_and_is_stiffer() {
    // K_stick ⪰ K at equal tensions (Cauchy–Schwarz; sinew_stiffness::stick_stiffness): every
    // diagonal entry of the joint's block is larger, at both ends.
    for pattern in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(pattern);
        for joint in 0..5 {
            let mut plain = probe(&robot, &routing, joint);
            let regime = FrictionRegime::Stick(History::Equal);
            let mut stick = probe(&robot, &routing, joint).with_friction(
                &routing,
                friction(&routing, 0.1),
                regime,
            );
            let stick = stick.as_mut().unwrap();
            let (q, tau) = ([-0.1, 0.25], [-0.5, 1.0]);
            let a = plain.evaluate(&robot, &routing, q, tau).unwrap();
            let b = stick.evaluate(&robot, &routing, q, tau).unwrap();
            assert_eq!(a.tensions, b.tensions, "{pattern:?}, joint {joint}");
            assert_eq!(a.interval, b.interval);
            for (ka, kb) in [(a.k_at_min, b.k_at_min), (a.k_at_max, b.k_at_max)] {
                let gain: Matrix2<f64> = kb - ka;
                assert!(
                    gain[(0, 0)] > 0.1 * ka[(0, 0)] && gain[(1, 1)] > 0.1 * ka[(1, 1)],
                    "{pattern:?}, joint {joint}: stick {kb} against frictionless {ka}"
                );
            }
        }
    }
}

#[test]
fn pull_leaves_less_tension_at_the_joint_than_release() {
    // The routed arm's distal joint: its cables pass every proximal hole, so after a pull their
    // anchors carry less than the actuator and after a release more. The least total actuator
    // tension holding the torque is higher after a pull than after a release.
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Routed);
    let totals = SLIPS.map(|slip| {
        let regime = FrictionRegime::Slip(slip);
        let mut p =
            probe(&robot, &routing, 4).with_friction(&routing, friction(&routing, 0.2), regime);
        let range = p.as_mut().unwrap().evaluate(&robot, &routing, [0.2, 0.1], [2.0, -1.0]);
        range.unwrap().tensions[0].sum()
    });
    assert!(totals[0] > 1.05 * totals[1], "pull {} against release {}", totals[0], totals[1]);
}

#[test]
fn the_sweep_with_friction_maps_the_probe_and_marks_empty_actuator_intervals_infeasible() {
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Routed);
    let grid = AngleGrid { lower: -0.3, upper: 0.3, points: 3 };
    let regime = FrictionRegime::Slip(Slip::Pull);
    let probe = probe(&robot, &routing, 4).with_friction(&routing, friction(&routing, 0.1), regime);
    let probe = probe.unwrap();
    let maps = sweep_probe(&probe, &robot, &routing, [0.5, 0.5], grid, &|_, _| ()).unwrap();
    let mut one = probe.clone();
    for a in 0..3 {
        for b in 0..3 {
            let q = [grid.angle(a), grid.angle(b)];
            let range = one.evaluate(&robot, &routing, q, [0.5, 0.5]).unwrap();
            let cell = maps.cell(a, b).unwrap();
            assert_eq!((cell.k_x, cell.k_y), (range.sigma_x(), range.sigma_y()));
        }
    }
    // Without friction the same sweep differs (friction changes the numbers).
    let plain = sweep_joint(&robot, &routing, 4, [0.5, 0.5], grid, &|_, _| ()).unwrap();
    assert_ne!(plain.cells, maps.cells);
    // μ so large that the capstan ratio along a cable exceeds f_max / f_min = 30 at a bent pose:
    // no actuator tension keeps every segment within the limits, an infeasible cell.
    let bent_hard = vec![0.5; robot.dof()];
    let mut hard = JointProbe::new(&robot, &routing, 4).unwrap();
    hard.set_configuration(&bent_hard).unwrap();
    let hard = hard.with_friction(&routing, friction(&routing, 4.0), regime).unwrap();
    let err = hard.clone().evaluate(&robot, &routing, [0.5, 0.5], [0.5, 0.5]).unwrap_err();
    assert!(err.is_infeasible(), "{err}");
    assert!(err.to_string().contains("capstan ratio"), "{err}");
    let grid = AngleGrid { lower: 0.4, upper: 0.5, points: 2 };
    let maps = sweep_probe(&hard, &robot, &routing, [0.5, 0.5], grid, &|_, _| ()).unwrap();
    assert_eq!(maps.feasible(), 0);
}

#[test]
fn stick_at_mu_zero_and_a_foreign_model_are_refused_by_name() {
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Routed);
    let stick = FrictionRegime::Stick(History::Pull);
    let err = probe(&robot, &routing, 1)
        .with_friction(&routing, friction(&routing, 0.0), stick)
        .unwrap_err();
    assert!(
        matches!(&err, IndicatorError::Stiffness(e) if matches!(**e, StiffnessError::StickWithoutFriction { cable: 0 })),
        "{err:?}"
    );
    let chain = cdhrm5::chain(3, PatternModel::Routed).1;
    let err = probe(&robot, &routing, 1)
        .with_friction(&routing, friction(&chain, 0.1), stick)
        .unwrap_err();
    assert!(err.to_string().contains("friction model's"), "{err}");
}
