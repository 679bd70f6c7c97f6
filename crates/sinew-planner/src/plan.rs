//! The planner: the model ([`Planner`]), its workspace ([`PlannerData`]), the objectives and
//! constraints, and the answer with its certificate ([`Plan`]).

use faer::Mat;
use nalgebra::{Matrix3, Vector3, Vector6};
use sinew_statics::{EquilibriumSet, TensionChoice, TensionPolicy};
use sinew_stiffness::{ArmStiffness, ArmStiffnessData};

use crate::bundle::{self, Cut, Evaluation, Linear, Outcome, Settings};
use crate::error::PlanError;
use crate::pencil::{End, Pencil};

/// What to optimise (one per plan).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Objective {
    /// Maximise `uᵀ K_fd u`: the stiffness along the unit direction `u` with the end's
    /// rotation held (`K_fd = K_x[0:3, 0:3]`, eq. 21).
    StiffnessAlong(Vector3<f64>),
    /// Minimise `uᵀ C_x[0:3, 0:3] u`: the compliance along `u` with rotations free (how far the
    /// end moves along `u` per newton along `u`). Defined also where `K_x` is not (a planar
    /// arm); the value reported is the compliance, m/N.
    ComplianceAlong(Vector3<f64>),
    /// Maximise `λ_min(K_fd)`: the softest direction made as stiff as possible.
    MinStiffness,
    /// Maximise `log det K_fd`: the smallest deformation ellipsoid.
    Volume,
    /// Minimise the total tension `Σ f` subject to [`Requirements`].
    LeastTension,
}

impl Objective {
    /// The name the command line and the JSON use.
    pub fn name(&self) -> &'static str {
        match self {
            Objective::StiffnessAlong(_) => "stiffness-along",
            Objective::ComplianceAlong(_) => "compliance-along",
            Objective::MinStiffness => "min-stiffness",
            Objective::Volume => "volume",
            Objective::LeastTension => "least-tension",
        }
    }
}

/// Constraints of every plan, besides exact equilibrium (by construction) and the tension
/// limits (always).
#[derive(Debug, Clone, PartialEq)]
pub struct Requirements {
    /// Stability margin `λ_min(K_q + K_W) ≥ margin`, N m/rad (> 0: the arm must be stable).
    pub margin: f64,
    /// Total tension `Σ f ≤ budget`, N.
    pub budget: Option<f64>,
    /// `λ_min(K_fd) ≥ k_min`, N/m.
    pub k_min: Option<f64>,
    /// `K_fd ⪰ K_des` (symmetric positive definite), N/m.
    pub k_des: Option<Matrix3<f64>>,
    /// Per-joint budgets `(joint, B)`: the tensions of the cables that drive `joint`
    /// (0-based, [`sinew_routing::Routing::cables_of_joint`]) sum to at most `B`, N.
    pub joint_budgets: Vec<(usize, f64)>,
    /// Joints held at a given tension level `(joint, s)`, `s ∈ [0, 1]` (the paper's levels: the
    /// closed form, decoupled model only: there a joint's own tensions at a level do not depend
    /// on the others).
    pub fixed_levels: Vec<(usize, f64)>,
}

impl Default for Requirements {
    fn default() -> Self {
        Requirements {
            margin: DEFAULT_MARGIN,
            budget: None,
            k_min: None,
            k_des: None,
            joint_budgets: Vec::new(),
            fixed_levels: Vec::new(),
        }
    }
}

/// The default stability margin, N m/rad.
pub const DEFAULT_MARGIN: f64 = 1e-3;

/// The default relative gap at which a plan stops.
pub const DEFAULT_GAP: f64 = 1e-6;

/// How a plan stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanSettings {
    /// Stop when the certified gap is at most this fraction of the value.
    pub relative_gap: f64,
    /// Give up (with [`PlanError::NotConverged`]) after this many iterations.
    pub max_iterations: usize,
}

impl Default for PlanSettings {
    fn default() -> Self {
        PlanSettings { relative_gap: DEFAULT_GAP, max_iterations: 2000 }
    }
}

/// A certified answer.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The objective.
    pub objective: Objective,
    /// Its value at the answer: `uᵀ K_fd u` (N/m), `uᵀ C_x u` (m/N), `λ_min(K_fd)` (N/m),
    /// `log det K_fd` (ln of (N/m)³) or `Σ f` (N).
    pub value: f64,
    /// The certificate: the true optimum is at most `gap` better than `value` (same unit).
    pub gap: f64,
    /// The coordinates `λ` of the tensions in the equilibrium set.
    pub lambda: Vec<f64>,
    /// The tensions (m, N, routing order): balance to rounding, limits exact.
    pub tensions: Vec<f64>,
    /// `Σ f`, N.
    pub total_tension: f64,
    /// The paper's tension levels of these tensions (one per joint, in `[0, 1]`), where the
    /// closed form applies (three cables per universal joint).
    pub levels: Option<Vec<f64>>,
    /// `K_fd` at the answer, N/m (`None` when `J_x` has rank < 6).
    pub k_fd: Option<Matrix3<f64>>,
    /// `C_x` at the answer (6 × 6).
    pub c_x: nalgebra::Matrix6<f64>,
    /// `λ_min(K_q + K_W)` at the answer, N m/rad.
    pub min_eigenvalue: f64,
    /// Iterations of the method (both phases).
    pub iterations: usize,
}

/// The planner's model: the arm (robot, routing, statics). Immutable; one [`PlannerData`] per
/// thread.
#[derive(Debug, Clone)]
pub struct Planner {
    arm: ArmStiffness,
}

/// The planner's workspace.
#[derive(Debug)]
pub struct PlannerData {
    stiffness: ArmStiffnessData,
}

impl PlannerData {
    /// A workspace for `planner`.
    pub fn new(planner: &Planner) -> PlannerData {
        PlannerData { stiffness: ArmStiffnessData::new(&planner.arm) }
    }

    /// The stiffness workspace of the last plan (the arm evaluated at its tensions).
    pub fn stiffness(&self) -> &ArmStiffnessData {
        &self.stiffness
    }
}

impl Planner {
    /// The planner of an arm.
    pub fn new(arm: ArmStiffness) -> Planner {
        Planner { arm }
    }

    /// The arm.
    pub fn arm(&self) -> &ArmStiffness {
        &self.arm
    }

    /// The tensions that optimise `objective` at pose `q` under the force `f0` (base frame,
    /// the end's wrench; its moment must be zero) and gravity, with `requirements`, certified
    /// to `settings.relative_gap`.
    ///
    /// # Errors
    /// [`PlanError::NonConservativeLoad`] for a moment in `f0`; [`PlanError::InvalidInput`];
    /// infeasible loads ([`PlanError::Statics`]); [`PlanError::NoStableTensions`],
    /// [`PlanError::RequirementUnreachable`], [`PlanError::BudgetTooSmall`] when no tensions
    /// meet the requirements, with the best reachable; [`PlanError::NoEndStiffness`];
    /// [`PlanError::NotConverged`]; [`PlanError::Solver`].
    pub fn plan(
        &self,
        data: &mut PlannerData,
        q: &[f64],
        f0: &Vector6<f64>,
        objective: Objective,
        requirements: &Requirements,
        settings: &PlanSettings,
    ) -> Result<Plan, PlanError> {
        check_inputs(f0, objective, requirements, settings)?;
        let arm = &self.arm;
        let joints = arm.routing().joint_count();
        if let Some(&(joint, _)) = requirements.joint_budgets.iter().find(|(j, _)| *j >= joints) {
            return Err(PlanError::InvalidInput {
                what: "joint_budget",
                problem: format!("joint {} does not exist: the arm has {joints} joints", joint + 1),
            });
        }
        let sd = &mut data.stiffness;
        let fixed = self.fixed_tensions(sd, q, f0, requirements)?;
        // The least-total tensions: geometry, T0, K_W at the pose, and whether any tensions
        // balance the load (a typed infeasibility naming the joint otherwise).
        arm.joint_level_with(sd, q, f0, TensionChoice::Policy(TensionPolicy::LeastTotal))?;
        let set = arm.equilibrium_set(sd)?;
        let least_total: f64 = sd.tensions().iter().sum();
        let least_total_lambda = set.coordinates(sd.tensions());
        if let Some(budget) = requirements.budget
            && least_total > budget * (1.0 + 1e-12)
        {
            return Err(PlanError::BudgetTooSmall { budget, least: least_total });
        }
        let pencil = self.pencil(sd, &set)?;
        let k = set.dimension();
        let mut linear =
            linear_rows(&set, requirements.budget, &self.joint_budget_rows(requirements));
        fix_rows(&set, &fixed, &mut linear);
        let linear = linear.merged();
        // A start inside the limits (and the budget): the safest tensions when within the
        // budget, else the least-total ones.
        arm.joint_level_with(sd, q, f0, TensionChoice::Policy(TensionPolicy::Safest))?;
        let safest_lambda = set.coordinates(sd.tensions());
        let safest_total: f64 = sd.tensions().iter().sum();
        let start = match requirements.budget {
            Some(b) if safest_total > b => least_total_lambda,
            _ => safest_lambda,
        };
        // Per-joint budgets: a start meeting them too, or the proof that none does.
        let start = if linear.satisfied(&start) {
            start
        } else {
            bundle::feasible_point(k, &linear)?.ok_or(PlanError::BudgetsInfeasible)?
        };
        // Σ f = Σ f_p + (Nᵀ 1)ᵀ λ: its constant and gradient, once per plan.
        let sums = column_sums(&set);
        let particular_total: f64 = set.particular().iter().sum();
        let negated_sums: Vec<f64> = sums.iter().map(|s| -s).collect();
        let total_of = |lambda: &[f64]| particular_total + bundle::dot(&sums, lambda);
        let scale = pencil_scale(&pencil);
        // Phase 1: a stable point (margin ≥ ε), by maximising the margin.
        let margin = requirements.margin;
        let mut iterations = 0;
        let (margin0, _) = pencil.margin(&start)?;
        let mut start = start;
        if margin0 < margin && k == 0 {
            return Err(PlanError::NoStableTensions {
                margin,
                best: margin0,
                budget: requirements.budget.is_some(),
            });
        }
        if margin0 < margin {
            let outcome = bundle::maximise(
                |l| {
                    let (value, gradient) = pencil.margin(l)?;
                    Ok(Evaluation {
                        objective: Some(Cut { at: l.to_vec(), value, gradient }),
                        constraints: Vec::new(),
                    })
                },
                &linear,
                &start,
                Settings {
                    relative_gap: 1e-9,
                    scale,
                    max_iterations: settings.max_iterations,
                    target: Some(margin),
                },
            );
            match outcome {
                Ok(Outcome::Reached { lambda, iterations: i, .. }) => {
                    start = lambda;
                    iterations += i;
                }
                Ok(Outcome::Unreachable { upper }) => {
                    return Err(PlanError::NoStableTensions {
                        margin,
                        best: upper,
                        budget: requirements.budget.is_some(),
                    });
                }
                Ok(Outcome::Optimum { value, upper, .. }) => {
                    if value < margin {
                        return Err(PlanError::NoStableTensions {
                            margin,
                            best: upper,
                            budget: requirements.budget.is_some(),
                        });
                    }
                }
                Ok(Outcome::Infeasible) => {
                    return Err(PlanError::NoStableTensions {
                        margin,
                        best: f64::NEG_INFINITY,
                        budget: requirements.budget.is_some(),
                    });
                }
                Err(e) => return Err(e),
            }
        }
        // Phase 1b (least tension): a point meeting the stiffness requirements.
        let k_des_scale = requirements.k_des.map(|k| k.cholesky().map(|c| c.l()));
        let k_des_scale = match k_des_scale {
            Some(Some(l)) => Some(l),
            Some(None) => {
                return Err(PlanError::InvalidInput {
                    what: "--k-des",
                    problem: "K_des must be symmetric positive definite".into(),
                });
            }
            None => None,
        };
        let stiffness_requirements = |end: &End| -> Option<Vec<(Cut, f64)>> {
            let mut cuts = Vec::new();
            if let Some(k_min) = requirements.k_min {
                let (value, gradient) = end.least_stiffness(&pencil, None)?;
                cuts.push((Cut { at: Vec::new(), value, gradient }, k_min));
            }
            if let Some(l) = &k_des_scale {
                let (value, gradient) = end.least_stiffness(&pencil, Some(l))?;
                cuts.push((Cut { at: Vec::new(), value, gradient }, 1.0));
            }
            Some(cuts)
        };
        let evaluate = |l: &[f64]| -> Result<Evaluation, PlanError> {
            let (m, mg) = pencil.margin(l)?;
            let mut constraints = vec![(Cut { at: l.to_vec(), value: m, gradient: mg }, margin)];
            let Some(end) = pencil.end(l) else {
                return Ok(Evaluation { objective: None, constraints });
            };
            if let Some(cuts) = stiffness_requirements(&end) {
                constraints.extend(cuts.into_iter().map(|(mut c, b)| {
                    c.at = l.to_vec();
                    (c, b)
                }));
            } else if requirements.k_min.is_some() || requirements.k_des.is_some() {
                return Err(PlanError::NoEndStiffness);
            }
            let value = match objective {
                Objective::StiffnessAlong(u) => {
                    let w = Vector6::new(u.x, u.y, u.z, 0.0, 0.0, 0.0);
                    end.stiffness_form(&pencil, &w).ok_or(PlanError::NoEndStiffness)?
                }
                Objective::ComplianceAlong(u) => end.compliance_form(&pencil, &u),
                Objective::MinStiffness => {
                    end.least_stiffness(&pencil, None).ok_or(PlanError::NoEndStiffness)?
                }
                Objective::Volume => end.log_volume(&pencil).ok_or(PlanError::NoEndStiffness)?,
                Objective::LeastTension => (-total_of(l), negated_sums.clone()),
            };
            Ok(Evaluation {
                objective: Some(Cut { at: l.to_vec(), value: value.0, gradient: value.1 }),
                constraints,
            })
        };
        if requirements.k_min.is_some() || requirements.k_des.is_some() {
            // Maximise the least scaled slack of the stiffness requirements (with the margin
            // kept) until it is ≥ 0.
            let phase = bundle::maximise(
                |l| {
                    let mut e = evaluate(l)?;
                    let slack = e
                        .constraints
                        .iter()
                        .skip(1)
                        .map(|(c, b)| (c.value - b, c.gradient.clone(), b.abs().max(1.0)))
                        .min_by(|a, b| (a.0 / a.2).total_cmp(&(b.0 / b.2)));
                    e.objective = match (&e.objective, slack) {
                        (Some(_), Some((s, g, n))) => Some(Cut {
                            at: l.to_vec(),
                            value: s / n,
                            gradient: g.iter().map(|x| x / n).collect(),
                        }),
                        _ => None,
                    };
                    e.constraints.truncate(1);
                    Ok(e)
                },
                &linear,
                &start,
                Settings {
                    relative_gap: 1e-9,
                    scale: 1.0,
                    max_iterations: settings.max_iterations,
                    target: Some(0.0),
                },
            )?;
            match phase {
                Outcome::Reached { lambda, iterations: i, .. } => {
                    start = lambda;
                    iterations += i;
                }
                Outcome::Unreachable { upper } | Outcome::Optimum { upper, .. } => {
                    let (what, required) = match requirements.k_min {
                        Some(k) => ("least stiffness λ_min(K_fd), N/m,", k),
                        None => ("K_fd ⪰ K_des (scaled least eigenvalue)", 1.0),
                    };
                    let best = match requirements.k_min {
                        Some(k) => k + upper * k.abs().max(1.0),
                        None => 1.0 + upper,
                    };
                    return Err(PlanError::RequirementUnreachable { what, required, best });
                }
                Outcome::Infeasible => {
                    return Err(PlanError::NoStableTensions {
                        margin,
                        best: f64::NEG_INFINITY,
                        budget: requirements.budget.is_some(),
                    });
                }
            }
        }
        let outcome = bundle::maximise(
            evaluate,
            &linear,
            &start,
            Settings {
                relative_gap: settings.relative_gap,
                scale: objective_scale(objective, scale, least_total),
                max_iterations: settings.max_iterations,
                target: None,
            },
        )?;
        let (lambda, value, upper, i) = match outcome {
            Outcome::Optimum { lambda, value, upper, iterations } => {
                (lambda, value, upper, iterations)
            }
            Outcome::Reached { .. } | Outcome::Unreachable { .. } | Outcome::Infeasible => {
                return Err(PlanError::NoStableTensions {
                    margin,
                    best: f64::NEG_INFINITY,
                    budget: requirements.budget.is_some(),
                });
            }
        };
        iterations += i;
        // The answer, evaluated by the pipeline itself at its tensions.
        let mut tensions = vec![0.0; set.cable_count()];
        set.tensions(&lambda, &mut tensions)?;
        for (f, (lo, hi)) in tensions.iter_mut().zip(set.lower().iter().zip(set.upper())) {
            *f = f.clamp(*lo, *hi);
        }
        let outcome = arm.evaluate_with(sd, q, f0, TensionChoice::Given(&tensions));
        match outcome {
            Ok(()) | Err(sinew_stiffness::StiffnessError::RankDeficient { .. }) => {}
            Err(e) => return Err(e.into()),
        }
        let min_eigenvalue = sd.stability_margin()?;
        let end = pencil.end(&lambda).ok_or(PlanError::NoStableTensions {
            margin,
            best: min_eigenvalue,
            budget: requirements.budget.is_some(),
        })?;
        let (value, gap) = match objective {
            Objective::ComplianceAlong(_) => (-value, upper - value),
            Objective::LeastTension => (-value, upper - value),
            _ => (value, upper - value),
        };
        let levels = arm.statics().levels_of(&sd.cables, &sd.statics, &tensions).ok();
        Ok(Plan {
            objective,
            value,
            gap: gap.max(0.0),
            total_tension: tensions.iter().sum(),
            lambda,
            tensions,
            levels,
            k_fd: end.k_fd(),
            c_x: end.c_x,
            min_eigenvalue,
            iterations,
        })
    }

    /// The own tensions of every joint held at a level: `(cables, tensions)`.
    fn fixed_tensions(
        &self,
        sd: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
        requirements: &Requirements,
    ) -> Result<Vec<HeldTensions>, PlanError> {
        if requirements.fixed_levels.is_empty() {
            return Ok(Vec::new());
        }
        let arm = &self.arm;
        let joints = arm.routing().joint_count();
        if !(arm.statics().has_levels() && arm.routing().is_decoupled()) {
            return Err(PlanError::InvalidInput {
                what: "fixed_level",
                problem: "fixed tension levels need the paper's closed form in the decoupled model (three cables per universal joint, each crossing only its joint)".into(),
            });
        }
        let mut levels = vec![0.0; joints];
        for &(joint, s) in &requirements.fixed_levels {
            if joint >= joints || !(0.0..=1.0).contains(&s) {
                return Err(PlanError::InvalidInput {
                    what: "fixed_level",
                    problem: format!(
                        "joint {} at level {s}: joints are 1 to {joints}, levels in [0, 1]",
                        joint + 1
                    ),
                });
            }
            levels[joint] = s;
        }
        arm.joint_level(sd, q, f0, &levels)?;
        let routing = arm.routing();
        Ok(requirements
            .fixed_levels
            .iter()
            .map(|&(joint, _)| {
                let cables = routing.cables_of_joint(joint);
                (cables.clone(), sd.tensions()[cables].to_vec())
            })
            .collect())
    }

    /// Each per-joint budget as `(cables of the joint, B)`.
    fn joint_budget_rows(&self, requirements: &Requirements) -> Vec<(std::ops::Range<usize>, f64)> {
        let routing = self.arm.routing();
        requirements.joint_budgets.iter().map(|&(j, b)| (routing.cables_of_joint(j), b)).collect()
    }

    /// `A_0` and the `A_i` at the last joint-level evaluation in `sd`.
    fn pencil(&self, sd: &mut ArmStiffnessData, set: &EquilibriumSet) -> Result<Pencil, PlanError> {
        let routing = self.arm.routing();
        let dof = self.arm.dof();
        let mut a0 = Mat::<f64>::zeros(dof, dof);
        sd.cables.add_weighted_hessians(routing, set.particular(), a0.as_mut())?;
        let k_inherent = sd.k_inherent().to_owned();
        let k_w = sd.k_w().to_owned();
        for r in 0..dof {
            for c in 0..dof {
                a0[(r, c)] += k_inherent[(r, c)] + k_w[(r, c)];
            }
        }
        let null = set.null_basis();
        let mut ai = Vec::with_capacity(set.dimension());
        let mut weights = vec![0.0; set.cable_count()];
        for i in 0..set.dimension() {
            for (c, w) in weights.iter_mut().enumerate() {
                *w = null[(c, i)];
            }
            let mut a = Mat::<f64>::zeros(dof, dof);
            sd.cables.add_weighted_hessians(routing, &weights, a.as_mut())?;
            ai.push(a);
        }
        Ok(Pencil { a0, ai, j_x: sd.j_x().to_owned() })
    }
}

fn check_inputs(
    f0: &Vector6<f64>,
    objective: Objective,
    requirements: &Requirements,
    settings: &PlanSettings,
) -> Result<(), PlanError> {
    let bad = |what, problem: &str| Err(PlanError::InvalidInput { what, problem: problem.into() });
    if !f0.iter().all(|v| v.is_finite()) {
        return bad("wrench", "has a NaN or infinite component");
    }
    if f0[3] != 0.0 || f0[4] != 0.0 || f0[5] != 0.0 {
        return Err(PlanError::NonConservativeLoad { moment: [f0[3], f0[4], f0[5]] });
    }
    if let Objective::StiffnessAlong(u) | Objective::ComplianceAlong(u) = objective {
        let n = u.norm();
        if !(n.is_finite() && (n - 1.0).abs() <= 1e-9) {
            return bad("direction", "must be a finite unit vector");
        }
    }
    if !(requirements.margin.is_finite() && requirements.margin > 0.0) {
        return bad("margin", "must be finite and > 0 N m/rad (the arm must be stable)");
    }
    if let Some(b) = requirements.budget
        && !(b.is_finite() && b >= 0.0)
    {
        return bad("budget", "must be finite and ≥ 0 N");
    }
    if let Some(k) = requirements.k_min
        && !k.is_finite()
    {
        return bad("k_min", "must be finite");
    }
    if requirements.joint_budgets.iter().any(|(_, b)| !(b.is_finite() && *b >= 0.0)) {
        return bad("joint_budget", "must be finite and ≥ 0 N");
    }
    if let Some(k) = requirements.k_des {
        let symmetric = (k - k.transpose()).abs().max() <= 1e-9 * k.abs().max().max(1.0);
        if !(k.iter().all(|v| v.is_finite()) && symmetric && k.cholesky().is_some()) {
            return bad("k_des", "must be symmetric positive definite");
        }
    }
    if !(settings.relative_gap.is_finite() && settings.relative_gap > 0.0) {
        return bad("gap", "must be finite and > 0");
    }
    Ok(())
}

/// `Nᵀ 1`: how the total tension changes per unit of each `λ`.
fn column_sums(set: &EquilibriumSet) -> Vec<f64> {
    let null = set.null_basis();
    (0..set.dimension()).map(|i| (0..set.cable_count()).map(|c| null[(c, i)]).sum()).collect()
}

/// The limits `f_min ≤ f_p + N λ ≤ f_max`, the budget `Σ f ≤ B` and the per-joint budgets
/// `Σ_{c ∈ cables} f_c ≤ B_j` as rows in `λ`.
fn linear_rows(
    set: &EquilibriumSet,
    budget: Option<f64>,
    joint_budgets: &[(std::ops::Range<usize>, f64)],
) -> Linear {
    let null = set.null_basis();
    let (m, k) = (set.cable_count(), set.dimension());
    let p = set.particular();
    let mut linear = Linear::default();
    for c in 0..m {
        let row: Vec<f64> = (0..k).map(|i| null[(c, i)]).collect();
        linear.rhs.push(set.upper()[c] - p[c]);
        linear.rows.push(row.clone());
        linear.rhs.push(p[c] - set.lower()[c]);
        linear.rows.push(row.iter().map(|v| -v).collect());
    }
    if let Some(b) = budget {
        linear.rows.push(column_sums(set));
        linear.rhs.push(b - p.iter().sum::<f64>());
    }
    for (cables, b) in joint_budgets {
        linear.rows.push((0..k).map(|i| cables.clone().map(|c| null[(c, i)]).sum()).collect());
        linear.rhs.push(b - cables.clone().map(|c| p[c]).sum::<f64>());
    }
    linear
}

/// A joint held at a level: its cables and their tensions there.
type HeldTensions = (std::ops::Range<usize>, Vec<f64>);

/// Hold each fixed joint's own tensions: its null coordinate (the one column of `N` on its
/// cables, decoupled) fixed to the value that gives them, as two rows a rounding apart.
fn fix_rows(
    set: &EquilibriumSet,
    fixed: &[(std::ops::Range<usize>, Vec<f64>)],
    linear: &mut Linear,
) {
    let null = set.null_basis();
    let k = set.dimension();
    let p = set.particular();
    for (cables, target) in fixed {
        let Some(column) = (0..k).find(|&i| cables.clone().any(|c| null[(c, i)].abs() > 0.5))
        else {
            continue;
        };
        let value: f64 =
            cables.clone().zip(target).map(|(c, t)| null[(c, column)] * (t - p[c])).sum();
        let tol = 1e-9 * (1.0 + value.abs());
        let mut up = vec![0.0; k];
        up[column] = 1.0;
        linear.rows.push(up);
        linear.rhs.push(value + tol);
        let mut down = vec![0.0; k];
        down[column] = -1.0;
        linear.rows.push(down);
        linear.rhs.push(tol - value);
    }
}

/// A stiffness scale of the pencil (N m/rad), for absolute floors of the gaps.
fn pencil_scale(pencil: &Pencil) -> f64 {
    let n = pencil.a0.nrows();
    (0..n).map(|i| pencil.a0[(i, i)].abs()).fold(0.0, f64::max).max(1e-9)
}

fn objective_scale(objective: Objective, pencil_scale: f64, least_total: f64) -> f64 {
    match objective {
        Objective::LeastTension => least_total.abs().max(1.0),
        Objective::Volume => 1.0,
        _ => 1e-12 * pencil_scale.max(1.0),
    }
}
