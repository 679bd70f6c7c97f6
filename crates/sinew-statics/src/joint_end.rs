//! Joint-end statics: the equilibrium torques `T0(Q)` and their derivative `K_W = ∂T0/∂Q`
//! (eq. 6–9, spec §5).
//!
//! # Math
//! ```text
//! T0(Q)  = T_g(Q) + J_x(Q)ᵀ F0                                  (eq. 6)
//! K_W    = ∂T0/∂Q = ∂T_g/∂Q + ∂(J_x(Q)ᵀ F0)/∂Q   (F0 fixed in the base frame; eq. 9's W)
//! ```
//! `J_x` is the 6 × dof Jacobian of the end-effector point (linear rows first, base frame),
//! `F0 = [Fx, Fy, Fz, Mx, My, Mz]` the wrench the end-effector exerts on its environment, and
//! `T_g = ∂V/∂Q` the torques that hold the links against gravity. `∂T_g/∂Q` is symmetric (the
//! Hessian of `V`). So is the load part when `F0` is a pure force: a force fixed in the base
//! frame is conservative (potential `−F·p(Q)`). A moment fixed in the base frame is not
//! conservative, and then `K_W` is not symmetric (`∂(J_ωᵀ m)/∂Q` has entries `m·(a_i × a_j)`
//! on and below the diagonal only). Tests check both statements.

use faer::{Mat, MatMut};
use nalgebra::Vector6;
use sinew_robot::{Robot, RobotData};

use crate::error::StaticsError;

/// Workspace of the joint-end statics, sized once for a robot.
#[derive(Debug, Clone)]
pub struct JointEndData {
    scratch: Vec<f64>,
    square: Mat<f64>,
}

impl JointEndData {
    /// A workspace sized for `robot`.
    pub fn new(robot: &Robot) -> JointEndData {
        let n = robot.dof();
        JointEndData { scratch: vec![0.0; n], square: Mat::zeros(n, n) }
    }
}

fn check_wrench(f0: &Vector6<f64>) -> Result<(), StaticsError> {
    if f0.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        let mut wrench = [0.0; 6];
        wrench.copy_from_slice(f0.as_slice());
        Err(StaticsError::NonFiniteWrench { wrench })
    }
}

/// `T0 = T_g(Q) + J_x(Q)ᵀ F0` (eq. 6): the joint torques the cables must supply (N m).
///
/// Needs `robot.forward_kinematics(rdata, q)` first. `t0` has length dof. No allocation.
///
/// # Errors
/// [`StaticsError::NonFiniteWrench`], and robot errors for sizes and workspaces.
pub fn equilibrium_torques(
    robot: &Robot,
    rdata: &mut RobotData,
    data: &mut JointEndData,
    f0: &Vector6<f64>,
    t0: &mut [f64],
) -> Result<(), StaticsError> {
    check_wrench(f0)?;
    robot.gravity_torque(rdata, t0)?;
    robot.wrench_torque(rdata, &robot.tip_point(), f0, &mut data.scratch)?;
    for (t, load) in t0.iter_mut().zip(&data.scratch) {
        *t += load;
    }
    Ok(())
}

/// `K_W = ∂T0/∂Q = ∂T_g/∂Q + ∂(J_xᵀ F0)/∂Q` (eq. 9), dof × dof, with `F0` fixed in the base
/// frame. Entry `(j, i)` is `∂T0_j/∂q_i`.
///
/// Needs `robot.forward_kinematics(rdata, q)` first. No allocation.
///
/// # Errors
/// [`StaticsError::NonFiniteWrench`], and robot errors for sizes and workspaces.
pub fn equilibrium_torque_derivative(
    robot: &Robot,
    rdata: &mut RobotData,
    data: &mut JointEndData,
    f0: &Vector6<f64>,
    mut k_w: MatMut<'_, f64>,
) -> Result<(), StaticsError> {
    check_wrench(f0)?;
    robot.gravity_torque_derivative(rdata, k_w.as_mut())?;
    robot.wrench_torque_derivative(rdata, &robot.tip_point(), f0, data.square.as_mut())?;
    let n = robot.dof();
    for j in 0..n {
        for i in 0..n {
            k_w[(i, j)] += data.square[(i, j)];
        }
    }
    Ok(())
}
