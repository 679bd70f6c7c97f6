//! The whole pipeline `Q → K_x` for a robot and its routing: kinematics, cable geometry,
//! `T0`, tensions, `K_q`, `K_W`, `J_x`, `C_x`, `K_x` (eq. 5–19).
//!
//! When `K_q` is block diagonal with small blocks (the decoupled model), `C_x` and the
//! stability verdict come from the structured `O(dof)` solve (`structured.rs` has the whole
//! derivation; [`ArmStiffness::evaluate`] the summary); otherwise, or when that solve does not
//! vouch for its result, from the dense reference ([`end_compliance`]).
//! [`ArmStiffnessData::end_solver`] tells which one ran.

use std::sync::{Mutex, OnceLock, PoisonError};

use faer::MatRef;
use nalgebra::{Matrix2, Matrix3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, Routing, RoutingData, compute_cable_geometry};
use sinew_statics::{ArmStatics, ArmStaticsData, StaticsError, TensionInterval};

use crate::end::{EndStiffnessData, end_compliance};
use crate::error::StiffnessError;
use crate::joint::{joint_block, joint_stiffness, joint_stiffness_in_blocks, stiffness_slope};
use crate::structured::{self, BlockLayout, ColMajor, KwGenerators, Structured, StructuredData};

/// The immutable part of the pipeline: the statics solver checked against the routing.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmStiffness {
    statics: ArmStatics,
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
    /// The dense reference [`end_compliance`]: Cholesky of the symmetric part of
    /// `K_q + K_W`, then a Cholesky or LU solve (`O(dof³)`).
    Dense,
}

/// Every workspace and result of the pipeline, sized once (no allocation per configuration).
#[derive(Debug)]
pub struct ArmStiffnessData {
    /// Kinematics workspace.
    pub robot: RobotData,
    /// Cable geometry workspace (lengths, `J_c`, Hessians).
    pub cables: RoutingData,
    /// `T0`, intervals, tensions.
    pub statics: ArmStaticsData,
    /// The blocks of `K_q` (from the routing the workspace was made for).
    layout: BlockLayout,
    /// The routing of the last evaluation fits `layout`.
    fits: bool,
    /// Every entry of the three joint-stiffness matrices outside `layout`'s blocks is zero.
    clean: bool,
    generators: KwGenerators,
    structured: StructuredData,
    solver: EndSolver,
    k_controllable: ColMajor,
    k_inherent: ColMajor,
    k_q: ColMajor,
    /// `K_W`, filled from `generators` at the first request after an evaluation
    /// ([`ArmStiffnessData::k_w`], the dense fallback): `O(dof²)` only when asked for.
    k_w: OnceLock<ColMajor>,
    /// The storage of `K_W` while `k_w` is empty (no allocation per configuration).
    k_w_spare: Mutex<Option<ColMajor>>,
    j_x: ColMajor,
    end: EndStiffnessData,
    sensitivity: Vec<f64>,
}

impl ArmStiffness {
    /// Check the routing against the statics solver.
    ///
    /// # Errors
    /// [`StiffnessError::Statics`] with [`StaticsError::UnsupportedRouting`].
    pub fn new(routing: &Routing) -> Result<ArmStiffness, StiffnessError> {
        Ok(ArmStiffness { statics: ArmStatics::new(routing)? })
    }

    /// The statics solver.
    pub fn statics(&self) -> &ArmStatics {
        &self.statics
    }

    /// A workspace for this robot and routing. The blocks of `K_q` (the DOFs no cable couples),
    /// which decide whether [`ArmStiffness::evaluate`] takes the structured path, are read from
    /// `routing` here.
    pub fn data(&self, robot: &Robot, routing: &Routing) -> ArmStiffnessData {
        let n = robot.dof();
        let layout = BlockLayout::new(routing);
        ArmStiffnessData {
            robot: RobotData::new(robot),
            cables: RoutingData::new(routing),
            statics: self.statics.data(robot),
            structured: StructuredData::new(&layout),
            layout,
            fits: false,
            clean: true,
            generators: KwGenerators::new(n),
            solver: EndSolver::NotYet,
            k_controllable: ColMajor::zeros(n, n),
            k_inherent: ColMajor::zeros(n, n),
            k_q: ColMajor::zeros(n, n),
            k_w: OnceLock::new(),
            k_w_spare: Mutex::new(Some(ColMajor::zeros(n, n))),
            j_x: ColMajor::zeros(6, n),
            end: EndStiffnessData::new(n),
            sensitivity: vec![0.0; routing.cable_count()],
        }
    }

    /// Everything up to the joint stiffness and `K_W` at `Q`, for the load `F0` (the wrench the
    /// end-effector exerts, base frame) and the tension `levels` (one per joint, in `[0, 1]`).
    ///
    /// `K_q` is accumulated over each cable's joint range only (its entries outside the blocks
    /// the routing's cables span stay exactly zero), `K_W` is filled from its `O(dof)`
    /// generators (`a_k`, `u_k`, `w_k`: [`Robot::gravity_torque_derivative_generators`],
    /// [`Robot::wrench_torque_derivative_generators`]), `J_x` is the tip's point Jacobian.
    ///
    /// # Errors
    /// Infeasible tensions ([`StaticsError::Infeasible`] inside [`StiffnessError::Statics`]),
    /// robot and routing errors.
    pub fn joint_level(
        &self,
        robot: &Robot,
        routing: &Routing,
        data: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
        levels: &[f64],
    ) -> Result<(), StiffnessError> {
        compute_cable_geometry(
            routing,
            robot,
            &mut data.robot,
            &mut data.cables,
            q,
            Order::Hessians,
        )
        .map_err(StaticsError::from)?;
        data.solver = EndSolver::NotYet;
        data.structured.backward_error = f64::NAN;
        self.statics.solve(robot, &mut data.robot, &data.cables, &mut data.statics, f0, levels)?;
        let n = robot.dof();
        data.fits = data.layout.fits(routing) && data.k_q.rows() == n;
        if data.fits && data.clean {
            joint_stiffness_in_blocks(
                routing,
                &data.cables,
                &data.statics.tensions,
                &data.layout,
                &mut data.k_controllable,
                &mut data.k_inherent,
                &mut data.k_q,
            )?;
        } else {
            // Whole matrices: the first evaluation after one with a routing the workspace was
            // not made for, or that routing itself.
            data.clean = false;
            joint_stiffness(
                routing,
                &data.cables,
                &data.statics.tensions,
                data.k_controllable.as_mut(),
                data.k_inherent.as_mut(),
            )?;
            for j in 0..n {
                for i in 0..n {
                    *data.k_q.at_mut(i, j) =
                        data.k_controllable.at(i, j) + data.k_inherent.at(i, j);
                }
            }
            data.clean = data.fits;
        }
        data.invalidate_k_w();
        // The generators of K_W, and J_x (Robot::point_jacobian's values) on the way.
        data.generators.compute(robot, &mut data.robot, f0, &mut data.j_x)?;
        Ok(())
    }

    /// `C_x` into `data.end`: the structured solve when it applies and vouches for its result,
    /// else the dense reference.
    fn compliance(&self, data: &mut ArmStiffnessData) -> Result<(), StiffnessError> {
        if data.fits && data.layout.structured() {
            let outcome = structured::compliance(
                &data.layout,
                &data.k_q,
                &data.generators,
                &data.j_x,
                &mut data.structured,
            );
            if outcome == Structured::Done {
                data.end.set_compliance(&data.structured.c_x);
                data.solver = EndSolver::Structured;
                return Ok(());
            }
        }
        data.solver = EndSolver::Dense;
        data.k_w_filled();
        let k_w = data.k_w.get().map(ColMajor::as_ref).ok_or_else(|| {
            StiffnessError::DimensionMismatch { what: "K_W", expected: data.k_q.rows(), got: 0 }
        })?;
        end_compliance(data.k_q.as_ref(), k_w, data.j_x.as_ref(), &mut data.end)
    }

    /// The whole pipeline `Q → K_x` (eq. 19): [`ArmStiffness::joint_level`], then `C_x` and
    /// `K_x`. No allocation on success.
    ///
    /// `C_x` comes from the structured `O(dof)` solve when `K_q` is block diagonal with blocks
    /// of at most four DOFs (the decoupled model), and from the dense reference
    /// ([`end_compliance`], `O(dof³)`) otherwise, or when the structured solve finds
    /// `K_q + K_W` not positive definite (the dense path then reports the smallest eigenvalue)
    /// or its residual check fails. Both give the same results to rounding;
    /// [`ArmStiffnessData::end_solver`] says which ran. `K_x = C_x⁻¹` by a 6 × 6 LU with partial
    /// pivoting, as in [`crate::end_stiffness`].
    ///
    /// # Math
    /// The structured solve, with `n = dof`, joint axes `a_j` (base frame), `K_q` block
    /// diagonal (one 2 × 2 block `K_k` per universal joint, eq. 18) and `K_W = ∂T0/∂Q` (eq. 9)
    /// semiseparable:
    ///
    /// ```text
    /// K_W[j, i] = a_i · w_j  (i ≤ j),   a_j · u_i  (i > j)     (1)   (n × n, from 9n numbers)
    /// u_k = g × (a_k × r_k) + v_k × f,   w_k = u_k + a_k × m,   J_x[:, k] = [v_k; a_k]
    /// ```
    ///
    /// (`F0 = [f; m]`; [`Robot::gravity_torque_derivative_generators`],
    /// [`Robot::wrench_torque_derivative_generators`], [`Robot::point_partial_velocities`]).
    /// Eliminating the joints from the tip keeps that form, less `a_iᵀ P a_j` for a 3 × 3 `P`
    /// (a block `U D L` factorisation, like the articulated-body recursion); per joint block `k`
    /// (`A_k = [a_j]` 3 × 2, `J_k = J_x[:, B_k]` 6 × 2):
    ///
    /// ```text
    /// ũ_j = u_j − P a_j,   w̃_j = w_j − Pᵀ a_j
    /// Â_k = K_k + [a_i · w̃_j (i ≤ j), a_j · ũ_i (i > j)]                   (2 × 2 pivot block)
    /// Ŷ_k = J_kᵀ − A_kᵀ Z,   Ĵ_k = J_k − Z' A_k                                 (2 × 6, 6 × 2)
    /// C_x += Ĵ_k Â_k⁻¹ Ŷ_k                                                          (eq. 19)
    /// Z += Ũ_k Â_k⁻¹ Ŷ_k,   Z' += Ĵ_k Â_k⁻¹ W̃_kᵀ,   P += Ũ_k Â_k⁻¹ W̃_kᵀ      (3 × 6, 6 × 3, 3 × 3)
    /// ```
    ///
    /// With no moment in `F0` (`w = u`) this is a block `LDLᵀ` of `K_q + K_W`, symmetric
    /// updates throughout, and by Sylvester's law `K_q + K_W ≻ 0` exactly when every `Â_k ≻ 0`;
    /// with a moment, the verdict comes from the same sweep over the symmetric part first
    /// (generators `½(u + w)`), then the solve from the non-symmetric sweep. Every result is
    /// checked by the residual of one back-substituted right-hand side against `(1)`, formed
    /// from the original generators (backward error ≤ `1e-12`, else the dense path). Cost
    /// `O(n)`: about 125 flops per DOF.
    ///
    /// # Errors
    /// Those of [`ArmStiffness::joint_level`]; [`StiffnessError::Unstable`] when `K_q + K_W` is
    /// not positive definite; [`StiffnessError::RankDeficient`] when `J_x` has rank < 6 (then
    /// the compliance is still in `data`).
    pub fn evaluate(
        &self,
        robot: &Robot,
        routing: &Routing,
        data: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
        levels: &[f64],
    ) -> Result<(), StiffnessError> {
        self.joint_level(robot, routing, data, q, f0, levels)?;
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
        robot: &Robot,
        routing: &Routing,
        data: &mut ArmStiffnessData,
        q: &[f64],
        f0: &Vector6<f64>,
        levels: &[f64],
    ) -> Result<(), StiffnessError> {
        self.joint_level(robot, routing, data, q, f0, levels)?;
        self.compliance(data)
    }

    /// `∂K_q/∂λ_i` at the last evaluated configuration (dof × dof, into `out`): `K_q` is affine
    /// in each joint's null-space coordinate `λ_i`, so a sweep over joint `i`'s tension levels
    /// is `K_q + (λ − λ_now) · slope`, with no new geometry. Exact in both models (routed:
    /// through the proximal joints' balancing tensions, see
    /// [`ArmStatics::tension_sensitivity`]).
    ///
    /// # Errors
    /// Dimension errors; statics errors.
    pub fn stiffness_slope(
        &self,
        routing: &Routing,
        data: &mut ArmStiffnessData,
        joint: usize,
        out: faer::MatMut<'_, f64>,
    ) -> Result<(), StiffnessError> {
        self.statics.tension_sensitivity(
            &data.cables,
            &data.statics,
            joint,
            &mut data.sensitivity,
        )?;
        stiffness_slope(routing, &data.cables, &data.sensitivity, out)
    }
}

impl ArmStiffnessData {
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

    /// `K_W = ∂T0/∂Q` (dof × dof). Filled from its generators at the first request after an
    /// evaluation (`O(dof²)`, no allocation); the structured solve does not need it.
    pub fn k_w(&self) -> MatRef<'_, f64> {
        self.k_w_filled().as_ref()
    }

    fn k_w_filled(&self) -> &ColMajor {
        self.k_w.get_or_init(|| {
            let spare = self.k_w_spare.lock().unwrap_or_else(PoisonError::into_inner).take();
            let n = self.k_q.rows();
            let mut k_w = spare.unwrap_or_else(|| ColMajor::zeros(n, n));
            self.generators.fill_dense(&mut k_w);
            k_w
        })
    }

    /// Forget the dense `K_W` of the previous configuration, keeping its storage.
    fn invalidate_k_w(&mut self) {
        if let Some(k_w) = self.k_w.take() {
            *self.k_w_spare.get_mut().unwrap_or_else(PoisonError::into_inner) = Some(k_w);
        }
    }

    /// `J_x`, the end-effector Jacobian (6 × dof, linear rows first, base frame).
    pub fn j_x(&self) -> MatRef<'_, f64> {
        self.j_x.as_ref()
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

    /// The backward error of the residual check of the last structured solve (see
    /// [`ArmStiffness::evaluate`]): about `1e-17` when it was accepted, above `1e-12` when it was
    /// rejected for the dense path; NaN when the last evaluation did not reach the check (no
    /// structured solve, or a pivot block not positive definite).
    pub fn structured_backward_error(&self) -> f64 {
        self.structured.backward_error
    }
}
