//! Re-planning along a trajectory: 1,000 steps at 1 kHz on cdhrm5, joints moving at
//! 0.1–3 rad/s. Every step certified, warm equal to cold within the sum of the gaps, the
//! fallbacks counted, the results deterministic, and with a rate limit no tension changes by
//! more than `ḟ_max Δt`.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Vector3, Vector6};
use sinew_planner::{
    AlongStep, Objective, PlanError, PlanSettings, Planner, PlannerData, RateLimit, Requirements,
    Step,
};
use sinew_routing::PatternModel;
use sinew_stiffness::ArmStiffness;
use sinew_testkit::cdhrm5;

const DT: f64 = 1e-3;

/// The testkit's swaying trajectory (joint speeds up to 0.1–3 rad/s) with phases `φ_j = 0.3 j`,
/// under 5 N along y.
fn trajectory(steps: usize) -> Vec<Step> {
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    cdhrm5::swaying_poses(steps, DT, 0.3).into_iter().map(|q| Step { q, f0 }).collect()
}

fn run(
    planner: &Planner,
    steps: &[Step],
    objective: Objective,
    rate: Option<RateLimit>,
) -> Vec<AlongStep> {
    let mut data = PlannerData::new(planner);
    let settings = PlanSettings::default();
    planner
        .plan_along(&mut data, steps, objective, &Requirements::default(), &settings, rate)
        .unwrap()
}

#[test]
fn a_thousand_steps_are_certified_warm_equals_cold_and_runs_repeat() {
    let steps = trajectory(1000);
    // The Newton steps on the previous active set take one to three evaluations where the
    // interior-point method's warm start takes ten: `newton` bounds the median. Decoupled
    // least tension sits on the stability margin for part of the trajectory (`bound`: at least
    // this many steps with the margin binding), which the steps take into their working set.
    for (model, objective, newton, bound) in [
        (PatternModel::Decoupled, Objective::StiffnessAlong(Vector3::y()), 1, 0),
        (PatternModel::Decoupled, Objective::ComplianceAlong(Vector3::y()), 1, 0),
        (PatternModel::Routed, Objective::Volume, 1, 0),
        (PatternModel::Routed, Objective::LeastTension, 1, 0),
        (PatternModel::Decoupled, Objective::LeastTension, 3, 500),
        (PatternModel::Routed, Objective::MinStiffness, 1, 0),
    ] {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
        let along = run(&planner, &steps, objective, None);
        let mut data = PlannerData::new(&planner);
        let settings = PlanSettings::default();
        let mut warm = 0;
        let mut binding = 0;
        let mut iterations = Vec::new();
        for (k, (step, result)) in steps.iter().zip(&along).enumerate() {
            let plan = result.plan.as_ref().unwrap_or_else(|e| panic!("step {k}: {e}"));
            assert!(
                plan.gap >= 0.0 && plan.gap <= 1e-6 * plan.value.abs() * 1.000001,
                "step {k}: gap {}",
                plan.gap
            );
            let margin = Requirements::default().margin;
            assert!(
                plan.min_eigenvalue >= margin * (1.0 - 1e-9),
                "step {k}: margin {}",
                plan.min_eigenvalue
            );
            // Within 1e-6 N m/rad of the margin: binding (the answers keep a δ of about 1e-7).
            binding += usize::from(plan.min_eigenvalue <= margin + 1e-6);
            warm += usize::from(result.warm);
            if result.warm {
                iterations.push(result.iterations);
            }
            if k % 50 == 7 {
                let cold = planner
                    .plan(
                        &mut data,
                        &step.q,
                        &step.f0,
                        objective,
                        &Requirements::default(),
                        &settings,
                    )
                    .unwrap();
                let difference = (cold.value - plan.value).abs();
                assert!(
                    difference <= cold.gap + plan.gap,
                    "step {k}: warm {} cold {}",
                    plan.value,
                    cold.value
                );
            }
        }
        iterations.sort_unstable();
        let median = iterations.get(iterations.len() / 2).copied().unwrap_or(0);
        println!(
            "{model:?} {}: {warm} of 1000 steps warm, median warm iterations {median}, \
             margin binding at {binding}",
            objective.name()
        );
        // The warm path is the rule along a smooth trajectory, not the exception.
        assert!(warm >= 990, "only {warm} warm steps");
        assert!(median <= newton, "median warm iterations {median}: not the Newton steps");
        assert!(binding >= bound, "the margin binds at {binding} steps only");
        // Deterministic: a second run gives the same bits.
        let again = run(&planner, &steps, objective, None);
        for (a, b) in along.iter().zip(&again) {
            let (a, b) = (a.plan.as_ref().unwrap(), b.plan.as_ref().unwrap());
            assert_eq!(a.tensions, b.tensions);
            assert_eq!(a.value.to_bits(), b.value.to_bits());
        }
    }
}

#[test]
fn with_a_rate_limit_no_tension_changes_faster_than_the_limit() {
    let steps = trajectory(300);
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Decoupled);
    let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
    let objective = Objective::StiffnessAlong(Vector3::y());
    let free = run(&planner, &steps, objective, None);
    let change =
        |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    let largest_free = (1..steps.len())
        .map(|k| {
            let (a, b) = (free[k - 1].plan.as_ref().unwrap(), free[k].plan.as_ref().unwrap());
            change(&a.tensions, &b.tensions)
        })
        .fold(0.0, f64::max);
    // A limit below the free plans' fastest change binds. (Balance alone forces some change
    // per step, so a limit far below it makes steps infeasible: typed, see below.)
    let rate = RateLimit { max_rate: largest_free / 1.5 / DT, dt: DT };
    let limited = run(&planner, &steps, objective, Some(rate));
    let mut bound = 0;
    for k in 1..steps.len() {
        let (Ok(a), Ok(b)) = (&limited[k - 1].plan, &limited[k].plan) else {
            panic!("step {k}: {:?}", limited[k].plan.as_ref().err());
        };
        let c = change(&a.tensions, &b.tensions);
        assert!(c <= rate.max_change() * (1.0 + 1e-9) + 1e-9, "step {k}: change {c} N");
        bound += usize::from(c >= rate.max_change() * (1.0 - 1e-3));
    }
    println!("largest free change {largest_free:.3} N; the limit binds at {bound} steps");
    assert!(bound > 0);
    // And a limit too slow for the first move is typed per step, the next step starting cold.
    let slow = RateLimit { max_rate: 1e-6, dt: DT };
    let jump = vec![steps[0].clone(), Step { q: vec![0.3; 10], f0: steps[0].f0 }, steps[0].clone()];
    let result = run(&planner, &jump, objective, Some(slow));
    assert!(result[0].plan.is_ok());
    assert!(matches!(result[1].plan, Err(PlanError::RateLimitInfeasible)), "{:?}", result[1].plan);
    assert!(result[2].plan.is_ok() && !result[2].warm);
}

#[test]
fn a_bad_rate_is_refused_before_any_step() {
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Decoupled);
    let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
    let mut data = PlannerData::new(&planner);
    for rate in [RateLimit { max_rate: -1.0, dt: DT }, RateLimit { max_rate: 1.0, dt: f64::NAN }] {
        let result = planner.plan_along(
            &mut data,
            &trajectory(2),
            Objective::Volume,
            &Requirements::default(),
            &PlanSettings::default(),
            Some(rate),
        );
        assert!(matches!(result, Err(PlanError::InvalidInput { .. })));
    }
}

/// `replan`, one pose at a time as a controller gets them: `plan` at the first step and then
/// `replan` at each of the others give `plan_along`'s plans bit for bit, warm where it is warm,
/// with and without a rate limit, in both models. A `replan` that mapped from the wrong
/// tensions (or ignored the last plan, or dropped the rate rows) gives other tensions or other
/// warm flags.
#[test]
fn replanning_one_pose_at_a_time_gives_plan_along_s_plans() {
    let steps = trajectory(60);
    let settings = PlanSettings::default();
    let requirements = Requirements::default();
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
        for (objective, rate) in [
            (Objective::StiffnessAlong(Vector3::y()), None),
            (Objective::Volume, Some(RateLimit { max_rate: 2000.0, dt: DT })),
        ] {
            let along = run(&planner, &steps, objective, rate);
            let mut data = PlannerData::new(&planner);
            let first = planner.plan(
                &mut data,
                &steps[0].q,
                &steps[0].f0,
                objective,
                &requirements,
                &settings,
            );
            let bits = |p: &sinew_planner::Plan| {
                p.tensions.iter().map(|f| f.to_bits()).collect::<Vec<_>>()
            };
            assert_eq!(bits(&first.unwrap()), bits(along[0].plan.as_ref().unwrap()));
            let mut warm = 0;
            for (k, step) in steps.iter().enumerate().skip(1) {
                let one = planner
                    .replan(&mut data, step, objective, &requirements, &settings, rate)
                    .unwrap();
                let (a, b) = (one.plan.as_ref().unwrap(), along[k].plan.as_ref().unwrap());
                assert_eq!(bits(a), bits(b), "{model:?} {} step {k}", objective.name());
                assert_eq!((one.warm, one.iterations), (along[k].warm, along[k].iterations));
                warm += usize::from(one.warm);
            }
            // Warm-started, not cold at every step.
            assert!(warm >= 50, "{model:?} {}: {warm} of 59 warm", objective.name());
        }
    }
    // A bad rate is refused; after a step without a plan the next runs cold.
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Decoupled);
    let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
    let mut data = PlannerData::new(&planner);
    let objective = Objective::StiffnessAlong(Vector3::y());
    let bad = RateLimit { max_rate: 0.0, dt: DT };
    let refused =
        planner.replan(&mut data, &steps[0], objective, &requirements, &settings, Some(bad));
    assert!(
        matches!(refused, Err(PlanError::InvalidInput { what: "max_rate", .. })),
        "{refused:?}"
    );
    let first =
        planner.replan(&mut data, &steps[0], objective, &requirements, &settings, None).unwrap();
    assert!(first.plan.is_ok() && !first.warm);
    let second =
        planner.replan(&mut data, &steps[1], objective, &requirements, &settings, None).unwrap();
    assert!(second.plan.is_ok() && second.warm);
    let slow = Some(RateLimit { max_rate: 1e-6, dt: DT });
    let far = Step { q: vec![0.3; 10], f0: steps[0].f0 };
    let jump = planner.replan(&mut data, &far, objective, &requirements, &settings, slow).unwrap();
    assert!(matches!(jump.plan, Err(PlanError::RateLimitInfeasible)), "{:?}", jump.plan);
    let after =
        planner.replan(&mut data, &steps[2], objective, &requirements, &settings, None).unwrap();
    assert!(after.plan.is_ok() && !after.warm);
}
