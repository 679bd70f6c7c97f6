//! Solving the arm's statics at a configuration allocates nothing once the workspaces exist.
#![allow(clippy::unwrap_used, clippy::expect_used, unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use faer::Mat;
use nalgebra::Vector6;
use sinew_robot::RobotData;
use sinew_routing::RoutingData;
use sinew_statics::{ArmStatics, JointEndData, equilibrium_torque_derivative};

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
fn solving_the_statics_allocates_nothing() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/cdhrm5");
    let robot = sinew_robot::load(dir).unwrap();
    for file in [sinew_routing::ROUTING_FILE, sinew_routing::ROUTED_ROUTING_FILE] {
        let routing = sinew_routing::load(format!("{dir}/{file}"), &robot).unwrap();
        let statics = ArmStatics::new(&routing).unwrap();
        let mut rdata = RobotData::new(&robot);
        let mut gdata = RoutingData::new(&routing);
        let mut data = statics.data(&robot);
        let mut jdata = JointEndData::new(&robot);
        let mut k_w = Mat::<f64>::zeros(10, 10);
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        let q = [-0.45, -0.35, -0.35, -0.29, 0.52, 0.45, 0.39, -0.21, -0.26, -0.31];
        let levels = [0.3, 0.2, 0.1, 0.05, 0.0];
        statics
            .solve_at(&robot, &routing, &mut rdata, &mut gdata, &mut data, &q, &f0, &levels)
            .unwrap();
        let before = ALLOCATIONS.load(Ordering::SeqCst);
        for _ in 0..10 {
            statics
                .solve_at(&robot, &routing, &mut rdata, &mut gdata, &mut data, &q, &f0, &levels)
                .unwrap();
            equilibrium_torque_derivative(&robot, &mut rdata, &mut jdata, &f0, k_w.as_mut())
                .unwrap();
        }
        let after = ALLOCATIONS.load(Ordering::SeqCst);
        assert_eq!(after - before, 0, "{file}: {} allocations", after - before);
    }
}
