//! Joint-end statics: the equilibrium torques `T0(Q)`, their derivative `K_W = ∂T0/∂Q` as
//! `O(dof)` generators, and the end-effector Jacobian `J_x`, in one pass (eq. 6–9, spec §5).
//! This module is the one owner of `∂T0/∂Q`: the dense `K_W`
//! ([`equilibrium_torque_derivative`]) is the fill of its generators ([`KwGenerators`]).
//!
//! # Math
//! ```text
//! T0(Q)  = T_g(Q) + J_x(Q)ᵀ F0                                  (eq. 6)
//! K_W    = ∂T0/∂Q = ∂T_g/∂Q + ∂(J_x(Q)ᵀ F0)/∂Q   (F0 fixed in the base frame; eq. 9's W)
//! ```
//! `J_x` is the 6 × dof Jacobian of the end-effector point (linear rows first, base frame),
//! `F0 = [f; m] = [Fx, Fy, Fz, Mx, My, Mz]` the wrench the end-effector exerts on its
//! environment, and `T_g = ∂V/∂Q` the torques that hold the links against gravity. With the
//! joint axes `a_k`, the mass moments `r_k` of the bodies joint `k` moves (about its pivot
//! `p_k`, [`Robot::mass_moments`]) and the partial velocities `v_k = a_k × (p − p_k)` of the tip
//! `p` (for the joints `k < b` that move the tip's body `b`; the load terms vanish for the
//! others):
//!
//! ```text
//! T0_k       = −g · (a_k × r_k) + f · v_k + m · a_k                                  (eq. 6)
//! u_k        = g × (a_k × r_k) + v_k × f,      w_k = u_k + a_k × m
//! K_W[j, i]  = a_i · w_j  (i ≤ j),             a_j · u_i  (i > j)                 (eq. 9)  (1)
//! J_x[:, k]  = [v_k; a_k]
//! ```
//!
//! so `K_W` is semiseparable: `9 · dof` numbers instead of `dof²`. `∂T_g/∂Q` is symmetric
//! (the Hessian of `V`). So is the load part when `F0` is a pure force: a force fixed in the
//! base frame is conservative (potential `−f·p(Q)`). A moment fixed in the base frame is not
//! conservative, and then `K_W` is not symmetric (`w ≠ u`: `∂(J_ωᵀ m)/∂Q` has entries
//! `m·(a_i × a_j)` on and below the diagonal only). Tests check both statements, and (1)
//! against central differences of `T0` and against sinew-robot's dense
//! `gravity_torque_derivative` + `wrench_torque_derivative`.

use faer::{MatMut, MatRef};
use nalgebra::{Vector3, Vector6};
use sinew_robot::{Robot, RobotData};

use crate::error::StaticsError;

/// The generators of `K_W = ∂T0/∂Q` (module docs, (1)): `K_W[j, i] = a_i · w_j` for `i ≤ j`,
/// `a_j · u_i` for `i > j`, one `[a_k, u_k, w_k]` per joint (base frame).
#[derive(Debug, Clone)]
pub struct KwGenerators {
    /// `[a_k, u_k, w_k]`.
    joints: Vec<[[f64; 3]; 3]>,
    /// `w = u` exactly (no moment in `F0`): `K_W` is symmetric.
    symmetric: bool,
}

impl KwGenerators {
    fn new(n: usize) -> KwGenerators {
        KwGenerators { joints: vec![[[0.0; 3]; 3]; n], symmetric: true }
    }

    /// The number of joints (dof).
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// Whether there are no joints.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// Whether `w = u` exactly (no moment in `F0`): then `K_W` is symmetric.
    pub fn is_symmetric(&self) -> bool {
        self.symmetric
    }

    /// `a_k`, joint `k`'s unit axis (base frame). Panics for `k ≥ dof` (an index, not input).
    #[inline(always)]
    pub fn a(&self, k: usize) -> [f64; 3] {
        self.joints[k][0]
    }

    /// `u_k` (the generator of the entries above the diagonal), N m.
    #[inline(always)]
    pub fn u(&self, k: usize) -> [f64; 3] {
        self.joints[k][1]
    }

    /// `w_k` (the generator of the entries on and below the diagonal), N m.
    #[inline(always)]
    pub fn w(&self, k: usize) -> [f64; 3] {
        self.joints[k][2]
    }

    /// The lower triangle (diagonal included) of `K_W` into `k_w`, a dof × dof column-major
    /// buffer, column by column: the values of [`KwGenerators::fill_dense`] there, the strict
    /// upper triangle untouched. With [`KwGenerators::is_symmetric`] this is all of `K_W`.
    /// `O(dof²/2)`, no allocation.
    ///
    /// # Errors
    /// [`StaticsError::DimensionMismatch`] unless `k_w.len()` is dof².
    pub fn fill_lower(&self, k_w: &mut [f64]) -> Result<(), StaticsError> {
        let n = self.len();
        if k_w.len() != n * n {
            return Err(StaticsError::DimensionMismatch {
                what: "K_W",
                expected: n * n,
                got: k_w.len(),
            });
        }
        for (i, column) in k_w.chunks_exact_mut(n.max(1)).enumerate().take(n) {
            let a_i = self.a(i);
            for (v, g) in column[i..].iter_mut().zip(&self.joints[i..]) {
                *v = dot(a_i, g[2]);
            }
        }
        Ok(())
    }

    /// `K_W` (dof × dof) from the generators, column by column (eq. 9, (1) of the module
    /// docs). `O(dof²)`, no allocation.
    ///
    /// # Errors
    /// [`StaticsError::DimensionMismatch`] unless `k_w` is dof × dof.
    pub fn fill_dense(&self, mut k_w: MatMut<'_, f64>) -> Result<(), StaticsError> {
        let n = self.len();
        for got in [k_w.nrows(), k_w.ncols()] {
            if got != n {
                return Err(StaticsError::DimensionMismatch { what: "K_W", expected: n, got });
            }
        }
        for i in 0..n {
            let (a_i, u_i) = (self.a(i), self.u(i));
            // Rows j < i: a_j · u_i; rows j ≥ i: a_i · w_j.
            for (j, g) in self.joints.iter().enumerate() {
                k_w[(j, i)] = if j < i { dot(g[0], u_i) } else { dot(a_i, g[2]) };
            }
        }
        Ok(())
    }
}

#[inline(always)]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Workspace and results of the joint-end statics, sized once for a robot: the generators of
/// `K_W` and `J_x` of the last [`equilibrium_torques`].
#[derive(Debug, Clone)]
pub struct JointEndData {
    generators: KwGenerators,
    /// `J_x`, column by column (6 × dof).
    j_x: Vec<[f64; 6]>,
    /// The mass moments `r_k` (scratch).
    mass_moments: Vec<Vector3<f64>>,
    /// `T0` for [`equilibrium_torque_derivative`] (scratch).
    t0: Vec<f64>,
}

impl JointEndData {
    /// A workspace sized for `robot`.
    pub fn new(robot: &Robot) -> JointEndData {
        let n = robot.dof();
        JointEndData {
            generators: KwGenerators::new(n),
            j_x: vec![[0.0; 6]; n],
            mass_moments: vec![Vector3::zeros(); n],
            t0: vec![0.0; n],
        }
    }

    /// The generators of `K_W` at the last [`equilibrium_torques`].
    pub fn generators(&self) -> &KwGenerators {
        &self.generators
    }

    /// `J_x`, the end-effector Jacobian (6 × dof, linear rows first, base frame) at the last
    /// [`equilibrium_torques`]: the values of [`Robot::point_jacobian`] at the tip.
    pub fn j_x(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(self.j_x.as_flattened(), 6, self.j_x.len())
    }

    /// The columns of `J_x`, `[v_k; a_k]` (dof).
    pub fn j_x_columns(&self) -> &[[f64; 6]] {
        &self.j_x
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

/// `T0 = T_g(Q) + J_x(Q)ᵀ F0` (eq. 6): the joint torques the cables must supply (N m), and on
/// the way, from the same mass moments and partial velocities, the generators of
/// `K_W = ∂T0/∂Q` (eq. 9) and `J_x` into `data` ([`JointEndData::generators`],
/// [`JointEndData::j_x`]): one pass, `O(dof)`.
///
/// Needs `robot.forward_kinematics(rdata, q)` first. `t0` has length dof. No allocation.
///
/// # Errors
/// [`StaticsError::NonFiniteWrench`], [`StaticsError::DimensionMismatch`], and robot errors
/// for workspaces.
pub fn equilibrium_torques(
    robot: &Robot,
    rdata: &mut RobotData,
    data: &mut JointEndData,
    f0: &Vector6<f64>,
    t0: &mut [f64],
) -> Result<(), StaticsError> {
    check_wrench(f0)?;
    let n = robot.dof();
    for (what, expected, got) in
        [("equilibrium torques T0", n, t0.len()), ("joint-end workspace", n, data.j_x.len())]
    {
        if expected != got {
            return Err(StaticsError::DimensionMismatch { what, expected, got });
        }
    }
    robot.mass_moments(rdata, &mut data.mass_moments)?;
    let tip = robot.tip_point();
    let p = robot.point_position(rdata, &tip)?;
    let g = robot.gravity();
    let f = Vector3::new(f0[0], f0[1], f0[2]);
    let m = Vector3::new(f0[3], f0[4], f0[5]);
    let symmetric = m == Vector3::zeros();
    data.generators.symmetric = symmetric;
    let b = tip.body.min(n);
    for k in 0..n {
        let (Some(&a), Some(&pivot)) = (rdata.joint_axis(k), rdata.joint_origin(k)) else {
            return Err(StaticsError::DimensionMismatch {
                what: "robot workspace (joints)",
                expected: n,
                got: k,
            });
        };
        let ar = a.cross(&data.mass_moments[k]);
        let gravity = g.cross(&ar);
        let (load, u, w, column) = if k < b {
            let v = a.cross(&(p - pivot));
            let vf = v.cross(&f);
            let u = gravity + vf;
            let w = if symmetric { u } else { gravity + (vf + a.cross(&m)) };
            (f.dot(&v) + m.dot(&a), u, w, [v.x, v.y, v.z, a.x, a.y, a.z])
        } else {
            (0.0, gravity, gravity, [0.0; 6])
        };
        t0[k] = -g.dot(&ar) + load;
        data.generators.joints[k] = [a.into(), u.into(), w.into()];
        data.j_x[k] = column;
    }
    Ok(())
}

/// `K_W = ∂T0/∂Q = ∂T_g/∂Q + ∂(J_xᵀ F0)/∂Q` (eq. 9), dof × dof, with `F0` fixed in the base
/// frame: the dense fill of the generators of [`equilibrium_torques`]
/// ([`KwGenerators::fill_dense`]). Entry `(j, i)` is `∂T0_j/∂q_i`.
///
/// Needs `robot.forward_kinematics(rdata, q)` first. `O(dof²)`, no allocation.
///
/// # Errors
/// [`StaticsError::NonFiniteWrench`], [`StaticsError::DimensionMismatch`], and robot errors
/// for workspaces.
pub fn equilibrium_torque_derivative(
    robot: &Robot,
    rdata: &mut RobotData,
    data: &mut JointEndData,
    f0: &Vector6<f64>,
    k_w: MatMut<'_, f64>,
) -> Result<(), StaticsError> {
    // T0 is a by-product of the one pass, into the workspace's scratch.
    let mut t0 = std::mem::take(&mut data.t0);
    let pass = equilibrium_torques(robot, rdata, data, f0, &mut t0);
    data.t0 = t0;
    pass?;
    data.generators.fill_dense(k_w)
}
