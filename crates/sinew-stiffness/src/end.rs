//! End compliance and end stiffness (eq. 19, spec §5).
//!
//! # Math
//! ```text
//! C_x = J_x (K_q + K_W)⁻¹ J_xᵀ     (6 × 6)       K_x = C_x⁻¹
//! K_fd = K_x[0:3, 0:3]             (eq. 21, the paper's choice: rotations held)
//! K_t  = (C_x[0:3, 0:3])⁻¹         (translational stiffness with rotations free)
//! ```
//! `δx = C_x δw` for a small wrench `δw` applied to the end-effector (base frame, linear
//! rows first). The equilibrium is stable when `K_q + K_W` is positive definite, i.e. when its
//! symmetric part is (the two coincide when the load is conservative: gravity and forces fixed
//! in the base frame). Stability is decided by a Cholesky factorisation of the symmetric part
//! (faer, in place, no allocation); the smallest eigenvalue is computed only to report an
//! unstable equilibrium, or on request ([`stability_margin`]).

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt;
use faer::linalg::lu::partial_pivoting as lu;
use faer::{Mat, MatMut, MatRef, Par, Side};
use nalgebra::Matrix3;

use crate::error::StiffnessError;

/// Relative size below which a pivot of `C_x`'s factorisation counts as zero: the end-effector
/// Jacobian has rank < 6 and `K_x` does not exist.
pub const RANK_TOLERANCE: f64 = 1e-10;

/// Workspace of the end stiffness, sized once for `dof` joints: the factorisations run in place
/// in it, so evaluating a configuration allocates nothing.
pub struct EndStiffnessData {
    dof: usize,
    /// `K_q + K_W`, then its LU factors when it is not symmetric.
    a: Mat<f64>,
    /// Symmetric part of `K_q + K_W`, then its Cholesky factor.
    sym: Mat<f64>,
    /// `(K_q + K_W)⁻¹ J_xᵀ` (dof × 6).
    x: Mat<f64>,
    c_x: Mat<f64>,
    k_x: Mat<f64>,
    lu6: Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    perm6: Vec<usize>,
    perm6_inv: Vec<usize>,
    buffer: MemBuffer,
}

impl EndStiffnessData {
    /// A workspace for `dof` joints.
    pub fn new(dof: usize) -> EndStiffnessData {
        let req = StackReq::any_of(&[
            llt::factor::cholesky_in_place_scratch::<f64>(dof, Par::Seq, Default::default()),
            llt::solve::solve_in_place_scratch::<f64>(dof, 6, Par::Seq),
            lu::factor::lu_in_place_scratch::<usize, f64>(dof, dof, Par::Seq, Default::default()),
            lu::solve::solve_in_place_scratch::<usize, f64>(dof, 6, Par::Seq),
            lu::factor::lu_in_place_scratch::<usize, f64>(6, 6, Par::Seq, Default::default()),
            lu::solve::solve_in_place_scratch::<usize, f64>(6, 6, Par::Seq),
        ]);
        EndStiffnessData {
            dof,
            a: Mat::zeros(dof, dof),
            sym: Mat::zeros(dof, dof),
            x: Mat::zeros(dof, 6),
            c_x: Mat::zeros(6, 6),
            k_x: Mat::zeros(6, 6),
            lu6: Mat::zeros(6, 6),
            perm: vec![0; dof],
            perm_inv: vec![0; dof],
            perm6: vec![0; 6],
            perm6_inv: vec![0; 6],
            buffer: MemBuffer::new(req),
        }
    }

    /// `C_x` (6 × 6, m/N, rad/(N m)) from the last [`end_compliance`].
    pub fn compliance(&self) -> MatRef<'_, f64> {
        self.c_x.as_ref()
    }

    /// `K_x` (6 × 6) from the last [`end_stiffness`].
    pub fn stiffness(&self) -> MatRef<'_, f64> {
        self.k_x.as_ref()
    }

    /// `K_fd = K_x[0:3, 0:3]` (N/m), the paper's translational stiffness (eq. 21): the force
    /// per unit displacement when the end-effector's rotation is held.
    pub fn k_fd(&self) -> Matrix3<f64> {
        Matrix3::from_fn(|i, j| self.k_x[(i, j)])
    }

    /// `(C_x[0:3, 0:3])⁻¹` (N/m): the force per unit displacement when the end-effector is
    /// free to rotate (a pure force applied). `None` when that block is singular.
    pub fn translational_stiffness(&self) -> Option<Matrix3<f64>> {
        Matrix3::from_fn(|i, j| self.c_x[(i, j)]).try_inverse()
    }
}

impl std::fmt::Debug for EndStiffnessData {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EndStiffnessData")
            .field("dof", &self.dof)
            .field("c_x", &self.c_x)
            .field("k_x", &self.k_x)
            .finish_non_exhaustive()
    }
}

fn check_square(what: &'static str, m: MatRef<'_, f64>, n: usize) -> Result<(), StiffnessError> {
    for got in [m.nrows(), m.ncols()] {
        if got != n {
            return Err(StiffnessError::DimensionMismatch { what, expected: n, got });
        }
    }
    Ok(())
}

/// The smallest eigenvalue of the symmetric part of `K_q + K_W`: the stability margin
/// (positive: stable). Allocates (an eigen-decomposition); not for inner loops.
///
/// # Errors
/// [`StiffnessError::DimensionMismatch`], [`StiffnessError::Eigen`].
pub fn stability_margin(k_q: MatRef<'_, f64>, k_w: MatRef<'_, f64>) -> Result<f64, StiffnessError> {
    let n = k_q.nrows();
    check_square("K_q", k_q, n)?;
    check_square("K_W", k_w, n)?;
    let sym =
        Mat::from_fn(n, n, |i, j| 0.5 * (k_q[(i, j)] + k_q[(j, i)] + k_w[(i, j)] + k_w[(j, i)]));
    let eigenvalues =
        sym.self_adjoint_eigenvalues(Side::Lower).map_err(|_| StiffnessError::Eigen)?;
    Ok(eigenvalues.into_iter().fold(f64::INFINITY, f64::min))
}

/// `C_x = J_x (K_q + K_W)⁻¹ J_xᵀ` (eq. 19) into `data`; read it with
/// [`EndStiffnessData::compliance`].
///
/// `k_q`, `k_w`: dof × dof; `j_x`: 6 × dof (linear rows first, base frame). No allocation on
/// success.
///
/// # Errors
/// [`StiffnessError::Unstable`] with the smallest eigenvalue when `K_q + K_W` is not positive
/// definite; [`StiffnessError::NonFinite`]; [`StiffnessError::DimensionMismatch`].
pub fn end_compliance(
    k_q: MatRef<'_, f64>,
    k_w: MatRef<'_, f64>,
    j_x: MatRef<'_, f64>,
    data: &mut EndStiffnessData,
) -> Result<(), StiffnessError> {
    let n = data.dof;
    check_square("K_q", k_q, n)?;
    check_square("K_W", k_w, n)?;
    if j_x.nrows() != 6 || j_x.ncols() != n {
        let got = if j_x.nrows() != 6 { j_x.nrows() } else { j_x.ncols() };
        let expected = if j_x.nrows() != 6 { 6 } else { n };
        return Err(StiffnessError::DimensionMismatch { what: "J_x", expected, got });
    }
    let mut symmetric = true;
    for j in 0..n {
        for i in 0..n {
            let v = k_q[(i, j)] + k_w[(i, j)];
            if !v.is_finite() {
                return Err(StiffnessError::NonFinite { what: "K_q + K_W" });
            }
            data.a[(i, j)] = v;
        }
    }
    for j in 0..n {
        for i in j..n {
            let (u, l) = (data.a[(j, i)], data.a[(i, j)]);
            if u != l {
                symmetric = false;
            }
            let s = 0.5 * (u + l);
            data.sym[(i, j)] = s;
            data.sym[(j, i)] = s;
        }
    }
    let stack = MemStack::new(&mut data.buffer);
    let stable = llt::factor::cholesky_in_place(
        data.sym.as_mut(),
        Default::default(),
        Par::Seq,
        stack,
        Default::default(),
    )
    .is_ok();
    if !stable {
        return Err(StiffnessError::Unstable { min_eigenvalue: stability_margin(k_q, k_w)? });
    }
    // X = (K_q + K_W)⁻¹ J_xᵀ.
    for c in 0..6 {
        for r in 0..n {
            data.x[(r, c)] = j_x[(c, r)];
        }
    }
    if symmetric {
        llt::solve::solve_in_place(data.sym.as_ref(), data.x.as_mut(), Par::Seq, stack);
    } else {
        let (_, perm) = lu::factor::lu_in_place(
            data.a.as_mut(),
            &mut data.perm,
            &mut data.perm_inv,
            Par::Seq,
            stack,
            Default::default(),
        );
        lu::solve::solve_in_place(
            data.a.as_ref(),
            data.a.as_ref(),
            perm,
            data.x.as_mut(),
            Par::Seq,
            stack,
        );
    }
    faer::linalg::matmul::matmul(
        data.c_x.as_mut(),
        faer::Accum::Replace,
        j_x,
        data.x.as_ref(),
        1.0,
        Par::Seq,
    );
    if symmetric {
        // Exact symmetry, as the math says.
        for j in 0..6 {
            for i in j + 1..6 {
                let s = 0.5 * (data.c_x[(i, j)] + data.c_x[(j, i)]);
                data.c_x[(i, j)] = s;
                data.c_x[(j, i)] = s;
            }
        }
    }
    Ok(())
}

/// `C_x` and then `K_x = C_x⁻¹` (eq. 19) into `data`; read them with
/// [`EndStiffnessData::stiffness`], [`EndStiffnessData::k_fd`] and
/// [`EndStiffnessData::translational_stiffness`]. No allocation on success.
///
/// # Errors
/// Those of [`end_compliance`], and [`StiffnessError::RankDeficient`] when `J_x` has rank < 6
/// (a pivot of `C_x` below [`RANK_TOLERANCE`] of the largest): `C_x` is then still in `data`.
pub fn end_stiffness(
    k_q: MatRef<'_, f64>,
    k_w: MatRef<'_, f64>,
    j_x: MatRef<'_, f64>,
    data: &mut EndStiffnessData,
) -> Result<(), StiffnessError> {
    end_compliance(k_q, k_w, j_x, data)?;
    data.lu6.copy_from(data.c_x.as_ref());
    let stack = MemStack::new(&mut data.buffer);
    let (_, perm) = lu::factor::lu_in_place(
        data.lu6.as_mut(),
        &mut data.perm6,
        &mut data.perm6_inv,
        Par::Seq,
        stack,
        Default::default(),
    );
    let pivots = (0..6).map(|i| data.lu6[(i, i)].abs());
    let (lo, hi) = pivots.fold((f64::INFINITY, 0.0_f64), |(lo, hi), p| (lo.min(p), hi.max(p)));
    // Written so that NaN pivots also count as rank-deficient.
    let full_rank = lo > RANK_TOLERANCE * hi;
    if !full_rank {
        return Err(StiffnessError::RankDeficient {
            pivot_ratio: if hi > 0.0 { lo / hi } else { 0.0 },
        });
    }
    let mut k_x: MatMut<'_, f64> = data.k_x.as_mut();
    k_x.fill(0.0);
    for i in 0..6 {
        k_x[(i, i)] = 1.0;
    }
    lu::solve::solve_in_place(data.lu6.as_ref(), data.lu6.as_ref(), perm, k_x, Par::Seq, stack);
    Ok(())
}
