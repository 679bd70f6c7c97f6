//! Forward kinematics, point Jacobians and their derivatives with respect to `Q`.
//!
//! # Math
//! Joint `j` has, in the base frame, the unit axis `a_j` through the point `p_j`. For a point
//! `p` on body `b`, joints `j < b` move it, and the 6 × dof geometric Jacobian (linear rows
//! first, base frame; spec §5) has the columns
//!
//! ```text
//! J[:, j] = [ a_j × (p − p_j) ; a_j ]   (j < b),     0 otherwise.
//! ```
//!
//! Differentiating with `∂a_j/∂q_i = a_i × a_j` for `i ≤ j` (zero for `i > j`):
//!
//! ```text
//! ∂J[:, j]/∂q_i = [ a_i × v_j ; a_i × a_j ]   for i ≤ j < b,
//!               = [ a_j × v_i ; 0 ]           for j < i < b,        v_k = a_k × (p − p_k)
//! ```
//!
//! which is also the second derivative of the point, `∂²p/∂q_i∂q_j = a_min × v_max`.

use faer::MatMut;
use nalgebra::{IsometryMatrix3, Matrix3, Rotation3, Unit, Vector3, Vector6};

use crate::error::{Result, RobotError};
use crate::model::{BodyPoint, Robot};

/// The reusable workspace of a [`Robot`] (Pinocchio's *data*): everything computed for one
/// configuration, sized once so that evaluating a configuration allocates nothing.
///
/// Names say the frame: `o_` is the base frame.
#[derive(Debug, Clone)]
pub struct RobotData {
    dof: usize,
    /// Pose of every body frame in the base frame (`o_M_b`), root first.
    pub(crate) o_m_body: Vec<IsometryMatrix3<f64>>,
    /// Joint axes in the base frame.
    pub(crate) o_axis: Vec<Vector3<f64>>,
    /// A point of each joint axis (the joint frame origin) in the base frame.
    pub(crate) o_pivot: Vec<Vector3<f64>>,
    /// Gravity accumulators: `r_j = Σ_{b > j} m_b (c_b − p_j)` in the base frame.
    pub(crate) o_mass_moment: Vec<Vector3<f64>>,
    /// Scratch for one point's partial velocities `v_j = a_j × (p − p_j)`.
    pub(crate) v: Vec<Vector3<f64>>,
}

impl RobotData {
    /// A workspace sized for `robot`.
    pub fn new(robot: &Robot) -> RobotData {
        let n = robot.dof();
        RobotData {
            dof: n,
            o_m_body: vec![IsometryMatrix3::identity(); n + 1],
            o_axis: vec![Vector3::zeros(); n],
            o_pivot: vec![Vector3::zeros(); n],
            o_mass_moment: vec![Vector3::zeros(); n],
            v: vec![Vector3::zeros(); n],
        }
    }

    /// Number of joints the workspace is sized for.
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// Pose of body `b` in the base frame, as of the last [`Robot::forward_kinematics`].
    pub fn body_pose(&self, b: usize) -> Option<&IsometryMatrix3<f64>> {
        self.o_m_body.get(b)
    }

    /// Axis of joint `j` in the base frame.
    pub fn joint_axis(&self, j: usize) -> Option<&Vector3<f64>> {
        self.o_axis.get(j)
    }

    /// Origin of joint `j`'s frame (a point on its axis) in the base frame.
    pub fn joint_origin(&self, j: usize) -> Option<&Vector3<f64>> {
        self.o_pivot.get(j)
    }

    pub(crate) fn check(&self, robot: &Robot) -> Result<()> {
        if self.dof != robot.dof() {
            return Err(RobotError::WorkspaceMismatch {
                data_dof: self.dof,
                robot_dof: robot.dof(),
            });
        }
        Ok(())
    }
}

pub(crate) fn check_shape(
    what: &'static str,
    m: &MatMut<'_, f64>,
    rows: usize,
    cols: usize,
) -> Result<()> {
    if m.nrows() != rows {
        return Err(RobotError::DimensionMismatch { what, expected: rows, got: m.nrows() });
    }
    if m.ncols() != cols {
        return Err(RobotError::DimensionMismatch { what, expected: cols, got: m.ncols() });
    }
    Ok(())
}

impl Robot {
    /// Forward kinematics: every body pose, joint axis and joint origin at `Q`, into `data`.
    ///
    /// Recursive from the base, `O(dof)`; allocates nothing. Limits are not enforced here
    /// (see [`Robot::check_limits`]).
    ///
    /// # Errors
    /// [`RobotError::WorkspaceMismatch`], [`RobotError::DimensionMismatch`],
    /// [`RobotError::NonFiniteAngle`].
    pub fn forward_kinematics(&self, data: &mut RobotData, q: &[f64]) -> Result<()> {
        data.check(self)?;
        self.check_configuration(q)?;
        for (j, joint) in self.joints.iter().enumerate() {
            // o_M_{j+1} = o_M_j · j_M_joint · Rot(axis, q_j): one isometry product and one
            // rotation, the rotation done on columns when the axis is a coordinate axis (the
            // URDF of a universal joint has x and y).
            let o_m_joint = data.o_m_body[j] * joint.origin;
            let axis = joint.axis.into_inner();
            data.o_axis[j] = o_m_joint.rotation * axis;
            data.o_pivot[j] = o_m_joint.translation.vector;
            let rotation = rotate(o_m_joint.rotation.matrix(), &axis, q[j]);
            data.o_m_body[j + 1] = IsometryMatrix3::from_parts(
                o_m_joint.translation,
                Rotation3::from_matrix_unchecked(rotation),
            );
        }
        Ok(())
    }

    /// Position of a body point in the base frame, after [`Robot::forward_kinematics`].
    ///
    /// # Errors
    /// [`RobotError::WorkspaceMismatch`], [`RobotError::NoSuchBody`].
    pub fn point_position(&self, data: &RobotData, point: &BodyPoint) -> Result<Vector3<f64>> {
        data.check(self)?;
        self.check_body(point.body)?;
        Ok(world_point(data, point))
    }

    /// Pose of the end-effector frame (the tip link) in the base frame.
    ///
    /// # Errors
    /// [`RobotError::WorkspaceMismatch`].
    pub fn tip_pose(&self, data: &RobotData) -> Result<IsometryMatrix3<f64>> {
        data.check(self)?;
        Ok(data.o_m_body[self.tip.body] * self.tip.body_m_link)
    }

    /// The 6 × dof geometric Jacobian of a body point: linear rows first, base frame.
    ///
    /// `out` must be 6 × dof; it is overwritten.
    ///
    /// # Errors
    /// [`RobotError::WorkspaceMismatch`], [`RobotError::NoSuchBody`],
    /// [`RobotError::DimensionMismatch`].
    pub fn point_jacobian(
        &self,
        data: &RobotData,
        point: &BodyPoint,
        mut out: MatMut<'_, f64>,
    ) -> Result<()> {
        data.check(self)?;
        self.check_body(point.body)?;
        check_shape("point Jacobian", &out, 6, self.dof())?;
        let p = world_point(data, point);
        out.fill(0.0);
        for j in 0..point.body {
            let a = data.o_axis[j];
            let v = a.cross(&(p - data.o_pivot[j]));
            for r in 0..3 {
                out[(r, j)] = v[r];
                out[(r + 3, j)] = a[r];
            }
        }
        Ok(())
    }

    /// `∂J/∂q_i`, the derivative of the point Jacobian with respect to joint `i` (6 × dof).
    ///
    /// Calling it for every `i` gives the whole derivative in `O(dof²)`.
    ///
    /// # Errors
    /// [`RobotError::WorkspaceMismatch`], [`RobotError::NoSuchBody`],
    /// [`RobotError::DimensionMismatch`] (also for `i ≥ dof`).
    pub fn point_jacobian_derivative(
        &self,
        data: &RobotData,
        point: &BodyPoint,
        i: usize,
        mut out: MatMut<'_, f64>,
    ) -> Result<()> {
        data.check(self)?;
        self.check_body(point.body)?;
        check_shape("point Jacobian derivative", &out, 6, self.dof())?;
        if i >= self.dof() {
            return Err(RobotError::DimensionMismatch {
                what: "joint index of the derivative",
                expected: self.dof(),
                got: i,
            });
        }
        out.fill(0.0);
        if i >= point.body {
            return Ok(());
        }
        let p = world_point(data, point);
        let a_i = data.o_axis[i];
        let v_i = a_i.cross(&(p - data.o_pivot[i]));
        for j in 0..point.body {
            let a_j = data.o_axis[j];
            let (lin, ang) = if i <= j {
                let v_j = a_j.cross(&(p - data.o_pivot[j]));
                (a_i.cross(&v_j), a_i.cross(&a_j))
            } else {
                (a_j.cross(&v_i), Vector3::zeros())
            };
            for r in 0..3 {
                out[(r, j)] = lin[r];
                out[(r + 3, j)] = ang[r];
            }
        }
        Ok(())
    }

    /// `J(Q)ᵀ F`: the joint torques that balance a wrench `F = [f; m]` (base frame) exerted by a
    /// body point on its environment (the load part of eq. 6). `out` has length dof.
    ///
    /// Computed without forming `J`: `(JᵀF)_j = f · (a_j × (p − p_j)) + m · a_j` for `j < b`.
    ///
    /// # Errors
    /// [`RobotError::WorkspaceMismatch`], [`RobotError::NoSuchBody`],
    /// [`RobotError::DimensionMismatch`].
    pub fn wrench_torque(
        &self,
        data: &RobotData,
        point: &BodyPoint,
        wrench: &Vector6<f64>,
        out: &mut [f64],
    ) -> Result<()> {
        data.check(self)?;
        self.check_body(point.body)?;
        if out.len() != self.dof() {
            return Err(RobotError::DimensionMismatch {
                what: "wrench torque",
                expected: self.dof(),
                got: out.len(),
            });
        }
        let f = wrench.fixed_rows::<3>(0).into_owned();
        let m = wrench.fixed_rows::<3>(3).into_owned();
        let p = world_point(data, point);
        out.fill(0.0);
        for j in 0..point.body {
            let a = data.o_axis[j];
            out[j] = f.dot(&a.cross(&(p - data.o_pivot[j]))) + m.dot(&a);
        }
        Ok(())
    }

    /// `∂(J(Q)ᵀ F)/∂Q` for a wrench `F = [f; m]` fixed in the base frame (dof × dof).
    ///
    /// Entry `(j, i)` is `∂(J[:, j] · F)/∂q_i`. This is the load part of the paper's `W` term
    /// (eq. 9); it is not symmetric in general. `O(dof²)`, no allocation.
    ///
    /// # Errors
    /// [`RobotError::WorkspaceMismatch`], [`RobotError::NoSuchBody`],
    /// [`RobotError::DimensionMismatch`].
    pub fn wrench_torque_derivative(
        &self,
        data: &mut RobotData,
        point: &BodyPoint,
        wrench: &Vector6<f64>,
        mut out: MatMut<'_, f64>,
    ) -> Result<()> {
        data.check(self)?;
        self.check_body(point.body)?;
        let n = self.dof();
        check_shape("wrench torque derivative", &out, n, n)?;
        out.fill(0.0);
        let f = wrench.fixed_rows::<3>(0).into_owned();
        let m = wrench.fixed_rows::<3>(3).into_owned();
        let p = world_point(data, point);
        let b = point.body;
        for j in 0..b {
            data.v[j] = data.o_axis[j].cross(&(p - data.o_pivot[j]));
        }
        for j in 0..b {
            let a_j = data.o_axis[j];
            let v_j = data.v[j];
            // i ≤ j: f·(a_i × v_j) + m·(a_i × a_j) = a_i · (v_j × f + a_j × m)
            let w = v_j.cross(&f) + a_j.cross(&m);
            for i in 0..=j {
                out[(j, i)] = data.o_axis[i].dot(&w);
            }
            // i > j: f·(a_j × v_i) = v_i · (f × a_j)
            let u = f.cross(&a_j);
            for i in j + 1..b {
                out[(j, i)] = data.v[i].dot(&u);
            }
        }
        Ok(())
    }
}

#[inline]
pub(crate) fn world_point(data: &RobotData, point: &BodyPoint) -> Vector3<f64> {
    let pose = &data.o_m_body[point.body];
    pose.rotation * point.point + pose.translation.vector
}

/// `R · Rot(axis, q)` for a unit `axis`: column operations when `axis` is `±x`, `±y` or `±z`
/// (exact zeros and ones of the elementary rotation need no arithmetic), Rodrigues' formula
/// otherwise.
#[inline]
fn rotate(r: &Matrix3<f64>, axis: &Vector3<f64>, q: f64) -> Matrix3<f64> {
    let (s, c) = q.sin_cos();
    let (c0, c1, c2) = (r.column(0), r.column(1), r.column(2));
    match (axis.x, axis.y, axis.z) {
        (x, 0.0, 0.0) if x.abs() == 1.0 => {
            let s = x * s;
            Matrix3::from_columns(&[c0.into_owned(), c1 * c + c2 * s, c2 * c - c1 * s])
        }
        (0.0, y, 0.0) if y.abs() == 1.0 => {
            let s = y * s;
            Matrix3::from_columns(&[c0 * c - c2 * s, c1.into_owned(), c0 * s + c2 * c])
        }
        (0.0, 0.0, z) if z.abs() == 1.0 => {
            let s = z * s;
            Matrix3::from_columns(&[c0 * c + c1 * s, c1 * c - c0 * s, c2.into_owned()])
        }
        _ => r * Rotation3::from_axis_angle(&Unit::new_unchecked(*axis), q).matrix(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The column shortcut equals `R · Rot(axis, q)` by Rodrigues for every signed coordinate
    /// axis, and the general branch is taken for any other axis.
    #[test]
    fn rotate_matches_rodrigues() {
        let r = *Rotation3::from_euler_angles(0.3, -1.1, 2.0).matrix();
        let mut axes: Vec<Vector3<f64>> = Vec::new();
        for k in 0..3 {
            let mut a = Vector3::zeros();
            a[k] = 1.0;
            axes.push(a);
            axes.push(-a);
        }
        axes.push(Vector3::new(1.0, 2.0, -0.5).normalize());
        for axis in &axes {
            for q in [-2.5, -0.4, 0.0, 0.7, 3.0] {
                let expected =
                    r * Rotation3::from_axis_angle(&Unit::new_normalize(*axis), q).matrix();
                let got = rotate(&r, axis, q);
                let err = (got - expected).abs().max();
                assert!(err <= 1e-15, "axis {axis:?}, q {q}: {err:e}");
            }
        }
    }
}
