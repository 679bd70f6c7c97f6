//! The Cholesky factorisation `K_q + K_W = L Lᵀ` of the end's dense solve at small sizes: the
//! stability verdict and the factor of the solve (eq. 19; `end.rs`). faer's factorisation is
//! built for large matrices; up to [`SMALL`] this column-by-column (Crout, left-looking)
//! factorisation, with the rows of each column accumulated in registers and compiled for AVX2
//! where the processor has it (pulp's runtime dispatch), is as fast or faster: the routed
//! 50-DOF pipeline takes 27.4 instead of 29.1 µs, 100 DOF 105 instead of 107 µs, 10 DOF the
//! same (interleaved runs, docs/performance.md).
//!
//! Column `j` of `L` is `(a[j.., j] − Σ_{k<j} L[j.., k] L[j, k])` (the sum in increasing `k`),
//! divided by its diagonal entry `L[j, j]` (the square root of the first) as a product with the
//! reciprocal. Rust never fuses a multiply and an add, so the result does not depend on the
//! processor.

/// The largest size factorised here; faer's blocked factorisation above (measured crossover).
pub(crate) const SMALL: usize = 100;

/// `L Lᵀ = A` in place on the lower triangle of the column-major `n × n` matrix `a` (the upper
/// triangle is not written; its values are read but do not reach the result): `false` when a
/// pivot is not positive (or not a number), i.e. `A` is not positive definite. No allocation.
pub fn cholesky_lower_in_place(a: &mut [f64], n: usize) -> bool {
    if a.len() != n * n {
        return false;
    }
    pulp::Arch::new().dispatch(Crout { a, n })
}

/// [`cholesky_lower_in_place`] as a pulp operation (`with_simd` is inlined into pulp's
/// dispatch, so the loops are compiled with its vector instructions).
struct Crout<'a> {
    a: &'a mut [f64],
    n: usize,
}

impl pulp::WithSimd for Crout<'_> {
    type Output = bool;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> bool {
        let Crout { a, n } = self;
        for j in 0..n {
            let (done, rest) = a.split_at_mut(j * n);
            let column = &mut rest[..n];
            // Rows j.. in chunks held in registers, the chunks ending at n: the first starts
            // up to three rows above j (in the upper triangle: computed, not stored), or, in the
            // first columns, the rows it would miss are taken one by one.
            let pad = (4 - (n - j) % 4) % 4;
            let mut i = if pad == 0 {
                j
            } else if j >= pad {
                first_chunk(done, column, j - pad, j, n);
                j - pad + 4
            } else {
                for row in j..j + (n - j) % 4 {
                    update::<1>(done, column, row, j, n);
                }
                j + (n - j) % 4
            };
            while i + 32 <= n {
                update::<32>(done, column, i, j, n);
                i += 32;
            }
            // The rest, a multiple of four below 32 rows.
            if i + 16 <= n {
                update::<16>(done, column, i, j, n);
                i += 16;
            }
            if i + 8 <= n {
                update::<8>(done, column, i, j, n);
                i += 8;
            }
            if i + 4 <= n {
                update::<4>(done, column, i, j, n);
            }
            let pivot = column[j];
            // A NaN pivot also fails.
            if pivot.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return false;
            }
            let diagonal = pivot.sqrt();
            column[j] = diagonal;
            let inverse = 1.0 / diagonal;
            for v in &mut column[j + 1..] {
                *v *= inverse;
            }
        }
        true
    }
}

/// Rows `i..i + R` of column `j`: `a[i.., j] −= Σ_{k<j} L[i.., k] L[j, k]`, the `R` running
/// sums in registers. `done` holds the first `j` columns (already factorised).
#[inline(always)]
fn update<const R: usize>(done: &[f64], column: &mut [f64], i: usize, j: usize, n: usize) {
    let mut acc = [0.0; R];
    acc.copy_from_slice(&column[i..i + R]);
    accumulate(done, &mut acc, i, j, n);
    column[i..i + R].copy_from_slice(&acc);
}

/// `acc −= Σ_{k<j} L[i..i + R, k] L[j, k]`, in increasing `k`, four columns per step (fewer
/// loop steps; the same subtractions in the same order).
#[inline(always)]
fn accumulate<const R: usize>(done: &[f64], acc: &mut [f64; R], i: usize, j: usize, n: usize) {
    let mut quads = done.chunks_exact(4 * n);
    for quad in &mut quads {
        let (c0, rest) = quad.split_at(n);
        let (c1, rest) = rest.split_at(n);
        let (c2, c3) = rest.split_at(n);
        let (l0, l1, l2, l3) = (c0[j], c1[j], c2[j], c3[j]);
        let (r0, r1, r2, r3) = (&c0[i..i + R], &c1[i..i + R], &c2[i..i + R], &c3[i..i + R]);
        for r in 0..R {
            acc[r] = acc[r] - r0[r] * l0 - r1[r] * l1 - r2[r] * l2 - r3[r] * l3;
        }
    }
    for l in quads.remainder().chunks_exact(n) {
        let l_jk = l[j];
        let rows = &l[i..i + R];
        for r in 0..R {
            acc[r] -= rows[r] * l_jk;
        }
    }
}

/// [`update`] of the four rows `i..i + 4` of which only those from `j` on are column `j`'s
/// (`i < j`): the rows above are summed too, from zero, and dropped (their entries of `L` are
/// upper-triangle values, whatever they hold), so that the chunk is whole.
#[inline(always)]
fn first_chunk(done: &[f64], column: &mut [f64], i: usize, j: usize, n: usize) {
    let mut acc = [0.0; 4];
    for (r, a) in acc.iter_mut().enumerate() {
        if i + r >= j {
            *a = column[i + r];
        }
    }
    accumulate(done, &mut acc, i, j, n);
    for (r, v) in acc.into_iter().enumerate() {
        if i + r >= j {
            column[i + r] = v;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A symmetric positive definite matrix with entries of mixed signs.
    fn spd(n: usize) -> Vec<f64> {
        let b: Vec<f64> = (0..n * n).map(|k| ((k * 7 + 3) % 11) as f64 / 11.0 - 0.45).collect();
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let mut s = if i == j { n as f64 } else { 0.0 };
                for k in 0..n {
                    s += b[i + k * n] * b[j + k * n];
                }
                a[i + j * n] = s;
            }
        }
        a
    }

    #[test]
    fn factor_reproduces_the_matrix() {
        for n in [1, 2, 3, 5, 10, 17, 33, 50, 64] {
            let a = spd(n);
            let mut l = a.clone();
            // NaN in the upper triangle does not reach the factor, and is not overwritten.
            for j in 0..n {
                for i in 0..j {
                    l[i + j * n] = f64::NAN;
                }
            }
            assert!(cholesky_lower_in_place(&mut l, n), "n = {n}");
            let scale = a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for i in 0..n {
                for j in 0..=i {
                    let s: f64 = (0..=j).map(|k| l[i + k * n] * l[j + k * n]).sum();
                    assert!((s - a[i + j * n]).abs() <= 1e-13 * scale, "n = {n}, ({i}, {j})");
                }
                for j in 0..i {
                    assert!(l[j + i * n].is_nan(), "upper triangle written at n = {n}");
                }
            }
        }
    }

    #[test]
    fn indefinite_and_nan_fail() {
        let mut a = spd(10);
        a[4 + 4 * 10] = -50.0;
        assert!(!cholesky_lower_in_place(&mut a, 10));
        let mut a = spd(10);
        a[9 + 3 * 10] = f64::NAN;
        assert!(!cholesky_lower_in_place(&mut a, 10));
        assert!(!cholesky_lower_in_place(&mut [1.0; 3], 2));
    }
}
