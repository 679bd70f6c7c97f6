//! Planning in the stick regime (spec §9, issue #27): the tensions that optimise the end
//! stiffness when no hole slides, after a given history.
//!
//! # Math
//! After a history (`equal`, `pull` or `release`) the segment tensions are the actuator
//! tensions times the history's weights, `T_{c,s} = T_{c,0} w_{c,s}` (1 after `equal`), and
//! they balance the load through `J̃_c = Σ_s w_{c,s} J_{c,s}` (`J_c` after `equal`): the
//! balancing actuator tensions are `f = f_p + N λ` over the set of that statics, within the
//! actuator limits that keep every segment within the cable's limits. The stick stiffness
//! `K_stick = Σ_c Σ_s T_{c,s} H_{c,s} + Σ_c Σ_s J_{c,s}ᵀ (E A/ℓ_{c,s}) J_{c,s}` is affine in
//! `f` and symmetric, and so is `A(λ) = K_stick + K_W` under a conservative load: the
//! planner's problem, its methods and its certificate apply unchanged to this pencil
//! ([`crate::pencil::Pencil::fill_stick`]). A slip regime's `K` moves with the weights and is
//! not symmetric; its end stiffness is not concave in the tensions, so it is not planned.
//!
//! The stick stiffness is the tangent while every hole stays inside its band: for load
//! increments below the stick load limit ([`sinew_stiffness::stick_load_limits`]).

use nalgebra::{Matrix6, Vector6};
use sinew_routing::{
    FrictionData, FrictionModel, compute_capstan_weights, compute_friction_geometry,
};
use sinew_statics::{EquilibriumSet, TensionChoice, slip_equilibrium_set};
use sinew_stiffness::{
    ArmStiffness, ArmStiffnessData, FrictionArmData, FrictionRegime, FrictionStiffnessData, History,
};

use crate::answer::{Evaluated, accumulate, least_symmetric, plan_at};
use crate::error::{InputProblem, PlanError};
use crate::frame::Frame;
use crate::interior;
use crate::least::LeastEigen;
use crate::pencil::Pencil;
use crate::plan::{Planner, PlannerData};
use crate::problem::{Method, Objective, Plan, PlanSettings, Requirements, check_inputs};
use crate::rows::linear_rows;

/// The workspace of [`Planner::plan_in_stick`] beside the planner's own: the friction
/// pipeline's (the answer's evaluation) and a stick stiffness for the pencil's coefficients.
#[derive(Debug)]
pub struct StickPlanData {
    /// The friction pipeline's workspace: after a plan, its evaluation at the plan's tensions
    /// (segments, dead band, `K_q`, `C_x`, `K_x` of the stick regime).
    pub friction: FrictionArmData,
    scratch: FrictionStiffnessData,
    /// The answer's margin, `λ_min(sym(K_stick + K_W))`, by Cholesky trials.
    margin: (Vec<f64>, LeastEigen),
}

impl StickPlanData {
    /// A workspace for `planner` with the friction geometry `model`.
    pub fn new(planner: &Planner, model: &FrictionModel) -> StickPlanData {
        StickPlanData {
            friction: FrictionArmData::new(planner.arm(), model),
            scratch: FrictionStiffnessData::new(model),
            margin: (Vec::new(), LeastEigen::default()),
        }
    }
}

impl Planner {
    /// The tensions that optimise `objective` in the stick regime after `history`, at pose `q`
    /// under the force `f0` and gravity, with `requirements` (budgets, per-joint budgets, the
    /// margin, the stiffness floors), certified to `settings.relative_gap` by the
    /// interior-point method (module docs). The plan's value, `C_x`, `K_fd` and margin are the
    /// friction pipeline's at its actuator tensions ([`sinew_stiffness::ArmStiffness::evaluate_with_friction`],
    /// left in `stick.friction`); its `levels` are the paper's levels after `equal` (the
    /// frictionless statics), `None` after a pull or a release.
    ///
    /// # Errors
    /// As [`Planner::plan`]; [`PlanError::InvalidInput`] ([`InputProblem::NotInStick`]) for
    /// held levels or the bundle method; the stick stiffness's
    /// ([`sinew_stiffness::StiffnessError::StickWithoutFriction`] for a cable with μ = 0) and
    /// the friction geometry's.
    #[allow(clippy::too_many_arguments)]
    pub fn plan_in_stick(
        &self,
        data: &mut PlannerData,
        stick: &mut StickPlanData,
        (model, history): (&FrictionModel, History),
        q: &[f64],
        f0: &Vector6<f64>,
        objective: Objective,
        requirements: &Requirements,
        settings: &PlanSettings,
    ) -> Result<Plan, PlanError> {
        check_inputs(f0, objective, requirements, settings)?;
        self.check_joint_budgets(requirements)?;
        for (refused, what) in [
            (!requirements.fixed_levels.is_empty(), "fixed_level"),
            (settings.method != Method::InteriorPoint, "method"),
        ] {
            if refused {
                return Err(PlanError::InvalidInput { what, problem: InputProblem::NotInStick });
            }
        }
        data.forget();
        let arm = self.arm();
        let sd = &mut data.stiffness;
        arm.set_pose(sd, q, f0)?;
        let friction = &mut stick.friction.friction;
        let set = stick_set(arm, sd, (model, history), friction)?;
        let mut pencil = data.pencil.take().unwrap_or_else(Pencil::empty);
        let stage = (model, &*friction, history);
        pencil.fill_stick(arm, sd, stage, &set, &mut stick.scratch)?;
        let linear = linear_rows(&set, requirements.budget, &self.joint_budget_rows(requirements));
        let frame = Frame::new(&pencil, &set, &linear.merged(), &[]);
        data.pencil = Some(pencil);
        let (answer, before) =
            interior::cold(&frame, objective, requirements, settings, &mut data.warm)?;
        let lambda = frame.lambda(&answer.x);
        // The answer, evaluated by the friction pipeline at its actuator tensions.
        let mut tensions = vec![0.0; set.cable_count()];
        set.tensions(&lambda, &mut tensions)?;
        for (f, (lo, hi)) in tensions.iter_mut().zip(set.lower().iter().zip(set.upper())) {
            *f = f.clamp(*lo, *hi);
        }
        let out = &mut stick.friction;
        let regime = (model, FrictionRegime::Stick(history));
        let outcome =
            arm.evaluate_with_friction(sd, out, regime, q, f0, TensionChoice::Given(&tensions))?;
        let margin = &mut stick.margin;
        // A plan depends on its arguments alone: no eigenvector of an earlier plan starts it.
        margin.1.forget();
        let n = arm.dof();
        margin.0.resize(n * n, 0.0);
        accumulate(&mut margin.0, out.stiffness.stiffness()?, false);
        accumulate(&mut margin.0, sd.k_w(), true);
        let min_eigenvalue = least_symmetric(margin, outcome.is_stable().then_some(0.0))?;
        if !outcome.is_stable() {
            return Err(PlanError::NoStableTensions {
                margin: requirements.margin,
                best: min_eigenvalue,
                budget: requirements.budget.is_some(),
            });
        }
        let c = out.end.compliance();
        let c_x = Matrix6::from_fn(|r, col| 0.5 * (c[(r, col)] + c[(col, r)]));
        let k_fd =
            outcome.has_end_stiffness().then(|| out.end.k_fd()).map(|k| 0.5 * (k + k.transpose()));
        let levels = match history {
            History::Equal => arm.statics().levels_of(&sd.cables, &sd.statics, &tensions).ok(),
            History::Pull | History::Release => None,
        };
        let at = Evaluated { c_x, k_fd, min_eigenvalue };
        plan_at(objective, (lambda, tensions), at, answer.upper, before + answer.iterations, levels)
    }
}

/// At the pose of `sd`: the friction geometry (with the history's weights) into `friction`,
/// and the equilibrium set of the history's statics (`J_c` after `equal`, `J̃` with the
/// actuator limits after a pull or a release).
///
/// # Errors
/// The friction geometry's; the statics'.
pub(crate) fn stick_set(
    arm: &ArmStiffness,
    sd: &mut ArmStiffnessData,
    (model, history): (&FrictionModel, History),
    friction: &mut FrictionData,
) -> Result<EquilibriumSet, PlanError> {
    compute_friction_geometry(model, arm.routing(), &sd.cables, friction)?;
    Ok(match history.slip() {
        None => arm.equilibrium_set(sd)?.clone(),
        Some(slip) => {
            compute_capstan_weights(model, friction, slip)?;
            let statics = arm.statics();
            let (limits, groups) = (statics.cable_limits(), statics.joint_groups());
            slip_equilibrium_set(model, friction, &sd.statics.t0, limits, groups)?
        }
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use nalgebra::Vector6;
    use sinew_routing::FrictionModel;
    use sinew_routing::PatternModel;
    use sinew_statics::{TensionChoice, TensionPolicy};
    use sinew_stiffness::{ArmStiffness, FrictionRegime, History};
    use sinew_testkit::cdhrm5;

    use super::StickPlanData;
    use crate::pencil::Pencil;
    use crate::plan::{Planner, PlannerData};

    /// The stick pencil at random `λ` is the friction pipeline's `K_stick + K_W` at the
    /// tensions `f_p + N λ`, entry by entry (both models, every history): the pencil's `A_0`
    /// and `A_i` are the affine map's, not an approximation of it.
    #[test]
    fn the_stick_pencil_is_the_pipelines_stiffness_at_every_tension() {
        for model in [PatternModel::Decoupled, PatternModel::Routed] {
            let (robot, routing) = cdhrm5::robot_and_routing(model);
            let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
            let friction = FrictionModel::new(&routing).with_friction_coefficient(0.1).unwrap();
            let arm = planner.arm();
            let mut data = PlannerData::new(&planner);
            let mut stick = StickPlanData::new(&planner, &friction);
            let q = cdhrm5::LOADED_POSE;
            let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
            let mut worst: f64 = 0.0;
            for history in [History::Equal, History::Pull, History::Release] {
                let sd = &mut data.stiffness;
                arm.set_pose(sd, &q, &f0).unwrap();
                let fd = &mut stick.friction.friction;
                let set = super::stick_set(arm, sd, (&friction, history), fd).unwrap();
                let mut pencil = Pencil::empty();
                let stage = (&friction, &*fd, history);
                pencil.fill_stick(arm, sd, stage, &set, &mut stick.scratch).unwrap();
                // Balancing tensions within the limits: two policies of the regime's statics
                // and their midpoint.
                let mut policies = Vec::new();
                for policy in [TensionPolicy::LeastTotal, TensionPolicy::Safest] {
                    let out = &mut stick.friction;
                    let regime = (&friction, FrictionRegime::Stick(history));
                    let sd = &mut data.stiffness;
                    let choice = TensionChoice::Policy(policy);
                    arm.evaluate_with_friction(sd, out, regime, &q, &f0, choice).unwrap();
                    policies.push(out.actuator.clone());
                }
                let middle = policies[0].iter().zip(&policies[1]).map(|(a, b)| 0.5 * (a + b));
                policies.push(middle.collect());
                for f in policies {
                    let lambda = set.coordinates(&f);
                    let a = pencil.at(&lambda);
                    let out = &mut stick.friction;
                    let regime = (&friction, FrictionRegime::Stick(history));
                    let sd = &mut data.stiffness;
                    arm.evaluate_with_friction(sd, out, regime, &q, &f0, TensionChoice::Given(&f))
                        .unwrap();
                    let k = out.stiffness.symmetric_part().unwrap();
                    let k_w = sd.k_w();
                    let n = a.nrows();
                    let scale = (0..n).map(|i| a[(i, i)].abs()).fold(0.0, f64::max);
                    for r in 0..n {
                        for c in 0..n {
                            let reference = k[(r, c)] + 0.5 * (k_w[(r, c)] + k_w[(c, r)]);
                            worst = worst.max((a[(r, c)] - reference).abs() / scale);
                        }
                    }
                }
            }
            eprintln!("{model:?}: worst relative difference {worst:.1e}");
            assert!(worst < 1e-12, "{model:?}: {worst:e}");
        }
    }
}
