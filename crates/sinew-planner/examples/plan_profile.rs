//! Runs `N` certified plans of one objective on cdhrm5 at the loaded pose under 5 N along y,
//! for instruction counts (`scripts/planner-instructions`: callgrind with 0 and N plans, the
//! difference divided by N), and prints the iterations and the value of the last plan.
//!
//! `cargo run --release -p sinew-planner --example plan_profile -- MODEL OBJECTIVE N METHOD`
//! with MODEL `decoupled`, `routed` `chain25` (the bench's 50-DOF chain) or `chain100` (200 DOF), OBJECTIVE one of `stiffness-along`, `compliance-along`,
//! `min-stiffness`, `volume`, `least-tension`, and METHOD `ipm` or `bundle`; with METHOD
//! `along`, N times the bench's 100-step 1 kHz trajectory, warm-started (instructions per step:
//! the difference divided by 100 N).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;

use nalgebra::{Vector3, Vector6};
use sinew_planner::{Method, Objective, PlanSettings, Planner, PlannerData, Requirements, Step};
use sinew_routing::PatternModel;
use sinew_stiffness::ArmStiffness;
use sinew_testkit::cdhrm5;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let model = match args.get(1).map(String::as_str) {
        Some("routed") => PatternModel::Routed,
        _ => PatternModel::Decoupled,
    };
    let objective = match args.get(2).map(String::as_str).unwrap_or("stiffness-along") {
        "compliance-along" => Objective::ComplianceAlong(Vector3::y()),
        "min-stiffness" => Objective::MinStiffness,
        "volume" => Objective::Volume,
        "least-tension" => Objective::LeastTension,
        _ => Objective::StiffnessAlong(Vector3::y()),
    };
    let plans: usize = args.get(3).map_or(1, |n| n.parse().expect("N plans"));
    let method = match args.get(4).map(String::as_str) {
        Some("bundle") => Method::Bundle,
        _ => Method::InteriorPoint,
    };
    let (robot, routing) = cdhrm5::robot_and_routing(model);
    let mut q = cdhrm5::LOADED_POSE.to_vec();
    let mut f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    // MODEL `chain25`: the bench's 25-joint decoupled chain (50 DOF, weightless, 0.022 N at
    // the tip).
    // MODEL `chain100`: the 100-joint decoupled chain of the same kind (200 DOF, 0.00045 N at the tip).
    let chain = match args.get(1).map(String::as_str) {
        Some("chain25") => Some((25, 0.02)),
        Some("chain100") => Some((100, 0.0004)),
        _ => None,
    };
    let (robot, routing) = if let Some((joints, force)) = chain {
        let (robot, routing) = cdhrm5::chain(joints, PatternModel::Decoupled);
        q = (0..2 * joints).map(|i| 0.1 * ((i as f64) * 1.3).sin()).collect();
        f0 = Vector6::new(0.0, force, 0.5 * force, 0.0, 0.0, 0.0);
        (robot.with_gravity(Vector3::zeros()), routing)
    } else {
        (robot, routing)
    };
    let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
    let mut data = PlannerData::new(&planner);
    let requirements = Requirements::default();
    if args.get(4).map(String::as_str) == Some("along") {
        // The bench's trajectory: joints at up to 3 rad/s about the loaded pose, 1 kHz.
        let steps: Vec<Step> =
            cdhrm5::swaying_poses(100, 1e-3, 0.0).into_iter().map(|q| Step { q, f0 }).collect();
        let settings = PlanSettings::default();
        let (mut warm, mut median, mut digest) = (0, 0, 0_u64);
        for _ in 0..plans {
            let along = planner
                .plan_along(&mut data, black_box(&steps), objective, &requirements, &settings, None)
                .unwrap();
            warm = along.iter().filter(|s| s.warm).count();
            let mut iterations: Vec<usize> = along.iter().map(|s| s.iterations).collect();
            iterations.sort_unstable();
            median = iterations[iterations.len() / 2];
            // Every step's tensions, value, gap and margin, bit by bit: two builds that should
            // compute the same plans print the same digest.
            digest = along
                .iter()
                .filter_map(|s| s.plan.as_ref().ok())
                .flat_map(|p| p.tensions.iter().chain([&p.value, &p.gap, &p.min_eigenvalue]))
                .fold(0, |h: u64, v| (h.rotate_left(5) ^ v.to_bits()).wrapping_mul(0x100000001b3));
        }
        println!(
            "{warm} of 100 steps warm, median iterations or evaluations {median}, digest {digest:016x}"
        );
        return;
    }
    let mut settings = PlanSettings { method, ..PlanSettings::default() };
    // A fifth argument caps the iterations (the plans then end NotConverged): instructions per
    // iteration by difference.
    let cap: Option<usize> = args.get(5).map(|c| c.parse().expect("a cap"));
    if let Some(cap) = cap {
        settings.max_iterations = cap;
        for _ in 0..plans {
            let _ =
                planner.plan(&mut data, black_box(&q), &f0, objective, &requirements, &settings);
        }
        return;
    }
    let mut last = None;
    for _ in 0..plans {
        let plan = planner
            .plan(&mut data, black_box(&q), &f0, objective, &requirements, &settings)
            .unwrap();
        last = Some((plan.iterations, plan.value));
    }
    if let Some((iterations, value)) = last {
        println!("{iterations} iterations, value {value:.9e}");
    }
}
