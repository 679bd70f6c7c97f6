//! The interior-point method's iterations allocate nothing: its buffers are sized once per
//! run. A counting global allocator (this test binary only) counts every allocation of a plan
//! capped at 2, 4 and 6 iterations (each ends `NotConverged` in its last phase); equal counts
//! mean the iterations past the second allocated nothing. A method that allocated a scratch
//! vector per iteration, or per step-length trial, gives counts that grow with the cap.
//!
//! The set-up of a plan still allocates (the equilibrium set, the pencil, the frame, the
//! blocks of each phase, the plan's own vectors): counted here, not claimed to be zero.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Vector3, Vector6};
use sinew_planner::{
    Method, Objective, PlanError, PlanSettings, Planner, PlannerData, Requirements,
};
use sinew_stiffness::ArmStiffness;
use sinew_testkit::alloc::{CountingAllocator, assert_counting, count};
use sinew_testkit::cdhrm5;

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn iterations_of_the_interior_point_method_allocate_nothing() {
    assert_counting();
    let objectives = [
        Objective::StiffnessAlong(Vector3::y()),
        Objective::ComplianceAlong(Vector3::y()),
        Objective::MinStiffness,
        Objective::Volume,
        Objective::LeastTension,
    ];
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    let requirements = Requirements::default();
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
        let mut data = PlannerData::new(&planner);
        for objective in objectives {
            let mut counts = Vec::new();
            for cap in [2, 4, 6] {
                let settings = PlanSettings {
                    max_iterations: cap,
                    method: Method::InteriorPoint,
                    ..PlanSettings::default()
                };
                // Once before counting: the first plan of a workspace sizes its buffers.
                let _ = planner.plan(
                    &mut data,
                    &cdhrm5::LOADED_POSE,
                    &f0,
                    objective,
                    &requirements,
                    &settings,
                );
                // The counter is global: a thread of the test harness (or of a library's
                // pool) can allocate during a plan, now and then, and only ever adds. The least
                // of three counts is the plan's own.
                let mut least = usize::MAX;
                for _ in 0..3 {
                    let (allocations, result) = count(|| {
                        planner.plan(
                            &mut data,
                            &cdhrm5::LOADED_POSE,
                            &f0,
                            objective,
                            &requirements,
                            &settings,
                        )
                    });
                    match result {
                        Err(PlanError::NotConverged { iterations, .. }) => {
                            assert_eq!(iterations, cap, "{model:?} {}", objective.name());
                        }
                        other => {
                            panic!("{model:?} {}: capped at {cap}: {other:?}", objective.name())
                        }
                    }
                    least = least.min(allocations);
                }
                let allocations = least;
                counts.push(allocations);
            }
            println!(
                "{model:?} {}: allocations at 2, 4, 6 iterations: {counts:?}",
                objective.name()
            );
            assert!(
                counts.iter().all(|c| *c == counts[0]),
                "{model:?} {}: allocations grow with the iterations: {counts:?}",
                objective.name()
            );
        }
    }
}
