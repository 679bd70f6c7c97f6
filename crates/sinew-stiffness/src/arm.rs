//! The whole pipeline `Q → K_x` for a robot and its routing: kinematics, cable geometry,
//! `T0`, tensions, `K_q`, `K_W`, `J_x`, `C_x`, `K_x` (eq. 5–19), in three stages.
//!
//! [`ArmStiffness`] is the model (the robot, the routing, the statics solver checked against
//! it and the block layout of `K_q`), [`ArmStiffnessData`] the workspace sized from it
//! (Pinocchio's model/data split). The stages, each reading what the one before left in the
//! workspace:
//!
//! 1. the **pose stage** [`ArmStiffness::set_pose`]: everything that depends only on the pose
//!    and the load, computed once (kinematics, the cable geometry up to the Hessians, `T0`,
//!    `K_W`'s generators, `J_x`; the equilibrium set on its first use);
//! 2. any number of **tension stages** [`ArmStiffness::set_tensions`]: the tensions chosen by
//!    a [`TensionChoice`] and `K_q`;
//! 3. the **end stage** [`ArmStiffness::solve_end`]: `C_x`, `K_x` and the [`EndOutcome`].
//!
//! [`ArmStiffness::evaluate`] runs the three in one call. When `K_q` is block diagonal with
//! small blocks (the decoupled model), `C_x` and the stability verdict come from the
//! structured `O(dof)` solve (`structured/mod.rs` has the derivation); otherwise, or when that
//! solve does not vouch for its result, from the dense reference ([`crate::end_compliance`]).
//! [`ArmStiffnessData::end_solver`] tells which one ran.

use nalgebra::Vector6;
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, Routing, RoutingData, compute_cable_geometry};
use sinew_statics::{ArmStatics, EquilibriumSet, TensionChoice};

use crate::colmajor::ColMajor;
use crate::data::{ArmStiffnessData, EndOutcome, EndSolver, Stage};
use crate::end::{end_compliance_generated, stability_margin};
use crate::end_data::EndStiffnessData;
use crate::error::StiffnessError;
use crate::inherent::InherentPlan;
use crate::joint::{joint_stiffness_in_blocks, stiffness_slope};
use crate::structured::{self, BlockLayout, Structured, StructuredData};

/// The model of the pipeline `Q → K_x`: the robot and its routing, the statics solver checked
/// against the routing, and the block layout of `K_q` (which DOFs the cables couple; decoupled
/// or not). Immutable; share it between threads, one [`ArmStiffnessData`] per thread.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmStiffness {
    robot: Robot,
    routing: Routing,
    statics: ArmStatics,
    layout: BlockLayout,
    inherent: InherentPlan,
    /// Whether the pose stage refuses angles outside the joint limits.
    check_limits: bool,
}

impl ArmStiffness {
    /// The model of `robot` with `routing`: checks that the routing was built for the robot
    /// and fits the statics solver, and reads the block layout of `K_q` from the routing
    /// ([`Routing::dof_blocks`]). Keeps its own copies of both. Angles outside the joint
    /// limits are evaluated (the model is smooth there); [`ArmStiffness::checking_limits`]
    /// refuses them.
    ///
    /// # Errors
    /// [`StiffnessError::Routing`] with [`sinew_routing::RoutingError::RobotMismatch`];
    /// (Any cable set is accepted: the tension levels need the closed form,
    /// [`sinew_statics::ArmStatics::closed_form`]; the policies do not.)
    pub fn new(robot: &Robot, routing: &Routing) -> Result<ArmStiffness, StiffnessError> {
        routing.check_robot(robot)?;
        Ok(ArmStiffness {
            statics: ArmStatics::new(routing),
            layout: BlockLayout::new(routing),
            inherent: InherentPlan::new(routing),
            robot: robot.clone(),
            routing: routing.clone(),
            check_limits: false,
        })
    }

    /// The same model, whose pose stage refuses a pose outside the joint limits
    /// ([`Robot::check_limits`]: [`sinew_robot::RobotError::OutOfLimits`] naming the joint).
    /// The command line and the Python bindings build their arms this way.
    pub fn checking_limits(mut self) -> ArmStiffness {
        self.check_limits = true;
        self
    }

    /// Whether the pose stage refuses a pose outside the joint limits.
    pub fn checks_limits(&self) -> bool {
        self.check_limits
    }

    /// The robot.
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// The routing.
    pub fn routing(&self) -> &Routing {
        &self.routing
    }

    /// The statics solver.
    pub fn statics(&self) -> &ArmStatics {
        &self.statics
    }

    /// The number of revolute joints.
    pub fn dof(&self) -> usize {
        self.robot.dof()
    }

    /// Whether `K_q` is block diagonal with small blocks (at most four DOFs each; the decoupled
    /// model), so that the end stage takes the structured `O(dof)` solve.
    pub fn is_structured(&self) -> bool {
        self.layout.structured()
    }

    /// Check that `data` was made for this arm (by [`ArmStiffnessData::new`]), as Pinocchio's
    /// `model.check(data)`. Every stage does it first.
    ///
    /// # Errors
    /// [`StiffnessError::WorkspaceMismatch`].
    pub fn check(&self, data: &ArmStiffnessData) -> Result<(), StiffnessError> {
        if data.layout() == &self.layout {
            Ok(())
        } else {
            Err(StiffnessError::WorkspaceMismatch {
                dof: self.layout.dof(),
                cables: self.layout.cable_count(),
                workspace_dof: data.layout().dof(),
                workspace_cables: data.layout().cable_count(),
            })
        }
    }

    /// The pose stage at `Q` under the load `F0` (the wrench the end-effector exerts, base
    /// frame): kinematics, the cable geometry with Hessians, `T0`, `K_W`'s generators and
    /// `J_x` (sinew-statics, one pass). Forgets the previous pose's tensions, `K_q` and end.
    /// The equilibrium set is computed at its first use ([`ArmStiffness::equilibrium_set`], or
    /// a policy) and kept for the pose. No allocation.
    ///
    /// # Errors
    /// [`StiffnessError::WorkspaceMismatch`]; robot and routing errors for `Q` (with
    /// [`ArmStiffness::checking_limits`], [`sinew_robot::RobotError::OutOfLimits`]); a
    /// non-finite wrench.
    pub fn set_pose(
        &self,
        data: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
    ) -> Result<(), StiffnessError> {
        self.check(data)?;
        self.pose_checked(data, q, f0)
    }

    /// [`ArmStiffness::set_pose`] on a workspace already checked.
    fn pose_checked(
        &self,
        data: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
    ) -> Result<(), StiffnessError> {
        data.stage = Stage::Empty;
        data.inherent_current = false;
        data.pose_stages += 1;
        data.solver = EndSolver::NotYet;
        data.structured.backward_error = f64::NAN;
        if self.check_limits {
            self.robot.check_limits(q)?;
        }
        compute_cable_geometry(
            &self.routing,
            &self.robot,
            &mut data.robot,
            &mut data.cables,
            q,
            Order::Hessians,
        )?;
        self.statics.set_pose(&self.robot, &mut data.robot, &mut data.statics, f0)?;
        data.stage = Stage::Posed;
        Ok(())
    }

    /// A tension stage at the pose of the last [`ArmStiffness::set_pose`]: the tensions chosen
    /// by `choice` (the paper's levels, a named policy over the equilibrium set of any cable
    /// set, given tensions, or [`TensionChoice::Default`]), then `K_q` accumulated over the
    /// blocks of the layout only (its entries outside them stay exactly zero). Recomputes
    /// nothing of the pose. Levels and given tensions: no allocation; a policy solves a small
    /// convex program, which allocates.
    ///
    /// # Errors
    /// [`StiffnessError::StageMissing`] before a pose stage; infeasible tensions
    /// ([`sinew_statics::StaticsError::Infeasible`],
    /// [`sinew_statics::StaticsError::LevelsInfeasible`],
    /// [`sinew_statics::StaticsError::NoEquilibrium`] inside [`StiffnessError::Statics`]);
    /// the other errors of [`sinew_statics::ArmStatics::set_tensions`].
    pub fn set_tensions(
        &self,
        data: &mut ArmStiffnessData,
        choice: TensionChoice<'_>,
    ) -> Result<(), StiffnessError> {
        self.check(data)?;
        self.tensions_checked(data, choice)
    }

    /// [`ArmStiffness::set_tensions`] on a workspace already checked.
    fn tensions_checked(
        &self,
        data: &mut ArmStiffnessData,
        choice: TensionChoice<'_>,
    ) -> Result<(), StiffnessError> {
        if data.stage == Stage::Empty {
            return Err(StiffnessError::StageMissing { needs: "set_pose", missing: "pose" });
        }
        data.stage = Stage::Posed;
        data.solver = EndSolver::NotYet;
        data.structured.backward_error = f64::NAN;
        self.statics.set_tensions(&data.cables, &mut data.statics, choice)?;
        joint_stiffness_in_blocks(
            &self.routing,
            &data.cables,
            &data.statics.tensions,
            &self.layout,
            (&self.inherent, &mut data.inherent, &mut data.inherent_current),
            &mut data.k_controllable,
            &mut data.k_inherent,
            &mut data.k_q,
        )?;
        data.stage = Stage::Tensioned;
        Ok(())
    }

    /// The end stage at the last tensions: `C_x` (eq. 19), then `K_x = C_x⁻¹` when `J_x` has
    /// full rank ([`crate::has_full_rank`]), and the verdict. No allocation when stable.
    ///
    /// `C_x` comes from the structured `O(dof)` solve when [`ArmStiffness::is_structured`]
    /// (derivation, stability verdict and residual check: `structured/mod.rs`), and from the
    /// dense reference ([`crate::end_compliance`], `O(dof³)`) otherwise, or when the structured
    /// solve finds `K_q + K_W` not positive definite (the dense path then reports the smallest
    /// eigenvalue, which allocates) or its residual check fails. Both give the same results to
    /// rounding; [`ArmStiffnessData::end_solver`] says which ran.
    ///
    /// # Errors
    /// [`StiffnessError::StageMissing`] before a tension stage; numerical failures. Unstable
    /// and rank-deficient are outcomes ([`EndOutcome`]), not errors.
    pub fn solve_end(&self, data: &mut ArmStiffnessData) -> Result<EndOutcome, StiffnessError> {
        self.check(data)?;
        self.end_checked(data)
    }

    /// [`ArmStiffness::solve_end`] on a workspace already checked.
    fn end_checked(&self, data: &mut ArmStiffnessData) -> Result<EndOutcome, StiffnessError> {
        match data.stage {
            Stage::Empty | Stage::Posed => {
                return Err(StiffnessError::StageMissing {
                    needs: "set_tensions",
                    missing: "tensions",
                });
            }
            Stage::Tensioned | Stage::Ended(_) => {}
        }
        let outcome = match self.compliance(data)? {
            Some(min_eigenvalue) => EndOutcome::Unstable { min_eigenvalue },
            None => match data.end.invert_compliance() {
                Ok(()) => EndOutcome::Stiff,
                Err(StiffnessError::RankDeficient { pivot_ratio }) => {
                    EndOutcome::RankDeficient { pivot_ratio }
                }
                Err(e) => return Err(e),
            },
        };
        data.stage = Stage::Ended(outcome);
        Ok(outcome)
    }

    /// The whole pipeline `Q → K_x` in one call: [`ArmStiffness::set_pose`],
    /// [`ArmStiffness::set_tensions`] with `choice`, [`ArmStiffness::solve_end`]. With levels,
    /// given tensions or the default in closed form, no allocation on success. The outcome is
    /// also in `data` ([`ArmStiffnessData::outcome`]).
    ///
    /// # Errors
    /// Those of the three stages; [`StiffnessError::Unstable`] when `K_q + K_W` is not
    /// positive definite and [`StiffnessError::RankDeficient`] when `J_x` has rank < 6 (then
    /// the compliance is still in `data`): [`EndOutcome::into_result`].
    pub fn evaluate(
        &self,
        data: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
        choice: TensionChoice<'_>,
    ) -> Result<(), StiffnessError> {
        // The workspace is checked once for the three stages (by `evaluate_joints`).
        self.evaluate_joints(data, q, f0, choice)?;
        self.end_checked(data)?.into_result()
    }

    /// The pipeline up to the joint stiffness in one call: [`ArmStiffness::set_pose`], then
    /// [`ArmStiffness::set_tensions`] with `choice` (tensions and `K_q`; no end stage).
    ///
    /// # Errors
    /// Those of the two stages.
    pub fn evaluate_joints(
        &self,
        data: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
        choice: TensionChoice<'_>,
    ) -> Result<(), StiffnessError> {
        self.check(data)?;
        self.pose_checked(data, q, f0)?;
        self.tensions_checked(data, choice)
    }

    /// `C_x` into `data.end`: the structured solve when it applies and vouches for its result,
    /// else the dense reference. `Some(λ_min)` when `K_q + K_W` is not positive definite.
    fn compliance(&self, data: &mut ArmStiffnessData) -> Result<Option<f64>, StiffnessError> {
        let joint_end = data.statics.joint_end();
        if self.layout.structured() {
            let outcome = structured::compliance(
                &self.layout,
                &data.k_q,
                joint_end.generators(),
                joint_end.j_x_columns(),
                &mut data.structured,
            );
            if outcome == Structured::Done {
                data.end.set_compliance(&data.structured.c_x);
                data.solver = EndSolver::Structured;
                return Ok(None);
            }
        }
        data.solver = EndSolver::Dense;
        // The dense reference's sums, with K_W written straight into the storage of K_q + K_W
        // (`end_compliance` with a dense K_W computes the same numbers).
        let joint_end = data.statics.joint_end();
        let stable = end_compliance_generated(
            (&data.k_q, true),
            joint_end.generators(),
            joint_end.j_x(),
            &mut data.end,
        )?;
        if stable {
            Ok(None)
        } else {
            // Not positive definite: the reference's smallest eigenvalue, from the dense K_W.
            data.fill_k_w();
            Ok(Some(stability_margin(data.k_q.as_ref(), data.k_w_filled.as_ref())?))
        }
    }

    /// The equilibrium set `f = f_p + N λ` (with every cable's limits) at the pose of the last
    /// pose stage: every tension vector that balances its load
    /// ([`sinew_statics::EquilibriumSet`]). Computed at its first use after the pose stage (an
    /// SVD of `J_c`, which allocates), then kept in `data` for the pose: a policy's tension
    /// stage uses the same one.
    ///
    /// # Errors
    /// [`StiffnessError::WorkspaceMismatch`]; [`StiffnessError::StageMissing`] before a pose
    /// stage; those of [`sinew_statics::EquilibriumSet::new`].
    pub fn equilibrium_set<'d>(
        &self,
        data: &'d mut ArmStiffnessData,
    ) -> Result<&'d EquilibriumSet, StiffnessError> {
        self.check(data)?;
        if data.stage == Stage::Empty {
            return Err(StiffnessError::StageMissing { needs: "set_pose", missing: "pose" });
        }
        Ok(self.statics.equilibrium_set(&data.cables, &mut data.statics)?)
    }

    /// `∂K_q/∂λ_i` at the last tension stage (dof × dof, into `out`): `K_q` is affine in each
    /// joint's null-space coordinate `λ_i`, so a sweep over joint `i`'s tension levels is
    /// `K_q + (λ − λ_now) · slope`, with no new geometry. Exact in both models (routed:
    /// through the proximal joints' balancing tensions, see
    /// [`ArmStatics::tension_sensitivity`]).
    ///
    /// # Errors
    /// [`StiffnessError::WorkspaceMismatch`]; dimension errors; statics errors.
    pub fn stiffness_slope(
        &self,
        data: &mut ArmStiffnessData,
        joint: usize,
        out: faer::MatMut<'_, f64>,
    ) -> Result<(), StiffnessError> {
        self.check(data)?;
        self.statics.tension_sensitivity(
            &data.cables,
            &data.statics,
            joint,
            &mut data.sensitivity,
        )?;
        stiffness_slope(&self.routing, &data.cables, &data.sensitivity, out)
    }
}

impl ArmStiffnessData {
    /// A workspace for `arm`.
    pub fn new(arm: &ArmStiffness) -> ArmStiffnessData {
        let n = arm.dof();
        let layout = arm.layout.clone();
        ArmStiffnessData {
            robot: RobotData::new(arm.robot()),
            cables: RoutingData::new(arm.routing()),
            statics: arm.statics().data(arm.robot()),
            structured: StructuredData::new(&layout),
            layout,
            solver: EndSolver::NotYet,
            k_controllable: ColMajor::zeros(n, n),
            k_inherent: ColMajor::zeros(n, n),
            inherent: arm.inherent.scratch(),
            k_q: ColMajor::zeros(n, n),
            k_w_filled: ColMajor::zeros(n, n),
            end: EndStiffnessData::new(n),
            sensitivity: vec![0.0; arm.routing().cable_count()],
            stage: Stage::Empty,
            inherent_current: false,
            pose_stages: 0,
        }
    }
}
