//! The margin checked lazily (`ipm.rs`, `Interior::optimise`): the last phase runs without
//! the margin's block and its answer stands only where `A − m I ≻ 0`. On cdhrm5 (10 DOF, both
//! models, at the loaded pose) and on a 12-joint chain (24 DOF), against the bundle method
//! (which always carries the margin):
//!
//! - where the margin does not bind, the two agree within the sum of their gaps;
//! - where it binds (a margin above the unconstrained least-tension plan's), the plan is on
//!   the margin and still agrees: an answer accepted without the check, or a relaxed bound
//!   taken for the plan's, fails both.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Vector3, Vector6};
use sinew_planner::{Method, Objective, Plan, PlanSettings, Planner, PlannerData, Requirements};
use sinew_routing::PatternModel;
use sinew_stiffness::ArmStiffness;
use sinew_testkit::cdhrm5;

/// cdhrm5 in both models at the loaded pose under 5 N along y, and a 12-joint weightless chain
/// (24 DOF: the least-stiffness floor is a 21 × 21 block, above the fixed-size kernels, so its
/// coefficients are factored) with a 0.22 N force at the tip: `(name, planner, q, F0)`.
fn arms() -> Vec<(String, Planner, Vec<f64>, Vector6<f64>)> {
    let mut arms = Vec::new();
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        arms.push((format!("cdhrm5 {model:?}"), planner, cdhrm5::LOADED_POSE.to_vec(), f0));
    }
    let (robot, routing) = cdhrm5::chain(12, PatternModel::Decoupled);
    let robot = robot.with_gravity(Vector3::zeros());
    let q: Vec<f64> = (0..24).map(|i| 0.15 * ((i as f64) * 1.3).sin()).collect();
    let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
    arms.push(("chain 12".into(), planner, q, Vector6::new(0.0, 0.2, 0.1, 0.0, 0.0, 0.0)));
    arms
}

fn plan(
    planner: &Planner,
    q: &[f64],
    f0: &Vector6<f64>,
    objective: Objective,
    requirements: &Requirements,
    method: Method,
) -> Plan {
    let settings = PlanSettings { method, ..PlanSettings::default() };
    let mut data = PlannerData::new(planner);
    planner.plan(&mut data, q, f0, objective, requirements, &settings).unwrap()
}

fn agree(name: &str, ipm: &Plan, bundle: &Plan, margin: f64) {
    let difference = (ipm.value - bundle.value).abs();
    println!(
        "{name}: ipm {:.9e} (gap {:.1e}, margin {:.6e}), bundle {:.9e} (gap {:.1e})",
        ipm.value, ipm.gap, ipm.min_eigenvalue, bundle.value, bundle.gap
    );
    assert!(difference <= ipm.gap + bundle.gap, "{name}: {difference:e} apart");
    assert!(ipm.gap >= 0.0 && ipm.gap <= 1e-6 * ipm.value.abs(), "{name}: gap {:e}", ipm.gap);
    assert!(ipm.min_eigenvalue >= margin * (1.0 - 1e-9), "{name}: margin {:e}", ipm.min_eigenvalue);
}

#[test]
fn where_the_margin_does_not_bind_the_lazy_plan_is_the_bundles() {
    let requirements = Requirements::default();
    for (arm, planner, q, f0) in arms() {
        for objective in [
            Objective::StiffnessAlong(Vector3::new(0.0, 0.6, 0.8)),
            Objective::Volume,
            Objective::ComplianceAlong(Vector3::y()),
            Objective::MinStiffness,
            Objective::LeastTension,
        ] {
            let ipm = plan(&planner, &q, &f0, objective, &requirements, Method::InteriorPoint);
            let bundle = plan(&planner, &q, &f0, objective, &requirements, Method::Bundle);
            agree(&format!("{arm} {}", objective.name()), &ipm, &bundle, requirements.margin);
        }
    }
}

#[test]
fn where_the_margin_binds_the_plan_is_on_it() {
    for (arm, planner, q, f0) in arms() {
        let free = plan(
            &planner,
            &q,
            &f0,
            Objective::LeastTension,
            &Requirements::default(),
            Method::InteriorPoint,
        );
        let requirements =
            Requirements { margin: 1.5 * free.min_eigenvalue, ..Requirements::default() };
        let ipm =
            plan(&planner, &q, &f0, Objective::LeastTension, &requirements, Method::InteriorPoint);
        let bundle =
            plan(&planner, &q, &f0, Objective::LeastTension, &requirements, Method::Bundle);
        let name = format!("{arm} least tension, margin 1.5× the free plan's");
        agree(&name, &ipm, &bundle, requirements.margin);
        // On the margin: the least total needs every bit of it.
        assert!(
            ipm.min_eigenvalue <= requirements.margin * (1.0 + 1e-3),
            "{arm}: margin {:e} against {:e}",
            ipm.min_eigenvalue,
            requirements.margin
        );
        assert!(
            ipm.value > free.value * (1.0 + 1e-4),
            "{arm}: {} against {}",
            ipm.value,
            free.value
        );
    }
}
