//! Small dense kernels on stack arrays (`B ≤ 6`): the `L D Lᵀ` and the partially pivoted LU
//! of one block, their solves, and the rank-`K` updates of the sweep. The one LU here serves
//! both the structured solve's pivot blocks and the 6 × 6 inverse `K_x = C_x⁻¹` ([`crate::end`]).

#[inline(always)]
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `p · a` for a row-major 3 × 3 `p`.
#[inline(always)]
pub(crate) fn mul3(p: &[[f64; 3]; 3], a: [f64; 3]) -> [f64; 3] {
    [dot(p[0], a), dot(p[1], a), dot(p[2], a)]
}

/// `pᵀ · a`.
#[inline(always)]
pub(crate) fn mul3t(p: &[[f64; 3]; 3], a: [f64; 3]) -> [f64; 3] {
    [
        p[0][0] * a[0] + p[1][0] * a[1] + p[2][0] * a[2],
        p[0][1] * a[0] + p[1][1] * a[1] + p[2][1] * a[2],
        p[0][2] * a[0] + p[1][2] * a[1] + p[2][2] * a[2],
    ]
}

#[inline(always)]
pub(crate) fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// In-place `Â = L D Lᵀ` of the lower triangle of a block (`L` unit lower triangular below the
/// diagonal, `D⁻¹` on the diagonal); `false` unless every pivot `d_r` is positive (NaN
/// included). For a symmetric block this is Cholesky without its square roots:
/// `d_r = (L_chol)_rr²`, and the block is positive definite exactly when every `d_r > 0`.
#[inline(always)]
pub(crate) fn ldlt<const B: usize>(m: &mut [[f64; B]; B]) -> bool {
    let mut d = [0.0; B];
    for c in 0..B {
        // m[c][k] (k < c) holds L_ck; ld[k] = L_ck d_k.
        let mut ld = [0.0; B];
        let mut pivot = m[c][c];
        for k in 0..c {
            ld[k] = m[c][k] * d[k];
            pivot -= m[c][k] * ld[k];
        }
        // Written so that NaN is not positive.
        let positive = pivot > 0.0;
        if !positive {
            return false;
        }
        d[c] = pivot;
        let inv = 1.0 / pivot;
        m[c][c] = inv;
        for r in c + 1..B {
            let mut s = m[r][c];
            for k in 0..c {
                s -= m[r][k] * ld[k];
            }
            m[r][c] = s * inv;
        }
    }
    true
}

/// `V ← L⁻¹ V` for the rows `V[r]` (length `N`) of a `B × N` matrix, `L` unit lower triangular
/// (from [`ldlt`]).
#[inline(always)]
pub(crate) fn forward<const B: usize, const N: usize>(l: &[[f64; B]; B], v: &mut [[f64; N]; B]) {
    for r in 1..B {
        for k in 0..r {
            let f = l[r][k];
            let vk = v[k];
            for (x, y) in v[r].iter_mut().zip(vk) {
                *x -= f * y;
            }
        }
    }
}

/// `V ← D⁻¹ V` (from [`ldlt`]).
#[inline(always)]
pub(crate) fn scale<const B: usize, const N: usize>(l: &[[f64; B]; B], v: &mut [[f64; N]; B]) {
    for r in 0..B {
        let inv = l[r][r];
        for x in v[r].iter_mut() {
            *x *= inv;
        }
    }
}

/// `V ← L⁻ᵀ V`.
#[inline(always)]
pub(crate) fn backward<const B: usize, const N: usize>(l: &[[f64; B]; B], v: &mut [[f64; N]; B]) {
    for r in (0..B.saturating_sub(1)).rev() {
        for k in r + 1..B {
            let f = l[k][r];
            let vk = v[k];
            for (x, y) in v[r].iter_mut().zip(vk) {
                *x -= f * y;
            }
        }
    }
}

/// `S += Σ_r d_r⁻¹ V[r] V[r]ᵀ` on the upper triangle of `S` (`N × N`), the symmetric update
/// `Vᵀ D⁻¹ V` of [`ldlt`].
#[inline(always)]
pub(crate) fn add_gram<const B: usize, const N: usize>(
    l: &[[f64; B]; B],
    v: &[[f64; N]; B],
    s: &mut [[f64; N]; N],
) {
    let mut dv = *v;
    scale(l, &mut dv);
    add_at_b_upper(s, &dv, v);
}

/// `acc += Aᵀ B` for `A` (`K × M`) and `B` (`K × N`), row-major arrays: the rank-`K` updates
/// of the sweeps.
#[inline(always)]
pub(crate) fn add_at_b<const K: usize, const M: usize, const N: usize>(
    acc: &mut [[f64; N]; M],
    a: &[[f64; M]; K],
    b: &[[f64; N]; K],
) {
    for (p, acc_row) in acc.iter_mut().enumerate() {
        for (q, acc_pq) in acc_row.iter_mut().enumerate() {
            let mut sum = 0.0;
            for r in 0..K {
                sum += a[r][p] * b[r][q];
            }
            *acc_pq += sum;
        }
    }
}

/// [`add_at_b`] on and above the diagonal only (`M = N`), for updates known to be symmetric.
#[inline(always)]
pub(crate) fn add_at_b_upper<const K: usize, const N: usize>(
    acc: &mut [[f64; N]; N],
    a: &[[f64; N]; K],
    b: &[[f64; N]; K],
) {
    for p in 0..N {
        for q in p..N {
            let mut sum = 0.0;
            for r in 0..K {
                sum += a[r][p] * b[r][q];
            }
            acc[p][q] += sum;
        }
    }
}

/// In-place LU with partial pivoting of a block (`P Â = L U`, `L` unit lower, the diagonal of
/// `U` stored as its reciprocal); `false` for a zero or non-finite pivot.
#[inline(always)]
pub(crate) fn lu<const B: usize>(m: &mut [[f64; B]; B], perm: &mut [usize; B]) -> bool {
    for (r, p) in perm.iter_mut().enumerate() {
        *p = r;
    }
    for c in 0..B {
        let mut best = c;
        for r in c + 1..B {
            if m[r][c].abs() > m[best][c].abs() {
                best = r;
            }
        }
        if best != c {
            m.swap(best, c);
            perm.swap(best, c);
        }
        let pivot = m[c][c];
        if !(pivot != 0.0 && pivot.is_finite()) {
            return false;
        }
        let inv = 1.0 / pivot;
        m[c][c] = inv;
        for r in c + 1..B {
            let f = m[r][c] * inv;
            m[r][c] = f;
            for k in c + 1..B {
                m[r][k] -= f * m[c][k];
            }
        }
    }
    true
}

/// `V ← Â⁻¹ V` from the LU factors, for the rows `V[r]` of a `B × N` matrix.
#[inline(always)]
pub(crate) fn lu_solve<const B: usize, const N: usize>(
    m: &[[f64; B]; B],
    perm: &[usize; B],
    v: &mut [[f64; N]; B],
) {
    let mut t = [[0.0; N]; B];
    for r in 0..B {
        t[r] = v[perm[r]];
        for k in 0..r {
            let f = m[r][k];
            let tk = t[k];
            for (x, y) in t[r].iter_mut().zip(tk) {
                *x -= f * y;
            }
        }
    }
    for r in (0..B).rev() {
        for k in r + 1..B {
            let f = m[r][k];
            let tk = t[k];
            for (x, y) in t[r].iter_mut().zip(tk) {
                *x -= f * y;
            }
        }
        let inv = m[r][r];
        for x in t[r].iter_mut() {
            *x *= inv;
        }
    }
    *v = t;
}
