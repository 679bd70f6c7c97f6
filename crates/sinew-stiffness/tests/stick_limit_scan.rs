//! The stick load limit skips most holes on a bound (`stick_limit.rs`, `Reach`); this checks
//! that it still gives the full pass's answer to the bit. The reference here computes every
//! edge of every hole from the friction geometry's public rows, in the full pass's order (cable
//! by cable, hole by hole, lower edge first, the first of equal `α` kept), and is compared with
//! the library's magnitude (bits), first event and holes at once, along many directions: the
//! twelve base directions, seeded random ones and their mirrors (`−u`, computed from `u`'s
//! rates), alone and all at once, on cdhrm5 (routed, decoupled) and routed chains
//! of 6 and 25 joints, after each history, bent and straight (every hole kinked, on an edge).
//! A bound that is too tight (a term of `ρ` left out, the wrong DOFs' motion, no margin) skips
//! the hole that is reached first in some of these directions and fails.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use faer::linalg::solvers::Solve;
use nalgebra::Vector6;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sinew_robot::{Robot, RobotData};
use sinew_routing::{
    DofRow, FrictionData, FrictionModel, Order, PatternModel, Routing, RoutingData,
    compute_cable_geometry, compute_capstan_weights, compute_friction_geometry,
};
use sinew_stiffness::{
    BandEdge, EDGE_TOLERANCE, History, HoleEvent, RATE_TOLERANCE, base_directions,
    stick_load_limits,
};
use sinew_testkit::cdhrm5;

fn dot(row: &DofRow<'_>, x: &[f64]) -> f64 {
    row.values.iter().zip(row.dofs.clone()).map(|(v, d)| v * x[d]).sum()
}

/// The full pass: `(magnitude, first, at_once)` along the joint motion `dq`.
fn full_pass(
    model: &FrictionModel,
    routing: &Routing,
    friction: &FrictionData,
    history: History,
    actuator: &[f64],
    dq: &[f64],
) -> (f64, Option<HoleEvent>, Vec<HoleEvent>) {
    let ea = routing.youngs_modulus() * routing.area();
    let (mut magnitude, mut first, mut at_once) = (f64::INFINITY, None, Vec::new());
    for (c, (&t_0, &mu)) in actuator.iter().zip(model.friction_coefficients()).enumerate() {
        let rows = friction.cable(model, c).unwrap();
        let kinked = friction.kinked(model, c).unwrap();
        let tension = |s: usize| match history {
            History::Equal => t_0,
            _ => t_0 * rows.weights.unwrap()[s],
        };
        for k in 0..rows.len() - 1 {
            let (t_k, t_next) = (tension(k), tension(k + 1));
            let springs = [ea / rows.lengths[k], ea / rows.lengths[k + 1]];
            let theta = rows.wrap[k];
            // The library's band edges: `e^{+μθ}` as `1/e^{−μθ}` (one exponential per hole).
            let lo = (-mu * theta).exp();
            let hi = 1.0 / lo;
            let dt_k = springs[0] * dot(&rows.jacobian(k), dq);
            let dt_next = springs[1] * dot(&rows.jacobian(k + 1), dq);
            let dtheta = dot(&rows.wrap_gradient(k).expect("wrap gradients"), dq);
            let turn = mu * t_k;
            for (edge, g, (a, b, d)) in [
                (BandEdge::Lower, t_next - t_k * lo, (1.0, -lo, lo * turn)),
                (BandEdge::Upper, t_k * hi - t_next, (-1.0, hi, hi * turn)),
            ] {
                let dg = a * dt_next + b * dt_k + d * dtheta;
                let terms = (a * dt_next).abs() + (b * dt_k).abs() + (d * dtheta).abs();
                if dg >= -RATE_TOLERANCE * terms {
                    continue;
                }
                let event = HoleEvent { cable: c, hole: k, edge, kinked: kinked[k] };
                if g <= EDGE_TOLERANCE * (t_k + t_next) {
                    at_once.push(event);
                } else if g / -dg < magnitude {
                    (magnitude, first) = (g / -dg, Some(event));
                }
            }
        }
    }
    if let Some(&event) = at_once.first() {
        (magnitude, first) = (0.0, Some(event));
    }
    (magnitude, first, at_once)
}

/// Every direction's limit against the full pass, after every history, at `q`; returns how
/// many directions had a finite, positive limit (so that the comparison saw the skipping).
fn check(robot: &Robot, routing: &Routing, q: &[f64], seed: u64) -> usize {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let n = routing.dof();
    let model = FrictionModel::new(routing).with_friction_coefficient(0.15).unwrap();
    let mut rdata = RobotData::new(robot);
    let mut geometry = RoutingData::new(routing);
    compute_cable_geometry(routing, robot, &mut rdata, &mut geometry, q, Order::Hessians).unwrap();
    let mut friction = FrictionData::new(&model);
    compute_friction_geometry(&model, routing, &geometry, &mut friction).unwrap();
    let actuator: Vec<f64> =
        (0..routing.cable_count()).map(|_| rng.random_range(30.0..300.0)).collect();
    // Any positive definite K and any J_x: the pass reads only the joint motions they give.
    let j_x = Mat::<f64>::from_fn(6, n, |_, _| rng.random_range(-1.0..1.0));
    let b = Mat::<f64>::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
    let k = &b * b.transpose() + Mat::<f64>::identity(n, n) * (n as f64);
    let zero = Mat::<f64>::zeros(n, n);
    let mut directions = base_directions().to_vec();
    directions.extend((0..60).map(|_| Vector6::from_fn(|_, _| rng.random_range(-1.0..1.0))));
    // Mirrors of random directions (computed from their partner's rates, negated), a repeated
    // direction and a second mirror of it.
    let mirrors: Vec<Vector6<f64>> = directions[12..20].iter().map(|u| -u).collect();
    directions.extend(mirrors);
    directions.extend([directions[12], -directions[12], -directions[12]]);
    let mut positive = 0;
    for history in [History::Equal, History::Pull, History::Release] {
        if let Some(slip) = history.slip() {
            compute_capstan_weights(&model, &mut friction, slip).unwrap();
        }
        let lu = k.partial_piv_lu();
        // Every direction at once, then one direction and one pair alone (without bounds).
        let (one, pair) = ([directions[13]], [directions[14], -directions[14]]);
        for set in [&directions[..], &one, &pair] {
            let mats = (k.as_ref(), zero.as_ref(), j_x.as_ref());
            let limits =
                stick_load_limits(&model, routing, &friction, history, &actuator, mats, set)
                    .unwrap();
            for (u, limit) in set.iter().zip(&limits) {
                let rhs =
                    Mat::<f64>::from_fn(n, 1, |i, _| (0..6).map(|r| j_x[(r, i)] * u[r]).sum());
                let dq = lu.solve(&rhs);
                for (i, x) in limit.joint_motion.iter().enumerate() {
                    let tolerance = 1e-12 * dq[(i, 0)].abs().max(1e-3);
                    assert!((x - dq[(i, 0)]).abs() <= tolerance, "δQ_{i}");
                }
                let (magnitude, first, at_once) =
                    full_pass(&model, routing, &friction, history, &actuator, &limit.joint_motion);
                let what = format!("{history:?} along {u:?}");
                assert_eq!(limit.direction, *u, "{what}");
                assert_eq!(limit.magnitude.to_bits(), magnitude.to_bits(), "{what}");
                assert_eq!(limit.first, first, "{what}");
                assert_eq!(limit.at_once, at_once, "{what}");
                positive += usize::from(magnitude > 0.0 && magnitude.is_finite());
            }
        }
    }
    positive
}

#[test]
fn cdhrm5_bent_and_straight() {
    for model in [PatternModel::Routed, PatternModel::Decoupled] {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let positive = check(&robot, &routing, &cdhrm5::LOADED_POSE, 1);
        // After `equal` every direction's limit is positive; after pull or release most are 0.
        assert!(positive >= 72, "{model:?}: {positive}");
        check(&robot, &routing, &[0.0; 10], 2);
    }
}

#[test]
fn routed_chains() {
    for (joints, seed) in [(6, 3), (25, 4)] {
        let (robot, routing) = cdhrm5::chain(joints, PatternModel::Routed);
        let q: Vec<f64> = (0..2 * joints).map(|i| 0.05 * ((i as f64) * 0.7).sin()).collect();
        assert!(check(&robot, &routing, &q, seed) >= 72, "{joints} joints");
        let q: Vec<f64> = (0..2 * joints).map(|i| 0.2 * ((i as f64) * 1.3).cos()).collect();
        check(&robot, &routing, &q, seed + 10);
        // Straight and bent joints in runs of three: along a cable, holes on an edge (kinked,
        // their band of no width) between holes with room.
        let q: Vec<f64> = (0..2 * joints)
            .map(|i| if (i / 6) % 2 == 0 { 0.0 } else { 0.15 * ((i as f64) * 0.9).sin() })
            .collect();
        check(&robot, &routing, &q, seed + 20);
    }
}
