//! The warm step's time per step, as issue #24's target states it ("median per step along a
//! smooth trajectory, certified"): each `replan` along the benches' trajectory (cdhrm5, 100
//! poses at 1 kHz, joints at up to 3 rad/s about the loaded pose, 5 N along y) timed by itself,
//! `PASSES` passes per objective (each starting cold), with one pipeline evaluation of the same
//! arm timed in the same run (the ratio is what carries to another machine). Prints, per model
//! and objective: the median, 90th percentile and largest warm step, the mean, how many steps
//! were warm, and the median step over the median evaluation. The criterion bench
//! `cdhrm5 MODEL warm step OBJECTIVE` gives the mean of the warm steps instead.
//!
//! `cargo run --release -p sinew-planner --example warm_steps [PASSES]` (default 20). The
//! objectives are interleaved pass by pass, so a drift of the machine's speed reaches them all
//! alike.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;
use std::time::Instant;

use nalgebra::{Vector3, Vector6};
use sinew_planner::{Objective, PlanSettings, Planner, PlannerData, Requirements, Step};
use sinew_statics::TensionChoice;
use sinew_stiffness::{ArmStiffness, ArmStiffnessData};
use sinew_testkit::cdhrm5;

/// The value at quantile `p` of the sorted `v`.
fn quantile(v: &[f64], p: f64) -> f64 {
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn main() {
    let passes: usize = std::env::args().nth(1).map_or(20, |n| n.parse().expect("PASSES"));
    let objectives = [
        Objective::StiffnessAlong(Vector3::y()),
        Objective::ComplianceAlong(Vector3::y()),
        Objective::MinStiffness,
        Objective::Volume,
        Objective::LeastTension,
    ];
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    let steps: Vec<Step> =
        cdhrm5::swaying_poses(100, 1e-3, 0.0).into_iter().map(|q| Step { q, f0 }).collect();
    let (requirements, settings) = (Requirements::default(), PlanSettings::default());
    println!("warm step, µs: median, p90, max, mean; warm steps; median / one evaluation");
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let arm = ArmStiffness::new(&robot, &routing).unwrap();
        let planner = Planner::new(arm.clone());
        let mut data = PlannerData::new(&planner);
        let mut sd = ArmStiffnessData::new(&arm);
        let mut evaluations = Vec::new();
        let mut times = vec![Vec::new(); objectives.len()];
        let mut warm = vec![0; objectives.len()];
        for _ in 0..passes {
            // One evaluation of the arm at the loaded pose, 100 times per pass.
            for _ in 0..100 {
                let started = Instant::now();
                let ok = arm
                    .evaluate(&mut sd, black_box(&cdhrm5::LOADED_POSE), &f0, {
                        TensionChoice::Levels(&[0.5; 5])
                    })
                    .is_ok();
                evaluations.push(started.elapsed().as_secs_f64() * 1e6);
                assert!(ok);
            }
            for (o, objective) in objectives.iter().enumerate() {
                let first = &steps[0];
                planner
                    .plan(&mut data, &first.q, &first.f0, *objective, &requirements, &settings)
                    .unwrap();
                for step in &steps[1..] {
                    let started = Instant::now();
                    let result = planner
                        .replan(&mut data, step, *objective, &requirements, &settings, None)
                        .unwrap();
                    let spent = started.elapsed().as_secs_f64() * 1e6;
                    let plan = result.plan.as_ref().expect("a plan at every step");
                    assert!(plan.gap <= 1e-6 * plan.value.abs() * 1.000001, "certified");
                    if result.warm {
                        times[o].push(spent);
                        warm[o] += 1;
                    }
                }
            }
        }
        evaluations.sort_by(f64::total_cmp);
        let evaluation = quantile(&evaluations, 0.5);
        println!("{model:?}: one evaluation, median {evaluation:.2} µs");
        for (o, objective) in objectives.iter().enumerate() {
            let t = &mut times[o];
            t.sort_by(f64::total_cmp);
            let mean = t.iter().sum::<f64>() / t.len() as f64;
            let median = quantile(t, 0.5);
            println!(
                "{model:?} {:<16} {median:6.2} {:6.2} {:7.2} {mean:6.2}; {} of {}; {:.1}",
                objective.name(),
                quantile(t, 0.9),
                t[t.len() - 1],
                warm[o],
                passes * (steps.len() - 1),
                median / evaluation
            );
        }
    }
}
