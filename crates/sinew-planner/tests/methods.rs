//! The interior-point method against the bundle method, two independent methods with
//! independent certificates: `|v_ipm − v_bundle| ≤ gap_ipm + gap_bundle` over poses, the five
//! objectives, both models, with and without budgets; and every answer checked as a candidate
//! would be (its margin re-evaluated by the pipeline).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Vector3, Vector6};
use sinew_planner::{Method, Objective, PlanSettings, Planner, PlannerData, Requirements};
use sinew_stiffness::ArmStiffness;
use sinew_testkit::cdhrm5;

fn objectives() -> [Objective; 5] {
    [
        Objective::StiffnessAlong(Vector3::new(0.0, 0.6, 0.8)),
        Objective::ComplianceAlong(Vector3::y()),
        Objective::MinStiffness,
        Objective::Volume,
        Objective::LeastTension,
    ]
}

#[test]
fn interior_point_and_bundle_agree_within_their_gaps() {
    let poses: [[f64; 10]; 2] =
        [cdhrm5::LOADED_POSE, [0.1, -0.05, 0.08, 0.02, -0.06, 0.1, 0.04, -0.03, 0.07, 0.05]];
    let mut worst: f64 = 0.0;
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
        let mut data = PlannerData::new(&planner);
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        for q in &poses {
            for objective in objectives() {
                for budget in [None, Some(1.15)] {
                    let mut requirements = Requirements::default();
                    if let Some(b) = budget {
                        let least = planner
                            .plan(
                                &mut data,
                                q,
                                &f0,
                                Objective::LeastTension,
                                &requirements,
                                &PlanSettings::default(),
                            )
                            .unwrap()
                            .value;
                        requirements.budget = Some(b * least);
                    }
                    let plan = |method| {
                        let settings = PlanSettings { method, ..PlanSettings::default() };
                        let mut data = PlannerData::new(&planner);
                        planner
                            .plan(&mut data, q, &f0, objective, &requirements, &settings)
                            .unwrap()
                    };
                    let ipm = plan(Method::InteriorPoint);
                    let bundle = plan(Method::Bundle);
                    let difference = (ipm.value - bundle.value).abs();
                    println!(
                        "{model:?} {} budget {budget:?}: ipm {:.10e} (gap {:.1e}, {} it, margin {:.3e}) bundle {:.10e} (gap {:.1e}, margin {:.3e})",
                        objective.name(),
                        ipm.value,
                        ipm.gap,
                        ipm.iterations,
                        ipm.min_eigenvalue,
                        bundle.value,
                        bundle.gap,
                        bundle.min_eigenvalue
                    );
                    for p in [&ipm, &bundle] {
                        let arm = planner.arm();
                        let mut sd = sinew_stiffness::ArmStiffnessData::new(arm);
                        arm.evaluate(
                            &mut sd,
                            q,
                            &f0,
                            sinew_statics::TensionChoice::Given(&p.tensions),
                        )
                        .unwrap();
                        // The pipeline's own verdict at the plan's tensions.
                        let margin = sd.stability_margin().unwrap();
                        assert!(margin >= requirements.margin * (1.0 - 1e-9), "margin {margin}");
                        assert!(p.min_eigenvalue >= requirements.margin * (1.0 - 1e-9));
                        if let Some(b) = requirements.budget {
                            assert!(p.total_tension <= b * (1.0 + 1e-9));
                        }
                    }
                    let allowed = ipm.gap + bundle.gap + 1e-9 * ipm.value.abs();
                    worst = worst.max(difference / allowed);
                    assert!(
                        difference <= allowed,
                        "{model:?} {}: |{} − {}| = {difference:e} > {allowed:e}",
                        objective.name(),
                        ipm.value,
                        bundle.value
                    );
                }
            }
        }
    }
    println!("worst |v_ipm − v_bundle| / (gap_ipm + gap_bundle) = {worst:.3}");
}
