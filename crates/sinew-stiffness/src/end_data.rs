//! [`EndStiffnessData`], the end stage's workspace (eq. 19), and the one test of whether `J_x`
//! has full rank ([`has_full_rank`]).

use faer::dyn_stack::{MemBuffer, StackReq};
use faer::linalg::cholesky::llt;
use faer::linalg::lu::partial_pivoting as lu;
use faer::{Mat, MatRef, Par};
use nalgebra::{Matrix3, Matrix6};

use crate::colmajor::ColMajor;
use crate::error::StiffnessError;

/// Relative size below which a pivot of `C_x`'s factorisation counts as zero: the end-effector
/// Jacobian has rank < 6 and `K_x` does not exist ([`has_full_rank`], the one test of it).
/// The same fraction decides that `C_x[0:3, 0:3]` is singular
/// ([`EndStiffnessData::translational_stiffness`]).
pub const END_RANK_TOLERANCE: f64 = 1e-10;

/// Whether `J_x` has full rank, read from the compliance `C_x = J_x (K_q + K_W)⁻¹ J_xᵀ` of a
/// stable arm: the one definition of it in Sinew. `C_x`'s 6 × 6 LU with partial pivoting has
/// every pivot above [`END_RANK_TOLERANCE`] of the largest in magnitude (NaN fails).
pub fn has_full_rank(c_x: &Matrix6<f64>) -> bool {
    compliance_inverse(c_x).is_ok()
}

/// `K_x = C_x⁻¹` (eq. 19) when `J_x` has full rank ([`has_full_rank`]): the same LU, rank test
/// and solve as the pipeline's end stage.
///
/// # Errors
/// [`StiffnessError::RankDeficient`] with the pivot ratio.
pub fn compliance_inverse(c_x: &Matrix6<f64>) -> Result<Matrix6<f64>, StiffnessError> {
    let mut flat = [0.0; 36];
    flat.copy_from_slice(c_x.as_slice());
    let mut k_x = [0.0; 36];
    invert_6x6(&flat, &mut k_x)?;
    Ok(Matrix6::from_column_slice(&k_x))
}

/// `k_x = c_x⁻¹`, both column-major 6 × 6: LU with partial pivoting on the stack (the
/// structured solve's block LU), the rank test on its pivots, then the inverse from the factors
/// (`k_x` written only when the test passes).
fn invert_6x6(c_x: &[f64; 36], k_x: &mut [f64; 36]) -> Result<(), StiffnessError> {
    const IDENTITY: [[f64; 6]; 6] = [
        [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
    ];
    // Rows of C_x, factorised in place: P C_x = L U (the structured solve's block LU),
    // the reciprocals of U's pivots on the diagonal.
    let mut lu = [[0.0; 6]; 6];
    for (j, col) in c_x.chunks_exact(6).enumerate() {
        for (i, v) in col.iter().enumerate() {
            lu[i][j] = *v;
        }
    }
    let mut perm = [0; 6];
    let factored = crate::structured::lu(&mut lu, &mut perm);
    let (mut lo, mut hi) = (f64::INFINITY, 0.0_f64);
    if factored {
        for (r, row) in lu.iter().enumerate() {
            let pivot = 1.0 / row[r];
            (lo, hi) = (lo.min(pivot.abs()), hi.max(pivot.abs()));
        }
    } else {
        // A zero or non-finite pivot.
        lo = 0.0;
        hi = c_x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    }
    // Written so that NaN pivots also count as rank-deficient.
    let full_rank = factored && lo > END_RANK_TOLERANCE * hi;
    if !full_rank {
        return Err(StiffnessError::RankDeficient {
            pivot_ratio: if hi > 0.0 { lo / hi } else { 0.0 },
        });
    }
    // K_x = U⁻¹ L⁻¹ P, all six columns at once (x[r] is row r of the solution).
    let mut x = IDENTITY;
    crate::structured::lu_solve(&lu, &perm, &mut x);
    for (c, col) in k_x.chunks_exact_mut(6).enumerate() {
        for (r, out) in col.iter_mut().enumerate() {
            *out = x[r][c];
        }
    }
    Ok(())
}

/// Workspace of the end stiffness, sized once for `dof` joints: the factorisations run in place
/// in it, so evaluating a configuration allocates nothing.
pub struct EndStiffnessData {
    pub(crate) dof: usize,
    /// `K_q + K_W`, then its LU factors when it is not symmetric.
    pub(crate) a: ColMajor,
    /// Symmetric part of `K_q + K_W`, then its Cholesky factor.
    pub(crate) sym: ColMajor,
    /// faer's solve of the non-symmetric case above `lu::SMALL` DOF (dof × 6).
    pub(crate) x: Mat<f64>,
    /// `J_xᵀ`, then `L⁻¹ J_xᵀ` (the symmetric case) or `(K_q + K_W)⁻¹ J_xᵀ`: row-major dof × 6.
    pub(crate) y: Vec<f64>,
    /// `C_x`, column-major 6 × 6.
    pub(crate) c_x: [f64; 36],
    /// `K_x`, column-major 6 × 6.
    pub(crate) k_x: [f64; 36],
    pub(crate) perm: Vec<usize>,
    pub(crate) perm_inv: Vec<usize>,
    pub(crate) buffer: MemBuffer,
}

impl EndStiffnessData {
    /// A workspace for `dof` joints.
    pub fn new(dof: usize) -> EndStiffnessData {
        let req = StackReq::any_of(&[
            llt::factor::cholesky_in_place_scratch::<f64>(dof, Par::Seq, Default::default()),
            lu::factor::lu_in_place_scratch::<usize, f64>(dof, dof, Par::Seq, Default::default()),
            lu::solve::solve_in_place_scratch::<usize, f64>(dof, 6, Par::Seq),
        ]);
        EndStiffnessData {
            dof,
            a: ColMajor::zeros(dof, dof),
            sym: ColMajor::zeros(dof, dof),
            x: Mat::zeros(dof, 6),
            y: vec![0.0; 6 * dof],
            c_x: [0.0; 36],
            k_x: [0.0; 36],
            perm: vec![0; dof],
            perm_inv: vec![0; dof],
            buffer: MemBuffer::new(req),
        }
    }

    /// `C_x` (6 × 6, m/N, rad/(N m)) from the last [`crate::end_compliance`].
    pub fn compliance(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.c_x, 6, 6)
    }

    /// `K_x` (6 × 6) from the last [`crate::end_stiffness`].
    pub fn stiffness(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.k_x, 6, 6)
    }

    /// `K_fd = K_x[0:3, 0:3]` (N/m), the paper's translational stiffness (eq. 21): the force
    /// per unit displacement when the end-effector's rotation is held.
    pub fn k_fd(&self) -> Matrix3<f64> {
        Matrix3::from_fn(|i, j| self.k_x[i + 6 * j])
    }

    /// `(C_x[0:3, 0:3])⁻¹` (N/m): the force per unit displacement when the end-effector is
    /// free to rotate (a pure force applied). `None` when that block is singular: its smallest
    /// singular value at most [`END_RANK_TOLERANCE`] of its largest (the end cannot translate in
    /// some direction, and a plain inverse would return numbers of 1e17), or not finite.
    pub fn translational_stiffness(&self) -> Option<Matrix3<f64>> {
        let block = Matrix3::from_fn(|i, j| self.c_x[i + 6 * j]);
        let sv = block.singular_values();
        // Written so that NaN also counts as singular.
        if sv.min() > END_RANK_TOLERANCE * sv.max() { block.try_inverse() } else { None }
    }

    /// Store a compliance computed elsewhere (the structured solve), row-major.
    pub(crate) fn set_compliance(&mut self, c_x: &[[f64; 6]; 6]) {
        for (i, row) in c_x.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                self.c_x[i + 6 * j] = *v;
            }
        }
    }

    /// `K_x = C_x⁻¹` (eq. 19) from the stored `C_x`: LU with partial pivoting (6 × 6, on the
    /// stack), the rank test on its pivots, then the inverse from the factors (`K_x` written
    /// only when the test passes).
    ///
    /// # Errors
    /// [`StiffnessError::RankDeficient`] when a pivot is below [`END_RANK_TOLERANCE`] of the
    /// largest (NaN pivots included).
    pub(crate) fn invert_compliance(&mut self) -> Result<(), StiffnessError> {
        invert_6x6(&self.c_x, &mut self.k_x)
    }
}

impl std::fmt::Debug for EndStiffnessData {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EndStiffnessData")
            .field("dof", &self.dof)
            .field("c_x", &self.compliance())
            .field("k_x", &self.stiffness())
            .finish_non_exhaustive()
    }
}
