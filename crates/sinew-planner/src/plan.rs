//! The planner: the model ([`Planner`]) and its workspace ([`PlannerData`]). A plan runs the
//! stiffness pipeline's pose stage once (geometry, `T0`, `K_W`, `J_x`, the equilibrium set) and
//! then works on tensions only: two policy tension stages for its start, the pencil
//! `A(λ)` built from the pose's workspace, the phases ([`crate::phases`]), and the answer
//! re-evaluated by one more tension stage and the end stage.

use nalgebra::{Matrix6, Vector6};
use sinew_statics::{EquilibriumSet, TensionChoice, TensionPolicy};
use sinew_stiffness::{ArmStiffness, ArmStiffnessData, EndOutcome};

use crate::active;
use crate::answer::{Evaluated, plan_at, stable_margin};
use crate::bundle::{self, Linear};
pub use crate::data::PlannerData;
use crate::error::{InputProblem, PlanError};
use crate::frame::Frame;
use crate::interior;
use crate::pencil::Pencil;
use crate::phases::{Problem, pencil_scale};
use crate::problem::{Method, Objective, Plan, PlanSettings, Requirements, check_inputs};
use crate::rows::{
    HeldTensions, column_sums, fix_rows, held_coordinates, linear_rows_into, predicted, rate_error,
    rate_rows,
};

/// The planner's model: the arm (robot, routing, statics). Immutable; one [`PlannerData`] per
/// thread.
#[derive(Debug, Clone)]
pub struct Planner {
    arm: ArmStiffness,
}

impl PlannerData {
    /// A workspace for `planner`.
    pub fn new(planner: &Planner) -> PlannerData {
        PlannerData::for_arm(&planner.arm)
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
    /// to `settings.relative_gap`. One pose stage of the pipeline per plan.
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
        data.forget();
        self.plan_step(data, q, f0, objective, requirements, settings, None).map(|(p, _, _)| p)
    }

    /// One plan; with `rate`, each tension within `rate` N of the previous plan's (kept in
    /// `data`), and the interior-point method warm-started from that plan when there is one.
    /// Returns the plan, whether the warm answer was accepted, and the iterations.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn plan_step(
        &self,
        data: &mut PlannerData,
        q: &[f64],
        f0: &Vector6<f64>,
        objective: Objective,
        requirements: &Requirements,
        settings: &PlanSettings,
        rate: Option<f64>,
    ) -> Result<(Plan, bool, usize), PlanError> {
        check_inputs(f0, objective, requirements, settings)?;
        self.check_joint_budgets(requirements)?;
        let arm = &self.arm;
        self.check_fixed_levels(requirements)?;
        let sd = &mut data.stiffness;
        // The pose stage, once: geometry, T0, K_W and J_x at the pose.
        arm.set_pose(sd, q, f0)?;
        // The statics' set, copied into the last plan's buffers (the statics keep theirs).
        let mut kept = data.set.take();
        let mut own = |source: &EquilibriumSet| match kept.take() {
            Some(mut set) => {
                set.clone_from(source);
                set
            }
            None => source.clone(),
        };
        let fixed = self.fixed_tensions(sd, requirements)?;
        let (set, least_total) = match settings.method {
            // The equilibrium set and one tension stage (the pencil needs the stage's inherent
            // stiffness, which does not depend on the tensions); infeasibility shows in the
            // first phase. Any balancing tensions within the limits do: the closed form's
            // lowest levels when it holds them (no program), else the least-total policy.
            Method::InteriorPoint => {
                let set = own(arm.equilibrium_set(sd)?);
                let by_levels = arm.statics().has_levels()
                    && arm.set_tensions(sd, TensionChoice::Default).is_ok();
                if !by_levels {
                    arm.set_tensions(sd, TensionChoice::Policy(TensionPolicy::LeastTotal))?;
                }
                (set, f64::NAN)
            }
            // The least-total tensions: whether any tensions balance the load (a typed
            // infeasibility naming the joint otherwise), and the equilibrium set they computed.
            Method::Bundle => {
                arm.set_tensions(sd, TensionChoice::Policy(TensionPolicy::LeastTotal))?;
                let least_total: f64 = sd.tensions().iter().sum();
                let set = own(arm.equilibrium_set(sd)?);
                if let Some(budget) = requirements.budget
                    && least_total > budget * (1.0 + 1e-12)
                {
                    return Err(PlanError::BudgetTooSmall { budget, least: least_total });
                }
                (set, least_total)
            }
        };
        let mut pencil = data.pencil.take().unwrap_or_else(Pencil::empty);
        pencil.fill(arm, sd, &set)?;
        let (mut linear, mut merged, mut keys) =
            data.rows.take().unwrap_or_else(|| (Linear::new(0, 0), Linear::new(0, 0), Vec::new()));
        let budgets = self.joint_budget_rows(requirements);
        linear_rows_into(&set, requirements.budget, &budgets, &mut linear);
        let previous = data.previous.take();
        if let (Some(change), Some(previous)) = (rate, &previous) {
            rate_rows(&set, previous, change, &mut linear);
        }
        let mut warm = false;
        let (lambda, upper, iterations) = match settings.method {
            Method::InteriorPoint => {
                let held = held_coordinates(&set, &fixed);
                linear.merged_into(&mut merged, &mut keys);
                let mut frame = data.frame.take().unwrap_or_else(Frame::empty);
                frame.fill(&pencil, &set, &merged, &held);
                let rows = frame.rhs.len();
                let taken = data.active.take();
                let active = taken.as_ref().filter(|(n, _)| *n == rows).map(|(_, a)| &a[..]);
                let mut work = std::mem::take(&mut data.warm);
                // The tensions before the last, for the warm start's prediction.
                let earlier = data.before.0.then_some(&data.before.1[..]);
                let attempt = previous.as_ref().map(|f| {
                    let f = predicted(&set, f, earlier, &mut work.predicted);
                    frame.x_of_tensions(&set, f, &mut work.mapped);
                    interior::warm(&frame, objective, requirements, settings, active, &mut work)
                });
                let limited = rate.is_some() && previous.is_some();
                let mut cold = |data: &mut PlannerData| {
                    interior::cold(&frame, objective, requirements, settings, &mut work)
                        .map_err(|e| self.infeasible(data, requirements, limited, e))
                };
                let (answer, before) = match attempt {
                    Some(Ok(answer)) => {
                        warm = true;
                        (answer, 0)
                    }
                    // Cold, after the iterations of a refused warm start; on an error the
                    // buffers go back into the workspace.
                    attempt => match cold(data) {
                        Ok((answer, before)) => {
                            (answer, before + attempt.map_or(0, |t| t.err().unwrap_or(0)))
                        }
                        Err(e) => {
                            data.active = taken;
                            let taken = (frame, work, pencil, (linear, merged, keys));
                            return Err(data.keep(taken, set, e));
                        }
                    },
                };
                let mut kept = taken.map(|(_, a)| a).unwrap_or_default();
                active::active_rows_into(&frame, &answer.x, &mut kept, work.pairs());
                data.active = Some((rows, kept));
                let lambda = frame.lambda(&answer.x);
                // The buffers back into the workspace, the answer's `x` as the next iterate's.
                work.x = answer.x;
                data.warm = work;
                data.frame = Some(frame);
                (lambda, answer.upper, before + answer.iterations)
            }
            Method::Bundle => {
                fix_rows(&set, &fixed, &mut linear);
                let linear = linear.merged();
                let sd = &mut data.stiffness;
                self.bundle(
                    sd,
                    &set,
                    &pencil,
                    &linear,
                    objective,
                    requirements,
                    settings,
                    least_total,
                )?
            }
        };
        data.pencil = Some(pencil);
        data.rows = Some((linear, merged, keys));
        let plan = self.answer(data, &set, objective, requirements, lambda, upper, iterations)?;
        // The last tensions into the buffer of those before them, these into the last ones'.
        data.before.0 = previous.is_some();
        if let Some(previous) = &previous {
            data.before.1.clone_from(previous);
        }
        let mut kept = previous.unwrap_or_else(|| std::mem::take(&mut data.warm.tensions));
        kept.clone_from(&plan.tensions);
        data.previous = Some(kept);
        data.set = Some(set);
        Ok((plan, warm, iterations))
    }

    /// The bundle method's phases from the safest (or least-total) start: `(λ, UB, iterations)`.
    #[allow(clippy::too_many_arguments)]
    fn bundle(
        &self,
        sd: &mut ArmStiffnessData,
        set: &EquilibriumSet,
        pencil: &Pencil,
        linear: &Linear,
        objective: Objective,
        requirements: &Requirements,
        settings: &PlanSettings,
        least_total: f64,
    ) -> Result<(Vec<f64>, f64, usize), PlanError> {
        let arm = &self.arm;
        let k = set.dimension();
        let least_total_lambda = set.coordinates(sd.tensions());
        // A start inside the limits (and the budget): the safest tensions when within the
        // budget, else the least-total ones.
        arm.set_tensions(sd, TensionChoice::Policy(TensionPolicy::Safest))?;
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
            bundle::feasible_point(k, linear)?.ok_or(PlanError::BudgetsInfeasible)?
        };
        let problem = Problem {
            pencil,
            objective,
            requirements,
            settings,
            linear,
            // Σ f = Σ f_p + (Nᵀ 1)ᵀ λ: its constant and gradient, once per plan.
            total: set.particular().iter().sum(),
            sums: column_sums(set).collect(),
            // K_des was checked symmetric positive definite.
            k_des_scale: requirements.k_des.and_then(|k| k.cholesky()).map(|c| c.l()),
            scale: pencil_scale(pencil),
        };
        let (start, stable_iterations) = problem.stable_start(start, k)?;
        let (start, floor_iterations) = problem.floors_start(start)?;
        let (lambda, _, upper, last_iterations) = problem.optimise(&start, least_total)?;
        Ok((lambda, upper, stable_iterations + floor_iterations + last_iterations))
    }

    /// The plan at `λ`, evaluated by the pipeline itself at its tensions (no new pose stage):
    /// its value, `C_x`, `K_fd` and margin are the pipeline's, with the gap to the bound
    /// `upper` of the maximised objective.
    #[allow(clippy::too_many_arguments)]
    fn answer(
        &self,
        data: &mut PlannerData,
        set: &EquilibriumSet,
        objective: Objective,
        requirements: &Requirements,
        lambda: Vec<f64>,
        upper: f64,
        iterations: usize,
    ) -> Result<Plan, PlanError> {
        let arm = &self.arm;
        let mut tensions = vec![0.0; set.cable_count()];
        set.tensions(&lambda, &mut tensions)?;
        for (f, (lo, hi)) in tensions.iter_mut().zip(set.lower().iter().zip(set.upper())) {
            *f = f.clamp(*lo, *hi);
        }
        let sd = &mut data.stiffness;
        arm.set_tensions(sd, TensionChoice::Given(&tensions))?;
        arm.solve_end(sd)?;
        let min_eigenvalue = match sd.outcome().ok_or(PlanError::NoEndStiffness)?.end() {
            EndOutcome::Unstable { min_eigenvalue } => min_eigenvalue,
            // K_W as the pencil of this pose holds it (filled from the generators once).
            _ => match &data.pencil {
                Some(pencil) => stable_margin(sd.k_q(), pencil.k_w.as_ref(), &mut data.margin)?,
                None => {
                    let k_w = sd.k_w().to_owned();
                    stable_margin(sd.k_q(), k_w.as_ref(), &mut data.margin)?
                }
            },
        };
        let outcome = sd.outcome().ok_or(PlanError::NoEndStiffness)?;
        let Some(c) = outcome.compliance() else {
            return Err(PlanError::NoStableTensions {
                margin: requirements.margin,
                best: min_eigenvalue,
                budget: requirements.budget.is_some(),
            });
        };
        let c_x = Matrix6::from_fn(|r, col| 0.5 * (c[(r, col)] + c[(col, r)]));
        let k_fd = outcome.k_fd().map(|k| 0.5 * (k + k.transpose()));
        let levels = arm.statics().levels_of(&sd.cables, &sd.statics, &tensions).ok();
        let at = Evaluated { c_x, k_fd, min_eigenvalue };
        plan_at(objective, (lambda, tensions), at, upper, iterations, levels)
    }

    /// `error`, or where it is [`PlanError::BudgetsInfeasible`], why no point meets the rows of
    /// a plan at the pose of `data`: an infeasible load (the statics' typed error, by the
    /// least-total policy), a budget below the least total, the rate limit, or the per-joint
    /// budgets.
    fn infeasible(
        &self,
        data: &mut PlannerData,
        requirements: &Requirements,
        limited: bool,
        error: PlanError,
    ) -> PlanError {
        if !matches!(error, PlanError::BudgetsInfeasible) {
            return error;
        }
        let sd = &mut data.stiffness;
        if let Err(e) = self.arm.set_tensions(sd, TensionChoice::Policy(TensionPolicy::LeastTotal))
        {
            return e.into();
        }
        let least: f64 = sd.tensions().iter().sum();
        match requirements.budget {
            Some(budget) if least > budget * (1.0 + 1e-12) => {
                PlanError::BudgetTooSmall { budget, least }
            }
            _ => rate_error(PlanError::BudgetsInfeasible, limited),
        }
    }

    /// Held levels need the decoupled closed form, and joints and levels that exist.
    fn check_fixed_levels(&self, requirements: &Requirements) -> Result<(), PlanError> {
        if requirements.fixed_levels.is_empty() {
            return Ok(());
        }
        let arm = &self.arm;
        let joints = arm.routing().joint_count();
        let what = "fixed_level";
        if !(arm.statics().has_levels() && arm.routing().is_decoupled()) {
            let problem = InputProblem::FixedLevelsNeedDecoupled;
            return Err(PlanError::InvalidInput { what, problem });
        }
        for &(joint, level) in &requirements.fixed_levels {
            if joint >= joints || !(0.0..=1.0).contains(&level) {
                let problem = InputProblem::BadFixedLevel { joint, level, joints };
                return Err(PlanError::InvalidInput { what, problem });
            }
        }
        Ok(())
    }

    /// The own tensions of every joint held at a level, by a tension stage at the pose of
    /// `sd`: `(cables, tensions)`.
    fn fixed_tensions(
        &self,
        sd: &mut ArmStiffnessData,
        requirements: &Requirements,
    ) -> Result<Vec<HeldTensions>, PlanError> {
        if requirements.fixed_levels.is_empty() {
            return Ok(Vec::new());
        }
        let arm = &self.arm;
        let mut levels = vec![0.0; arm.routing().joint_count()];
        for &(joint, s) in &requirements.fixed_levels {
            levels[joint] = s;
        }
        arm.set_tensions(sd, TensionChoice::Levels(&levels))?;
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

    /// Per-joint budgets name joints that exist.
    pub(crate) fn check_joint_budgets(&self, requirements: &Requirements) -> Result<(), PlanError> {
        let joints = self.arm.routing().joint_count();
        if let Some(&(joint, _)) = requirements.joint_budgets.iter().find(|(j, _)| *j >= joints) {
            let problem = InputProblem::NoSuchJoint { joint, joints };
            return Err(PlanError::InvalidInput { what: "joint_budget", problem });
        }
        Ok(())
    }

    /// Each per-joint budget as `(cables of the joint, B)`.
    pub(crate) fn joint_budget_rows(
        &self,
        requirements: &Requirements,
    ) -> Vec<(std::ops::Range<usize>, f64)> {
        let routing = self.arm.routing();
        requirements.joint_budgets.iter().map(|&(j, b)| (routing.cables_of_joint(j), b)).collect()
    }
}
