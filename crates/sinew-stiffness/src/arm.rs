//! The whole pipeline `Q → K_x` for a robot and its routing: kinematics, cable geometry,
//! `T0`, tensions, `K_q`, `K_W`, `J_x`, `C_x`, `K_x` (eq. 5–19).
//!
//! [`ArmStiffness`] is the model (the robot, the routing, the statics solver checked against
//! it and the block layout of `K_q`), [`ArmStiffnessData`] the workspace sized from it
//! (Pinocchio's model/data split). When `K_q` is block diagonal with small blocks (the
//! decoupled model), `C_x` and the stability verdict come from the structured `O(dof)` solve
//! (`structured/mod.rs` has the derivation); otherwise, or when that solve does not vouch for
//! its result, from the dense reference ([`crate::end_compliance`]).
//! [`ArmStiffnessData::end_solver`] tells which one ran.

use nalgebra::Vector6;
use sinew_robot::Robot;
use sinew_routing::{Order, Routing, compute_cable_geometry};
use sinew_statics::{ArmStatics, TensionChoice};

use crate::data::ArmStiffnessData;
use crate::end::{end_compliance_generated, stability_margin};
use crate::error::StiffnessError;
use crate::joint::{InherentPlan, joint_stiffness_in_blocks, stiffness_slope};
use crate::structured::{self, BlockLayout, Structured};

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
}

/// Which solver computed the end compliance of the last evaluation
/// ([`ArmStiffnessData::end_solver`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum EndSolver {
    /// No end compliance yet (no evaluation, or the last one stopped before `C_x`).
    NotYet,
    /// The structured `O(dof)` solve: `K_q` block diagonal (decoupled model), `K_W`
    /// semiseparable, the result checked by its residual.
    Structured,
    /// The dense reference [`crate::end_compliance`]: Cholesky of the symmetric part of
    /// `K_q + K_W`, then a Cholesky or LU solve (`O(dof³)`).
    Dense,
}

impl ArmStiffness {
    /// The model of `robot` with `routing`: checks that the routing was built for the robot
    /// and fits the statics solver, and reads the block layout of `K_q` from the routing
    /// ([`Routing::dof_blocks`]). Keeps its own copies of both.
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
        })
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
    /// model), so that [`ArmStiffness::evaluate`] takes the structured `O(dof)` solve.
    pub fn is_structured(&self) -> bool {
        self.layout.structured()
    }

    pub(crate) fn layout(&self) -> &BlockLayout {
        &self.layout
    }

    pub(crate) fn inherent_plan(&self) -> &InherentPlan {
        &self.inherent
    }

    /// Check that `data` was made for this arm (by [`ArmStiffnessData::new`]), as Pinocchio's
    /// `model.check(data)`. Every evaluation does it first.
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

    /// Everything up to the joint stiffness at `Q`, for the load `F0` (the wrench the
    /// end-effector exerts, base frame) and the tension `levels` (one per joint, in `[0, 1]`):
    /// `T0`, `K_W`'s generators and `J_x` in one pass (sinew-statics), the tensions, and `K_q`
    /// accumulated over the blocks of the layout only (its entries outside them stay exactly
    /// zero). The dense `K_W` is filled on request ([`ArmStiffnessData::k_w`]).
    ///
    /// # Errors
    /// [`StiffnessError::WorkspaceMismatch`]; infeasible tensions
    /// ([`sinew_statics::StaticsError::Infeasible`] inside [`StiffnessError::Statics`]);
    /// robot and routing errors for `Q`.
    pub fn joint_level(
        &self,
        data: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
        levels: &[f64],
    ) -> Result<(), StiffnessError> {
        self.joint_level_with(data, q, f0, TensionChoice::Levels(levels))
    }

    /// [`ArmStiffness::joint_level`] with the tensions chosen by `choice`: the paper's levels,
    /// a named policy over the equilibrium set (any cable set), or given tensions.
    ///
    /// # Errors
    /// As [`ArmStiffness::joint_level`], and those of
    /// [`sinew_statics::ArmStatics::solve_with`].
    pub fn joint_level_with(
        &self,
        data: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
        choice: TensionChoice<'_>,
    ) -> Result<(), StiffnessError> {
        self.check(data)?;
        data.solver = EndSolver::NotYet;
        data.structured.backward_error = f64::NAN;
        compute_cable_geometry(
            &self.routing,
            &self.robot,
            &mut data.robot,
            &mut data.cables,
            q,
            Order::Hessians,
        )?;
        self.statics.solve_with(
            &self.robot,
            &mut data.robot,
            &data.cables,
            &mut data.statics,
            f0,
            choice,
        )?;
        joint_stiffness_in_blocks(
            &self.routing,
            &data.cables,
            &data.statics.tensions,
            &self.layout,
            (&self.inherent, &mut data.inherent),
            &mut data.k_controllable,
            &mut data.k_inherent,
            &mut data.k_q,
        )
    }

    /// `C_x` into `data.end`: the structured solve when it applies and vouches for its result,
    /// else the dense reference.
    fn compliance(&self, data: &mut ArmStiffnessData) -> Result<(), StiffnessError> {
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
                return Ok(());
            }
        }
        data.solver = EndSolver::Dense;
        // The dense reference's sums, with K_W written straight into the storage of K_q + K_W
        // (`end_compliance` with a dense K_W computes the same numbers).
        let joint_end = data.statics.joint_end();
        let stable = end_compliance_generated(
            &data.k_q,
            joint_end.generators(),
            joint_end.j_x(),
            &mut data.end,
        )?;
        if stable {
            Ok(())
        } else {
            // Not positive definite: the reference's smallest eigenvalue, from the dense K_W.
            data.fill_k_w();
            let min_eigenvalue = stability_margin(data.k_q.as_ref(), data.k_w_filled.as_ref())?;
            Err(StiffnessError::Unstable { min_eigenvalue })
        }
    }

    /// The whole pipeline `Q → K_x` (eq. 19): [`ArmStiffness::joint_level`], then `C_x` and
    /// `K_x`. No allocation on success.
    ///
    /// `C_x` comes from the structured `O(dof)` solve when [`ArmStiffness::is_structured`]
    /// (derivation, stability verdict and residual check: `structured/mod.rs`), and from the
    /// dense reference ([`crate::end_compliance`], `O(dof³)`) otherwise, or when the structured solve
    /// finds `K_q + K_W` not positive definite (the dense path then reports the smallest
    /// eigenvalue) or its residual check fails. Both give the same results to rounding;
    /// [`ArmStiffnessData::end_solver`] says which ran. `K_x = C_x⁻¹` by a 6 × 6 LU with partial
    /// pivoting, as in [`crate::end_stiffness`].
    ///
    /// # Errors
    /// Those of [`ArmStiffness::joint_level`]; [`StiffnessError::Unstable`] when `K_q + K_W` is
    /// not positive definite; [`StiffnessError::RankDeficient`] when `J_x` has rank < 6 (then
    /// the compliance is still in `data`).
    pub fn evaluate(
        &self,
        data: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
        levels: &[f64],
    ) -> Result<(), StiffnessError> {
        self.evaluate_with(data, q, f0, TensionChoice::Levels(levels))
    }

    /// [`ArmStiffness::evaluate`] with the tensions chosen by `choice` (levels, a policy over
    /// the equilibrium set of any cable set, or given tensions). With levels, no allocation on
    /// success; a policy solves a small convex program, which allocates.
    ///
    /// # Errors
    /// As [`ArmStiffness::evaluate`], and those of [`sinew_statics::ArmStatics::solve_with`].
    pub fn evaluate_with(
        &self,
        data: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
        choice: TensionChoice<'_>,
    ) -> Result<(), StiffnessError> {
        self.joint_level_with(data, q, f0, choice)?;
        self.compliance(data)?;
        data.end.invert_compliance()
    }

    /// As [`ArmStiffness::evaluate`], stopping at the compliance `C_x` (defined also when
    /// `J_x` has rank < 6).
    ///
    /// # Errors
    /// Those of [`ArmStiffness::joint_level`] and [`StiffnessError::Unstable`].
    pub fn evaluate_compliance(
        &self,
        data: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
        levels: &[f64],
    ) -> Result<(), StiffnessError> {
        self.evaluate_compliance_with(data, q, f0, TensionChoice::Levels(levels))
    }

    /// [`ArmStiffness::evaluate_compliance`] with the tensions chosen by `choice`.
    ///
    /// # Errors
    /// As [`ArmStiffness::evaluate_compliance`], and those of
    /// [`sinew_statics::ArmStatics::solve_with`].
    pub fn evaluate_compliance_with(
        &self,
        data: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
        choice: TensionChoice<'_>,
    ) -> Result<(), StiffnessError> {
        self.joint_level_with(data, q, f0, choice)?;
        self.compliance(data)
    }

    /// The equilibrium set `f = f_p + N λ` (with every cable's limits) at the last evaluated
    /// configuration and load: every tension vector that balances it
    /// ([`sinew_statics::EquilibriumSet`]). Allocates (an SVD of `J_c`).
    ///
    /// # Errors
    /// [`StiffnessError::WorkspaceMismatch`]; those of [`sinew_statics::EquilibriumSet::new`].
    pub fn equilibrium_set(
        &self,
        data: &ArmStiffnessData,
    ) -> Result<sinew_statics::EquilibriumSet, StiffnessError> {
        self.check(data)?;
        Ok(self.statics.equilibrium_set(&data.cables, &data.statics)?)
    }

    /// `∂K_q/∂λ_i` at the last evaluated configuration (dof × dof, into `out`): `K_q` is affine
    /// in each joint's null-space coordinate `λ_i`, so a sweep over joint `i`'s tension levels
    /// is `K_q + (λ − λ_now) · slope`, with no new geometry. Exact in both models (routed:
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
