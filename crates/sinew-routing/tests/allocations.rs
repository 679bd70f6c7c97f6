//! Evaluating a configuration allocates nothing once the workspaces exist.
//!
//! A counting global allocator (this test binary only) counts every allocation made while the
//! per-configuration functions run.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use sinew_robot::RobotData;
use sinew_routing::{
    Order, RoutingData, compute_cable_geometry, compute_cable_geometry_from_kinematics,
};
use sinew_testkit::alloc::{CountingAllocator, count};
use sinew_testkit::{cdhrm5, config};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

fn evaluating_a_configuration_allocates_nothing() {
    for (name, robot, routing) in cdhrm5::cases(50) {
        let (n, m) = (robot.dof(), routing.cable_count());
        let mut rdata = RobotData::new(&robot);
        // The counter does count: building a workspace allocates.
        let (built, mut data) = count(|| RoutingData::new(&routing));
        assert!(built > 0, "the counter counts nothing");
        let mut hessian = Mat::<f64>::zeros(n, n);
        let mut k_l = Mat::<f64>::zeros(m, m);
        let f = vec![100.0; m];
        let qs = config::random_qs(&robot, 3, 10);
        // Warm-up: one full evaluation.
        compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &qs[0], Order::Hessians)
            .unwrap();

        let (allocations, checksum) = count(|| {
            let mut checksum = 0.0;
            for q in &qs {
                compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, q, Order::Hessians)
                    .unwrap();
                checksum += data.lengths().unwrap()[m - 1] + data.jacobian().unwrap()[(m - 1, 0)];
                data.cable_hessian(&routing, m - 1, hessian.as_mut()).unwrap();
                checksum += data.segment_hessian(&routing, 0).unwrap()[(0, 0)];
                data.add_weighted_hessians(&routing, &f, hessian.as_mut()).unwrap();
                routing.fill_stiffness_matrix(k_l.as_mut()).unwrap();
                robot.forward_kinematics(&mut rdata, q).unwrap();
                compute_cable_geometry_from_kinematics(
                    &routing,
                    &robot,
                    &rdata,
                    &mut data,
                    Order::Jacobian,
                )
                .unwrap();
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
    evaluating_a_configuration_allocates_nothing();
}
