//! Small dense kernels for the interior-point method: symmetric matrices stored row-major in a
//! flat slice (`a[r * n + c]`), factorised in place, with no allocation.
//!
//! # Numerics
//! The matrices are the method's slacks `S = F(x)` and its Schur complement: `n ≤ 200`,
//! positive definite where the method uses them. The Cholesky factorisation is the standard
//! column-oriented one (Golub and Van Loan, Alg. 4.2.1); it reports failure on the first pivot
//! that is not positive and finite, which is how the method tests `S ≻ 0` (its "Cholesky
//! trials") instead of computing eigenvalues. Tested against faer's `llt` below.

/// Overwrite the lower triangle of the symmetric `a` (n × n) with its Cholesky factor `L`
/// (`a = L Lᵀ`); the strict upper triangle is left as it was. `false` (and `a` spoilt) when
/// `a` is not positive definite to working precision.
pub(crate) fn cholesky(a: &mut [f64], n: usize) -> bool {
    for j in 0..n {
        let mut d = a[j * n + j];
        for p in 0..j {
            d -= a[j * n + p] * a[j * n + p];
        }
        if !(d > 0.0 && d.is_finite()) {
            return false;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut v = a[i * n + j];
            for p in 0..j {
                v -= a[i * n + p] * a[j * n + p];
            }
            a[i * n + j] = v / d;
        }
    }
    true
}

/// Solve `L Lᵀ x = b` in place (`l` from [`cholesky`]).
pub(crate) fn cholesky_solve(l: &[f64], n: usize, b: &mut [f64]) {
    for i in 0..n {
        let mut v = b[i];
        for p in 0..i {
            v -= l[i * n + p] * b[p];
        }
        b[i] = v / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut v = b[i];
        for p in i + 1..n {
            v -= l[p * n + i] * b[p];
        }
        b[i] = v / l[i * n + i];
    }
}

/// `out = (L Lᵀ)⁻¹`, full and symmetric (`l` from [`cholesky`]); `column` is scratch of n.
pub(crate) fn cholesky_inverse(l: &[f64], n: usize, out: &mut [f64], column: &mut [f64]) {
    for c in 0..n {
        column[..n].fill(0.0);
        column[c] = 1.0;
        cholesky_solve(l, n, &mut column[..n]);
        for r in 0..n {
            out[r * n + c] = column[r];
        }
    }
    symmetrise(out, n);
}

/// `a ← ½ (a + aᵀ)`.
pub(crate) fn symmetrise(a: &mut [f64], n: usize) {
    for r in 0..n {
        for c in r + 1..n {
            let v = 0.5 * (a[r * n + c] + a[c * n + r]);
            a[r * n + c] = v;
            a[c * n + r] = v;
        }
    }
}

/// `out = a b` (all n × n).
pub(crate) fn multiply(a: &[f64], b: &[f64], n: usize, out: &mut [f64]) {
    out[..n * n].fill(0.0);
    for r in 0..n {
        for p in 0..n {
            let v = a[r * n + p];
            if v == 0.0 {
                continue;
            }
            let row = &b[p * n..p * n + n];
            let target = &mut out[r * n..r * n + n];
            for (t, x) in target.iter_mut().zip(row) {
                *t += v * x;
            }
        }
    }
}

/// `⟨a, b⟩ = tr(aᵀ b)`.
pub(crate) fn inner(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
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
        for (n, seed) in [(1, 1), (3, 2), (10, 3), (37, 4)] {
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
            let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
            let mut b: Vec<f64> =
                (0..n).map(|r| (0..n).map(|c| a[r * n + c] * x_true[c]).sum()).collect();
            cholesky_solve(&l, n, &mut b);
            let error = b.iter().zip(&x_true).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
            assert!(error <= 1e-9, "n = {n}: solve error {error}");
            let mut inv = vec![0.0; n * n];
            let mut column = vec![0.0; n];
            cholesky_inverse(&l, n, &mut inv, &mut column);
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
    fn cholesky_refuses_indefinite_and_nan() {
        let mut a = vec![1.0, 2.0, 2.0, 1.0];
        assert!(!cholesky(&mut a, 2));
        let mut a = vec![1.0, 0.0, 0.0, f64::NAN];
        assert!(!cholesky(&mut a, 2));
        let mut a = vec![1.0, 0.0, 0.0, 0.0];
        assert!(!cholesky(&mut a, 2), "singular is not positive definite");
    }

    #[test]
    fn inner_is_the_trace_of_the_product() {
        let a = [2.0, 1.0, 1.0, 3.0];
        assert_eq!(inner(&a, &[1.0, 0.0, 0.0, 1.0]), 5.0);
        assert_eq!(inner(&a, &a), 4.0 + 1.0 + 1.0 + 9.0);
    }
}
