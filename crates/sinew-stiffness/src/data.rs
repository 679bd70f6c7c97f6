//! [`ArmStiffnessData`]: the workspace of [`crate::ArmStiffness`], sized from it once, and the
//! results of its last evaluation.

use faer::MatRef;
use nalgebra::{Matrix2, Matrix3};
use sinew_robot::RobotData;
use sinew_routing::RoutingData;
use sinew_statics::{ArmStaticsData, TensionInterval};

use crate::arm::{ArmStiffness, EndSolver};
use crate::colmajor::ColMajor;
use crate::end::{EndStiffnessData, stability_margin};
use crate::error::StiffnessError;
use crate::joint::{InherentScratch, joint_block};
use crate::structured::{BlockLayout, StructuredData};

/// Every workspace and result of the pipeline, sized once from an [`ArmStiffness`] (no
/// allocation per configuration). A plain workspace: which arm it belongs to is checked by
/// [`ArmStiffness::check`] at every evaluation.
#[derive(Debug)]
pub struct ArmStiffnessData {
    /// Kinematics workspace.
    pub robot: RobotData,
    /// Cable geometry workspace (lengths, `J_c`, Hessians).
    pub cables: RoutingData,
    /// `T0`, `K_W`'s generators, `J_x`, intervals, tensions.
    pub statics: ArmStaticsData,
    /// The layout of the arm the workspace was made for (its check).
    layout: BlockLayout,
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
}

impl ArmStiffnessData {
    /// A workspace for `arm`.
    pub fn new(arm: &ArmStiffness) -> ArmStiffnessData {
        let n = arm.dof();
        let layout = arm.layout().clone();
        ArmStiffnessData {
            robot: RobotData::new(arm.robot()),
            cables: RoutingData::new(arm.routing()),
            statics: arm.statics().data(arm.robot()),
            structured: StructuredData::new(&layout),
            layout,
            solver: EndSolver::NotYet,
            k_controllable: ColMajor::zeros(n, n),
            k_inherent: ColMajor::zeros(n, n),
            inherent: arm.inherent_plan().scratch(),
            k_q: ColMajor::zeros(n, n),
            k_w_filled: ColMajor::zeros(n, n),
            end: EndStiffnessData::new(n),
            sensitivity: vec![0.0; arm.routing().cable_count()],
        }
    }

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
