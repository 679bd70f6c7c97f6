//! The whole pipeline `Q → K_x` for a robot and its routing: kinematics, cable geometry,
//! `T0`, tensions, `K_q`, `K_W`, `J_x`, `C_x`, `K_x` (eq. 5–19).

use faer::{Mat, MatRef};
use nalgebra::{Matrix2, Matrix3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, Routing, RoutingData, compute_cable_geometry};
use sinew_statics::{
    ArmStatics, ArmStaticsData, JointEndData, StaticsError, TensionInterval,
    equilibrium_torque_derivative,
};

use crate::end::{EndStiffnessData, end_compliance, end_stiffness};
use crate::error::StiffnessError;
use crate::joint::{joint_block, joint_stiffness, stiffness_slope};

/// The immutable part of the pipeline: the statics solver checked against the routing.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmStiffness {
    statics: ArmStatics,
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
    joint_end: JointEndData,
    k_controllable: Mat<f64>,
    k_inherent: Mat<f64>,
    k_q: Mat<f64>,
    k_w: Mat<f64>,
    j_x: Mat<f64>,
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

    /// A workspace for this robot and routing.
    pub fn data(&self, robot: &Robot, routing: &Routing) -> ArmStiffnessData {
        let n = robot.dof();
        ArmStiffnessData {
            robot: RobotData::new(robot),
            cables: RoutingData::new(routing),
            statics: self.statics.data(robot),
            joint_end: JointEndData::new(robot),
            k_controllable: Mat::zeros(n, n),
            k_inherent: Mat::zeros(n, n),
            k_q: Mat::zeros(n, n),
            k_w: Mat::zeros(n, n),
            j_x: Mat::zeros(6, n),
            end: EndStiffnessData::new(n),
            sensitivity: vec![0.0; routing.cable_count()],
        }
    }

    /// Everything up to the joint stiffness and `K_W` at `Q`, for the load `F0` (the wrench the
    /// end-effector exerts, base frame) and the tension `levels` (one per joint, in `[0, 1]`).
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
        self.statics.solve(robot, &mut data.robot, &data.cables, &mut data.statics, f0, levels)?;
        joint_stiffness(
            routing,
            &data.cables,
            &data.statics.tensions,
            data.k_controllable.as_mut(),
            data.k_inherent.as_mut(),
        )?;
        let n = robot.dof();
        for j in 0..n {
            for i in 0..n {
                data.k_q[(i, j)] = data.k_controllable[(i, j)] + data.k_inherent[(i, j)];
            }
        }
        equilibrium_torque_derivative(
            robot,
            &mut data.robot,
            &mut data.joint_end,
            f0,
            data.k_w.as_mut(),
        )?;
        robot.point_jacobian(&data.robot, &robot.tip_point(), data.j_x.as_mut())?;
        Ok(())
    }

    /// The whole pipeline `Q → K_x` (eq. 19): [`ArmStiffness::joint_level`], then `C_x` and
    /// `K_x`. No allocation on success.
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
        end_stiffness(data.k_q.as_ref(), data.k_w.as_ref(), data.j_x.as_ref(), &mut data.end)
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
        end_compliance(data.k_q.as_ref(), data.k_w.as_ref(), data.j_x.as_ref(), &mut data.end)
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

    /// `K_W = ∂T0/∂Q` (dof × dof).
    pub fn k_w(&self) -> MatRef<'_, f64> {
        self.k_w.as_ref()
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
}
