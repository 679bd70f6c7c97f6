//! Tests of the dense kernels against faer and against each other.
#![allow(clippy::unwrap_used)]

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

/// `a · inverse = I` to `tolerance`, and `inverse` exactly symmetric.
fn assert_inverse(a: &[f64], inverse: &[f64], n: usize, tolerance: f64) {
    let mut product = vec![0.0; n * n];
    multiply(a, inverse, n, &mut product);
    for r in 0..n {
        for c in 0..n {
            let expected = if r == c { 1.0 } else { 0.0 };
            assert!((product[r * n + c] - expected).abs() <= tolerance, "n = {n}: S S⁻¹ ≠ I");
            assert_eq!(inverse[r * n + c], inverse[c * n + r], "n = {n}: not symmetric");
        }
    }
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
        assert_inverse(&a, &inv, n, 1e-8);
    }
}

#[test]
fn the_fast_product_is_the_plain_product_and_both_inverses_agree() {
    for n in [1, 4, 10, 11, 17, 18, 23] {
        let (a, b) = (spd(n, 7), spd(n, 8));
        // Not symmetric: a row-scaled copy.
        let a: Vec<f64> = a.iter().enumerate().map(|(e, v)| v * (1.0 + (e / n) as f64)).collect();
        let (mut plain, mut fast) = (vec![0.0; n * n], vec![0.0; n * n]);
        multiply(&a, &b, n, &mut plain);
        multiply_fast(&a, &b, n, &mut fast);
        for (p, f) in plain.iter().zip(&fast) {
            assert!((p - f).abs() <= 1e-12 * (1.0 + p.abs()), "n = {n}: {p} vs {f}");
        }
        // The fixed-size and the dynamic inverse (n ≤ 17 has both): each the inverse, exactly
        // symmetric, and the two agree.
        let mut l = b.clone();
        assert!(cholesky(&mut l, n));
        let (mut dynamic, mut t) = (vec![0.0; n * n], vec![f64::NAN; n * n]);
        inverse_dynamic(&l, n, &mut dynamic, &mut t);
        assert_inverse(&b, &dynamic, n, 1e-10);
        if n <= 17 {
            let mut fixed = vec![0.0; n * n];
            fixed_size!(n, inverse_fixed(&l, &mut t, &mut fixed), unreachable!());
            for (x, y) in fixed.iter().zip(&dynamic) {
                assert!((x - y).abs() <= 1e-12 * (1.0 + x.abs()), "n = {n}: {x} vs {y}");
            }
        }
    }
}

#[test]
fn a_whole_matrix_factorises_as_its_lower_triangle_does() {
    for (n, seed) in [(3, 9), (17, 10), (18, 11), (41, 12)] {
        let a = spd(n, seed);
        let mut lower = a.clone();
        assert!(cholesky(&mut lower, n));
        let mut whole = a.clone();
        assert!(cholesky_whole(&mut whole, n, true));
        for r in 0..n {
            assert_eq!(whole[r * n..r * n + r + 1], lower[r * n..r * n + r + 1], "n = {n}");
        }
        assert!(cholesky_whole(&mut a.clone(), n, false), "n = {n}");
        // Indefinite: the last diagonal entry lowered below its Schur complement's value.
        let mut bad = a.clone();
        let shift = (0..n).map(|i| a[i * n + i]).fold(0.0, f64::max) * 10.0;
        bad[n * n - 1] -= shift;
        assert!(!cholesky_whole(&mut bad.clone(), n, false), "n = {n}");
        assert!(!cholesky_whole(&mut bad, n, true), "n = {n}");
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
    let mut a: Vec<f64> = (0..n * n).map(|e| if e % (n + 1) == 0 { 1.0 } else { 0.0 }).collect();
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
