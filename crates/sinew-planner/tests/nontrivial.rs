//! Non-trivial optima (#24): plans whose answer is NOT every joint at the top of its tension
//! interval. On cdhrm5 in the decoupled model every `A_i ⪰ 0` at the loaded pose, so without a
//! binding budget the all-levels-1 point is optimal and a planner that always returned it
//! would pass most tests. Here each case makes that point wrong: a binding total or per-joint
//! budget, held levels, a stiffness floor or a desired stiffness matrix with least tension, and
//! a robot whose tension softens its joints (an indefinite `A_i`). Each plan is checked three
//! ways: (1) it beats the all-levels-1 point by far more than its gap, or that point breaks the
//! requirement and the plan meets it with equality; (2) no feasible point of a random search or
//! a brute-force grid beats it by more than its gap; (3) it is what the pipeline says at its
//! tensions (value, stability margin, floors, limits, budgets) and its gap is what was asked.
//! Every value of a candidate is computed by the stiffness pipeline at given tensions
//! (`TensionChoice::Given`), not by the planner's own algebra.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use nalgebra::{Matrix3, Vector3, Vector6};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sinew_planner::{Objective, Plan, PlanSettings, Planner, PlannerData, Requirements};
use sinew_robot::Robot;
use sinew_routing::{PatternModel, Routing, RoutingSpec};
use sinew_statics::{EquilibriumSet, TensionChoice, TensionPolicy};
use sinew_stiffness::{ArmStiffness, ArmStiffnessData, EndOutcome, StiffnessError};
use sinew_testkit::cdhrm5;
use sinew_testkit::numeric::grid_points;

/// Whether smaller is better for `objective`.
fn minimised(objective: Objective) -> bool {
    matches!(objective, Objective::ComplianceAlong(_) | Objective::LeastTension)
}

/// How much better `a` is than `b` for `objective` (positive: `a` is better).
fn advantage(objective: Objective, a: f64, b: f64) -> f64 {
    if minimised(objective) { b - a } else { a - b }
}

/// Whether `candidate` beats the plan by more than its certified gap (plus rounding).
fn beats(plan: &Plan, candidate: f64) -> bool {
    advantage(plan.objective, candidate, plan.value) > plan.gap + 1e-9 * plan.value.abs().max(1e-9)
}

/// Asserts that the plan beats `other` by far more than its gap: more than 100 gaps and more
/// than 1e-6 of its value.
fn assert_far_better(name: &str, plan: &Plan, other: f64, what: &str) {
    let by = advantage(plan.objective, plan.value, other);
    assert!(
        by > 100.0 * plan.gap && by > 1e-6 * plan.value.abs(),
        "{name}: plan {} (gap {:.1e}) beats {what} {other} only by {by:.3e}",
        plan.value,
        plan.gap
    );
}

/// The smallest eigenvalue of a symmetric 3 × 3 matrix.
fn least(m: &Matrix3<f64>) -> f64 {
    m.symmetric_eigen().eigenvalues.min()
}

struct Case {
    name: String,
    robot: Robot,
    routing: Routing,
    q: Vec<f64>,
    f0: Vector6<f64>,
}

impl Case {
    fn planner(&self) -> Planner {
        Planner::new(ArmStiffness::new(&self.robot, &self.routing).unwrap())
    }
}

fn cdhrm5_case(model: PatternModel) -> Case {
    let (robot, routing) = cdhrm5::robot_and_routing(model);
    Case {
        name: format!("cdhrm5 {model:?}"),
        robot,
        routing,
        q: cdhrm5::LOADED_POSE.to_vec(),
        f0: Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0),
    }
}

fn plan(
    case: &Case,
    planner: &Planner,
    pdata: &mut PlannerData,
    objective: Objective,
    requirements: &Requirements,
) -> Plan {
    planner
        .plan(pdata, &case.q, &case.f0, objective, requirements, &PlanSettings::default())
        .unwrap_or_else(|e| panic!("{} {}: {e}", case.name, objective.name()))
}

/// The pipeline at one pose (one pose stage), judging candidate tensions.
struct Judge<'a> {
    case: &'a Case,
    arm: &'a ArmStiffness,
    data: ArmStiffnessData,
    set: EquilibriumSet,
    /// The paper's levels exist (three cables per universal joint).
    levels: bool,
}

impl<'a> Judge<'a> {
    fn new(case: &'a Case, arm: &'a ArmStiffness) -> Judge<'a> {
        let mut data = ArmStiffnessData::new(arm);
        arm.set_pose(&mut data, &case.q, &case.f0).unwrap();
        let set = arm.equilibrium_set(&mut data).unwrap().clone();
        let levels = arm.statics().has_levels();
        Judge { case, arm, data, set, levels }
    }

    fn joints(&self) -> usize {
        self.arm.routing().joint_count()
    }

    /// The tensions at the paper's levels.
    fn at_levels(&mut self, levels: &[f64]) -> Option<Vec<f64>> {
        self.arm.set_tensions(&mut self.data, TensionChoice::Levels(levels)).ok()?;
        Some(self.data.tensions().to_vec())
    }

    /// Tensions within their limits at `lambda`, or None.
    fn at_lambda(&self, lambda: &[f64]) -> Option<Vec<f64>> {
        let set = &self.set;
        let mut f = vec![0.0; set.cable_count()];
        set.tensions(lambda, &mut f).unwrap();
        let inside = f
            .iter()
            .zip(set.lower().iter().zip(set.upper()))
            .all(|(f, (lo, hi))| lo <= f && f <= hi);
        inside.then_some(f)
    }

    /// The least total tensions that hold the held levels (decoupled: every other joint at
    /// level 0), else the least-total policy's.
    fn lowest(&mut self, held: &[(usize, f64)]) -> Vec<f64> {
        if held.is_empty() {
            let choice = TensionChoice::Policy(TensionPolicy::LeastTotal);
            self.arm.set_tensions(&mut self.data, choice).unwrap();
            self.data.tensions().to_vec()
        } else {
            let mut levels = vec![0.0; self.joints()];
            for &(j, s) in held {
                levels[j] = s;
            }
            self.at_levels(&levels).unwrap()
        }
    }

    /// The budgets of `requirements` as rows `(cables, B)`: `Σ f[cables] ≤ B`.
    fn budget_rows(&self, requirements: &Requirements) -> Vec<(std::ops::Range<usize>, f64)> {
        let routing = self.arm.routing();
        let mut rows: Vec<_> = requirements
            .joint_budgets
            .iter()
            .map(|&(j, b)| (routing.cables_of_joint(j), b))
            .collect();
        if let Some(b) = requirements.budget {
            rows.push((0..self.set.cable_count(), b));
        }
        rows
    }

    /// The objective's value at `tensions` by the pipeline, or None where they break a
    /// requirement (limits, budgets, margin, `k_min`, `K_des`; held levels are the sampler's
    /// business) or the value is undefined.
    fn value(
        &mut self,
        objective: Objective,
        requirements: &Requirements,
        tensions: &[f64],
    ) -> Option<f64> {
        let set = &self.set;
        let inside = tensions
            .iter()
            .zip(set.lower().iter().zip(set.upper()))
            .all(|(f, (lo, hi))| lo <= f && f <= hi);
        if !inside {
            return None;
        }
        for (cables, b) in self.budget_rows(requirements) {
            if tensions[cables].iter().sum::<f64>() > b {
                return None;
            }
        }
        self.arm.set_tensions(&mut self.data, TensionChoice::Given(tensions)).ok()?;
        match self.arm.solve_end(&mut self.data).ok()? {
            EndOutcome::Stiff => {}
            // No K_fd (a planar arm): only what does not need it.
            EndOutcome::RankDeficient { .. }
                if matches!(objective, Objective::ComplianceAlong(_) | Objective::LeastTension)
                    && requirements.k_min.is_none()
                    && requirements.k_des.is_none() => {}
            _ => return None,
        }
        if self.data.stability_margin().ok()? < requirements.margin {
            return None;
        }
        let k_fd = self.data.k_fd();
        if requirements.k_min.is_some_and(|k| least(&k_fd) < k) {
            return None;
        }
        if requirements.k_des.is_some_and(|k| least(&(k_fd - k)) < 0.0) {
            return None;
        }
        let c = self.data.compliance();
        Some(match objective {
            Objective::StiffnessAlong(u) => u.dot(&(k_fd * u)),
            Objective::ComplianceAlong(u) => {
                let c3 = Matrix3::from_fn(|r, k| c[(r, k)]);
                u.dot(&(c3 * u))
            }
            Objective::MinStiffness => least(&k_fd),
            Objective::Volume => k_fd.determinant().ln(),
            Objective::LeastTension => tensions.iter().sum(),
        })
    }

    /// `f` moved toward `low` until every budget row holds: `low + t (f − low)` with `t` the
    /// largest that meets them, times `shrink` (both balance the load and lie within the
    /// limits, so the whole segment does). None where `low` itself breaks a row.
    fn pull(
        &self,
        requirements: &Requirements,
        low: &[f64],
        f: Vec<f64>,
        shrink: f64,
    ) -> Option<Vec<f64>> {
        let mut t: f64 = 1.0;
        for (cables, b) in self.budget_rows(requirements) {
            let (gf, gl) = (f[cables.clone()].iter().sum::<f64>(), low[cables].iter().sum::<f64>());
            if gf > b {
                if gl >= b {
                    return None;
                }
                t = t.min((b - gl) / (gf - gl));
            }
        }
        if t >= 1.0 {
            return Some(f);
        }
        let t = t * shrink;
        Some(low.iter().zip(&f).map(|(l, x)| l + t * (x - l)).collect())
    }

    /// The all-levels-1 point (None in the routed model at cdhrm5's loaded pose: there the
    /// distal joints' top tensions overload joint 3) and its value (None: it breaks the
    /// requirements).
    fn top(
        &mut self,
        objective: Objective,
        requirements: &Requirements,
    ) -> (Option<Vec<f64>>, Option<f64>) {
        let top = self.at_levels(&vec![1.0; self.joints()]);
        let v = top.as_ref().and_then(|f| self.value(objective, requirements, f));
        (top, v)
    }
}

/// What the searches of one plan checked.
struct Searched {
    random: usize,
    grid: usize,
    best: Option<f64>,
}

/// Random feasible tensions against the plan: uniform levels, the box of λ (as plan.rs),
/// around the plan's λ and around its levels at radii over three decades; each pulled into the
/// budgets toward the least-total tensions (so that many sit on the budget's face). With held
/// levels only the free levels are sampled. Panics on any that beats the plan by more than its
/// gap.
fn random_search(
    judge: &mut Judge<'_>,
    plan: &Plan,
    requirements: &Requirements,
    wanted: usize,
    rng: &mut ChaCha8Rng,
) -> (usize, Option<f64>) {
    let held = &requirements.fixed_levels;
    let low = judge.lowest(held);
    let joints = judge.joints();
    let k = judge.set.dimension();
    let cables = judge.set.cable_count();
    let objective = plan.objective;
    let plan_levels = plan.levels.clone();
    let (mut tried, mut checked) = (0usize, 0usize);
    let mut best: Option<f64> = None;
    while checked < wanted && tried < 40 * wanted {
        tried += 1;
        let mode = if judge.levels && !held.is_empty() { [0, 3][tried % 2] } else { tried % 4 };
        let decades = 10f64.powf(-rng.random_range(0.0..3.0));
        let f = match (mode, judge.levels, &plan_levels) {
            (0, true, _) | (3, true, Some(_)) => {
                let mut levels: Vec<f64> = match (&plan_levels, mode) {
                    (Some(at), 3) => at
                        .iter()
                        .map(|s| (s + 0.1 * decades * rng.random_range(-1.0..1.0)).clamp(0.0, 1.0))
                        .collect(),
                    _ => (0..joints).map(|_| rng.random_range(0.0..=1.0)).collect(),
                };
                for &(j, s) in held {
                    levels[j] = s;
                }
                judge.at_levels(&levels)
            }
            (2 | 3, _, _) => {
                let lambda: Vec<f64> = plan
                    .lambda
                    .iter()
                    .map(|l| l + 20.0 * decades * rng.random_range(-1.0..1.0))
                    .collect();
                judge.at_lambda(&lambda)
            }
            _ => {
                let f: Vec<f64> = (0..cables)
                    .map(|c| rng.random_range(judge.set.lower()[c]..judge.set.upper()[c]))
                    .collect();
                let lambda = judge.set.coordinates(&f);
                judge.at_lambda(&lambda)
            }
        };
        let Some(f) = f else { continue };
        let shrink = 1.0 - 10f64.powf(-rng.random_range(1.0..9.0));
        let Some(f) = judge.pull(requirements, &low, f, shrink) else { continue };
        let Some(v) = judge.value(objective, requirements, &f) else { continue };
        checked += 1;
        assert!(
            !beats(plan, v),
            "{} {}: random {v} beats plan {} (gap {:.1e}) at {f:?}",
            judge.case.name,
            objective.name(),
            plan.value,
            plan.gap
        );
        if best.is_none_or(|b| advantage(objective, v, b) > 0.0) {
            best = Some(v);
        }
    }
    assert!(
        checked >= wanted,
        "{} {}: only {checked} feasible of {tried} (dimension {k})",
        judge.case.name,
        objective.name()
    );
    (checked, best)
}

/// A brute-force grid against the plan. With levels: the whole cube of the free levels (about
/// 8000 points), then a fine grid of half-width 0.01 around the plan's levels; without: grids of
/// 5 points per axis of λ around the plan's λ at half-widths 5, 0.5 and 0.05 N (most leave the
/// limits where the plan sits on some). Budgets as in
/// the random search (pulled to their face). Panics on a point that beats the plan by more
/// than its gap.
fn grid_search(
    judge: &mut Judge<'_>,
    plan: &Plan,
    requirements: &Requirements,
) -> (usize, Option<f64>) {
    let held = &requirements.fixed_levels;
    let low = judge.lowest(held);
    let objective = plan.objective;
    let mut candidates: Vec<Vec<f64>> = Vec::new();
    match &plan.levels {
        Some(at) if judge.levels => {
            let free: Vec<usize> =
                (0..judge.joints()).filter(|j| !held.iter().any(|(h, _)| h == j)).collect();
            let n = (8000f64.powf(1.0 / free.len() as f64).floor() as usize).max(2);
            let centre_free: Vec<f64> = free.iter().map(|&j| at[j]).collect();
            for (centre, half, n) in
                [(vec![0.5; free.len()], 0.5, n), (centre_free, 0.01, n.min(5))]
            {
                for point in grid_points(&centre, half, n) {
                    let mut levels = at.clone();
                    for (&j, s) in free.iter().zip(&point) {
                        levels[j] = s.clamp(0.0, 1.0);
                    }
                    for &(j, s) in held {
                        levels[j] = s;
                    }
                    if let Some(f) = judge.at_levels(&levels) {
                        candidates.push(f);
                    }
                }
            }
        }
        _ => {
            for half in [5.0, 0.5, 0.05] {
                for lambda in grid_points(&plan.lambda, half, 5) {
                    if let Some(f) = judge.at_lambda(&lambda) {
                        candidates.push(f);
                    }
                }
            }
        }
    }
    let (mut evaluated, mut best): (usize, Option<f64>) = (0, None);
    for f in candidates {
        let Some(f) = judge.pull(requirements, &low, f, 1.0 - 1e-9) else { continue };
        let Some(v) = judge.value(objective, requirements, &f) else { continue };
        evaluated += 1;
        assert!(
            !beats(plan, v),
            "{} {}: grid {v} beats plan {} (gap {:.1e}) at {f:?}",
            judge.case.name,
            objective.name(),
            plan.value,
            plan.gap
        );
        if best.is_none_or(|b| advantage(objective, v, b) > 0.0) {
            best = Some(v);
        }
    }
    assert!(evaluated >= 100, "{} {}: {evaluated} grid points", judge.case.name, objective.name());
    (evaluated, best)
}

/// Both searches.
fn search(judge: &mut Judge<'_>, plan: &Plan, requirements: &Requirements, seed: u64) -> Searched {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (random, best_random) = random_search(judge, plan, requirements, 5000, &mut rng);
    let (grid, best_grid) = grid_search(judge, plan, requirements);
    let best = match (best_random, best_grid) {
        (Some(a), Some(b)) => Some(if advantage(plan.objective, a, b) > 0.0 { a } else { b }),
        (a, b) => a.or(b),
    };
    Searched { random, grid, best }
}

/// The plan checked as a candidate would be, by a fresh run of the whole pipeline at its
/// tensions: its value, its margin and floors, limits, budgets and held levels; and its gap
/// between 0 and the relative gap asked for (plus the few ulps the gap adds for rounding).
fn check_candidate(case: &Case, arm: &ArmStiffness, plan: &Plan, requirements: &Requirements) {
    let name = format!("{} {}", case.name, plan.objective.name());
    let mut data = ArmStiffnessData::new(arm);
    let outcome = arm.evaluate(&mut data, &case.q, &case.f0, TensionChoice::Given(&plan.tensions));
    let rank_deficient = matches!(outcome, Err(StiffnessError::RankDeficient { .. }));
    assert!(outcome.is_ok() || (rank_deficient && plan.k_fd.is_none()), "{name}: {outcome:?}");
    let k_fd = data.k_fd();
    let c = data.compliance();
    let value = match plan.objective {
        Objective::StiffnessAlong(u) => u.dot(&(k_fd * u)),
        Objective::ComplianceAlong(u) => u.dot(&(Matrix3::from_fn(|r, k| c[(r, k)]) * u)),
        Objective::MinStiffness => least(&k_fd),
        Objective::Volume => k_fd.determinant().ln(),
        Objective::LeastTension => plan.tensions.iter().sum(),
    };
    assert!(
        (value - plan.value).abs() <= 1e-9 * value.abs(),
        "{name}: plan says {} and the pipeline {value}",
        plan.value
    );
    let margin = data.stability_margin().unwrap();
    assert!(margin >= requirements.margin * (1.0 - 1e-9), "{name}: margin {margin}");
    assert!(
        (margin - plan.min_eigenvalue).abs() <= 1e-9 * margin.abs().max(1.0),
        "{name}: margin {margin}, plan says {}",
        plan.min_eigenvalue
    );
    for (f, [lo, hi]) in plan.tensions.iter().zip(case.routing.cable_limits()) {
        assert!(lo <= f && f <= hi, "{name}: {f} outside [{lo}, {hi}]");
    }
    let total: f64 = plan.tensions.iter().sum();
    assert!((total - plan.total_tension).abs() <= 1e-12 * total, "{name}: total");
    if let Some(b) = requirements.budget {
        assert!(total <= b * (1.0 + 1e-12), "{name}: total {total} > budget {b}");
    }
    for &(j, b) in &requirements.joint_budgets {
        let sum: f64 = plan.tensions[case.routing.cables_of_joint(j)].iter().sum();
        assert!(sum <= b * (1.0 + 1e-12), "{name}: joint {j} sum {sum} > {b}");
    }
    if let Some(k) = requirements.k_min {
        assert!(least(&k_fd) >= k * (1.0 - 1e-9), "{name}: λ_min {} < {k}", least(&k_fd));
    }
    if let Some(k) = requirements.k_des {
        let slack = least(&(k_fd - k));
        assert!(slack >= -1e-9 * least(&k), "{name}: K_fd − K_des has eigenvalue {slack}");
    }
    if !requirements.fixed_levels.is_empty() {
        let levels = plan.levels.as_ref().expect("levels");
        for &(j, s) in &requirements.fixed_levels {
            assert!((levels[j] - s).abs() <= 1e-6, "{name}: level {j} {} not {s}", levels[j]);
        }
    }
    let asked = PlanSettings::default().relative_gap;
    assert!(
        plan.gap >= 0.0
            && plan.gap <= asked * plan.value.abs() + 16.0 * f64::EPSILON * plan.value.abs(),
        "{name}: gap {} for value {} (asked {asked} relative)",
        plan.gap,
        plan.value
    );
}

/// The all-levels-1 value as printed.
fn shown(top: Option<f64>) -> String {
    top.map_or("infeasible (breaks a requirement or does not balance)".to_owned(), |v| {
        v.to_string()
    })
}

/// Prints a case's numbers (`top`: the all-levels-1 value, or why there is none).
fn report(name: &str, plan: &Plan, top: &str, searched: &Searched, started: Instant) {
    println!(
        "{name} {}: plan {} gap {:.2e}; all-levels-1 {top}; {} random, {} grid, best {:?}; {:.2} s",
        plan.objective.name(),
        plan.value,
        plan.gap,
        searched.random,
        searched.grid,
        searched.best,
        started.elapsed().as_secs_f64()
    );
}

/// The objectives of the cdhrm5 cases.
fn objectives() -> [Objective; 2] {
    [Objective::StiffnessAlong(Vector3::y()), Objective::MinStiffness]
}

/// The value of uniform levels `s` (every joint alike) whose total tension is `budget`, by
/// bisection (a level that does not balance, routed, counts as too high): what a planner that
/// only scales the paper's levels would answer.
fn uniform_at_budget(
    judge: &mut Judge<'_>,
    objective: Objective,
    requirements: &Requirements,
) -> Option<f64> {
    let budget = requirements.budget?;
    let n = judge.joints();
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        match judge.at_levels(&vec![mid; n]) {
            Some(f) if f.iter().sum::<f64>() <= budget => lo = mid,
            _ => hi = mid,
        }
    }
    let f = judge.at_levels(&vec![lo; n])?;
    judge.value(objective, requirements, &f)
}

/// A total budget of half the free optimum's total tension: the all-levels-1 point breaks it,
/// the plan spends it all (to 1e-4), and it beats every joint at one common level that spends
/// it. Catches a planner that returns the top of every interval (over budget), one that leaves
/// budget unspent or ignores the budget row, and one that scales every joint's level alike.
#[test]
fn a_binding_total_budget_is_spent_where_it_stiffens_most() {
    for model in cdhrm5::MODELS {
        let case = cdhrm5_case(model);
        let planner = case.planner();
        let mut pdata = PlannerData::new(&planner);
        let arm = planner.arm();
        let mut judge = Judge::new(&case, arm);
        // The two of every case, and (cheap here) the volume and a compliance.
        let more = [Objective::Volume, Objective::ComplianceAlong(Vector3::new(0.6, 0.8, 0.0))];
        for (o, objective) in objectives().into_iter().chain(more).enumerate() {
            let started = Instant::now();
            let free = plan(&case, &planner, &mut pdata, objective, &Requirements::default());
            let budget = 0.5 * free.total_tension;
            let requirements = Requirements { budget: Some(budget), ..Requirements::default() };
            let plan = plan(&case, &planner, &mut pdata, objective, &requirements);
            let name = format!("{} budget {budget:.1} N", case.name);
            check_candidate(&case, arm, &plan, &requirements);
            let (top, v_top) = judge.top(objective, &requirements);
            let top_total = top.map(|f| f.iter().sum::<f64>());
            assert!(
                v_top.is_none() && top_total.is_none_or(|t| t > budget),
                "{name}: levels 1 total {top_total:?}"
            );
            assert!(
                plan.total_tension >= budget * (1.0 - 1e-4),
                "{name}: spends {}",
                plan.total_tension
            );
            let uniform = uniform_at_budget(&mut judge, objective, &requirements);
            println!(
                "{name} {}: free {} (total {}), uniform levels at the budget {uniform:?}",
                objective.name(),
                free.value,
                free.total_tension
            );
            let uniform = uniform.expect("a common level within the budget");
            assert_far_better(&name, &plan, uniform, "uniform levels at the budget");
            let searched = search(&mut judge, &plan, &requirements, 100 + o as u64);
            report(&name, &plan, &shown(v_top), &searched, started);
        }
    }
}

/// The least total tension of one common level `s` for every joint that meets the
/// requirements (a scan of `s` in steps of 0.05, then bisection: the floors grow with `s`
/// here): what a planner that only raises every level alike until the floor holds would
/// answer. None where no common level meets them.
fn uniform_meeting(judge: &mut Judge<'_>, requirements: &Requirements) -> Option<f64> {
    let n = judge.joints();
    let meets = |judge: &mut Judge<'_>, s: f64| {
        let f = judge.at_levels(&vec![s; n])?;
        judge.value(Objective::LeastTension, requirements, &f)
    };
    let first = (0..=20).map(|i| f64::from(i) / 20.0).find(|&s| meets(judge, s).is_some())?;
    let (mut lo, mut hi) = ((first - 0.05).max(0.0), first);
    if lo == hi {
        return meets(judge, hi);
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if meets(judge, mid).is_some() {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    meets(judge, hi)
}

/// Per-joint budgets of 0.6 of the free optimum's sums on joints 1 and 5 (0 and 4): the
/// all-levels-1 point breaks them, the plan spends both to 1e-4. Catches a planner that
/// returns the top of every interval, one that drops or misindexes the per-joint rows (a cap
/// on the wrong joint's cables leaves the capped joint over its budget), and one that leaves
/// a capped joint below its cap.
#[test]
fn binding_joint_budgets_are_spent_to_the_cap() {
    for model in cdhrm5::MODELS {
        let case = cdhrm5_case(model);
        let planner = case.planner();
        let mut pdata = PlannerData::new(&planner);
        let arm = planner.arm();
        let mut judge = Judge::new(&case, arm);
        for (o, objective) in objectives().into_iter().enumerate() {
            let started = Instant::now();
            let free = plan(&case, &planner, &mut pdata, objective, &Requirements::default());
            let sum = |f: &[f64], j: usize| f[case.routing.cables_of_joint(j)].iter().sum::<f64>();
            let caps: Vec<(usize, f64)> =
                [0, 4].iter().map(|&j| (j, 0.6 * sum(&free.tensions, j))).collect();
            let requirements =
                Requirements { joint_budgets: caps.clone(), ..Requirements::default() };
            let plan = plan(&case, &planner, &mut pdata, objective, &requirements);
            let name = format!("{} joint budgets {caps:.1?}", case.name);
            check_candidate(&case, arm, &plan, &requirements);
            let (top, v_top) = judge.top(objective, &requirements);
            assert!(v_top.is_none(), "{name}: levels 1 meet the caps");
            if let Some(top) = &top {
                assert!(caps.iter().any(|&(j, b)| sum(top, j) > b), "{name}: levels 1 under caps");
            }
            for &(j, b) in &caps {
                let spent = sum(&plan.tensions, j);
                assert!(spent >= b * (1.0 - 1e-4), "{name}: joint {j} spends {spent} of {b}");
            }
            let searched = search(&mut judge, &plan, &requirements, 200 + o as u64);
            report(&name, &plan, &shown(v_top), &searched, started);
        }
    }
}

/// Joint 2 (index 1) held at level 0.2, alone and with a binding total budget (half the free
/// optimum's): the all-levels-1 point does not hold it, the plan does (1e-6) and spends the
/// budget. Catches a planner that drops held levels or holds the wrong joint, and, with the
/// budget, one that answers the top of every free interval or spends the budget on the held
/// joint.
#[test]
fn held_levels_are_held_while_the_other_joints_are_optimised() {
    let case = cdhrm5_case(PatternModel::Decoupled);
    let planner = case.planner();
    let mut pdata = PlannerData::new(&planner);
    let arm = planner.arm();
    let mut judge = Judge::new(&case, arm);
    for (o, objective) in objectives().into_iter().enumerate() {
        let free = plan(&case, &planner, &mut pdata, objective, &Requirements::default());
        let held = Requirements { fixed_levels: vec![(1, 0.2)], ..Requirements::default() };
        let budget = Requirements { budget: Some(0.5 * free.total_tension), ..held.clone() };
        for (b, requirements) in [held, budget].into_iter().enumerate() {
            let started = Instant::now();
            let plan = plan(&case, &planner, &mut pdata, objective, &requirements);
            let name = format!("{} held (1, 0.2) budget {:?}", case.name, requirements.budget);
            check_candidate(&case, arm, &plan, &requirements);
            // The top's level of joint 2 is 1, not the 0.2 held: infeasible, whatever its value.
            let (top, v_top) = judge.top(objective, &Requirements::default());
            assert!(top.is_some() && v_top.is_some(), "{name}: levels 1 evaluate");
            assert!(plan.value <= free.value + free.gap, "{name}: holding cannot help");
            if let Some(b) = requirements.budget {
                assert!(
                    plan.total_tension >= b * (1.0 - 1e-4),
                    "{name}: spends {}",
                    plan.total_tension
                );
            }
            let seed = 300 + 2 * o as u64 + b as u64;
            let searched = search(&mut judge, &plan, &requirements, seed);
            report(&name, &plan, "breaks the held level", &searched, started);
        }
    }
}

/// What a least-tension plan under a binding stiffness floor must beat: the top of every
/// interval (decoupled; routed, it does not balance the load at this pose), the least common
/// level that meets the floor, and the random and grid searches; and the least-total tensions
/// must not meet the floor (else it would not bind).
fn judge_least_tension_floor(
    judge: &mut Judge<'_>,
    model: PatternModel,
    plan: &Plan,
    requirements: &Requirements,
    name: &str,
    seed: u64,
    started: Instant,
) {
    let objective = Objective::LeastTension;
    let (top, v_top) = judge.top(objective, requirements);
    match model {
        PatternModel::Decoupled => {
            assert_far_better(name, plan, v_top.expect("levels 1 meet the floor"), "levels 1")
        }
        PatternModel::Routed => assert!(top.is_none(), "{name}: levels 1 balance"),
    }
    let lowest = judge.lowest(&[]);
    assert!(judge.value(objective, requirements, &lowest).is_none(), "{name}: least total meets");
    let uniform = uniform_meeting(judge, requirements);
    println!("{name}: uniform levels {uniform:?}");
    let uniform = uniform.expect("a common level meets the floor");
    assert_far_better(name, plan, uniform, "the least common level");
    let searched = search(judge, plan, requirements, seed);
    report(name, plan, &shown(v_top), &searched, started);
}

/// Least tension with the floor `λ_min(K_fd) ≥ k_min`, 0.8 of the best reachable (at 0.5,
/// decoupled, the stability margin binds first and the floor is slack): the plan's
/// total is far below the all-levels-1 point's (decoupled; routed, that point does not
/// balance) and below the least common level that meets the floor, the floor binds (1e-4) and
/// the least-total tensions break it. Catches a planner that answers the top (too much
/// tension), the least-total tensions (floor broken), or raises every level alike.
#[test]
fn least_tension_meets_a_stiffness_floor_with_equality() {
    for (m, model) in cdhrm5::MODELS.into_iter().enumerate() {
        let case = cdhrm5_case(model);
        let planner = case.planner();
        let mut pdata = PlannerData::new(&planner);
        let arm = planner.arm();
        let mut judge = Judge::new(&case, arm);
        let started = Instant::now();
        let best =
            plan(&case, &planner, &mut pdata, Objective::MinStiffness, &Requirements::default());
        let k_min = 0.8 * best.value;
        let requirements = Requirements { k_min: Some(k_min), ..Requirements::default() };
        let objective = Objective::LeastTension;
        let plan = plan(&case, &planner, &mut pdata, objective, &requirements);
        let name = format!("{} k_min {k_min:.4} N/m", case.name);
        check_candidate(&case, arm, &plan, &requirements);
        let reached = least(&plan.k_fd.unwrap());
        assert!(reached <= k_min * (1.0 + 1e-4), "{name}: λ_min {reached}, floor not binding");
        println!("{name}: λ_min {reached}");
        let seed = 400 + m as u64;
        judge_least_tension_floor(&mut judge, model, &plan, &requirements, &name, seed, started);
    }
}

/// Least tension with `K_fd ⪰ K_des`, half the `K_fd` of the stiffest-least-direction plan:
/// as the floor, with the matrix floor binding (`λ_min(K_fd − K_des)` within 1e-4 of
/// `λ_min(K_des)` of 0). Catches a planner that answers the top, the least-total tensions, a
/// common level, or one that imposes only `K_des`'s diagonal (its answer breaks
/// `K_fd ⪰ K_des`, or the diagonal is out of reach and the plan is refused).
#[test]
fn least_tension_meets_a_desired_stiffness_with_equality() {
    for (m, model) in cdhrm5::MODELS.into_iter().enumerate() {
        let case = cdhrm5_case(model);
        let planner = case.planner();
        let mut pdata = PlannerData::new(&planner);
        let arm = planner.arm();
        let mut judge = Judge::new(&case, arm);
        let started = Instant::now();
        let best =
            plan(&case, &planner, &mut pdata, Objective::MinStiffness, &Requirements::default());
        let k_des = 0.5 * best.k_fd.unwrap();
        let k_des = 0.5 * (k_des + k_des.transpose());
        let requirements = Requirements { k_des: Some(k_des), ..Requirements::default() };
        let objective = Objective::LeastTension;
        let plan = plan(&case, &planner, &mut pdata, objective, &requirements);
        let name = format!("{} K_des", case.name);
        check_candidate(&case, arm, &plan, &requirements);
        let slack = least(&(plan.k_fd.unwrap() - k_des));
        assert!(slack <= 1e-4 * least(&k_des), "{name}: λ_min(K_fd − K_des) {slack}, not binding");
        println!("{name}: λ_min(K_fd − K_des) {slack}");
        let seed = 500 + m as u64;
        judge_least_tension_floor(&mut judge, model, &plan, &requirements, &name, seed, started);
    }
}

/// cdhrm5's links with its pattern (decoupled or routed) written out cable by cable, but every
/// distal hole ABOVE the joint centre (the pattern's sit on it; the proximal holes stay on the
/// disc 30 mm below): 2 mm and limits [20, 200] N decoupled, 1 mm and [20, 120] N routed (whose
/// cables cross, and soften, every joint before their own). A cable through holes a below and b
/// above the centre has `∂²L/∂θ² = −ab/(a+b)` at θ = 0 in both bending directions: tension
/// then softens the joint, while at the loaded pose the pattern's own curvature stiffens one
/// direction. So `A_i` is indefinite and more tension is not stiffer.
fn softening_case(model: PatternModel) -> Case {
    let robot = cdhrm5::robot().with_gravity(Vector3::zeros());
    let (proximal, distal) = (cdhrm5::proximal_discs(5), cdhrm5::distal_discs(5));
    let (free_length, above, most) = match model {
        PatternModel::Decoupled => ("[3.2128, 3.4628, 3.7128, 3.9628, 4.2128]", 0.002, 200.0),
        PatternModel::Routed => ("3.2128", 0.001, 120.0),
    };
    let mut text = format!(
        "tension_limits = [20.0, {most:.1}]\nfree_length = {free_length}\n\
         [material]\nyoungs_modulus = 12.5e9\ndiameter = 1.0e-3\n",
    );
    for i in 0..5 {
        for k in 0..3 {
            let theta = cdhrm5::THETA0
                + std::f64::consts::TAU * f64::from(k) / 3.0
                + i as f64 * cdhrm5::JOINT_OFFSET;
            let (x, y) = (cdhrm5::HOLE_RADIUS * theta.cos(), cdhrm5::HOLE_RADIUS * theta.sin());
            let hole = |link: &str, z: f64| {
                format!("  {{ link = \"{link}\", point = [{x}, {y}, {z}] }},\n")
            };
            // Decoupled: the proximal disc of its joint, then its anchor. Routed: from the base,
            // through both discs of every joint before its own (the pattern's order).
            let first = match model {
                PatternModel::Decoupled => i,
                PatternModel::Routed => 0,
            };
            text +=
                &format!("[[cable]]\nname = \"j{}c{}\"\njoint = {i}\nholes = [\n", i + 1, k + 1);
            text += &hole(&proximal[first], 0.0);
            for m in first..i {
                text += &hole(&distal[m], above);
                text += &hole(&proximal[m + 1], 0.0);
            }
            text += &hole(&distal[i], above);
            text += "]\n";
        }
    }
    let name = format!("softening cdhrm5 {model:?}");
    let spec = RoutingSpec::from_toml_str(&text, &name).unwrap();
    let routing = Routing::new(&robot, &spec, &name).unwrap();
    assert_eq!(routing.is_decoupled(), model == PatternModel::Decoupled, "{name}");
    Case {
        name,
        robot,
        routing,
        q: cdhrm5::LOADED_POSE.to_vec(),
        // Weightless with a light tip load: the softened arm is stable at every level
        // (under gravity and 5 N it is stable at none).
        f0: Vector6::new(0.0, 0.5, 0.0, 0.0, 0.0, 0.0),
    }
}

/// A robot whose tension softens its joints: first that some `A_i = ∂K_q/∂λ_i` (the pipeline's
/// [`ArmStiffness::stiffness_slope`]) is indefinite, then that each plan is not the
/// all-levels-1 point (which is stable and feasible here) and beats it by far more than its
/// gap, and that the optima found inside the cube of levels (decoupled: the least stiffness,
/// the volume and the compliance along y; routed: the stiffness along y and the least
/// stiffness) beat every corner of it by far more than their gap. Both models. Catches a
/// planner that assumes more tension is stiffer (answers the top of every interval) and one
/// that searches only the corners of the levels (bang-bang, as an LP would).
#[test]
fn where_tension_softens_the_joints_the_optimum_is_not_the_top() {
    let (along_y, compliance_y) =
        (Objective::StiffnessAlong(Vector3::y()), Objective::ComplianceAlong(Vector3::y()));
    // Where each optimum is interior (elsewhere it is a corner that is not the top).
    let decoupled = [Objective::MinStiffness, Objective::Volume, compliance_y];
    softening(&softening_case(PatternModel::Decoupled), 600, &decoupled);
    softening(&softening_case(PatternModel::Routed), 610, &[along_y, Objective::MinStiffness]);
}

/// The checks of one softening arm; `interior`: the objectives whose optimum lies inside the
/// cube of levels.
fn softening(case: &Case, seed: u64, interior: &[Objective]) {
    let planner = case.planner();
    let mut pdata = PlannerData::new(&planner);
    let arm = planner.arm();
    assert!(arm.statics().has_levels());
    let mut judge = Judge::new(case, arm);
    judge.at_levels(&[0.5; 5]).unwrap();
    let mut indefinite = 0;
    for joint in 0..5 {
        let mut slope = faer::Mat::<f64>::zeros(10, 10);
        arm.stiffness_slope(&mut judge.data, joint, slope.as_mut()).unwrap();
        let e = slope.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
        let (lo, hi) = (e[0], e[e.len() - 1]);
        println!("{}: A_{joint} eigenvalues from {lo:.3e} to {hi:.3e}", case.name);
        if lo < 0.0 && hi > 0.0 {
            indefinite += 1;
        }
    }
    assert!(indefinite >= 3, "{indefinite} indefinite A_i");
    let corners: Vec<Vec<f64>> =
        (0..32).map(|m| (0..5).map(|j| f64::from((m >> j) & 1)).collect()).collect();
    let requirements = Requirements::default();
    let objectives = [
        Objective::StiffnessAlong(Vector3::y()),
        Objective::MinStiffness,
        Objective::Volume,
        Objective::ComplianceAlong(Vector3::y()),
    ];
    for (o, objective) in objectives.into_iter().enumerate() {
        let started = Instant::now();
        let plan = plan(case, &planner, &mut pdata, objective, &requirements);
        let name = case.name.clone();
        check_candidate(case, arm, &plan, &requirements);
        let (_, v_top) = judge.top(objective, &requirements);
        let v_top = v_top.expect("levels 1 are stable here");
        assert_far_better(&name, &plan, v_top, "levels 1");
        let levels = plan.levels.clone().unwrap();
        assert!(levels.iter().any(|&s| s < 0.5), "{name} {}: {levels:?}", objective.name());
        let mut best_corner: Option<f64> = None;
        for corner in &corners {
            let f = judge.at_levels(corner).unwrap();
            if let Some(v) = judge.value(objective, &requirements, &f)
                && best_corner.is_none_or(|b| advantage(objective, v, b) > 0.0)
            {
                best_corner = Some(v);
            }
        }
        println!("{name} {}: levels {levels:.4?}, best corner {best_corner:?}", objective.name());
        if interior.contains(&objective) {
            assert!(levels.iter().any(|&s| (0.01..0.99).contains(&s)), "{name}: {levels:?}");
            assert_far_better(&name, &plan, best_corner.unwrap(), "every corner of the levels");
        }
        let searched = search(&mut judge, &plan, &requirements, seed + o as u64);
        report(&name, &plan, &v_top.to_string(), &searched, started);
    }
}

/// The robots beyond the closed form: ua3x4 (four cables per universal joint, a 6-dimensional
/// equilibrium set) and the planar snake (shared cable, 1-DOF joints, `J_x` of rank 3 so no
/// `K_fd`: the compliance along y in its bending plane, and least tension with a margin). No
/// levels there, so checks 2 and 3 only: random tensions over the box of λ and around the
/// plan's λ, grids around it, and the pipeline at the plan. Catches a planner whose general
/// path (no levels, cables crossing joints) answers a point that is not optimal, not
/// balanced, or not what the pipeline says.
#[test]
fn plans_on_ua3x4_and_the_planar_snake_survive_the_searches() {
    let load = |name: &str, q: Vec<f64>| {
        let dir = cdhrm5::workspace_root().join("robots").join(name);
        let robot = sinew_robot::load(&dir).unwrap();
        let routing = sinew_routing::load(&dir, &robot).unwrap();
        let f0 = Vector6::new(0.0, 2.0, 0.0, 0.0, 0.0, 0.0);
        Case { name: name.to_owned(), robot, routing, q, f0 }
    };
    let ua = load("ua3x4", vec![0.2, -0.3, 0.25, 0.1, -0.15, 0.3]);
    let snake = load("planar-snake", vec![0.3, -0.2, 0.25, -0.1]);
    let margin = Requirements { margin: 0.2, ..Requirements::default() };
    let cases = [
        (&ua, Objective::StiffnessAlong(Vector3::y()), Requirements::default()),
        (&ua, Objective::MinStiffness, Requirements::default()),
        (&snake, Objective::ComplianceAlong(Vector3::y()), Requirements::default()),
        (&snake, Objective::LeastTension, margin),
    ];
    for (c, (case, objective, requirements)) in cases.into_iter().enumerate() {
        let started = Instant::now();
        let planner = case.planner();
        let mut pdata = PlannerData::new(&planner);
        let arm = planner.arm();
        assert!(!arm.statics().has_levels(), "{}: levels", case.name);
        let plan = plan(case, &planner, &mut pdata, objective, &requirements);
        check_candidate(case, arm, &plan, &requirements);
        let mut judge = Judge::new(case, arm);
        let searched = search(&mut judge, &plan, &requirements, 700 + c as u64);
        report(&case.name, &plan, "none (no levels)", &searched, started);
    }
}
