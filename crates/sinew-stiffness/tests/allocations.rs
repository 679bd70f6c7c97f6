//! The whole pipeline `Q → K_x` allocates nothing once the workspace exists: decoupled (the
//! structured solve) and routed (the dense reference), `evaluate` and the stages one by one (a pose, two tension stages, the end),
//! and the dense `K_W` materialised on request.
//!
//! A counting global allocator (this test binary only) counts every allocation made while the
//! per-configuration functions run.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Vector3, Vector6};
use sinew_robot::Robot;
use sinew_routing::{PatternModel, Routing};
use sinew_statics::TensionChoice;
use sinew_stiffness::{ArmStiffness, ArmStiffnessData, EndSolver};
use sinew_testkit::alloc::{CountingAllocator, assert_counting, count};
use sinew_testkit::{cdhrm5, config};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

fn arms() -> Vec<(String, Robot, Routing, EndSolver)> {
    let mut v = Vec::new();
    for (model, solver) in
        [(PatternModel::Decoupled, EndSolver::Structured), (PatternModel::Routed, EndSolver::Dense)]
    {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        v.push((format!("cdhrm5 {}", cdhrm5::routing_file(model)), robot, routing, solver));
    }
    for (model, solver) in
        [(PatternModel::Decoupled, EndSolver::Structured), (PatternModel::Routed, EndSolver::Dense)]
    {
        let (robot, routing) = cdhrm5::chain(25, model);
        let robot = robot.with_gravity(Vector3::new(0.0, 0.01, 0.0));
        v.push((format!("uniform25 {model:?}"), robot, routing, solver));
    }
    v
}

fn evaluating_the_pipeline_allocates_nothing() {
    assert_counting();
    for (name, robot, routing, solver) in arms() {
        let n = robot.dof();
        let model = ArmStiffness::new(&robot, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        let mut rng = config::rng(17);
        // Around a loaded pose (E4 rounded) for cdhrm5, around the straight arm (slightly bent)
        // for the chain.
        let centre: Vec<f64> = if n == 10 { cdhrm5::LOADED_POSE.to_vec() } else { vec![0.05; n] };
        let qs: Vec<Vec<f64>> = (0..10).map(|_| config::near(&centre, 0.02, &mut rng)).collect();
        let levels = vec![0.5; n / 2];
        // A force and a moment (the non-symmetric structured sweep), then a pure force.
        let f = if n == 10 { 5.0 } else { 0.01 };
        let loads = [
            Vector6::new(0.0, f, 0.0, 0.0, 0.0, 0.01 * f),
            Vector6::new(0.0, f, 0.0, 0.0, 0.0, 0.0),
        ];
        // Warm-up: the first evaluation and the first request of K_W.
        model.evaluate(&mut data, &qs[0], &loads[0], TensionChoice::Levels(&levels)).unwrap();
        let _ = data.k_w();

        let (allocations, ()) = count(|| {
            for q in &qs {
                for f0 in &loads {
                    model.evaluate(&mut data, q, f0, TensionChoice::Levels(&levels)).unwrap();
                    assert_eq!(data.end_solver(), solver, "{name}");
                    // The same by stages: a pose, two tension stages, the end.
                    model.set_pose(&mut data, q, f0).unwrap();
                    model.set_tensions(&mut data, TensionChoice::Default).unwrap();
                    model.set_tensions(&mut data, TensionChoice::Levels(&levels)).unwrap();
                    assert!(model.solve_end(&mut data).unwrap().is_stable());
                    // K_W is filled on request, into the storage kept from the last request.
                    assert!(data.k_w()[(0, 0)].is_finite());
                }
            }
        });
        assert_eq!(allocations, 0, "{name}: {allocations} allocations in 40 evaluations");
    }
}

/// The equilibrium set of each new pose is rebuilt in the last pose's buffers: no allocation,
/// and the set a fresh build gives (closed forms in both models: one cross product per joint
/// when decoupled, the block-triangular basis when routed).
fn the_equilibrium_set_of_a_new_pose_allocates_nothing() {
    assert_counting();
    for (name, robot, routing, _) in arms() {
        let n = robot.dof();
        let model = ArmStiffness::new(&robot, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        let mut rng = config::rng(23);
        let centre: Vec<f64> = if n == 10 { cdhrm5::LOADED_POSE.to_vec() } else { vec![0.05; n] };
        let qs: Vec<Vec<f64>> = (0..6).map(|_| config::near(&centre, 0.05, &mut rng)).collect();
        let f = if n == 10 { 5.0 } else { 0.01 };
        let f0 = Vector6::new(0.0, f, 0.5 * f, 0.0, 0.0, 0.0);
        model.set_pose(&mut data, &qs[0], &f0).unwrap();
        model.equilibrium_set(&mut data).unwrap();
        for q in &qs[1..] {
            let (allocations, ()) = count(|| {
                model.set_pose(&mut data, q, &f0).unwrap();
                model.equilibrium_set(&mut data).unwrap();
            });
            assert_eq!(allocations, 0, "{name}: {allocations} allocations for a new pose's set");
            let fresh = sinew_statics::EquilibriumSet::new(
                data.cables.jacobian().unwrap(),
                &data.statics.t0,
                model.statics().cable_limits(),
                model.statics().joint_groups(),
            )
            .unwrap();
            assert_eq!(model.equilibrium_set(&mut data).unwrap(), &fresh, "{name}");
        }
    }
}

/// The checks one after another, in a plain binary (`harness = false` in Cargo.toml): the
/// counter is global, and a test harness's own thread allocates for its bookkeeping (starting a
/// test, recording its result) while a test runs, which the counter would count.
fn main() {
    evaluating_the_pipeline_allocates_nothing();
    the_equilibrium_set_of_a_new_pose_allocates_nothing();
}
