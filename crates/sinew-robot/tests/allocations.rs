//! Evaluating a configuration allocates nothing once the workspace exists.
//!
//! A counting global allocator (this test binary only) counts every allocation made while the
//! per-configuration functions run.
#![allow(clippy::unwrap_used, clippy::expect_used, unsafe_code)]

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use faer::Mat;
use nalgebra::Vector6;
use sinew_robot::RobotData;

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn evaluating_a_configuration_allocates_nothing() {
    for robot in [common::cdhrm5(), common::chain(50)] {
        let n = robot.dof();
        let mut data = RobotData::new(&robot);
        let mut jacobian = Mat::<f64>::zeros(6, n);
        let mut derivative = Mat::<f64>::zeros(6, n);
        let mut square = Mat::<f64>::zeros(n, n);
        let mut torque = vec![0.0; n];
        let tip = robot.tip_point();
        let wrench = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.1);
        let mut rng = common::rng(3);
        let qs: Vec<Vec<f64>> = (0..10).map(|_| common::random_q(&robot, &mut rng)).collect();

        let before = ALLOCATIONS.load(Ordering::SeqCst);
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
        let after = ALLOCATIONS.load(Ordering::SeqCst);
        assert_eq!(
            after - before,
            0,
            "{}: {} allocations in 10 configurations",
            robot.name(),
            after - before
        );
    }
}
