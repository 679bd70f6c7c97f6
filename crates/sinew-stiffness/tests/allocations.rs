//! The whole pipeline `Q → K_x` allocates nothing once the workspace exists: decoupled (the
//! structured solve) and routed (the dense reference), `evaluate` and `evaluate_compliance`,
//! and the dense `K_W` materialised on request.
//!
//! A counting global allocator (this test binary only) counts every allocation made while the
//! per-configuration functions run.
#![allow(clippy::unwrap_used, clippy::expect_used, unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{Vector3, Vector6};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sinew_robot::{Robot, UniformChain};
use sinew_routing::{PatternModel, Routing, RoutingSpec};
use sinew_stiffness::{ArmStiffness, ArmStiffnessData, EndSolver};

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

const ROBOT_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/cdhrm5");

fn arms() -> Vec<(String, Robot, Routing, EndSolver)> {
    let cdhrm5 = sinew_robot::load(ROBOT_DIR).unwrap();
    let mut v = Vec::new();
    for (file, solver) in [
        (sinew_routing::ROUTING_FILE, EndSolver::Structured),
        (sinew_routing::ROUTED_ROUTING_FILE, EndSolver::Dense),
    ] {
        let routing = sinew_routing::load(format!("{ROBOT_DIR}/{file}"), &cdhrm5).unwrap();
        v.push((format!("cdhrm5 {file}"), cdhrm5.clone(), routing, solver));
    }
    for (model, solver) in
        [(PatternModel::Decoupled, EndSolver::Structured), (PatternModel::Routed, EndSolver::Dense)]
    {
        let chain = UniformChain::like_cdhrm5(25);
        let robot = chain.build().unwrap().with_gravity(Vector3::new(0.0, 0.01, 0.0));
        let routing =
            Routing::new(&robot, &RoutingSpec::for_uniform_chain(&chain, model), "<test>").unwrap();
        v.push((format!("uniform25 {model:?}"), robot, routing, solver));
    }
    v
}

#[test]
fn evaluating_the_pipeline_allocates_nothing() {
    for (name, robot, routing, solver) in arms() {
        let n = robot.dof();
        let model = ArmStiffness::new(&robot, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        let mut rng = ChaCha8Rng::seed_from_u64(17);
        // Around E4 for cdhrm5, around the straight arm (slightly bent) for the chain.
        let pi = std::f64::consts::PI;
        let e4 = [-7.0, -9.0, -9.0, -11.0, 6.0, 7.0, 8.0, -15.0, -12.0, -10.0].map(|d| pi / d);
        let centre: Vec<f64> = if n == 10 { e4.to_vec() } else { vec![0.05; n] };
        let qs: Vec<Vec<f64>> = (0..10)
            .map(|_| centre.iter().map(|c| c + rng.random_range(-0.02..0.02)).collect())
            .collect();
        let levels = vec![0.5; n / 2];
        // A force and a moment (the non-symmetric structured sweep), then a pure force.
        let f = if n == 10 { 5.0 } else { 0.01 };
        let loads = [
            Vector6::new(0.0, f, 0.0, 0.0, 0.0, 0.01 * f),
            Vector6::new(0.0, f, 0.0, 0.0, 0.0, 0.0),
        ];
        // Warm-up: the first evaluation and the first request of K_W.
        model.evaluate(&mut data, &qs[0], &loads[0], &levels).unwrap();
        let _ = data.k_w();

        let before = ALLOCATIONS.load(Ordering::SeqCst);
        for q in &qs {
            for f0 in &loads {
                model.evaluate(&mut data, q, f0, &levels).unwrap();
                assert_eq!(data.end_solver(), solver, "{name}");
                model.evaluate_compliance(&mut data, q, f0, &levels).unwrap();
                // K_W is filled on request, into the storage kept from the last request.
                assert!(data.k_w()[(0, 0)].is_finite());
            }
        }
        let after = ALLOCATIONS.load(Ordering::SeqCst);
        assert_eq!(after - before, 0, "{name}: {} allocations in 40 evaluations", after - before);
    }
}
