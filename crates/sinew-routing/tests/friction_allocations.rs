//! The friction geometry and the capstan weights allocate nothing once their workspace exists
//! (a binary of its own: the counting allocator counts every thread of the process, so this
//! test must not run beside `allocations.rs`'s).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use sinew_robot::RobotData;
use sinew_routing::{
    FrictionData, FrictionModel, Order, RoutingData, Slip, compute_cable_geometry,
    compute_capstan_weights, compute_friction_geometry,
};
use sinew_testkit::alloc::{CountingAllocator, count};
use sinew_testkit::{cdhrm5, config};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

fn the_friction_geometry_and_weights_allocate_nothing() {
    for (name, robot, routing) in cdhrm5::cases(20) {
        let mut rdata = RobotData::new(&robot);
        let mut data = RoutingData::new(&routing);
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.2).unwrap();
        let (built, mut friction) = count(|| FrictionData::new(&model));
        assert!(built > 0, "the counter counts nothing");
        let qs = config::random_qs(&robot, 4, 10);
        compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &qs[0], Order::Hessians)
            .unwrap();
        compute_friction_geometry(&model, &routing, &data, &mut friction).unwrap();
        compute_capstan_weights(&model, &mut friction, Slip::Pull).unwrap();

        let (allocations, checksum) = count(|| {
            let mut checksum = 0.0;
            for q in &qs {
                compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, q, Order::Hessians)
                    .unwrap();
                compute_friction_geometry(&model, &routing, &data, &mut friction).unwrap();
                for slip in [Slip::Pull, Slip::Release] {
                    compute_capstan_weights(&model, &mut friction, slip).unwrap();
                    let last = routing.cable_count() - 1;
                    checksum += friction.weights(&model, last).unwrap()[1]
                        + friction.wrap_gradient(&model, last, 0).unwrap().get(0)
                        + friction.effective_jacobian().unwrap()[(last, 0)];
                }
            }
            checksum
        });
        assert!(checksum.is_finite());
        assert_eq!(allocations, 0, "{name}: {allocations} allocations in 10 configurations");
    }
}

/// The checks one after another, in a plain binary (`harness = false` in Cargo.toml): the
/// counter is global, and a test harness's own thread allocates for its bookkeeping (starting a
/// test, recording its result) while a test runs, which the counter would count.
fn main() {
    the_friction_geometry_and_weights_allocate_nothing();
}
