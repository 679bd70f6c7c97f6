//! A plan allocates only the plan it returns once its workspace has the room, cold or warm. A
//! counting global allocator (this test binary only) counts every allocation:
//!
//! - of a cold plan capped at 2, 3 and 5 iterations (each ends `NotConverged` in its last
//!   phase): none. A method that allocated a scratch vector per iteration, or per step-length
//!   trial, gives counts that grow with the cap; one that built a phase's blocks or its run's
//!   buffers anew, or dropped the workspace's buffers on an error, counts more than zero
//!   (before the phases worked in the workspace's buffers, 152–272 a plan);
//! - of a cold plan to its answer, with and without stiffness floors and a budget: its plan's
//!   own vectors only;
//! - of a warm step along a trajectory: its plan's own vectors only (the last test).
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

/// The five objectives, those along a direction along y.
fn objectives() -> [Objective; 5] {
    [
        Objective::StiffnessAlong(Vector3::y()),
        Objective::ComplianceAlong(Vector3::y()),
        Objective::MinStiffness,
        Objective::Volume,
        Objective::LeastTension,
    ]
}

fn iterations_of_the_interior_point_method_allocate_nothing() {
    assert_counting();
    let objectives = objectives();
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    let requirements = Requirements::default();
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
        let mut data = PlannerData::new(&planner);
        for objective in objectives {
            let mut counts = Vec::new();
            for cap in [2, 3, 5] {
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
                "{model:?} {}: allocations at 2, 3, 5 iterations: {counts:?}",
                objective.name()
            );
            assert!(
                counts.iter().all(|c| *c == 0),
                "{model:?} {}: a capped plan allocates: {counts:?}",
                objective.name()
            );
        }
    }
}

/// A cold plan to its answer allocates its plan's own vectors only (`λ`, the tensions, and the
/// levels where the arm has the closed form), under requirements that run every phase: none,
/// a floor on the least stiffness (`k_min`, 0.8 of the best), a floor `K_des` (half the best
/// plan's `K_fd`), and a budget between the least and the free optimum's totals. The least of
/// three counts, after two plans that size the workspace's buffers.
fn a_cold_plan_allocates_only_its_plan() {
    assert_counting();
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    let settings = PlanSettings::default();
    let mut plans = 0;
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
        let mut data = PlannerData::new(&planner);
        let own = 2 + usize::from(planner.arm().statics().has_levels());
        let q = &cdhrm5::LOADED_POSE;
        let plan = |data: &mut PlannerData, objective, requirements: &Requirements| {
            planner.plan(data, q, &f0, objective, requirements, &settings)
        };
        let none = Requirements::default();
        let best = plan(&mut data, Objective::MinStiffness, &none).unwrap();
        let least = plan(&mut data, Objective::LeastTension, &none).unwrap();
        let free = plan(&mut data, Objective::Volume, &none).unwrap();
        let variants = [
            ("none", none.clone()),
            ("k_min", Requirements { k_min: Some(0.8 * best.value), ..none.clone() }),
            ("K_des", Requirements { k_des: Some(0.5 * best.k_fd.unwrap()), ..none.clone() }),
            (
                "budget",
                Requirements {
                    budget: Some(0.5 * (least.total_tension + free.total_tension)),
                    ..none.clone()
                },
            ),
        ];
        for (name, requirements) in &variants {
            for objective in objectives() {
                for _ in 0..2 {
                    plan(&mut data, objective, requirements).unwrap();
                }
                let mut counts = Vec::new();
                for _ in 0..3 {
                    let (allocations, result) = count(|| plan(&mut data, objective, requirements));
                    result.unwrap();
                    counts.push(allocations);
                }
                let least_count = counts.iter().copied().min().unwrap();
                println!(
                    "{model:?} {} {name}: allocations of a cold plan: {counts:?}",
                    objective.name()
                );
                assert_eq!(
                    least_count,
                    own,
                    "{model:?} {} {name}: a cold plan allocates more than its plan's {own} vectors",
                    objective.name()
                );
                plans += 1;
            }
        }
    }
    assert_eq!(plans, 2 * 4 * 5);
}

/// A warm step along a trajectory allocates only its plan's own vectors (`λ`, the tensions,
/// and the levels where the arm has the closed form: allocated then, and kept when every
/// joint's interval holds the plan's tensions), for the objectives whose warm step is Newton's
/// on the active set (module docs of `along.rs`). The allocations of step `j` are those of a
/// run over the first `j + 1` steps less those of a run over the first `j` (the runs are the
/// same up to there: each starts cold from its first step), the least of three counts each.
/// Before the warm step had its workspace (41ca3ab), decoupled stiffness-along: 124 a step.
fn a_warm_step_allocates_only_its_plan() {
    assert_counting();
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    let steps: Vec<sinew_planner::Step> = cdhrm5::swaying_poses(12, 1e-3, 0.0)
        .into_iter()
        .map(|q| sinew_planner::Step { q, f0 })
        .collect();
    let requirements = Requirements::default();
    let settings = PlanSettings::default();
    let mut warm_steps = 0;
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
        let mut data = PlannerData::new(&planner);
        let own = 2 + usize::from(planner.arm().statics().has_levels());
        for objective in objectives() {
            let mut run = |n: usize| {
                let mut least = usize::MAX;
                let mut along = Vec::new();
                for _ in 0..3 {
                    let (allocations, result) = count(|| {
                        planner.plan_along(
                            &mut data,
                            &steps[..n],
                            objective,
                            &requirements,
                            &settings,
                            None,
                        )
                    });
                    least = least.min(allocations);
                    along = result.unwrap();
                }
                (least, along)
            };
            // Once before counting: the first run sizes the workspace's buffers.
            run(steps.len());
            let mut counts = Vec::new();
            let (mut before, _) = run(1);
            for n in 2..=steps.len() {
                let (now, along) = run(n);
                let last = along.last().unwrap();
                assert!(last.plan.is_ok(), "{model:?} {}: step {n}", objective.name());
                if last.warm {
                    warm_steps += 1;
                    counts.push(now - before);
                }
                before = now;
            }
            println!("{model:?} {}: allocations of the warm steps: {counts:?}", objective.name());
            assert!(
                counts.iter().all(|c| *c == own),
                "{model:?} {}: a warm step allocates more than its plan's {own} vectors: {counts:?}",
                objective.name()
            );
        }
    }
    // Every objective takes (almost) every step warm, decoupled least tension with its margin
    // binding at this load.
    assert!(warm_steps >= 10 * 11 - 4, "{warm_steps} warm steps of 110");
}

/// The checks one after another, in a plain binary (`harness = false` in Cargo.toml): the
/// counter is global, and a test harness's own thread allocates for its bookkeeping (starting a
/// test, recording its result) while a test runs, which the counter would count.
fn main() {
    iterations_of_the_interior_point_method_allocate_nothing();
    a_cold_plan_allocates_only_its_plan();
    a_warm_step_allocates_only_its_plan();
}
