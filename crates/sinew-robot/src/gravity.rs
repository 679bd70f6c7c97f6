//! Gravity torques `T_g(Q)` and their derivative `∂T_g/∂Q` (spec §5; the gravity part of eq. 6
//! and of the paper's `W`, eq. 9).
//!
//! # Math
//! With `V(Q) = −Σ_b m_b g·c_b(Q)` the gravitational potential energy (g in the base frame,
//! `c_b` the centre of mass of body `b`), the torques that hold the links against gravity are
//! `T_g = ∂V/∂Q`. Writing `r_j = Σ_{b > j} m_b (c_b − p_j)` (mass moment of everything joint
//! `j` moves, about a point of its axis) and `w_j = a_j × r_j`:
//!
//! ```text
//! T_g[j]            = −g · (a_j × r_j) = −g · w_j
//! ∂T_g[j]/∂q_i      = a_min(i,j) · (g × w_max(i,j))        (symmetric: the Hessian of V)
//! ```
//!
//! Both are computed by one backward sweep (`O(dof)`) plus `O(dof²)` for the matrix; the
//! generators `a_k`, `u_k = g × w_k` alone cost `O(dof)` (sinew-statics forms them from
//! [`Robot::mass_moments`], with the load's, in one pass).

use faer::MatMut;
use nalgebra::Vector3;

use crate::error::{Result, RobotError};
use crate::kinematics::{RobotData, check_shape, world_point};
use crate::model::{BodyPoint, Robot};

impl Robot {
    fn accumulate_mass_moments(&self, data: &mut RobotData) {
        // S = Σ_{b > j} m_b c_b, accumulated from the tip; r_j = S − M_j p_j.
        let mut s = Vector3::zeros();
        for j in (0..self.dof()).rev() {
            let body = &self.bodies[j + 1];
            if body.mass > 0.0 {
                let c = world_point(data, &BodyPoint { body: j + 1, point: body.com });
                s += body.mass * c;
            }
            data.o_mass_moment[j] = s - self.subtree_mass[j] * data.o_pivot[j];
        }
    }

    /// The mass moments `r_j = Σ_{b > j} m_b (c_b − p_j)` (base frame, kg m): of everything
    /// joint `j` moves, about its pivot `p_j` (module docs), into `out` (length dof). With them
    /// `T_g[j] = −g · (a_j × r_j)` and the generators `u_j = g × (a_j × r_j)`: sinew-statics
    /// forms `T0`, `∂T0/∂Q`'s generators and `J_x` from them in one pass.
    ///
    /// Needs [`Robot::forward_kinematics`] first. `O(dof)`, no allocation.
    ///
    /// # Errors
    /// [`RobotError::WorkspaceMismatch`], [`RobotError::DimensionMismatch`].
    pub fn mass_moments(&self, data: &mut RobotData, out: &mut [Vector3<f64>]) -> Result<()> {
        data.check(self)?;
        if out.len() != self.dof() {
            return Err(RobotError::DimensionMismatch {
                what: "mass moments",
                expected: self.dof(),
                got: out.len(),
            });
        }
        self.accumulate_mass_moments(data);
        out.copy_from_slice(&data.o_mass_moment);
        Ok(())
    }

    /// `T_g(Q)`: the joint torques that hold the links against gravity, `∂V/∂Q` (N m).
    ///
    /// Needs [`Robot::forward_kinematics`] first; `out` has length dof.
    ///
    /// # Errors
    /// [`RobotError::WorkspaceMismatch`], [`RobotError::DimensionMismatch`].
    pub fn gravity_torque(&self, data: &mut RobotData, out: &mut [f64]) -> Result<()> {
        data.check(self)?;
        if out.len() != self.dof() {
            return Err(RobotError::DimensionMismatch {
                what: "gravity torque",
                expected: self.dof(),
                got: out.len(),
            });
        }
        self.accumulate_mass_moments(data);
        let g = self.gravity;
        for j in 0..self.dof() {
            out[j] = -g.dot(&data.o_axis[j].cross(&data.o_mass_moment[j]));
        }
        Ok(())
    }

    /// `∂T_g/∂Q` (dof × dof, symmetric): the Hessian of the gravitational potential energy.
    ///
    /// Needs [`Robot::forward_kinematics`] first.
    ///
    /// # Errors
    /// [`RobotError::WorkspaceMismatch`], [`RobotError::DimensionMismatch`].
    pub fn gravity_torque_derivative(
        &self,
        data: &mut RobotData,
        mut out: MatMut<'_, f64>,
    ) -> Result<()> {
        data.check(self)?;
        let n = self.dof();
        check_shape("gravity torque derivative", &out, n, n)?;
        self.accumulate_mass_moments(data);
        let g = self.gravity;
        // u_k = g × (a_k × r_k), kept in the scratch buffer.
        for k in 0..n {
            data.v[k] = g.cross(&data.o_axis[k].cross(&data.o_mass_moment[k]));
        }
        for j in 0..n {
            for i in 0..=j {
                let value = data.o_axis[i].dot(&data.v[j]);
                out[(j, i)] = value;
                out[(i, j)] = value;
            }
        }
        Ok(())
    }
}
