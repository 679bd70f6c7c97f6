//! Planning in the stick regime (issue #27): each plan is certified and no sampled balancing
//! tensions within the limits beat it, as the friction pipeline evaluates them; after `equal`
//! the stick optimum is at least the frictionless one (the stick stiffness is ⪰ the
//! frictionless at the same tensions, over the same set); what the stick planner does not offer
//! is refused by name.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Vector3, Vector6};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sinew_planner::{
    InputProblem, Method, Objective, PlanError, PlanSettings, Planner, PlannerData, Requirements,
    StickPlanData,
};
use sinew_routing::{FrictionModel, PatternModel};
use sinew_statics::{TensionChoice, TensionPolicy};
use sinew_stiffness::{ArmStiffness, ArmStiffnessData, FrictionRegime, History, StiffnessError};
use sinew_testkit::cdhrm5;

const F0: Vector6<f64> = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
const MU: f64 = 0.1;

fn planner(model: PatternModel) -> (Planner, FrictionModel) {
    let (robot, routing) = cdhrm5::robot_and_routing(model);
    let friction = FrictionModel::new(&routing).with_friction_coefficient(MU).unwrap();
    (Planner::new(ArmStiffness::new(&robot, &routing).unwrap()), friction)
}

fn objectives() -> [Objective; 4] {
    [
        Objective::StiffnessAlong(Vector3::y()),
        Objective::MinStiffness,
        Objective::ComplianceAlong(Vector3::y()),
        Objective::LeastTension,
    ]
}

/// The objective in its maximised sense at actuator tensions `f`, by the friction pipeline
/// (`None` where the arm is unstable there or `K_x` does not exist).
fn maximised(
    planner: &Planner,
    stick: &mut StickPlanData,
    (friction, history): (&FrictionModel, History),
    objective: Objective,
    f: &[f64],
) -> Option<f64> {
    let arm = planner.arm();
    let mut sd = ArmStiffnessData::new(arm);
    let regime = (friction, FrictionRegime::Stick(history));
    let q = cdhrm5::LOADED_POSE;
    let outcome = arm
        .evaluate_with_friction(
            &mut sd,
            &mut stick.friction,
            regime,
            &q,
            &F0,
            TensionChoice::Given(f),
        )
        .unwrap();
    if !outcome.has_end_stiffness() {
        return None;
    }
    let end = &stick.friction.end;
    let k_fd = end.k_fd();
    let c = end.compliance();
    Some(match objective {
        Objective::StiffnessAlong(u) => u.dot(&(k_fd * u)),
        Objective::MinStiffness => k_fd.symmetric_eigenvalues().min(),
        Objective::ComplianceAlong(u) => {
            -(0..3).map(|i| (0..3).map(|j| u[i] * c[(i, j)] * u[j]).sum::<f64>()).sum::<f64>()
        }
        Objective::LeastTension => -f.iter().sum::<f64>(),
        Objective::Volume => k_fd.determinant().ln(),
    })
}

/// Balancing actuator tensions within the limits of the regime: two policies, then random
/// convex combinations of them and the plan's own (the feasible set is convex).
fn candidates(
    planner: &Planner,
    stick: &mut StickPlanData,
    (friction, history): (&FrictionModel, History),
    plan: &[f64],
) -> Vec<Vec<f64>> {
    let arm = planner.arm();
    let mut sd = ArmStiffnessData::new(arm);
    let q = cdhrm5::LOADED_POSE;
    let regime = (friction, FrictionRegime::Stick(history));
    let mut vertices = vec![plan.to_vec()];
    for policy in [TensionPolicy::LeastTotal, TensionPolicy::Safest] {
        let choice = TensionChoice::Policy(policy);
        arm.evaluate_with_friction(&mut sd, &mut stick.friction, regime, &q, &F0, choice).unwrap();
        vertices.push(stick.friction.actuator.clone());
    }
    let mut rng = ChaCha8Rng::seed_from_u64(27);
    let mut out = vertices[1..].to_vec();
    for _ in 0..60 {
        let w: Vec<f64> = (0..vertices.len()).map(|_| rng.random_range(0.0..1.0)).collect();
        let total: f64 = w.iter().sum();
        let f = (0..plan.len())
            .map(|c| vertices.iter().zip(&w).map(|(v, wi)| v[c] * wi / total).sum())
            .collect();
        out.push(f);
    }
    out
}

#[test]
fn a_stick_plan_is_certified_and_no_sampled_tensions_beat_it() {
    for model in cdhrm5::MODELS {
        let (planner, friction) = planner(model);
        let mut data = PlannerData::new(&planner);
        let mut stick = StickPlanData::new(&planner, &friction);
        let settings = PlanSettings::default();
        for history in [History::Equal, History::Pull, History::Release] {
            for objective in objectives() {
                let plan = planner
                    .plan_in_stick(
                        &mut data,
                        &mut stick,
                        (&friction, history),
                        &cdhrm5::LOADED_POSE,
                        &F0,
                        objective,
                        &Requirements::default(),
                        &settings,
                    )
                    .unwrap();
                let case = format!("{model:?} {history:?} {}", objective.name());
                let scale = plan.value.abs().max(1e-12);
                assert!(
                    plan.gap >= 0.0 && plan.gap <= 2.0 * settings.relative_gap * scale,
                    "{case}: gap {:e}",
                    plan.gap
                );
                assert!(plan.min_eigenvalue >= Requirements::default().margin * (1.0 - 1e-9));
                let sense = match objective {
                    Objective::ComplianceAlong(_) | Objective::LeastTension => -1.0,
                    _ => 1.0,
                };
                let at_plan = maximised(
                    &planner,
                    &mut stick,
                    (&friction, history),
                    objective,
                    &plan.tensions,
                )
                .unwrap();
                assert!((at_plan - sense * plan.value).abs() <= 1e-12 * scale, "{case}");
                let mut best = f64::NEG_INFINITY;
                let fs = candidates(&planner, &mut stick, (&friction, history), &plan.tensions);
                for f in fs {
                    if let Some(v) =
                        maximised(&planner, &mut stick, (&friction, history), objective, &f)
                    {
                        best = best.max(v);
                    }
                }
                assert!(
                    best <= at_plan + plan.gap + 1e-9 * scale,
                    "{case}: a sample reaches {best}, the plan {at_plan} (gap {:e})",
                    plan.gap
                );
                eprintln!("{case}: plan {at_plan:.6e}, best sample {best:.6e}");
            }
        }
    }
}

#[test]
fn after_equal_tensions_the_stick_optimum_is_at_least_the_frictionless_one() {
    for model in cdhrm5::MODELS {
        let (planner, friction) = planner(model);
        let mut data = PlannerData::new(&planner);
        let mut stick = StickPlanData::new(&planner, &friction);
        let settings = PlanSettings::default();
        let requirements = Requirements::default();
        let q = cdhrm5::LOADED_POSE;
        for objective in [Objective::StiffnessAlong(Vector3::y()), Objective::MinStiffness] {
            let free =
                planner.plan(&mut data, &q, &F0, objective, &requirements, &settings).unwrap();
            let held = planner
                .plan_in_stick(
                    &mut data,
                    &mut stick,
                    (&friction, History::Equal),
                    &q,
                    &F0,
                    objective,
                    &requirements,
                    &settings,
                )
                .unwrap();
            // K_stick ⪰ K at the same tensions (Cauchy–Schwarz, stick.rs), over the same set.
            assert!(
                held.value >= free.value - free.gap - held.gap,
                "{model:?} {}: stick {} < frictionless {}",
                objective.name(),
                held.value,
                free.value
            );
            eprintln!(
                "{model:?} {}: stick {:.4e} vs frictionless {:.4e} ({:.2}×)",
                objective.name(),
                held.value,
                free.value,
                held.value / free.value
            );
        }
    }
}

#[test]
fn what_the_stick_planner_does_not_offer_is_refused_by_name() {
    let (planner, friction) = planner(PatternModel::Decoupled);
    let mut data = PlannerData::new(&planner);
    let mut stick = StickPlanData::new(&planner, &friction);
    let q = cdhrm5::LOADED_POSE;
    let objective = Objective::MinStiffness;
    let stage = (&friction, History::Pull);
    let bundle = PlanSettings { method: Method::Bundle, ..PlanSettings::default() };
    let err = planner
        .plan_in_stick(
            &mut data,
            &mut stick,
            stage,
            &q,
            &F0,
            objective,
            &Requirements::default(),
            &bundle,
        )
        .unwrap_err();
    assert!(
        matches!(
            err,
            PlanError::InvalidInput { what: "method", problem: InputProblem::NotInStick }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("stick"), "{err}");
    let held = Requirements { fixed_levels: vec![(0, 0.5)], ..Requirements::default() };
    let err = planner
        .plan_in_stick(
            &mut data,
            &mut stick,
            stage,
            &q,
            &F0,
            objective,
            &held,
            &PlanSettings::default(),
        )
        .unwrap_err();
    assert!(
        matches!(
            err,
            PlanError::InvalidInput { what: "fixed_level", problem: InputProblem::NotInStick }
        ),
        "{err}"
    );
    // μ = 0: no band, nothing can stick; the cable is named.
    let frictionless = FrictionModel::new(planner.arm().routing());
    let mut stick = StickPlanData::new(&planner, &frictionless);
    let err = planner
        .plan_in_stick(
            &mut data,
            &mut stick,
            (&frictionless, History::Equal),
            &q,
            &F0,
            objective,
            &Requirements::default(),
            &PlanSettings::default(),
        )
        .unwrap_err();
    let PlanError::Stiffness(e) = &err else { panic!("{err}") };
    assert!(matches!(**e, StiffnessError::StickWithoutFriction { cable: 0 }), "{err}");
}

#[test]
fn a_friction_model_or_workspace_of_another_arm_is_an_error_not_a_panic() {
    let (planner, friction) = planner(PatternModel::Decoupled);
    let (_, other) = cdhrm5::chain(3, PatternModel::Decoupled);
    let foreign = FrictionModel::new(&other).with_friction_coefficient(MU).unwrap();
    let mut data = PlannerData::new(&planner);
    let q = cdhrm5::LOADED_POSE;
    let settings = PlanSettings::default();
    let requirements = Requirements::default();
    let objective = Objective::MinStiffness;
    // The model of another routing, with a workspace made for it.
    let mut stick = StickPlanData::new(&planner, &foreign);
    let stage = (&foreign, History::Pull);
    let err = planner
        .plan_in_stick(&mut data, &mut stick, stage, &q, &F0, objective, &requirements, &settings)
        .unwrap_err();
    assert!(matches!(err, PlanError::Routing(_) | PlanError::Stiffness(_)), "{err}");
    // This arm's model with a workspace made for the other one.
    let stage = (&friction, History::Equal);
    let err = planner
        .plan_in_stick(&mut data, &mut stick, stage, &q, &F0, objective, &requirements, &settings)
        .unwrap_err();
    assert!(matches!(err, PlanError::Routing(_) | PlanError::Stiffness(_)), "{err}");
    eprintln!("{err}");
}
