//! The stick and slip stiffness allocate nothing once their workspace exists (a binary of its
//! own: the counting allocator counts every thread of the process).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use sinew_robot::RobotData;
use sinew_routing::{
    FrictionData, FrictionModel, Order, RoutingData, Slip, compute_cable_geometry,
    compute_capstan_weights, compute_friction_geometry,
};
use sinew_stiffness::{FrictionStiffnessData, History, slip_stiffness, stick_stiffness};
use sinew_testkit::alloc::{CountingAllocator, count};
use sinew_testkit::{cdhrm5, config};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

fn the_friction_stiffness_allocates_nothing() {
    for (name, robot, routing) in cdhrm5::cases(20) {
        let mut rdata = RobotData::new(&robot);
        let mut geometry = RoutingData::new(&routing);
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.2).unwrap();
        let mut friction = FrictionData::new(&model);
        let (built, mut out) = count(|| FrictionStiffnessData::new(&model));
        assert!(built > 0, "the counter counts nothing");
        let tensions = vec![50.0; routing.cable_count()];
        let qs = config::random_qs(&robot, 5, 5);
        // One evaluation before counting: faer's matrix product (the slip stiffness's series
        // terms) allocates once, on its first use in the process (measured: 1, then none).
        compute_cable_geometry(
            &routing,
            &robot,
            &mut rdata,
            &mut geometry,
            &qs[0],
            Order::Hessians,
        )
        .unwrap();
        compute_friction_geometry(&model, &routing, &geometry, &mut friction).unwrap();
        compute_capstan_weights(&model, &mut friction, Slip::Pull).unwrap();
        slip_stiffness(&model, &routing, &geometry, &friction, Slip::Pull, &tensions, &mut out)
            .unwrap();
        let (allocations, checksum) = count(|| {
            let mut checksum = 0.0;
            for q in &qs {
                compute_cable_geometry(
                    &routing,
                    &robot,
                    &mut rdata,
                    &mut geometry,
                    q,
                    Order::Hessians,
                )
                .unwrap();
                compute_friction_geometry(&model, &routing, &geometry, &mut friction).unwrap();
                for slip in [Slip::Pull, Slip::Release] {
                    compute_capstan_weights(&model, &mut friction, slip).unwrap();
                    slip_stiffness(
                        &model, &routing, &geometry, &friction, slip, &tensions, &mut out,
                    )
                    .unwrap();
                    checksum += out.stiffness().unwrap()[(0, 0)] + out.skew_norm().unwrap();
                    let history = if slip == Slip::Pull { History::Pull } else { History::Release };
                    stick_stiffness(
                        &model, &routing, &geometry, &friction, history, &tensions, &mut out,
                    )
                    .unwrap();
                    checksum += out.symmetric_part().unwrap()[(0, 0)];
                }
            }
            checksum
        });
        assert!(checksum.is_finite());
        assert_eq!(allocations, 0, "{name}: {allocations} allocations in 5 configurations");
    }
}

/// The checks one after another, in a plain binary (`harness = false` in Cargo.toml): the
/// counter is global, and a test harness's own thread allocates for its bookkeeping (starting a
/// test, recording its result) while a test runs, which the counter would count.
fn main() {
    the_friction_stiffness_allocates_nothing();
}
