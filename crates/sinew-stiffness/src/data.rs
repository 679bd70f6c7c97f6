//! [`ArmStiffnessData`]: the workspace of [`crate::ArmStiffness`], sized from it once
//! ([`ArmStiffnessData::new`]), and the results of its stages: the pose stage (geometry,
//! `T0`, `K_W`'s generators, `J_x`, the equilibrium set on demand), the tension stage
//! (tensions, `K_q`) and the end stage (`C_x`, `K_x`, the [`EndOutcome`]).

use faer::MatRef;
use nalgebra::{Matrix2, Matrix3};
use sinew_robot::RobotData;
use sinew_routing::RoutingData;
use sinew_statics::{ArmStaticsData, TensionInterval};

use crate::colmajor::ColMajor;
use crate::end::stability_margin;
use crate::end_data::EndStiffnessData;
use crate::error::StiffnessError;
use crate::inherent::InherentScratch;
use crate::joint::joint_block;
use crate::structured::{BlockLayout, StructuredData};

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

/// What the end stage found (eq. 19, spec §5): the typed outcome of an evaluation. Unstable
/// and rank-deficient are answers, not failures: [`EndOutcome::into_result`] turns them into
/// [`StiffnessError::Unstable`] and [`StiffnessError::RankDeficient`] for callers that need
/// `K_x`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EndOutcome {
    /// `K_q + K_W` positive definite and `J_x` of full rank ([`crate::has_full_rank`]):
    /// `C_x`, `K_x` and `K_fd` exist.
    Stiff,
    /// Stable, but `J_x` has rank < 6: `C_x` exists, `K_x` and `K_fd` do not.
    RankDeficient {
        /// Smallest over largest pivot magnitude of `C_x`'s LU factorisation.
        pivot_ratio: f64,
    },
    /// `K_q + K_W` is not positive definite: the equilibrium is unstable, no `C_x` exists.
    Unstable {
        /// The smallest eigenvalue of the symmetric part of `K_q + K_W`, N m/rad.
        min_eigenvalue: f64,
    },
}

impl EndOutcome {
    /// Whether `K_q + K_W` is positive definite (`C_x` exists).
    pub fn is_stable(self) -> bool {
        !matches!(self, EndOutcome::Unstable { .. })
    }

    /// Whether `K_x` exists: stable and `J_x` of full rank.
    pub fn has_end_stiffness(self) -> bool {
        matches!(self, EndOutcome::Stiff)
    }

    /// `Ok(())` when `K_x` exists, else the error that says why not.
    ///
    /// # Errors
    /// [`StiffnessError::Unstable`], [`StiffnessError::RankDeficient`].
    pub fn into_result(self) -> Result<(), StiffnessError> {
        match self {
            EndOutcome::Stiff => Ok(()),
            EndOutcome::RankDeficient { pivot_ratio } => {
                Err(StiffnessError::RankDeficient { pivot_ratio })
            }
            EndOutcome::Unstable { min_eigenvalue } => {
                Err(StiffnessError::Unstable { min_eigenvalue })
            }
        }
    }
}

/// How far the workspace's stages have come since the last pose stage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Stage {
    /// No pose (new workspace, or the last pose stage failed).
    Empty,
    /// Geometry, `T0`, `K_W`'s generators and `J_x` of a pose.
    Posed,
    /// And tensions and `K_q`.
    Tensioned,
    /// And the end stage's outcome.
    Ended(EndOutcome),
}

/// Every workspace and result of the pipeline, sized once from a [`crate::ArmStiffness`] (no
/// allocation per configuration). A plain workspace: which arm it belongs to is checked by
/// [`crate::ArmStiffness::check`] at every stage.
///
/// Who writes what: the pose stage writes `robot`, `cables` and the pose part of `statics`
/// (`T0`, `J_x`, `K_W`'s generators) and clears the rest; the tension stage writes the
/// tensions (`statics`), `K_c`, `K_i` and `K_q`; the end stage writes `C_x`, `K_x` and the
/// outcome. Nothing else writes them.
#[derive(Debug)]
pub struct ArmStiffnessData {
    /// Kinematics workspace.
    pub robot: RobotData,
    /// Cable geometry workspace (lengths, `J_c`, Hessians).
    pub cables: RoutingData,
    /// `T0`, `K_W`'s generators, `J_x`, intervals, tensions.
    pub statics: ArmStaticsData,
    /// The layout of the arm the workspace was made for (its check).
    pub(crate) layout: BlockLayout,
    pub(crate) structured: StructuredData,
    pub(crate) solver: EndSolver,
    pub(crate) k_controllable: ColMajor,
    pub(crate) k_inherent: ColMajor,
    /// The workspace of the inherent part's staircase kernel (routed model).
    pub(crate) inherent: InherentScratch,
    pub(crate) k_q: ColMajor,
    /// The dense `K_W`, written by [`ArmStiffnessData::fill_k_w`] (the dense path, or on
    /// request): the structured solve does not need it.
    pub(crate) k_w_filled: ColMajor,
    pub(crate) end: EndStiffnessData,
    pub(crate) sensitivity: Vec<f64>,
    /// How far the stages have come.
    pub(crate) stage: Stage,
    /// Whether `k_inherent` is that of the current pose (the routed model computes it at the
    /// first tension stage of a pose and keeps it: it does not depend on the tensions).
    pub(crate) inherent_current: bool,
    /// How many pose stages this workspace has run ([`ArmStiffnessData::pose_stages`]).
    pub(crate) pose_stages: u64,
}

impl ArmStiffnessData {
    pub(crate) fn layout(&self) -> &BlockLayout {
        &self.layout
    }

    /// `Σ f_c H_c` (dof × dof).
    pub fn k_controllable(&self) -> MatRef<'_, f64> {
        self.k_controllable.as_ref()
    }

    /// `J_cᵀ K_l J_c` (dof × dof).
    pub fn k_inherent(&self) -> MatRef<'_, f64> {
        self.k_inherent.as_ref()
    }

    /// `K_q`, the arm's joint stiffness (dof × dof; block diagonal when decoupled).
    pub fn k_q(&self) -> MatRef<'_, f64> {
        self.k_q.as_ref()
    }

    /// The dense `K_W` from the generators of the last evaluation
    /// ([`sinew_statics::KwGenerators::fill_dense`], `O(dof²)`, no allocation).
    pub(crate) fn fill_k_w(&mut self) {
        let generators = self.statics.joint_end().generators();
        if generators.fill_dense(self.k_w_filled.as_mut()).is_err() {
            // Not reached: both are sized from the same arm.
            self.k_w_filled.as_mut().fill(f64::NAN);
        }
    }

    /// `K_W = ∂T0/∂Q` (dof × dof) at the last evaluation: filled from its generators at every
    /// call (`O(dof²)`, no allocation); the structured solve does not need it.
    pub fn k_w(&mut self) -> MatRef<'_, f64> {
        self.fill_k_w();
        self.k_w_filled.as_ref()
    }

    /// The stability margin at the last evaluation: the smallest eigenvalue of the symmetric
    /// part of `K_q + K_W` (N m/rad; positive: stable). Allocates (an eigendecomposition); not
    /// for inner loops.
    ///
    /// # Errors
    /// [`StiffnessError::Eigen`].
    pub fn stability_margin(&mut self) -> Result<f64, StiffnessError> {
        self.fill_k_w();
        stability_margin(self.k_q.as_ref(), self.k_w_filled.as_ref())
    }

    /// `J_x`, the end-effector Jacobian (6 × dof, linear rows first, base frame).
    pub fn j_x(&self) -> MatRef<'_, f64> {
        self.statics.joint_end().j_x()
    }

    /// The end compliance `C_x` (6 × 6).
    pub fn compliance(&self) -> MatRef<'_, f64> {
        self.end.compliance()
    }

    /// The end stiffness `K_x` (6 × 6).
    pub fn stiffness(&self) -> MatRef<'_, f64> {
        self.end.stiffness()
    }

    /// `K_fd = K_x[0:3, 0:3]` (eq. 21), N/m.
    pub fn k_fd(&self) -> Matrix3<f64> {
        self.end.k_fd()
    }

    /// `(C_x[0:3, 0:3])⁻¹`, N/m: translational stiffness with rotations free.
    pub fn translational_stiffness(&self) -> Option<Matrix3<f64>> {
        self.end.translational_stiffness()
    }

    /// Joint `i`'s 2 × 2 block of `K_q` (`K_{i,x}`, `K_{i,y}` on the diagonal).
    pub fn joint_stiffness(&self, i: usize) -> Option<Matrix2<f64>> {
        joint_block(self.k_q.as_ref(), i)
    }

    /// Every joint's feasible tension interval.
    pub fn intervals(&self) -> &[TensionInterval] {
        &self.statics.intervals
    }

    /// The tensions (N), cables in routing order.
    pub fn tensions(&self) -> &[f64] {
        &self.statics.tensions
    }

    /// The outcome of the last end stage, `None` when the stages since the last pose have not
    /// reached it ([`crate::ArmStiffness::solve_end`]).
    pub fn end_outcome(&self) -> Option<EndOutcome> {
        match self.stage {
            Stage::Ended(outcome) => Some(outcome),
            _ => None,
        }
    }

    /// How many pose stages this workspace has run since it was made: what a caller that
    /// should pose once (the planner) is tested by.
    pub fn pose_stages(&self) -> u64 {
        self.pose_stages
    }

    /// Which solver computed the last end compliance.
    pub fn end_solver(&self) -> EndSolver {
        self.solver
    }

    /// The backward error of the residual check of the last structured solve
    /// (`structured/mod.rs`): about `1e-17` when it was accepted, above `1e-12` when it was
    /// rejected for the dense path; NaN when the last evaluation did not reach the check (no
    /// structured solve, or a pivot block not positive definite).
    pub fn structured_backward_error(&self) -> f64 {
        self.structured.backward_error
    }
}
