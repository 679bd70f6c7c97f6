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
//! (the crate's own up to 100 DOF, `cholesky.rs`, faer's above; in place, no allocation); the
//! smallest eigenvalue is computed only to report an unstable equilibrium, or on request
//! ([`stability_margin`]).
//!
//! This is the dense path, `O(dof³)`, for any `K_q` and `K_W`: the reference of the structured
//! `O(dof)` solve that [`crate::ArmStiffness`] uses when `K_q` is block diagonal (derivation
//! in `structured/mod.rs`). When `K_q + K_W` is exactly symmetric it is solved with
//! the Cholesky factor already computed for the verdict, else with a partially pivoted LU (the
//! crate's own up to `lu::SMALL` DOF, `lu.rs`; faer's above).
//! `K_x = C_x⁻¹` comes from a 6 × 6 LU with partial pivoting on the stack (the kernel the
//! structured solve uses for its pivot blocks), whose pivots also decide whether `J_x` has
//! full rank ([`crate::END_RANK_TOLERANCE`]).

use faer::dyn_stack::MemStack;
use faer::linalg::cholesky::llt;
use faer::linalg::lu::partial_pivoting as faer_lu;
use faer::{Mat, MatRef, Par, Side};
use sinew_statics::KwGenerators;

use crate::cholesky;
use crate::colmajor::ColMajor;
use crate::end_data::EndStiffnessData;
use crate::error::StiffnessError;
use crate::lu;

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
    // One pass over both triangles: finiteness, exact symmetry, the symmetric part.
    let mut symmetric = true;
    for j in 0..n {
        for i in j..n {
            let l = k_q[(i, j)] + k_w[(i, j)];
            let u = k_q[(j, i)] + k_w[(j, i)];
            if !(l.is_finite() && u.is_finite()) {
                return Err(StiffnessError::NonFinite { what: "K_q + K_W" });
            }
            symmetric &= u == l;
            let s = 0.5 * (u + l);
            *data.sym.at_mut(i, j) = s;
            *data.sym.at_mut(j, i) = s;
        }
    }
    if !symmetric {
        // K_q + K_W itself, for its LU factorisation.
        for j in 0..n {
            for i in 0..n {
                *data.a.at_mut(i, j) = k_q[(i, j)] + k_w[(i, j)];
            }
        }
    }
    if !factor_and_solve(j_x, symmetric, data) {
        return Err(StiffnessError::Unstable { min_eigenvalue: stability_margin(k_q, k_w)? });
    }
    Ok(())
}

/// [`end_compliance`] with `K_W` given by its generators (the arm's dense path): `K_W` is
/// written straight into the storage of `K_q + K_W` (its LU's), which one pass then completes
/// while forming the lower triangle of the symmetric part for the Cholesky factorisation. The
/// same sums as [`end_compliance`] with the dense `K_W`, term for term; no dof × dof matrix
/// besides those two. Returns `Ok(false)` when the symmetric part is not positive definite
/// (the caller reports the smallest eigenvalue).
///
/// `k_q_symmetric` says that `k_q` is exactly symmetric, as the frictionless pipeline and the
/// stick regime build it (their parts are written in symmetric pairs; `tests/routed.rs` and
/// the stick tests check it): when `K_W` is symmetric too (no moment in `F0`), only the lower
/// triangle of `K_q + K_W` is then formed, straight into the storage of the Cholesky factor.
/// A slip `K_q` is not symmetric: it takes the general branch.
///
/// # Errors
/// [`StiffnessError::NonFinite`]; [`StiffnessError::DimensionMismatch`].
pub(crate) fn end_compliance_generated(
    (k_q, k_q_symmetric): (&ColMajor, bool),
    k_w: &KwGenerators,
    j_x: MatRef<'_, f64>,
    data: &mut EndStiffnessData,
) -> Result<bool, StiffnessError> {
    let n = data.dof;
    check_square("K_q", k_q.as_ref(), n)?;
    if j_x.nrows() != 6 || j_x.ncols() != n {
        let got = if j_x.nrows() != 6 { j_x.nrows() } else { j_x.ncols() };
        let expected = if j_x.nrows() != 6 { 6 } else { n };
        return Err(StiffnessError::DimensionMismatch { what: "J_x", expected, got });
    }
    let mismatch =
        |_| StiffnessError::DimensionMismatch { what: "K_W", expected: n, got: k_w.len() };
    if k_q_symmetric && k_w.is_symmetric() {
        // K_q (symmetric by construction) + K_W (symmetric: no moment in F0) is its own
        // symmetric part: its lower triangle, formed in place of the Cholesky factor, is all
        // the solve needs (the same numbers as the general branch: 0.5 · (l + l) = l).
        k_w.fill_lower(data.sym.as_mut_slice()).map_err(mismatch)?;
        let mut finite = true;
        for j in 0..n {
            for (a, k) in data.sym.col_mut(j)[j..].iter_mut().zip(&k_q.col(j)[j..]) {
                *a += k;
                finite &= a.is_finite();
            }
        }
        if !finite {
            return Err(StiffnessError::NonFinite { what: "K_q + K_W" });
        }
        return Ok(factor_and_solve(j_x, true, data));
    }
    k_w.fill_dense(data.a.as_mut()).map_err(mismatch)?;
    // K_q + K_W in place, column by column.
    for j in 0..n {
        for (a, k) in data.a.col_mut(j).iter_mut().zip(k_q.col(j)) {
            *a += k; // k + a: IEEE addition commutes exactly
        }
    }
    // Finiteness, exact symmetry, the lower triangle of the symmetric part.
    let mut symmetric = true;
    for j in 0..n {
        for i in j..n {
            let (l, u) = (data.a.at(i, j), data.a.at(j, i));
            if !(l.is_finite() && u.is_finite()) {
                return Err(StiffnessError::NonFinite { what: "K_q + K_W" });
            }
            symmetric &= u == l;
            *data.sym.at_mut(i, j) = 0.5 * (u + l);
        }
    }
    Ok(factor_and_solve(j_x, symmetric, data))
}

/// The Cholesky factorisation `L Lᵀ` of `data.sym` (lower triangle: the symmetric part of
/// `K_q + K_W`), which is the stability verdict; then `C_x` (eq. 19). When `symmetric`,
/// `C_x = Yᵀ Y` with `Y = L⁻¹ J_xᵀ` ([`gram_of_forward_substitution`]: one triangular solve,
/// and `C_x` symmetric by construction); else `X = (K_q + K_W)⁻¹ J_xᵀ` with the LU of `data.a`
/// (`K_q + K_W`) and `C_x = J_x X`. `false` when the factorisation fails (not positive
/// definite).
fn factor_and_solve(j_x: MatRef<'_, f64>, symmetric: bool, data: &mut EndStiffnessData) -> bool {
    let n = data.dof;
    let stack = MemStack::new(&mut data.buffer);
    let stable = if n <= cholesky::SMALL {
        cholesky::cholesky_lower_in_place(data.sym.as_mut_slice(), n)
    } else {
        llt::factor::cholesky_in_place(
            data.sym.as_mut(),
            Default::default(),
            Par::Seq,
            stack,
            Default::default(),
        )
        .is_ok()
    };
    if !stable {
        return false;
    }
    // Y = J_xᵀ row by row (six values per joint): the right-hand sides of either solve.
    for (k, row) in data.y.chunks_exact_mut(6).enumerate() {
        for (r, v) in row.iter_mut().enumerate() {
            *v = j_x[(r, k)];
        }
    }
    if symmetric {
        // L⁻¹ Y in place, then C_x = Yᵀ Y.
        pulp::Arch::new().dispatch(Gram { l: &data.sym, y: &mut data.y, c_x: &mut data.c_x });
        return true;
    }
    // X = (K_q + K_W)⁻¹ J_xᵀ into `y`: the small LU, or faer's above `lu::SMALL`.
    if n <= lu::SMALL {
        if !lu::lu_in_place(data.a.as_mut_slice(), n, &mut data.perm) {
            // A positive definite symmetric part makes K_q + K_W non-singular (xᵀ A x > 0):
            // only a matrix singular to working precision gets here, and it is reported as not
            // stable, with the smallest eigenvalue of its symmetric part.
            return false;
        }
        lu::lu_solve_six(data.a.as_slice(), n, &data.perm, &mut data.y);
    } else {
        for (k, row) in data.y.chunks_exact(6).enumerate() {
            for (c, v) in row.iter().enumerate() {
                data.x[(k, c)] = *v;
            }
        }
        let (_, perm) = faer_lu::factor::lu_in_place(
            data.a.as_mut(),
            &mut data.perm,
            &mut data.perm_inv,
            Par::Seq,
            stack,
            Default::default(),
        );
        faer_lu::solve::solve_in_place(
            data.a.as_ref(),
            data.a.as_ref(),
            perm,
            data.x.as_mut(),
            Par::Seq,
            stack,
        );
        for (k, row) in data.y.chunks_exact_mut(6).enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = data.x[(k, c)];
            }
        }
    }
    // C_x = J_x X: 36 dof multiply-adds in plain loops. (faer's matmul here returned with the
    // vector registers' upper halves dirty on the project machine, which slowed the scalar code
    // of the next evaluation threefold; see docs/performance.md.)
    for (c, out) in data.c_x.chunks_exact_mut(6).enumerate() {
        let mut col = [0.0; 6];
        for (k, x) in data.y.chunks_exact(6).enumerate() {
            for (r, v) in col.iter_mut().enumerate() {
                *v += j_x[(r, k)] * x[c];
            }
        }
        out.copy_from_slice(&col);
    }
    true
}

/// `Y ← L⁻¹ Y` (forward substitution with the lower Cholesky factor `l`, the six right-hand
/// sides of each row of the row-major dof × 6 `y` at once: column `k` of `L` updates the rows
/// below `k` by six-wide multiply-adds), then `C_x = Yᵀ Y` (column-major 6 × 6, exactly
/// symmetric): `J_x (L Lᵀ)⁻¹ J_xᵀ = (L⁻¹ J_xᵀ)ᵀ (L⁻¹ J_xᵀ)`. `dof²·3 + 36·dof` multiply-adds.
/// [`gram_of_forward_substitution`] as a pulp operation (`with_simd` is inlined into pulp's
/// dispatch, so the loops are compiled for AVX2 where the processor has it).
struct Gram<'a> {
    l: &'a ColMajor,
    y: &'a mut [f64],
    c_x: &'a mut [f64; 36],
}

impl pulp::WithSimd for Gram<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        gram_of_forward_substitution(self.l, self.y, self.c_x);
    }
}

#[inline(always)]
fn gram_of_forward_substitution(l: &ColMajor, y: &mut [f64], c_x: &mut [f64; 36]) {
    let n = l.cols();
    for k in 0..n {
        let column = &l.col(k)[k..];
        let (head, tail) = y.split_at_mut((k + 1) * 6);
        let y_k = &mut head[k * 6..];
        for v in y_k.iter_mut() {
            *v /= column[0];
        }
        for (row, &l_jk) in tail.chunks_exact_mut(6).zip(&column[1..]) {
            for t in 0..6 {
                row[t] -= l_jk * y_k[t];
            }
        }
    }
    let mut gram = [[0.0; 6]; 6];
    for row in y.chunks_exact(6) {
        for a in 0..6 {
            for b in 0..6 {
                gram[a][b] += row[a] * row[b];
            }
        }
    }
    for a in 0..6 {
        for b in 0..6 {
            // Exactly symmetric: row[a]·row[b] and row[b]·row[a] are the same products.
            c_x[a + 6 * b] = gram[a][b];
        }
    }
}

/// `C_x` and then `K_x = C_x⁻¹` (eq. 19) into `data`; read them with
/// [`EndStiffnessData::stiffness`], [`EndStiffnessData::k_fd`] and
/// [`EndStiffnessData::translational_stiffness`]. No allocation on success.
///
/// # Errors
/// Those of [`end_compliance`], and [`StiffnessError::RankDeficient`] when `J_x` has rank < 6
/// (a pivot of `C_x` below [`crate::END_RANK_TOLERANCE`] of the largest): `C_x` is then still in `data`.
pub fn end_stiffness(
    k_q: MatRef<'_, f64>,
    k_w: MatRef<'_, f64>,
    j_x: MatRef<'_, f64>,
    data: &mut EndStiffnessData,
) -> Result<(), StiffnessError> {
    end_compliance(k_q, k_w, j_x, data)?;
    data.invert_compliance()
}
