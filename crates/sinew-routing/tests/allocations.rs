//! Evaluating a configuration allocates nothing once the workspaces exist.
//!
//! A counting global allocator (this test binary only) counts every allocation made while the
//! per-configuration functions run.
#![allow(clippy::unwrap_used, clippy::expect_used, unsafe_code)]

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use faer::Mat;
use sinew_robot::RobotData;
use sinew_routing::{
    Order, RoutingData, compute_cable_geometry, compute_cable_geometry_from_kinematics,
};

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
    for (name, robot, routing) in common::cases() {
        let (n, m) = (robot.dof(), routing.cable_count());
        let mut rdata = RobotData::new(&robot);
        // The counter does count: building a workspace allocates.
        let before = ALLOCATIONS.load(Ordering::SeqCst);
        let mut data = RoutingData::new(&routing);
        assert!(ALLOCATIONS.load(Ordering::SeqCst) > before, "the counter counts nothing");
        let mut hessian = Mat::<f64>::zeros(n, n);
        let mut k_l = Mat::<f64>::zeros(m, m);
        let f = vec![100.0; m];
        let mut rng = common::rng(3);
        let qs: Vec<Vec<f64>> = (0..10).map(|_| common::random_q(&robot, &mut rng)).collect();
        // Warm-up: one full evaluation.
        compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &qs[0], Order::Hessians)
            .unwrap();

        let before = ALLOCATIONS.load(Ordering::SeqCst);
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
        let after = ALLOCATIONS.load(Ordering::SeqCst);
        assert!(checksum.is_finite());
        assert_eq!(
            after - before,
            0,
            "{name}: {} allocations in 10 configurations",
            after - before
        );
    }
}
