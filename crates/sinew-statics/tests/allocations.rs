//! Solving the arm's statics at a configuration allocates nothing once the workspaces exist.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use nalgebra::Vector6;
use sinew_robot::RobotData;
use sinew_routing::RoutingData;
use sinew_statics::{ArmStatics, JointEndData, equilibrium_torque_derivative};
use sinew_testkit::alloc::{CountingAllocator, assert_counting, count};
use sinew_testkit::cdhrm5;

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

fn solving_the_statics_allocates_nothing() {
    assert_counting();
    let robot = cdhrm5::robot();
    for model in cdhrm5::MODELS {
        let routing = cdhrm5::routing(&robot, model);
        let file = cdhrm5::routing_file(model);
        let statics = ArmStatics::new(&routing);
        let mut rdata = RobotData::new(&robot);
        let mut gdata = RoutingData::new(&routing);
        let mut data = statics.data(&robot);
        let mut jdata = JointEndData::new(&robot);
        let mut k_w = Mat::<f64>::zeros(10, 10);
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        let q = cdhrm5::LOADED_POSE;
        let levels = [0.3, 0.2, 0.1, 0.05, 0.0];
        statics
            .solve_at(&robot, &routing, &mut rdata, &mut gdata, &mut data, &q, &f0, &levels)
            .unwrap();
        let (allocations, ()) = count(|| {
            for _ in 0..10 {
                statics
                    .solve_at(&robot, &routing, &mut rdata, &mut gdata, &mut data, &q, &f0, &levels)
                    .unwrap();
                equilibrium_torque_derivative(&robot, &mut rdata, &mut jdata, &f0, k_w.as_mut())
                    .unwrap();
            }
        });
        assert_eq!(allocations, 0, "{file}: {allocations} allocations");
    }
}

/// The checks one after another, in a plain binary (`harness = false` in Cargo.toml): the
/// counter is global, and a test harness's own thread allocates for its bookkeeping (starting a
/// test, recording its result) while a test runs, which the counter would count.
fn main() {
    solving_the_statics_allocates_nothing();
}
