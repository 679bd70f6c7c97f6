//! The LU factorisation with partial pivoting `P A = L U` of the end's dense solve at small
//! sizes, for a `K_q + K_W` that is not symmetric (a load with a moment, or a slip regime's
//! `K_q`): `X = (K_q + K_W)⁻¹ J_xᵀ` (eq. 19; `end.rs`). faer's factorisation is blocked and
//! recursive, built for large matrices: at cdhrm5's 10 DOF its factorisation and the solve of
//! six right-hand sides take 11.9 k instructions, for about 700 multiply-adds. Up to
//! [`SMALL`] this column-by-column one (left-looking, as [`crate::cholesky`]), compiled for
//! AVX2 where the processor has it (pulp's runtime dispatch), is used instead; its solutions
//! agree with faer's to rounding (tests below).
//!
//! Column `j` (Crout's order): rows `0..j` become `U[..j, j]`, the unit lower triangular solve
//! `L[..j, ..j] U[..j, j] = a[..j, j]`, and rows `j..` become `a[j.., j] − Σ_{k<j} L[j.., k]
//! U[k, j]`; both sums in increasing `k`, chunks of rows held in registers. Of rows `j..`, the
//! largest in magnitude (the first, on a tie) is the pivot: its row is swapped
//! with row `j` across the whole matrix (LAPACK's `getf2` convention: `pivots[j]` is the row
//! swapped with `j`), and the rows below are divided by it as a product with its reciprocal.

/// The largest size factorised here; faer's blocked factorisation above. Measured by
/// `scripts/lu-instructions` (callgrind, the factorisation and the solve of six right-hand
/// sides): 7.8 k instead of faer's 11.9 k instructions at 10, 57.8 k instead of 61.5 k at 32,
/// 85.5 k against 79.3 k at 36.
pub(crate) const SMALL: usize = 32;

/// `P A = L U` in place on the column-major `n × n` matrix `a` (`L` unit lower below the
/// diagonal, `U` on and above it), with the row interchanges in `pivots` (row `j` was swapped
/// with row `pivots[j] ≥ j`, in increasing `j`). `false` when a pivot is zero or not finite
/// (`A` singular to working precision, or holding a NaN). No allocation.
pub(crate) fn lu_in_place(a: &mut [f64], n: usize, pivots: &mut [usize]) -> bool {
    if a.len() != n * n || pivots.len() != n {
        return false;
    }
    pulp::Arch::new().dispatch(Factor { a, n, pivots })
}

/// `Y ← A⁻¹ Y` from the factors of [`lu_in_place`], for the row-major `n × 6` matrix `y` (the
/// six right-hand sides of each row together): the interchanges, then `L` forward and `U`
/// backward, a column of the factor at a time (six-wide multiply-adds). No allocation.
pub(crate) fn lu_solve_six(a: &[f64], n: usize, pivots: &[usize], y: &mut [f64]) {
    if a.len() != n * n || pivots.len() != n || y.len() != 6 * n {
        return;
    }
    pulp::Arch::new().dispatch(Solve { a, n, pivots, y });
}

/// [`lu_in_place`] as a pulp operation (`with_simd` is inlined into pulp's dispatch, so the
/// loops are compiled with its vector instructions).
struct Factor<'a> {
    a: &'a mut [f64],
    n: usize,
    pivots: &'a mut [usize],
}

impl pulp::WithSimd for Factor<'_> {
    type Output = bool;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> bool {
        let Factor { a, n, pivots } = self;
        for j in 0..n {
            let (done, rest) = a.split_at_mut(j * n);
            let column = &mut rest[..n];
            // Rows 0..j become U[..j, j] (the unit lower triangular solve), rows j.. the
            // candidates for the pivot; chunks of rows in registers (16 at a time below j).
            let mut i = 0;
            while i < n {
                if i >= j && i + 16 <= n {
                    rows::<16>(done, column, i, j, n);
                    i += 16;
                } else if i + 8 <= n {
                    rows::<8>(done, column, i, j, n);
                    i += 8;
                } else if i + 4 <= n {
                    rows::<4>(done, column, i, j, n);
                    i += 4;
                } else {
                    rows::<1>(done, column, i, j, n);
                    i += 1;
                }
            }
            // The pivot: the largest magnitude from row j on, the first on a tie.
            let mut p = j;
            for (r, v) in column.iter().enumerate().skip(j + 1) {
                if v.abs() > column[p].abs() {
                    p = r;
                }
            }
            pivots[j] = p;
            let pivot = column[p];
            if !(pivot != 0.0 && pivot.is_finite()) {
                return false;
            }
            if p != j {
                for col in a.chunks_exact_mut(n) {
                    col.swap(j, p);
                }
            }
            let column = &mut a[j * n..(j + 1) * n];
            let inverse = 1.0 / pivot;
            for v in &mut column[j + 1..] {
                *v *= inverse;
            }
        }
        true
    }
}

/// Rows `i..i + R` of column `j`, the `R` running sums in registers: each row `r` minus
/// `Σ_{k < min(r, j)} L[r, k] U[k, j]` in increasing `k` (`U[k, j] = column[k]`, final for
/// `k < i`; `done` holds the first `j` columns, factorised). The columns `k < min(i, j)` reach
/// every row of the chunk; those from `i` to `j` (a chunk above `j`: the triangular solve) reach
/// only the rows below `k` in it, each once `U[k, j]` is final.
#[inline(always)]
fn rows<const R: usize>(done: &[f64], column: &mut [f64], i: usize, j: usize, n: usize) {
    let mut acc = [0.0; R];
    acc.copy_from_slice(&column[i..i + R]);
    // Four columns per step (fewer loop steps; the same subtractions in the same order).
    let full = i.min(j);
    let mut quads = done[..full * n].chunks_exact(4 * n).zip(column[..full].chunks_exact(4));
    for (quad, u) in &mut quads {
        let (c0, rest) = quad.split_at(n);
        let (c1, rest) = rest.split_at(n);
        let (c2, c3) = rest.split_at(n);
        let (r0, r1, r2, r3) = (&c0[i..i + R], &c1[i..i + R], &c2[i..i + R], &c3[i..i + R]);
        for r in 0..R {
            acc[r] = acc[r] - r0[r] * u[0] - r1[r] * u[1] - r2[r] * u[2] - r3[r] * u[3];
        }
    }
    for k in full / 4 * 4..full {
        let (rows, u) = (&done[k * n + i..k * n + i + R], column[k]);
        for r in 0..R {
            acc[r] -= rows[r] * u;
        }
    }
    for k in i..j.min(i + R) {
        let u = acc[k - i];
        let l = &done[k * n + i..k * n + i + R];
        for r in k - i + 1..R {
            acc[r] -= l[r] * u;
        }
    }
    column[i..i + R].copy_from_slice(&acc);
}

/// [`lu_solve_six`] as a pulp operation.
struct Solve<'a> {
    a: &'a [f64],
    n: usize,
    pivots: &'a [usize],
    y: &'a mut [f64],
}

impl pulp::WithSimd for Solve<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let Solve { a, n, pivots, y } = self;
        for (j, &p) in pivots.iter().enumerate() {
            if p != j {
                for t in 0..6 {
                    y.swap(6 * j + t, 6 * p + t);
                }
            }
        }
        // L (unit lower), column k updating the rows below k.
        for (k, column) in a.chunks_exact(n).enumerate() {
            let (head, tail) = y.split_at_mut((k + 1) * 6);
            let y_k = &head[k * 6..];
            for (row, &l_ik) in tail.chunks_exact_mut(6).zip(&column[k + 1..]) {
                for t in 0..6 {
                    row[t] -= l_ik * y_k[t];
                }
            }
        }
        // U, from the last column back, column k updating the rows above k.
        for (k, column) in a.chunks_exact(n).enumerate().rev() {
            let (head, tail) = y.split_at_mut(k * 6);
            let y_k = &mut tail[..6];
            let inverse = 1.0 / column[k];
            for v in y_k.iter_mut() {
                *v *= inverse;
            }
            for (row, &u_ik) in head.chunks_exact_mut(6).zip(&column[..k]) {
                for t in 0..6 {
                    row[t] -= u_ik * y_k[t];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use faer::linalg::solvers::Solve as _;
    use faer::{Mat, MatRef, Par};

    use super::*;

    /// Reproducible values in `[-0.5, 0.5)` (a 64-bit LCG, Knuth's constants).
    fn values(count: usize, seed: u64) -> Vec<f64> {
        let mut state = seed;
        (0..count)
            .map(|_| {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    /// A non-symmetric `n × n` matrix (column-major), `shift` added to its diagonal.
    fn matrix(n: usize, shift: f64) -> Vec<f64> {
        let mut a = values(n * n, 7);
        for i in 0..n {
            a[i + i * n] += shift;
        }
        a
    }

    /// Six right-hand sides, row-major `n × 6`.
    fn rhs(n: usize) -> Vec<f64> {
        values(6 * n, 11)
    }

    #[test]
    fn solutions_agree_with_faers_lu() {
        // Shift 0: small diagonal, so rows are interchanged; shift n: dominant diagonal.
        for n in [1, 2, 3, 4, 5, 7, 10, 16, 17, 33, 50, 64, 100] {
            for shift in [0.0, n as f64] {
                let a = matrix(n, shift);
                let b = rhs(n);
                let mut factors = a.clone();
                let mut pivots = vec![0; n];
                assert!(lu_in_place(&mut factors, n, &mut pivots), "n = {n}");
                let mut x = b.clone();
                lu_solve_six(&factors, n, &pivots, &mut x);
                let reference = Mat::from_fn(n, n, |i, j| a[i + j * n]).partial_piv_lu();
                let expected = reference.solve(Mat::from_fn(n, 6, |i, t| b[6 * i + t]));
                let scale = expected.norm_max();
                for i in 0..n {
                    for t in 0..6 {
                        let (got, want) = (x[6 * i + t], expected[(i, t)]);
                        // Measured: 1.8e-13 at n = 50 without the shift (its condition number).
                        assert!((got - want).abs() <= 1e-12 * scale, "n = {n} ({i}, {t})");
                    }
                }
                // The residual A X − B, at rounding (measured: 5.6e-17 n of the largest |X|).
                for i in 0..n {
                    for t in 0..6 {
                        let r: f64 = (0..n).map(|k| a[i + k * n] * x[6 * k + t]).sum();
                        let bound = 4e-16 * (n as f64) * scale.max(1.0);
                        assert!((r - b[6 * i + t]).abs() <= bound, "n = {n} ({i}, {t})");
                    }
                }
            }
        }
    }

    #[test]
    fn rows_are_interchanged_for_the_largest_pivot() {
        // [[1, 2], [4, 3]]: row 1 holds the larger first entry.
        let mut a = vec![1.0, 4.0, 2.0, 3.0];
        let mut pivots = vec![0; 2];
        assert!(lu_in_place(&mut a, 2, &mut pivots));
        assert_eq!(pivots, [1, 1]);
        // P A = [[4, 3], [1, 2]] = [[1, 0], [0.25, 1]] [[4, 3], [0, 1.25]].
        assert_eq!(a, [4.0, 0.25, 3.0, 1.25]);
        // A tie goes to the first row: [[1, 2], [-1, 3]] keeps its order.
        let mut a = vec![1.0, -1.0, 2.0, 3.0];
        assert!(lu_in_place(&mut a, 2, &mut pivots));
        assert_eq!(pivots, [0, 1]);
        assert_eq!(a, [1.0, -1.0, 2.0, 5.0]);
        // A zero leading entry needs the interchange to factorise at all.
        let mut a = vec![0.0, 1.0, 1.0, 0.0];
        assert!(lu_in_place(&mut a, 2, &mut pivots));
        let mut y = vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0];
        lu_solve_six(&a, 2, &pivots, &mut y);
        assert_eq!(y, [7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    }

    #[test]
    fn singular_and_nan_fail() {
        let mut a = matrix(10, 0.0);
        // Column 3 zero: its pivot is exactly 0 whatever the interchanges.
        a[30..40].fill(0.0);
        assert!(!lu_in_place(&mut a, 10, &mut [0; 10]));
        let mut a = matrix(10, 10.0);
        a[9 + 3 * 10] = f64::NAN;
        assert!(!lu_in_place(&mut a, 10, &mut [0; 10]));
        assert!(!lu_in_place(&mut [1.0; 3], 2, &mut [0; 2]));
        assert!(!lu_in_place(&mut matrix(3, 3.0), 3, &mut [0; 2]));
    }

    #[test]
    fn a_solve_of_mismatched_sizes_does_nothing() {
        let mut a = matrix(3, 3.0);
        let mut pivots = [0; 3];
        assert!(lu_in_place(&mut a, 3, &mut pivots));
        // Each size wrong alone: nothing read out of bounds, nothing written.
        let mut y = rhs(3);
        let before = y.clone();
        lu_solve_six(&a[..8], 3, &pivots, &mut y);
        lu_solve_six(&a, 3, &pivots[..2], &mut y);
        assert_eq!(y, before);
        let mut short = before[..17].to_vec();
        lu_solve_six(&a, 3, &pivots, &mut short);
        assert_eq!(short, before[..17]);
    }

    /// The workload of `scripts/lu-instructions` (not a test: it asserts nothing): `LU_N`,
    /// `LU_REPS` factorisations and solves of an `LU_N × LU_N` matrix, by this module, or by
    /// faer's LU when `LU_FAER` is set; callgrind counts the instructions.
    #[test]
    #[ignore = "a workload for callgrind (scripts/lu-instructions)"]
    fn instruction_workload() {
        use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
        use faer::linalg::lu::partial_pivoting as faer_lu;
        let var = |name: &str| std::env::var(name).ok().and_then(|v| v.parse::<usize>().ok());
        let (Some(n), Some(reps)) = (var("LU_N"), var("LU_REPS")) else { return };
        let a = matrix(n, n as f64);
        let (mut factors, mut pivots, mut y) = (a.clone(), vec![0; n], rhs(n));
        let mut m = Mat::<f64>::zeros(n, n);
        let mut x = Mat::<f64>::zeros(n, 6);
        let (mut perm, mut perm_inv) = (vec![0_usize; n], vec![0_usize; n]);
        let mut buffer = MemBuffer::new(StackReq::any_of(&[
            faer_lu::factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default()),
            faer_lu::solve::solve_in_place_scratch::<usize, f64>(n, 6, Par::Seq),
        ]));
        let faer = std::env::var_os("LU_FAER").is_some();
        for _ in 0..reps {
            if faer {
                m.copy_from(MatRef::from_column_major_slice(&a, n, n));
                let params = Default::default();
                let stack = MemStack::new(&mut buffer);
                let (_, p) = faer_lu::factor::lu_in_place(
                    m.as_mut(),
                    &mut perm,
                    &mut perm_inv,
                    Par::Seq,
                    stack,
                    params,
                );
                let stack = MemStack::new(&mut buffer);
                faer_lu::solve::solve_in_place(
                    m.as_ref(),
                    m.as_ref(),
                    p,
                    x.as_mut(),
                    Par::Seq,
                    stack,
                );
            } else {
                factors.copy_from_slice(&a);
                lu_in_place(&mut factors, n, &mut pivots);
                lu_solve_six(&factors, n, &pivots, &mut y);
            }
        }
        std::hint::black_box((&factors, &y, &x));
    }
}
