//! Small dense kernels for the interior-point method: symmetric matrices stored row-major in a
//! flat slice (`a[r * n + c]`), factorised in place, with no allocation.
//!
//! # Numerics
//! The matrices are the method's slacks `S = F(x)` and its Schur complement: `n ≤ 200`,
//! positive definite where the method uses them. The Cholesky factorisation is the standard
//! column-oriented one (Golub and Van Loan, Alg. 4.2.1); it reports failure on the first pivot
//! that is not positive and finite, which is how the method tests `S ≻ 0` (its "Cholesky
//! trials") instead of computing eigenvalues. Tested against faer's `llt` below.

/// `Σ a_i b_i` over the shorter of the two, with four accumulators (so that the loop
/// vectorises and pipelines; the order of the additions is fixed, so results repeat).
#[inline(always)]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    let mut acc = [0.0; 4];
    for (x, y) in ca.zip(cb) {
        for i in 0..4 {
            acc[i] += x[i] * y[i];
        }
    }
    let mut s = (acc[0] + acc[2]) + (acc[1] + acc[3]);
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}

/// `y ← y + α x` over the shorter of the two.
#[inline(always)]
pub(crate) fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (o, v) in y.iter_mut().zip(x) {
        *o += alpha * v;
    }
}

/// Calls `$f::<N>` for the block sizes that have a fixed-size kernel (every `n ≤ 17`: an arm of
/// up to 16 DOF, its bordered compliance block included), else runs `$dynamic`.
macro_rules! fixed_size {
    ($n:expr, $f:ident($($arg:expr),*), $dynamic:expr) => {
        match $n {
            1 => $f::<1>($($arg),*),
            2 => $f::<2>($($arg),*),
            3 => $f::<3>($($arg),*),
            4 => $f::<4>($($arg),*),
            5 => $f::<5>($($arg),*),
            6 => $f::<6>($($arg),*),
            7 => $f::<7>($($arg),*),
            8 => $f::<8>($($arg),*),
            9 => $f::<9>($($arg),*),
            10 => $f::<10>($($arg),*),
            11 => $f::<11>($($arg),*),
            12 => $f::<12>($($arg),*),
            13 => $f::<13>($($arg),*),
            14 => $f::<14>($($arg),*),
            15 => $f::<15>($($arg),*),
            16 => $f::<16>($($arg),*),
            17 => $f::<17>($($arg),*),
            _ => $dynamic,
        }
    };
}

/// Overwrite the lower triangle of the symmetric `a` (n × n, only its lower triangle read) with
/// its Cholesky factor `L` (`a = L Lᵀ`); the strict upper triangle is scratch afterwards.
/// `false` (and `a` spoilt) when `a` is not positive definite to working precision.
///
/// Above n = 17 the pipeline's vectorised column-oriented factorisation (`cholesky_dynamic`);
/// up to n = 17 right-looking on fixed-size rows.
#[inline(always)]
pub(crate) fn cholesky(a: &mut [f64], n: usize) -> bool {
    fixed_size!(n, cholesky_fixed(a), cholesky_dynamic(a, n))
}

/// The fixed-size factorisation is right-looking: after each pivot the trailing rows are
/// updated in full (`row_i −= L_ij L_j` over all N columns, `L_j` zero up to j), which keeps
/// every loop at the fixed length N, at the price of overwriting the strict upper triangle.
#[inline(always)]
fn cholesky_fixed<const N: usize>(a: &mut [f64]) -> bool {
    let (rows, _) = a[..N * N].as_chunks_mut::<N>();
    for j in 0..N {
        let d = rows[j][j];
        if !(d > 0.0 && d < f64::INFINITY) {
            return false;
        }
        let d = d.sqrt();
        rows[j][j] = d;
        let inv = 1.0 / d;
        let mut column = [0.0; N];
        for i in j + 1..N {
            let v = rows[i][j] * inv;
            rows[i][j] = v;
            column[i] = v;
        }
        for i in j + 1..N {
            let li = column[i];
            for c in 0..N {
                rows[i][c] -= li * column[c];
            }
        }
    }
    true
}

/// Above the fixed sizes: the stiffness pipeline's column-oriented (Crout) factorisation,
/// vectorised ([`sinew_stiffness::cholesky_lower_in_place`]). A symmetric matrix is its own
/// transpose, so the row-major buffer is read as column-major once its lower triangle is
/// mirrored into the upper one; the factor, written into the column-major lower triangle
/// (the row-major upper one), is then mirrored back into the row-major lower triangle.
fn cholesky_dynamic(a: &mut [f64], n: usize) -> bool {
    mirror_lower(a, n);
    whole_dynamic(a, n, true)
}

/// [`cholesky`] of a matrix stored whole (both triangles, equal: the method's slacks,
/// multipliers and their steps are). Above the fixed sizes the factorisation reads the
/// row-major upper triangle, so it needs no mirror first; with `factor` false only the verdict
/// is wanted (a step length's trial) and the factor is not mirrored into the lower triangle
/// either (`a` is then spoilt).
#[inline(always)]
pub(crate) fn cholesky_whole(a: &mut [f64], n: usize, factor: bool) -> bool {
    fixed_size!(n, cholesky_fixed(a), whole_dynamic(a, n, factor))
}

fn whole_dynamic(a: &mut [f64], n: usize, factor: bool) -> bool {
    let a = &mut a[..n * n];
    if !sinew_stiffness::cholesky_lower_in_place(a, n) {
        return false;
    }
    if factor {
        for i in 0..n {
            for j in 0..i {
                a[i * n + j] = a[j * n + i];
            }
        }
    }
    true
}

/// Solve `L w = b` in place (`l` from [`cholesky`]) for a `b` that is zero before `start`:
/// `w` is too, and the substitution starts there.
#[inline(always)]
pub(crate) fn forward_solve_from(l: &[f64], n: usize, b: &mut [f64], start: usize) {
    let b = &mut b[..n];
    for i in start..n {
        let row = &l[i * n + start..i * n + i];
        b[i] = (b[i] - dot(row, &b[start..i])) / l[i * n + i];
    }
}

/// Solve `L Lᵀ x = b` in place (`l` from [`cholesky`]): forward by rows of `L`, backward by
/// the same rows (`Lᵀ`'s columns); fixed-size kernels up to n = 17.
#[inline(always)]
pub(crate) fn cholesky_solve(l: &[f64], n: usize, b: &mut [f64]) {
    fixed_size!(n, cholesky_solve_fixed(l, b), cholesky_solve_dynamic(l, n, b))
}

#[inline(always)]
fn cholesky_solve_fixed<const N: usize>(l: &[f64], b: &mut [f64]) {
    let (rows, _) = l[..N * N].as_chunks::<N>();
    let b = &mut b[..N];
    for i in 0..N {
        let mut v = b[i];
        for p in 0..i {
            v -= rows[i][p] * b[p];
        }
        b[i] = v / rows[i][i];
    }
    for i in (0..N).rev() {
        let v = b[i] / rows[i][i];
        b[i] = v;
        for p in 0..i {
            b[p] -= v * rows[i][p];
        }
    }
}

#[inline(always)]
fn cholesky_solve_dynamic(l: &[f64], n: usize, b: &mut [f64]) {
    let b = &mut b[..n];
    for i in 0..n {
        let row = &l[i * n..i * n + i];
        b[i] = (b[i] - dot(row, &b[..i])) / l[i * n + i];
    }
    for i in (0..n).rev() {
        let row = &l[i * n..i * n + i];
        let v = b[i] / l[i * n + i];
        b[i] = v;
        axpy(-v, row, &mut b[..i]);
    }
}

/// `S⁻¹ = L⁻ᵀ L⁻¹` into `out` from the factor `L` of [`cholesky`] (`t` n × n scratch), exactly
/// symmetric. Up to the fixed sizes: `T = L⁻¹` row by row (`T_i = (e_i − Σ_{p<i} L_ip T_p) /
/// L_ii`), then `Tᵀ T` as a sum of outer products of its rows; above, faer's triangular inverse
/// and its triangle-aware product (the lower triangle of `Tᵀ T`, mirrored).
#[inline(always)]
pub(crate) fn cholesky_inverse(l: &[f64], n: usize, out: &mut [f64], t: &mut [f64]) {
    fixed_size!(n, inverse_fixed(l, t, out), inverse_dynamic(l, n, out, t));
}

#[inline(always)]
fn inverse_fixed<const N: usize>(l: &[f64], t: &mut [f64], out: &mut [f64]) {
    lower_inverse_fixed::<N>(l, t);
    gram_of_rows(t, N, out);
    symmetrise(out, N);
}

#[inline(always)]
fn lower_inverse_fixed<const N: usize>(l: &[f64], t: &mut [f64]) {
    let (l, _) = l[..N * N].as_chunks::<N>();
    let (t, _) = t[..N * N].as_chunks_mut::<N>();
    for i in 0..N {
        let mut row = [0.0; N];
        for p in 0..i {
            let lip = l[i][p];
            for c in 0..=p {
                row[c] -= lip * t[p][c];
            }
        }
        let inv = 1.0 / l[i][i];
        for v in &mut row[..i] {
            *v *= inv;
        }
        row[i] = inv;
        t[i] = row;
    }
}

fn inverse_dynamic(l: &[f64], n: usize, out: &mut [f64], t: &mut [f64]) {
    use faer::linalg::matmul::triangular::{BlockStructure, matmul};
    use faer::{Accum, MatMut, MatRef, Par};
    let l = MatRef::from_row_major_slice(&l[..n * n], n, n);
    let mut tm = MatMut::from_row_major_slice_mut(&mut t[..n * n], n, n);
    faer::linalg::triangular_inverse::invert_lower_triangular(tm.as_mut(), l, Par::Seq);
    let tr = tm.as_ref();
    let o = MatMut::from_row_major_slice_mut(&mut out[..n * n], n, n);
    let (lower, upper) = (BlockStructure::TriangularLower, BlockStructure::TriangularUpper);
    matmul(o, lower, Accum::Replace, tr.transpose(), upper, tr, lower, 1.0, Par::Seq);
    mirror_lower(out, n);
}

/// The upper triangle of the row-major square `out` (side `side`) set to its lower one's.
pub(crate) fn mirror_lower(out: &mut [f64], side: usize) {
    for r in 0..side {
        for c in 0..r {
            out[c * side + r] = out[r * side + c];
        }
    }
}

/// `a ← ½ (a + aᵀ)`.
#[inline(always)]
pub(crate) fn symmetrise(a: &mut [f64], n: usize) {
    for r in 0..n {
        for c in r + 1..n {
            let v = 0.5 * (a[r * n + c] + a[c * n + r]);
            a[r * n + c] = v;
            a[c * n + r] = v;
        }
    }
}

/// `out = a b` (all n × n, row-major): fixed-size kernels up to n = 17 (each output row an
/// accumulation of whole rows of `b`, which the compiler unrolls and vectorises), faer's
/// product above.
#[inline(always)]
pub(crate) fn multiply_fast(a: &[f64], b: &[f64], n: usize, out: &mut [f64]) {
    fixed_size!(n, multiply_fixed(a, b, out), multiply_faer(a, b, n, out))
}

#[inline(always)]
fn multiply_fixed<const N: usize>(a: &[f64], b: &[f64], out: &mut [f64]) {
    let (a, _) = a[..N * N].as_chunks::<N>();
    let (b, _) = b[..N * N].as_chunks::<N>();
    let (out, _) = out[..N * N].as_chunks_mut::<N>();
    for (row_a, row_out) in a.iter().zip(out.iter_mut()) {
        let mut acc = [0.0; N];
        for (v, row_b) in row_a.iter().zip(b) {
            for c in 0..N {
                acc[c] += v * row_b[c];
            }
        }
        *row_out = acc;
    }
}

fn multiply_faer(a: &[f64], b: &[f64], n: usize, out: &mut [f64]) {
    let a = faer::MatRef::from_row_major_slice(&a[..n * n], n, n);
    let b = faer::MatRef::from_row_major_slice(&b[..n * n], n, n);
    let out = faer::MatMut::from_row_major_slice_mut(&mut out[..n * n], n, n);
    faer::linalg::matmul::matmul(out, faer::Accum::Replace, a, b, 1.0, faer::Par::Seq);
}

/// `out = Tᵀ T` (all n × n, row-major; `T` lower triangular): `Σ_p T_p ⊗ T_p` over the rows
/// of `T`, each row's non-zero head only.
#[inline(always)]
fn gram_of_rows(t: &[f64], n: usize, out: &mut [f64]) {
    let out = &mut out[..n * n];
    out.fill(0.0);
    for p in 0..n {
        let row = &t[p * n..p * n + p + 1];
        for (r, v) in row.iter().enumerate() {
            axpy(*v, row, &mut out[r * n..r * n + p + 1]);
        }
    }
}

/// `out = a b` (all n × n).
#[cfg(test)]
pub(crate) fn multiply(a: &[f64], b: &[f64], n: usize, out: &mut [f64]) {
    out[..n * n].fill(0.0);
    for r in 0..n {
        for p in 0..n {
            axpy(a[r * n + p], &b[p * n..p * n + n], &mut out[r * n..r * n + n]);
        }
    }
}

/// `⟨a, b⟩ = tr(aᵀ b)`.
#[inline(always)]
pub(crate) fn inner(a: &[f64], b: &[f64]) -> f64 {
    dot(a, b)
}

#[cfg(test)]
mod tests;
