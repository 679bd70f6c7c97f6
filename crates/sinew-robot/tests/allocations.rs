//! Evaluating a configuration allocates nothing once the workspace exists.
//!
//! A counting global allocator (this test binary only) counts every allocation made while the
//! per-configuration functions run.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use nalgebra::Vector6;
use sinew_robot::RobotData;
use sinew_testkit::alloc::{CountingAllocator, assert_counting, count};
use sinew_testkit::{cdhrm5, config};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

fn evaluating_a_configuration_allocates_nothing() {
    assert_counting();
    for robot in [cdhrm5::robot(), cdhrm5::chain_robot(50)] {
        let n = robot.dof();
        let mut data = RobotData::new(&robot);
        let mut jacobian = Mat::<f64>::zeros(6, n);
        let mut derivative = Mat::<f64>::zeros(6, n);
        let mut square = Mat::<f64>::zeros(n, n);
        let mut torque = vec![0.0; n];
        let tip = robot.tip_point();
        let wrench = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.1);
        let qs = config::random_qs(&robot, 3, 10);

        let (allocations, ()) = count(|| {
            for q in &qs {
                robot.check_limits(q).unwrap();
                robot.forward_kinematics(&mut data, q).unwrap();
                robot.point_jacobian(&data, &tip, jacobian.as_mut()).unwrap();
                for i in 0..n {
                    robot.point_jacobian_derivative(&data, &tip, i, derivative.as_mut()).unwrap();
                }
                robot.wrench_torque(&data, &tip, &wrench, &mut torque).unwrap();
                robot.wrench_torque_derivative(&mut data, &tip, &wrench, square.as_mut()).unwrap();
                robot.gravity_torque(&mut data, &mut torque).unwrap();
                robot.gravity_torque_derivative(&mut data, square.as_mut()).unwrap();
                robot.tip_pose(&data).unwrap();
            }
        });
        assert_eq!(
            allocations,
            0,
            "{}: {allocations} allocations in 10 configurations",
            robot.name()
        );
    }
}

/// The checks one after another, in a plain binary (`harness = false` in Cargo.toml): the
/// counter is global, and a test harness's own thread allocates for its bookkeeping (starting a
/// test, recording its result) while a test runs, which the counter would count.
fn main() {
    evaluating_a_configuration_allocates_nothing();
}
