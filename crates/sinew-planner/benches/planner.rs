//! `cargo bench -p sinew-planner`: a certified plan (relative gap 1e-6) on cdhrm5 at the loaded
//! pose under 5 N along y (both models, every objective, both methods), one pipeline evaluation
//! of the same arm (the ratio is what carries to another machine), 100 warm-started steps along
//! a 1 kHz trajectory and one warm step of it as a controller makes it (`replan`), a 25-joint decoupled chain (50 DOF, weightless, 0.022 N at the tip) and a
//! 100-joint one (200 DOF, 0.00045 N), and plans in the stick regime (μ = 0.1).
//! Prints each plan's iterations once, for the time per iteration.
#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Vector3, Vector6};
use sinew_planner::{
    Method, Objective, PlanSettings, Planner, PlannerData, Requirements, Step, StickPlanData,
};
use sinew_routing::{FrictionModel, PatternModel};
use sinew_statics::TensionChoice;
use sinew_stiffness::ArmStiffnessData;
use sinew_stiffness::{ArmStiffness, History};
use sinew_testkit::cdhrm5;

fn objectives() -> [Objective; 5] {
    [
        Objective::StiffnessAlong(Vector3::y()),
        Objective::ComplianceAlong(Vector3::y()),
        Objective::MinStiffness,
        Objective::Volume,
        Objective::LeastTension,
    ]
}

/// Each case's plan by both methods, and one pipeline evaluation of the same arm, in one run:
/// the ratio plan / evaluation is what stays meaningful on another machine.
fn bench_plans(c: &mut Criterion) {
    let mut group = c.benchmark_group("plan");
    group.sample_size(20);
    let requirements = Requirements::default();
    let methods = [(Method::InteriorPoint, "ipm"), (Method::Bundle, "bundle")];
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let arm = ArmStiffness::new(&robot, &routing).unwrap();
        let planner = Planner::new(arm.clone());
        let mut data = PlannerData::new(&planner);
        let q = cdhrm5::LOADED_POSE;
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        let name = if model == PatternModel::Decoupled { "decoupled" } else { "routed" };
        let mut sd = ArmStiffnessData::new(&arm);
        let levels = [0.5; 5];
        group.bench_function(format!("cdhrm5 {name} one evaluation"), |b| {
            b.iter(|| {
                arm.evaluate(&mut sd, black_box(&q), &f0, TensionChoice::Levels(&levels)).is_ok()
            })
        });
        for objective in objectives() {
            for (method, label) in methods {
                let settings = PlanSettings { method, ..PlanSettings::default() };
                let plan =
                    planner.plan(&mut data, &q, &f0, objective, &requirements, &settings).unwrap();
                println!(
                    "cdhrm5 {name} {} {label}: {} iterations, value {:.9e}, gap {:.1e}",
                    objective.name(),
                    plan.iterations,
                    plan.value,
                    plan.gap
                );
                group.bench_function(format!("cdhrm5 {name} {} {label}", objective.name()), |b| {
                    b.iter(|| {
                        planner
                            .plan(
                                &mut data,
                                black_box(&q),
                                &f0,
                                objective,
                                &requirements,
                                &settings,
                            )
                            .unwrap()
                    })
                });
            }
        }
    }
    // In the stick regime (#27), μ = 0.1, after a pull and after equal tensions: the same
    // problem on the stick pencil, the answer evaluated by the friction pipeline.
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
        let friction = FrictionModel::new(&routing).with_friction_coefficient(0.1).unwrap();
        let mut data = PlannerData::new(&planner);
        let mut stick = StickPlanData::new(&planner, &friction);
        let name = if model == PatternModel::Decoupled { "decoupled" } else { "routed" };
        let q = cdhrm5::LOADED_POSE;
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        let objective = Objective::StiffnessAlong(Vector3::y());
        let settings = PlanSettings::default();
        for (history, label) in [(History::Pull, "pull"), (History::Equal, "equal")] {
            let stage = (&friction, history);
            group.bench_function(
                format!("cdhrm5 {name} stick after {label} stiffness-along"),
                |b| {
                    b.iter(|| {
                        planner
                            .plan_in_stick(
                                &mut data,
                                &mut stick,
                                stage,
                                black_box(&q),
                                &f0,
                                objective,
                                &requirements,
                                &settings,
                            )
                            .unwrap()
                    })
                },
            );
        }
    }
    // Re-planning along a smooth trajectory (1 kHz, joints at up to 3 rad/s): per step.
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
        let mut data = PlannerData::new(&planner);
        let name = if model == PatternModel::Decoupled { "decoupled" } else { "routed" };
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        let steps: Vec<Step> =
            cdhrm5::swaying_poses(100, 1e-3, 0.0).into_iter().map(|q| Step { q, f0 }).collect();
        let settings = PlanSettings::default();
        for objective in objectives() {
            let along = planner
                .plan_along(&mut data, &steps, objective, &requirements, &settings, None)
                .unwrap();
            let warm = along.iter().filter(|s| s.warm).count();
            let mut iterations: Vec<usize> = along.iter().map(|s| s.iterations).collect();
            iterations.sort_unstable();
            let label = objective.name();
            println!(
                "cdhrm5 {name} along 100 steps {label}: {warm} warm, median iterations {}",
                iterations[50]
            );
            group.bench_function(format!("cdhrm5 {name} along 100 steps {label}"), |b| {
                b.iter(|| {
                    planner.plan_along(
                        &mut data,
                        black_box(&steps),
                        objective,
                        &requirements,
                        &settings,
                        None,
                    )
                })
            });
            // One warm step as a controller makes it (`replan`, the next pose of the same
            // trajectory, cycling): the time of the warm steps alone, each timed by itself;
            // the cold ones (the first of each cycle, and any the warm path refuses) are
            // planned but neither timed nor counted.
            group.bench_function(format!("cdhrm5 {name} warm step {label}"), |b| {
                let mut k = 0;
                b.iter_custom(|iterations| {
                    let mut total = std::time::Duration::ZERO;
                    let mut timed = 0;
                    while timed < iterations {
                        let started = std::time::Instant::now();
                        let step = planner
                            .replan(&mut data, &steps[k], objective, &requirements, &settings, None)
                            .unwrap();
                        let spent = started.elapsed();
                        if step.warm {
                            total += spent;
                            timed += 1;
                        }
                        k = (k + 1) % steps.len();
                    }
                    total
                })
            });
        }
    }
    let (robot, routing) = cdhrm5::chain(25, PatternModel::Decoupled);
    let robot = robot.with_gravity(Vector3::zeros());
    let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
    let mut data = PlannerData::new(&planner);
    let q: Vec<f64> = (0..50).map(|i| 0.1 * ((i as f64) * 1.3).sin()).collect();
    let f0 = Vector6::new(0.0, 0.02, 0.01, 0.0, 0.0, 0.0);
    group.sample_size(10);
    for objective in [Objective::StiffnessAlong(Vector3::y()), Objective::MinStiffness] {
        for (method, label) in methods {
            let settings = PlanSettings { method, ..PlanSettings::default() };
            // The bundle's clarabel LPs can lose their accuracy on this chain: said, not timed.
            let plan = match planner.plan(&mut data, &q, &f0, objective, &requirements, &settings) {
                Ok(plan) => plan,
                Err(e) => {
                    println!("chain 25 decoupled {} {label}: no plan ({e})", objective.name());
                    continue;
                }
            };
            println!(
                "chain 25 decoupled {} {label}: {} iterations, value {:.9e}, gap {:.1e}",
                objective.name(),
                plan.iterations,
                plan.value,
                plan.gap
            );
            group.bench_function(format!("chain 25 decoupled {} {label}", objective.name()), |b| {
                b.iter(|| {
                    planner
                        .plan(&mut data, black_box(&q), &f0, objective, &requirements, &settings)
                        .is_ok()
                })
            });
        }
    }
    // The 100-joint decoupled chain (200 DOF, weightless, 0.00045 N at the tip): the
    // interior-point method only (a plan takes a good part of a second), beside one pipeline
    // evaluation of the same arm.
    let (robot, routing) = cdhrm5::chain(100, PatternModel::Decoupled);
    let robot = robot.with_gravity(Vector3::zeros());
    let arm = ArmStiffness::new(&robot, &routing).unwrap();
    let planner = Planner::new(arm.clone());
    let mut data = PlannerData::new(&planner);
    let q: Vec<f64> = (0..200).map(|i| 0.1 * ((i as f64) * 1.3).sin()).collect();
    let f0 = Vector6::new(0.0, 0.0004, 0.0002, 0.0, 0.0, 0.0);
    let mut sd = ArmStiffnessData::new(&arm);
    let levels = [0.5; 100];
    group.bench_function("chain 100 decoupled one evaluation", |b| {
        b.iter(|| arm.evaluate(&mut sd, black_box(&q), &f0, TensionChoice::Levels(&levels)).is_ok())
    });
    let settings = PlanSettings::default();
    for objective in [Objective::StiffnessAlong(Vector3::y()), Objective::LeastTension] {
        let plan = planner.plan(&mut data, &q, &f0, objective, &requirements, &settings).unwrap();
        println!(
            "chain 100 decoupled {} ipm: {} iterations, value {:.9e}, gap {:.1e}",
            objective.name(),
            plan.iterations,
            plan.value,
            plan.gap
        );
        group.bench_function(format!("chain 100 decoupled {} ipm", objective.name()), |b| {
            b.iter(|| {
                planner
                    .plan(&mut data, black_box(&q), &f0, objective, &requirements, &settings)
                    .is_ok()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_plans);
criterion_main!(benches);
