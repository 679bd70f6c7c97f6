//! Every typed outcome of a plan, produced and its numbers checked, by the default method:
//! `NoStableTensions` (a margin out of reach, its bound above the best the bundle reaches),
//! `NoEndStiffness` (a 2-joint arm, a `K_x` objective), `NotConverged` (one iteration), an
//! infeasible load (the statics' `NoEquilibrium`, naming the joint), the `K_des` branch of `RequirementUnreachable`, and `BudgetTooSmall`.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Matrix3, Vector3, Vector6};
use sinew_planner::{
    Method, Objective, PlanError, PlanSettings, Planner, PlannerData, Requirements,
};
use sinew_routing::PatternModel;
use sinew_statics::StaticsError;
use sinew_stiffness::ArmStiffness;
use sinew_testkit::cdhrm5;

fn planner(model: PatternModel) -> Planner {
    let (robot, routing) = cdhrm5::robot_and_routing(model);
    Planner::new(ArmStiffness::new(&robot, &routing).unwrap())
}

const F0: Vector6<f64> = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);

#[test]
fn an_unreachable_margin_is_refused_with_a_bound_above_the_best_margin() {
    for model in cdhrm5::MODELS {
        let planner = planner(model);
        let mut data = PlannerData::new(&planner);
        let q = cdhrm5::LOADED_POSE;
        let requirements = Requirements { margin: 1e3, ..Requirements::default() };
        let err = planner
            .plan(&mut data, &q, &F0, Objective::Volume, &requirements, &PlanSettings::default())
            .unwrap_err();
        let PlanError::NoStableTensions { margin, best, budget } = err else { panic!("{err}") };
        assert_eq!((margin, budget), (1e3, false));
        // The bound is ≥ the best margin any tensions reach: the margin of the stiffest plan is
        // one such; and it is far below 1e3 (cdhrm5's joints reach a few N m/rad).
        let stiff = planner
            .plan(
                &mut data,
                &q,
                &F0,
                Objective::Volume,
                &Requirements::default(),
                &PlanSettings::default(),
            )
            .unwrap();
        assert!(best >= stiff.min_eigenvalue && best < 1e2, "{model:?}: bound {best}");
    }
}

#[test]
fn a_budget_just_below_the_least_stable_total_is_refused() {
    let planner = planner(PatternModel::Decoupled);
    let mut data = PlannerData::new(&planner);
    let q = cdhrm5::LOADED_POSE;
    let settings = PlanSettings::default();
    // The least total tension with margin 0.5: a budget 1 % below it leaves no stable tensions.
    let margin = 0.5;
    let least = planner
        .plan(
            &mut data,
            &q,
            &F0,
            Objective::LeastTension,
            &Requirements { margin, ..Requirements::default() },
            &settings,
        )
        .unwrap();
    assert!(least.min_eigenvalue >= margin * (1.0 - 1e-9));
    let requirements =
        Requirements { margin, budget: Some(0.99 * least.value), ..Requirements::default() };
    let err =
        planner.plan(&mut data, &q, &F0, Objective::Volume, &requirements, &settings).unwrap_err();
    let PlanError::NoStableTensions { best, budget: true, .. } = err else { panic!("{err}") };
    assert!(best < margin, "bound {best}");
}

#[test]
fn no_end_stiffness_not_converged_infeasible_and_k_des_are_typed() {
    // A 2-joint arm (4 DOF): J_x has rank < 6, K_x does not exist.
    let (robot, routing) = cdhrm5::chain(2, PatternModel::Decoupled);
    let small = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
    let mut data = PlannerData::new(&small);
    let q = [0.1, 0.0, -0.1, 0.05];
    let f0 = Vector6::new(0.0, 1.0, 0.0, 0.0, 0.0, 0.0);
    let err = small
        .plan(
            &mut data,
            &q,
            &f0,
            Objective::MinStiffness,
            &Requirements::default(),
            &PlanSettings::default(),
        )
        .unwrap_err();
    assert!(matches!(err, PlanError::NoEndStiffness), "{err}");
    // Its compliance objective exists.
    let plan = small
        .plan(
            &mut data,
            &q,
            &f0,
            Objective::ComplianceAlong(Vector3::y()),
            &Requirements::default(),
            &PlanSettings::default(),
        )
        .unwrap();
    assert!(plan.value > 0.0 && plan.gap <= 1e-6 * plan.value);

    let planner = planner(PatternModel::Routed);
    let mut data = PlannerData::new(&planner);
    let q = cdhrm5::LOADED_POSE;
    for method in [Method::InteriorPoint, Method::Bundle] {
        let settings = PlanSettings { max_iterations: 1, method, ..PlanSettings::default() };
        let err = planner
            .plan(&mut data, &q, &F0, Objective::Volume, &Requirements::default(), &settings)
            .unwrap_err();
        let PlanError::NotConverged { iterations, gap, tolerance } = err else { panic!("{err}") };
        assert!(iterations <= 1 && gap > tolerance && tolerance > 0.0, "{method:?}: {err}");
    }
    // A load no tensions within the limits hold: the statics' error, naming the joint.
    let heavy = Vector6::new(0.0, 5e4, 0.0, 0.0, 0.0, 0.0);
    let err = planner
        .plan(
            &mut data,
            &q,
            &heavy,
            Objective::Volume,
            &Requirements::default(),
            &PlanSettings::default(),
        )
        .unwrap_err();
    match &err {
        PlanError::Statics(e) => {
            assert!(matches!(**e, StaticsError::NoEquilibrium(_)), "{e:?}");
            assert!(
                e.to_string().contains("at joint 1") && e.to_string().contains("49685 N m"),
                "{e}"
            );
            assert_eq!(err.kind(), sinew_robot::ErrorKind::Infeasible);
        }
        e => panic!("{e:?}"),
    }
    // K_des ten times the free optimum's K_fd: unreachable, with the best τ (K_fd ⪰ τ K_des).
    let free = planner
        .plan(
            &mut data,
            &q,
            &F0,
            Objective::Volume,
            &Requirements::default(),
            &PlanSettings::default(),
        )
        .unwrap();
    let k_fd: Matrix3<f64> = free.k_fd.unwrap();
    let requirements = Requirements { k_des: Some(10.0 * k_fd), ..Requirements::default() };
    let err = planner
        .plan(&mut data, &q, &F0, Objective::Volume, &requirements, &PlanSettings::default())
        .unwrap_err();
    let PlanError::RequirementUnreachable { required, best, .. } = err else { panic!("{err}") };
    assert_eq!(required, 1.0);
    // τ = 0.1 is reached (the free optimum's own K_fd): the bound is at least that, and below 1.
    assert!((0.1..1.0).contains(&best), "best τ {best}");
    // Half of it is reachable, and the plan meets it.
    let requirements = Requirements { k_des: Some(0.5 * k_fd), ..Requirements::default() };
    let plan = planner
        .plan(&mut data, &q, &F0, Objective::LeastTension, &requirements, &PlanSettings::default())
        .unwrap();
    let l = (0.5 * k_fd).cholesky().unwrap().l();
    let l_inv = l.try_inverse().unwrap();
    let scaled = l_inv * plan.k_fd.unwrap() * l_inv.transpose();
    assert!(scaled.symmetric_eigen().eigenvalues.min() >= 1.0 - 1e-6);
    // And least tension under that floor is well below the free optimum's total.
    assert!(plan.value < free.total_tension - 100.0 * plan.gap);
}
