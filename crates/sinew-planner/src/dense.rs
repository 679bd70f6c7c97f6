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
    let a = &mut a[..n * n];
    for i in 0..n {
        for j in 0..i {
            a[j * n + i] = a[i * n + j];
        }
    }
    if !sinew_stiffness::cholesky_lower_in_place(a, n) {
        return false;
    }
    for i in 0..n {
        for j in 0..i {
            a[i * n + j] = a[j * n + i];
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

/// `out = (L Lᵀ)⁻¹ = L⁻ᵀ L⁻¹`, full and symmetric (`l` from [`cholesky`]): `T = L⁻¹` row by
/// row (`T_i = (e_i − Σ_{p<i} L_ip T_p) / L_ii`) into the scratch `t` (n × n), then `Tᵀ T`
/// as a sum of outer products of its rows.
#[inline(always)]
pub(crate) fn cholesky_inverse(l: &[f64], n: usize, out: &mut [f64], t: &mut [f64]) {
    fixed_size!(n, lower_inverse_fixed(l, t), lower_inverse_dynamic(l, n, t));
    gram_of_rows(t, n, out);
    symmetrise(out, n);
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

fn lower_inverse_dynamic(l: &[f64], n: usize, t: &mut [f64]) {
    let t = &mut t[..n * n];
    t.fill(0.0);
    for i in 0..n {
        let (done, rest) = t.split_at_mut(i * n);
        let row = &mut rest[..n];
        for p in 0..i {
            axpy(-l[i * n + p], &done[p * n..p * n + p + 1], &mut row[..p + 1]);
        }
        let inv = 1.0 / l[i * n + i];
        for v in &mut row[..i] {
            *v *= inv;
        }
        row[i] = inv;
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
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use faer::Mat;

    fn spd(n: usize, seed: u64) -> Vec<f64> {
        // B Bᵀ + n I with B from a small linear congruential sequence.
        let mut state = seed;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let b: Vec<f64> = (0..n * n).map(|_| next()).collect();
        let mut a = vec![0.0; n * n];
        for r in 0..n {
            for c in 0..n {
                a[r * n + c] = (0..n).map(|p| b[r * n + p] * b[c * n + p]).sum::<f64>()
                    + if r == c { 0.1 } else { 0.0 };
            }
        }
        a
    }

    #[test]
    fn cholesky_matches_faer_and_solves_and_inverts() {
        for (n, seed) in [(1, 1), (3, 2), (10, 3), (17, 5), (18, 6), (37, 4)] {
            let a = spd(n, seed);
            let mut l = a.clone();
            assert!(cholesky(&mut l, n));
            let fa = Mat::from_fn(n, n, |r, c| a[r * n + c]);
            let fl = fa.llt(faer::Side::Lower).unwrap();
            let fl = fl.L();
            for r in 0..n {
                for c in 0..=r {
                    assert!((l[r * n + c] - fl[(r, c)]).abs() <= 1e-12 * (1.0 + fl[(r, c)].abs()));
                }
            }
            // Only the lower triangle is read.
            let mut spoilt = a.clone();
            for r in 0..n {
                for c in r + 1..n {
                    spoilt[r * n + c] = f64::NAN;
                }
            }
            assert!(cholesky(&mut spoilt, n), "n = {n}: the upper triangle was read");
            for r in 0..n {
                assert_eq!(spoilt[r * n..r * n + r + 1], l[r * n..r * n + r + 1], "n = {n}");
            }
            // A forward substitution from a later row, for a right-hand side zero before it,
            // is the whole one.
            let start = n / 2;
            let rhs: Vec<f64> =
                (0..n).map(|i| if i < start { 0.0 } else { (i as f64).cos() }).collect();
            let (mut whole, mut from) = (rhs.clone(), rhs.clone());
            forward_solve_from(&l, n, &mut whole, 0);
            forward_solve_from(&l, n, &mut from, start);
            for i in start..n {
                assert!((whole[i] - from[i]).abs() <= 1e-14 * (1.0 + whole[i].abs()));
            }
            let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
            let mut b: Vec<f64> =
                (0..n).map(|r| (0..n).map(|c| a[r * n + c] * x_true[c]).sum()).collect();
            cholesky_solve(&l, n, &mut b);
            let error = b.iter().zip(&x_true).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
            assert!(error <= 1e-9, "n = {n}: solve error {error}");
            let mut inv = vec![0.0; n * n];
            let mut scratch = vec![0.0; n * n];
            cholesky_inverse(&l, n, &mut inv, &mut scratch);
            let mut product = vec![0.0; n * n];
            multiply(&a, &inv, n, &mut product);
            for r in 0..n {
                for c in 0..n {
                    let expected = if r == c { 1.0 } else { 0.0 };
                    assert!((product[r * n + c] - expected).abs() <= 1e-8);
                }
            }
        }
    }

    #[test]
    fn the_fast_product_is_the_plain_product_and_both_inverses_agree() {
        for n in [1, 4, 10, 11, 17, 18, 23] {
            let (a, b) = (spd(n, 7), spd(n, 8));
            // Not symmetric: a row-scaled copy.
            let a: Vec<f64> =
                a.iter().enumerate().map(|(e, v)| v * (1.0 + (e / n) as f64)).collect();
            let (mut plain, mut fast) = (vec![0.0; n * n], vec![0.0; n * n]);
            multiply(&a, &b, n, &mut plain);
            multiply_fast(&a, &b, n, &mut fast);
            for (p, f) in plain.iter().zip(&fast) {
                assert!((p - f).abs() <= 1e-12 * (1.0 + p.abs()), "n = {n}: {p} vs {f}");
            }
            // The fixed-size and the dynamic lower inverse (n ≤ 17 has both).
            let mut l = b.clone();
            assert!(cholesky(&mut l, n));
            let mut dynamic = vec![0.0; n * n];
            lower_inverse_dynamic(&l, n, &mut dynamic);
            let mut product = vec![0.0; n * n];
            for r in 0..n {
                for c in 0..n {
                    product[r * n + c] = (0..=r).map(|p| l[r * n + p] * dynamic[p * n + c]).sum();
                }
            }
            for r in 0..n {
                for c in 0..n {
                    let expected = if r == c { 1.0 } else { 0.0 };
                    assert!((product[r * n + c] - expected).abs() <= 1e-10, "n = {n}: L T ≠ I");
                }
            }
            if n <= 17 {
                let mut fixed = vec![0.0; n * n];
                fixed_size!(n, lower_inverse_fixed(&l, &mut fixed), unreachable!());
                for (x, y) in fixed.iter().zip(&dynamic) {
                    assert!((x - y).abs() <= 1e-12 * (1.0 + x.abs()));
                }
            }
        }
    }

    #[test]
    fn cholesky_refuses_indefinite_and_nan() {
        let mut a = vec![1.0, 2.0, 2.0, 1.0];
        assert!(!cholesky(&mut a, 2));
        let mut a = vec![1.0, 0.0, 0.0, f64::NAN];
        assert!(!cholesky(&mut a, 2));
        let mut a = vec![1.0, 0.0, 0.0, 0.0];
        assert!(!cholesky(&mut a, 2), "singular is not positive definite");
        // Above the fixed sizes: one negative direction in a 30 × 30 identity, at its last row.
        let n = 30;
        let mut a: Vec<f64> =
            (0..n * n).map(|e| if e % (n + 1) == 0 { 1.0 } else { 0.0 }).collect();
        a[(n - 1) * n + n - 2] = 1.5;
        a[(n - 2) * n + n - 1] = 1.5;
        assert!(!cholesky(&mut a, n));
    }

    #[test]
    fn inner_is_the_trace_of_the_product() {
        let a = [2.0, 1.0, 1.0, 3.0];
        assert_eq!(inner(&a, &[1.0, 0.0, 0.0, 1.0]), 5.0);
        assert_eq!(inner(&a, &a), 4.0 + 1.0 + 1.0 + 9.0);
    }
}
