//! The planner against independent evidence: brute-force grids over the equilibrium set of 1-
//! and 2-joint arms, 10,000 random feasible tensions on cdhrm5 and a 10-joint chain, the top
//! of every interval when every `A_i ⪰ 0`, budgets binding or not, balance and limits, the
//! pipeline's `K_fd` at the returned levels, the concavity the method relies on, and bad input.
//! Every value of a candidate is computed by the stiffness pipeline itself at given tensions
//! (`TensionChoice::Given`), not by the planner's own algebra.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Matrix3, Vector3, Vector6};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sinew_planner::{Objective, Plan, PlanError, PlanSettings, Planner, PlannerData, Requirements};
use sinew_robot::Robot;
use sinew_routing::{PatternModel, Routing};
use sinew_statics::{EquilibriumSet, TensionChoice};
use sinew_stiffness::{ArmStiffness, ArmStiffnessData, StiffnessError};
use sinew_testkit::cdhrm5;
use sinew_testkit::numeric::grid_points;

/// The objectives a brute force checks (least tension with a stiffness floor separately).
fn objectives() -> [Objective; 4] {
    [
        Objective::StiffnessAlong(Vector3::y()),
        Objective::ComplianceAlong(Vector3::new(0.6, 0.8, 0.0)),
        Objective::MinStiffness,
        Objective::Volume,
    ]
}

/// The objective's value at `tensions` by the pipeline (None where the margin is not met or
/// the value is undefined). For ComplianceAlong and LeastTension the value is the quantity
/// minimised, so "better" is smaller.
fn value_at(
    arm: &ArmStiffness,
    data: &mut ArmStiffnessData,
    q: &[f64],
    f0: &Vector6<f64>,
    objective: Objective,
    requirements: &Requirements,
    tensions: &[f64],
) -> Option<f64> {
    match arm.evaluate(data, q, f0, TensionChoice::Given(tensions)) {
        Ok(()) | Err(StiffnessError::RankDeficient { .. }) => {}
        Err(_) => return None,
    }
    if data.stability_margin().ok()? < requirements.margin {
        return None;
    }
    let k_fd = data.k_fd();
    if requirements.budget.is_some_and(|b| tensions.iter().sum::<f64>() > b) {
        return None;
    }
    if requirements.k_min.is_some_and(|k| k_fd.symmetric_eigen().eigenvalues.min() < k) {
        return None;
    }
    let c = data.compliance();
    Some(match objective {
        Objective::StiffnessAlong(u) => u.dot(&(k_fd * u)),
        Objective::ComplianceAlong(u) => {
            let c3 = Matrix3::from_fn(|r, k| c[(r, k)]);
            u.dot(&(c3 * u))
        }
        Objective::MinStiffness => k_fd.symmetric_eigen().eigenvalues.min(),
        Objective::Volume => k_fd.determinant().ln(),
        Objective::LeastTension => tensions.iter().sum(),
    })
}

/// Whether `candidate` beats the plan by more than its certified gap (plus rounding).
fn beats(plan: &Plan, candidate: f64) -> bool {
    let slack = plan.gap + 1e-9 * plan.value.abs().max(1e-9);
    match plan.objective {
        Objective::ComplianceAlong(_) | Objective::LeastTension => candidate < plan.value - slack,
        _ => candidate > plan.value + slack,
    }
}

struct Case {
    robot: Robot,
    routing: Routing,
    q: Vec<f64>,
    f0: Vector6<f64>,
}

impl Case {
    fn planner(&self) -> Planner {
        Planner::new(ArmStiffness::new(&self.robot, &self.routing).unwrap())
    }

    /// The equilibrium set at the pose (least-total tensions solved first).
    fn set(&self, arm: &ArmStiffness, data: &mut ArmStiffnessData) -> EquilibriumSet {
        let choice = TensionChoice::Policy(sinew_statics::TensionPolicy::LeastTotal);
        arm.evaluate_joints(data, &self.q, &self.f0, choice).unwrap();
        arm.equilibrium_set(data).unwrap().clone()
    }
}

fn small_case(joints: usize, model: PatternModel, q: &[f64]) -> Case {
    let (robot, routing) = cdhrm5::chain(joints, model);
    Case { robot, routing, q: q.to_vec(), f0: Vector6::new(0.0, 3.0, 0.0, 0.0, 0.0, 0.0) }
}

fn cdhrm5_case(model: PatternModel) -> Case {
    let (robot, routing) = cdhrm5::robot_and_routing(model);
    Case {
        robot,
        routing,
        q: cdhrm5::LOADED_POSE.to_vec(),
        f0: Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0),
    }
}

/// Tensions within their limits at `lambda`, or None.
fn feasible_tensions(set: &EquilibriumSet, lambda: &[f64]) -> Option<Vec<f64>> {
    let mut f = vec![0.0; set.cable_count()];
    set.tensions(lambda, &mut f).unwrap();
    let inside =
        f.iter().zip(set.lower().iter().zip(set.upper())).all(|(f, (lo, hi))| lo <= f && f <= hi);
    inside.then_some(f)
}

/// Brute force over the levels' set: 1 and 2 joints (`J_x` of rank 2 and 4, so `K_x` does not
/// exist there: the compliance along a direction and the least tension), and 3 joints (all
/// objectives, a 3-D grid).
#[test]
fn a_brute_force_grid_never_beats_the_plan_by_more_than_its_gap() {
    let cases = [
        ("1 joint", small_case(1, PatternModel::Decoupled, &[0.3, -0.2])),
        ("2 joints decoupled", small_case(2, PatternModel::Decoupled, &[0.3, -0.2, 0.1, 0.25])),
        ("2 joints routed", small_case(2, PatternModel::Routed, &[0.3, -0.2, 0.1, 0.25])),
        (
            "3 joints decoupled",
            small_case(3, PatternModel::Decoupled, &[0.3, -0.2, 0.1, 0.25, -0.15, 0.2]),
        ),
    ];
    for (name, case) in &cases {
        let planner = case.planner();
        let arm = planner.arm();
        let mut pdata = PlannerData::new(&planner);
        let mut data = ArmStiffnessData::new(arm);
        let set = case.set(arm, &mut data);
        let k = set.dimension();
        assert!((1..=3).contains(&k), "{name}: dimension {k}");
        // The box of λ: N is orthonormal, so |λ| = |f − f_p| ≤ √m f_max.
        let reach =
            (set.cable_count() as f64).sqrt() * set.upper().iter().fold(0.0_f64, |a, b| a.max(*b));
        let n = [0, 2001, 161, 31][k];
        let mut list: Vec<(Objective, Requirements)> = if k == 3 {
            objectives().into_iter().map(|o| (o, Requirements::default())).collect()
        } else {
            vec![
                (Objective::ComplianceAlong(Vector3::new(0.6, 0.8, 0.0)), Requirements::default()),
                (Objective::ComplianceAlong(Vector3::x()), Requirements::default()),
            ]
        };
        list.push((
            Objective::LeastTension,
            Requirements { margin: 0.2, ..Requirements::default() },
        ));
        if k == 3 {
            list.push((
                Objective::LeastTension,
                Requirements { k_min: Some(15.0), ..Requirements::default() },
            ));
        }
        for (objective, requirements) in list {
            let plan = planner
                .plan(
                    &mut pdata,
                    &case.q,
                    &case.f0,
                    objective,
                    &requirements,
                    &PlanSettings::default(),
                )
                .unwrap_or_else(|e| panic!("{name} {}: {e}", objective.name()));
            // A coarse grid over the box, then two finer grids around its best point.
            let mut best: Option<(f64, Vec<f64>)> = None;
            let (mut centre, mut half) = (vec![0.0; k], reach);
            let mut evaluated = 0;
            for _ in 0..3 {
                for lambda in grid_points(&centre, half, n) {
                    let Some(f) = feasible_tensions(&set, &lambda) else { continue };
                    let Some(v) =
                        value_at(arm, &mut data, &case.q, &case.f0, objective, &requirements, &f)
                    else {
                        continue;
                    };
                    evaluated += 1;
                    assert!(
                        !beats(&plan, v),
                        "{name} {}: grid {v} beats plan {} (gap {})",
                        objective.name(),
                        plan.value,
                        plan.gap
                    );
                    let better = match (&best, objective) {
                        (None, _) => true,
                        (Some((b, _)), Objective::ComplianceAlong(_) | Objective::LeastTension) => {
                            v < *b
                        }
                        (Some((b, _)), _) => v > *b,
                    };
                    if better {
                        best = Some((v, lambda));
                    }
                }
                let Some((_, at)) = &best else { break };
                centre.clone_from(at);
                half *= 4.0 / (n - 1) as f64;
            }
            assert!(evaluated > 50, "{name} {}: {evaluated} grid points", objective.name());
            let best = best.map(|(v, _)| v);
            let best = best.expect("some grid point meets the requirements");
            // The zoomed grid comes close to the plan: the plan is not a poor point.
            // (The least tension sits on the curved boundary of the margin or stiffness floor,
            // which a 3-D grid resolves to about 2 %.)
            let off = (best - plan.value).abs() / plan.value.abs();
            let resolution =
                if k == 3 && objective == Objective::LeastTension { 0.02 } else { 1e-3 };
            assert!(
                off < resolution,
                "{name} {}: grid best {best}, plan {}",
                objective.name(),
                plan.value
            );
            println!(
                "{name} {}: plan {} gap {:.1e} grid best {best} ({} iterations)",
                objective.name(),
                plan.value,
                plan.gap,
                plan.iterations
            );
        }
    }
}

#[test]
fn ten_thousand_random_feasible_tensions_never_beat_the_plan() {
    let mut rng = ChaCha8Rng::seed_from_u64(14);
    let ten = {
        // Weightless (ten links on [20, 600] N cables cannot carry their own weight), a 0.22 N
        // force at the tip.
        let (robot, routing) = cdhrm5::chain(10, PatternModel::Decoupled);
        let robot = robot.with_gravity(Vector3::zeros());
        let q: Vec<f64> = (0..20).map(|i| 0.15 * ((i as f64) * 1.3).sin()).collect();
        Case { robot, routing, q, f0: Vector6::new(0.0, 0.2, 0.1, 0.0, 0.0, 0.0) }
    };
    let cases = [
        ("cdhrm5 decoupled", cdhrm5_case(PatternModel::Decoupled)),
        ("cdhrm5 routed", cdhrm5_case(PatternModel::Routed)),
        ("10 joints", ten),
    ];
    for (name, case) in &cases {
        let planner = case.planner();
        let arm = planner.arm();
        let mut pdata = PlannerData::new(&planner);
        let mut data = ArmStiffnessData::new(arm);
        let set = case.set(arm, &mut data);
        for objective in [Objective::StiffnessAlong(Vector3::y()), Objective::MinStiffness] {
            let requirements = Requirements::default();
            let plan = planner
                .plan(
                    &mut pdata,
                    &case.q,
                    &case.f0,
                    objective,
                    &requirements,
                    &PlanSettings::default(),
                )
                .unwrap_or_else(|e| panic!("{name} {}: {e}", objective.name()));
            let (mut tried, mut checked) = (0, 0);
            while checked < 10_000 / 2 && tried < 400_000 {
                tried += 1;
                // Half near the answer, half anywhere in the box of the limits.
                let lambda: Vec<f64> = if tried % 2 == 0 {
                    plan.lambda.iter().map(|l| l + rng.random_range(-20.0..20.0)).collect()
                } else {
                    let f: Vec<f64> = (0..set.cable_count())
                        .map(|c| rng.random_range(set.lower()[c]..set.upper()[c]))
                        .collect();
                    set.coordinates(&f)
                };
                let Some(f) = feasible_tensions(&set, &lambda) else { continue };
                let Some(v) =
                    value_at(arm, &mut data, &case.q, &case.f0, objective, &requirements, &f)
                else {
                    continue;
                };
                checked += 1;
                assert!(
                    !beats(&plan, v),
                    "{name} {}: random {v} beats plan {} (gap {})",
                    objective.name(),
                    plan.value,
                    plan.gap
                );
            }
            assert!(
                checked >= 5_000,
                "{name} {}: only {checked} feasible of {tried}",
                objective.name()
            );
            println!(
                "{name} {}: {checked} feasible random tensions, none beats {} (gap {:.1e})",
                objective.name(),
                plan.value,
                plan.gap
            );
        }
    }
}

#[test]
fn the_answer_balances_the_load_within_the_limits_and_is_the_pipelines() {
    for model in cdhrm5::MODELS {
        let case = cdhrm5_case(model);
        let planner = case.planner();
        let arm = planner.arm();
        let mut pdata = PlannerData::new(&planner);
        let mut data = ArmStiffnessData::new(arm);
        for objective in objectives() {
            let plan = planner
                .plan(
                    &mut pdata,
                    &case.q,
                    &case.f0,
                    objective,
                    &Requirements::default(),
                    &PlanSettings::default(),
                )
                .unwrap();
            // The margin asked for; limits exactly; balance (1e-9 relative).
            assert!(plan.min_eigenvalue >= Requirements::default().margin * (1.0 - 1e-9));
            for (f, [lo, hi]) in plan.tensions.iter().zip(case.routing.cable_limits()) {
                assert!(lo <= f && f <= hi, "{model:?}: {f} outside [{lo}, {hi}]");
            }
            arm.evaluate(&mut data, &case.q, &case.f0, TensionChoice::Given(&plan.tensions))
                .unwrap();
            let t0 = &data.statics.t0;
            let j = data.cables.jacobian().unwrap();
            let residual: f64 = (0..t0.len())
                .map(|d| {
                    (t0[d]
                        + (0..plan.tensions.len())
                            .map(|c| j[(c, d)] * plan.tensions[c])
                            .sum::<f64>())
                    .powi(2)
                })
                .sum::<f64>()
                .sqrt();
            let t0_norm = t0.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!(residual <= 1e-9 * t0_norm, "{model:?}: residual {residual}");
            // The reported K_fd is the pipeline's at these tensions, and at the returned levels.
            let k_fd = plan.k_fd.unwrap();
            assert!((data.k_fd() - k_fd).abs().max() <= 1e-9 * k_fd.abs().max());
            let levels = plan.levels.clone().expect("three cables per joint: levels");
            arm.evaluate(&mut data, &case.q, &case.f0, TensionChoice::Levels(&levels)).unwrap();
            let diff = (data.k_fd() - k_fd).abs().max();
            assert!(
                diff <= 1e-8 * k_fd.abs().max(),
                "{model:?} {}: K_fd at the levels differs by {diff}",
                objective.name()
            );
        }
    }
}

#[test]
fn with_every_a_i_psd_and_no_budget_the_optimum_is_the_top_of_every_interval() {
    // cdhrm5 decoupled at the loaded pose: raising any joint's tension along its interval
    // stiffens it (A_i ⪰ 0, checked below through the pipeline's K_q), so the stiffness along
    // any direction is best with every joint at level 1.
    let case = cdhrm5_case(PatternModel::Decoupled);
    let planner = case.planner();
    let arm = planner.arm();
    let mut data = ArmStiffnessData::new(arm);
    let n = 5;
    let k_q_at = |data: &mut ArmStiffnessData, levels: &[f64]| {
        arm.evaluate_joints(data, &case.q, &case.f0, TensionChoice::Levels(levels)).unwrap();
        data.k_q().to_owned()
    };
    let bottom = k_q_at(&mut data, &[0.0; 5]);
    for i in 0..n {
        let mut levels = [0.0; 5];
        levels[i] = 1.0;
        let d = k_q_at(&mut data, &levels) - &bottom;
        let eigen = d.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
        assert!(eigen.iter().all(|&e| e >= -1e-9), "A_{i} has eigenvalue {:?}", eigen);
    }
    let mut pdata = PlannerData::new(&planner);
    for objective in objectives() {
        let plan = planner
            .plan(
                &mut pdata,
                &case.q,
                &case.f0,
                objective,
                &Requirements::default(),
                &PlanSettings::default(),
            )
            .unwrap();
        arm.evaluate(&mut data, &case.q, &case.f0, TensionChoice::Levels(&[1.0; 5])).unwrap();
        let top = data.tensions().to_vec();
        let requirements = Requirements::default();
        let v =
            value_at(arm, &mut data, &case.q, &case.f0, objective, &requirements, &top).unwrap();
        // The top is optimal: within the plan's gap of it, and not beaten by it.
        assert!(!beats(&plan, v), "{}", objective.name());
        let worse_than_plan = match objective {
            Objective::ComplianceAlong(_) => v > plan.value + plan.gap + 1e-12,
            _ => v < plan.value - plan.gap - 1e-12,
        };
        assert!(
            !worse_than_plan,
            "{}: top {v}, plan {} ± {}",
            objective.name(),
            plan.value,
            plan.gap
        );
        let levels = plan.levels.unwrap();
        assert!(levels.iter().all(|&s| s > 0.99), "{}: {levels:?}", objective.name());
    }
}

#[test]
fn a_binding_budget_is_met_with_equality_and_a_loose_one_is_not() {
    let case = cdhrm5_case(PatternModel::Decoupled);
    let planner = case.planner();
    let mut pdata = PlannerData::new(&planner);
    let objective = Objective::StiffnessAlong(Vector3::y());
    let free = planner
        .plan(
            &mut pdata,
            &case.q,
            &case.f0,
            objective,
            &Requirements::default(),
            &PlanSettings::default(),
        )
        .unwrap();
    let tight = 0.5 * free.total_tension;
    let bound = Requirements { budget: Some(tight), ..Requirements::default() };
    let plan = planner
        .plan(&mut pdata, &case.q, &case.f0, objective, &bound, &PlanSettings::default())
        .unwrap();
    assert!(plan.total_tension <= tight * (1.0 + 1e-12));
    assert!(
        plan.total_tension >= tight * (1.0 - 1e-4),
        "binding: {} of {tight}",
        plan.total_tension
    );
    assert!(plan.value < free.value);
    let loose = Requirements { budget: Some(2.0 * free.total_tension), ..Requirements::default() };
    let plan = planner
        .plan(&mut pdata, &case.q, &case.f0, objective, &loose, &PlanSettings::default())
        .unwrap();
    assert!(plan.total_tension < 0.9 * 2.0 * free.total_tension, "loose: {}", plan.total_tension);
    assert!((plan.value - free.value).abs() <= free.gap + plan.gap + 1e-9 * free.value);
}

#[test]
fn the_concavity_the_method_relies_on_holds_on_random_segments() {
    let case = cdhrm5_case(PatternModel::Routed);
    let arm = ArmStiffness::new(&case.robot, &case.routing).unwrap();
    let mut data = ArmStiffnessData::new(&arm);
    let set = case.set(&arm, &mut data);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let loose = Requirements { margin: 1e-9, ..Requirements::default() };
    let mut segments = 0;
    while segments < 200 {
        let pick = |rng: &mut ChaCha8Rng| {
            let f: Vec<f64> = (0..set.cable_count())
                .map(|c| rng.random_range(set.lower()[c]..set.upper()[c]))
                .collect();
            set.coordinates(&f)
        };
        let (a, b) = (pick(&mut rng), pick(&mut rng));
        let t: f64 = rng.random_range(0.05..0.95);
        let mid: Vec<f64> = a.iter().zip(&b).map(|(x, y)| (1.0 - t) * x + t * y).collect();
        let (Some(fa), Some(fb), Some(fm)) = (
            feasible_tensions(&set, &a),
            feasible_tensions(&set, &b),
            feasible_tensions(&set, &mid),
        ) else {
            continue;
        };
        let mut all = Vec::new();
        for objective in objectives() {
            let v = |f: &[f64], data: &mut ArmStiffnessData| {
                value_at(&arm, data, &case.q, &case.f0, objective, &loose, f)
            };
            let (Some(va), Some(vb), Some(vm)) =
                (v(&fa, &mut data), v(&fb, &mut data), v(&fm, &mut data))
            else {
                continue;
            };
            let chord = (1.0 - t) * va + t * vb;
            let tol = 1e-9 * chord.abs().max(1e-12);
            match objective {
                Objective::ComplianceAlong(_) => {
                    assert!(vm <= chord + tol, "convex: {vm} > {chord}")
                }
                _ => assert!(vm >= chord - tol, "{} concave: {vm} < {chord}", objective.name()),
            }
            all.push(vm);
        }
        // The stability margin too.
        let margin = |f: &[f64], data: &mut ArmStiffnessData| {
            let _ = arm.evaluate_joints(data, &case.q, &case.f0, TensionChoice::Given(f));
            data.stability_margin().unwrap()
        };
        let (ma, mb, mm) = (margin(&fa, &mut data), margin(&fb, &mut data), margin(&fm, &mut data));
        assert!(mm >= (1.0 - t) * ma + t * mb - 1e-9 * ma.abs().max(1.0));
        if all.len() == 4 {
            segments += 1;
        }
    }
}

#[test]
fn bad_input_and_unreachable_requirements_are_typed() {
    let case = cdhrm5_case(PatternModel::Decoupled);
    let planner = case.planner();
    let mut pdata = PlannerData::new(&planner);
    let s = PlanSettings::default();
    let plan =
        |f0: &Vector6<f64>, objective, requirements: &Requirements, pdata: &mut PlannerData| {
            planner.plan(pdata, &case.q, f0, objective, requirements, &s)
        };
    let d = Requirements::default();
    let moment = Vector6::new(0.0, 5.0, 0.0, 0.1, 0.0, 0.0);
    let err = plan(&moment, Objective::MinStiffness, &d, &mut pdata).unwrap_err();
    assert!(matches!(err, PlanError::NonConservativeLoad { .. }), "{err}");
    assert!(err.to_string().contains("not symmetric"), "{err}");
    let err =
        plan(&case.f0, Objective::StiffnessAlong(Vector3::zeros()), &d, &mut pdata).unwrap_err();
    assert!(matches!(err, PlanError::InvalidInput { what: "direction", .. }), "{err}");
    let not_spd = Requirements {
        k_des: Some(Matrix3::new(1.0, 2.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)),
        ..d.clone()
    };
    let err = plan(&case.f0, Objective::LeastTension, &not_spd, &mut pdata).unwrap_err();
    assert!(matches!(err, PlanError::InvalidInput { what: "k_des", .. }), "{err}");
    for bad in [
        Requirements { budget: Some(-1.0), ..d.clone() },
        Requirements { margin: -1.0, ..d.clone() },
    ] {
        let err = plan(&case.f0, Objective::Volume, &bad, &mut pdata).unwrap_err();
        assert!(matches!(err, PlanError::InvalidInput { .. }), "{err}");
    }
    let err = plan(
        &case.f0,
        Objective::Volume,
        &Requirements { budget: Some(10.0), ..d.clone() },
        &mut pdata,
    )
    .unwrap_err();
    assert!(matches!(err, PlanError::BudgetTooSmall { budget: 10.0, .. }), "{err}");
    // A floor above the best reachable least stiffness: refused with the best reachable.
    let best = plan(&case.f0, Objective::MinStiffness, &d, &mut pdata).unwrap();
    let too_high = Requirements { k_min: Some(2.0 * best.value), ..d.clone() };
    let err = plan(&case.f0, Objective::LeastTension, &too_high, &mut pdata).unwrap_err();
    match err {
        PlanError::RequirementUnreachable { best: reachable, .. } => {
            assert!(
                reachable >= best.value - best.gap && reachable < 2.0 * best.value,
                "{reachable} vs {}",
                best.value
            );
        }
        e => panic!("{e}"),
    }
    // A floor within reach: the least tension that meets it meets it, and costs more than none.
    let floor = Requirements { k_min: Some(0.5 * best.value), ..d.clone() };
    let cheap = plan(&case.f0, Objective::LeastTension, &floor, &mut pdata).unwrap();
    let k_fd = cheap.k_fd.unwrap();
    assert!(k_fd.symmetric_eigen().eigenvalues.min() >= 0.5 * best.value * (1.0 - 1e-9));
    assert!((cheap.value - cheap.total_tension).abs() <= 1e-9 * cheap.value);
}

#[test]
fn a_binding_joint_budget_is_met_with_equality() {
    let case = cdhrm5_case(PatternModel::Decoupled);
    let planner = case.planner();
    let mut pdata = PlannerData::new(&planner);
    let objective = Objective::StiffnessAlong(Vector3::y());
    let free = planner
        .plan(
            &mut pdata,
            &case.q,
            &case.f0,
            objective,
            &Requirements::default(),
            &PlanSettings::default(),
        )
        .unwrap();
    let own = case.routing.cables_of_joint(4);
    let sum = |plan: &Plan| plan.tensions[own.clone()].iter().sum::<f64>();
    let cap = 0.6 * sum(&free);
    let bound = Requirements { joint_budgets: vec![(4, cap)], ..Requirements::default() };
    let plan = planner
        .plan(&mut pdata, &case.q, &case.f0, objective, &bound, &PlanSettings::default())
        .unwrap();
    assert!(sum(&plan) <= cap * (1.0 + 1e-12), "{} > {cap}", sum(&plan));
    assert!(sum(&plan) >= cap * (1.0 - 1e-4), "binding: {} of {cap}", sum(&plan));
    assert!(plan.value <= free.value + free.gap);
    // Below joint 5's least sum: refused.
    let impossible = Requirements { joint_budgets: vec![(4, 1.0)], ..Requirements::default() };
    let err = planner
        .plan(&mut pdata, &case.q, &case.f0, objective, &impossible, &PlanSettings::default())
        .unwrap_err();
    assert!(matches!(err, PlanError::BudgetsInfeasible), "{err}");
}

#[test]
fn fixed_levels_are_held_and_need_the_decoupled_closed_form() {
    let case = cdhrm5_case(PatternModel::Decoupled);
    let planner = case.planner();
    let mut pdata = PlannerData::new(&planner);
    let objective = Objective::MinStiffness;
    let s = PlanSettings::default();
    let free = planner
        .plan(&mut pdata, &case.q, &case.f0, objective, &Requirements::default(), &s)
        .unwrap();
    let held = Requirements { fixed_levels: vec![(2, 0.25), (4, 1.0)], ..Requirements::default() };
    let plan = planner.plan(&mut pdata, &case.q, &case.f0, objective, &held, &s).unwrap();
    let levels = plan.levels.clone().unwrap();
    assert!((levels[2] - 0.25).abs() <= 1e-6 && (levels[4] - 1.0).abs() <= 1e-6, "{levels:?}");
    assert!(plan.value <= free.value + free.gap, "holding joints cannot help");
    // The held joints' tensions are those of the closed form at those levels.
    let arm = planner.arm();
    let mut data = ArmStiffnessData::new(arm);
    let mut at = levels.clone();
    at[2] = 0.25;
    at[4] = 1.0;
    arm.evaluate_joints(&mut data, &case.q, &case.f0, TensionChoice::Levels(&at)).unwrap();
    for c in case.routing.cables_of_joint(2).chain(case.routing.cables_of_joint(4)) {
        let (a, b) = (plan.tensions[c], data.tensions()[c]);
        assert!((a - b).abs() <= 1e-6 * b, "cable {c}: {a} vs {b}");
    }
    let routed = cdhrm5_case(PatternModel::Routed);
    let planner = routed.planner();
    let mut pdata = PlannerData::new(&planner);
    let err = planner.plan(&mut pdata, &routed.q, &routed.f0, objective, &held, &s).unwrap_err();
    assert!(matches!(err, PlanError::InvalidInput { what: "fixed_level", .. }), "{err}");
}

#[test]
fn a_plan_at_one_pose_runs_exactly_one_pose_stage() {
    // Before the pose stage existed, a plan ran the pipeline's geometry, T0 and K_W three times
    // (least-total tensions, safest tensions, the answer's evaluation) and four with held
    // levels. The workspace counts its pose stages: one per plan, whatever the objective, the
    // model or the requirements.
    let s = PlanSettings::default();
    let objectives = [
        Objective::StiffnessAlong(Vector3::y()),
        Objective::ComplianceAlong(Vector3::new(0.6, 0.8, 0.0)),
        Objective::MinStiffness,
        Objective::Volume,
        Objective::LeastTension,
    ];
    for model in [PatternModel::Decoupled, PatternModel::Routed] {
        let case = cdhrm5_case(model);
        let planner = case.planner();
        let mut pdata = PlannerData::new(&planner);
        let mut plans = 0;
        for objective in objectives {
            let mut requirements = Requirements::default();
            if objective == Objective::LeastTension {
                requirements.k_min = Some(3.0);
            }
            let before = pdata.stiffness().pose_stages();
            planner.plan(&mut pdata, &case.q, &case.f0, objective, &requirements, &s).unwrap();
            assert_eq!(pdata.stiffness().pose_stages() - before, 1, "{model:?} {objective:?}");
            plans += 1;
        }
        if model == PatternModel::Decoupled {
            let held = Requirements { fixed_levels: vec![(2, 0.25)], ..Requirements::default() };
            let objective = Objective::MinStiffness;
            planner.plan(&mut pdata, &case.q, &case.f0, objective, &held, &s).unwrap();
            plans += 1;
        }
        assert_eq!(pdata.stiffness().pose_stages(), plans, "{model:?}");
    }
}
