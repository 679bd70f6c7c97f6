//! End compliance and stiffness on synthetic inputs with known answers.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use faer::linalg::solvers::Solve;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use sinew_stiffness::{
    EndStiffnessData, StiffnessError, end_compliance, end_stiffness, stability_margin,
};
use sinew_testkit::config;
use sinew_testkit::numeric::max_abs;

fn random(rng: &mut ChaCha8Rng, r: usize, c: usize) -> Mat<f64> {
    Mat::from_fn(r, c, |_, _| rng.random_range(-1.0..1.0))
}

/// A random symmetric positive definite matrix `B Bᵀ + n I`.
fn spd(rng: &mut ChaCha8Rng, n: usize) -> Mat<f64> {
    let b = random(rng, n, n);
    let mut a = &b * b.transpose();
    for i in 0..n {
        a[(i, i)] += n as f64;
    }
    a
}

#[test]
fn compliance_is_j_a_inverse_jt_and_stiffness_its_inverse() {
    let mut rng = config::rng(41);
    for (n, symmetric) in [(10, true), (10, false), (40, true), (40, false)] {
        let k_q = spd(&mut rng, n);
        // A small non-symmetric K_W (a base-fixed moment) keeps the symmetric part definite.
        let k_w =
            if symmetric { Mat::zeros(n, n) } else { random(&mut rng, n, n) * faer::Scale(0.1) };
        let j_x = random(&mut rng, 6, n);
        let mut data = EndStiffnessData::new(n);
        end_stiffness(k_q.as_ref(), k_w.as_ref(), j_x.as_ref(), &mut data).unwrap();
        let a = &k_q + &k_w;
        // Reference: C_x = J_x A⁻¹ J_xᵀ by faer's own dense LU solver.
        let x =
            faer::linalg::solvers::PartialPivLu::new(a.as_ref()).solve(j_x.transpose().to_owned());
        let expected = &j_x * &x;
        let c_x = data.compliance().to_owned();
        let err = max_abs((&c_x - &expected).as_ref()) / max_abs(expected.as_ref());
        assert!(err <= 1e-12, "n = {n}: C_x error {err:e}");
        let product = &c_x * data.stiffness();
        let identity = Mat::<f64>::identity(6, 6);
        let err = max_abs((&product - &identity).as_ref());
        println!("n = {n}, symmetric = {symmetric}: |C_x K_x − I| = {err:.2e}");
        // Old bound 1e-9; measured worst 1.6e-15 (n = 10, non-symmetric).
        assert!(err <= 1e-14, "n = {n}: C_x K_x − I = {err:e}");
        if symmetric {
            assert_eq!(
                max_abs((&c_x - c_x.transpose()).as_ref()),
                0.0,
                "C_x symmetric for symmetric K"
            );
        }
        // K_fd is the top-left block of K_x; the rotations-free stiffness inverts C_x's block.
        let k_fd = data.k_fd();
        let k_t = data.translational_stiffness().unwrap();
        for i in 0..3 {
            for j in 0..3 {
                assert_eq!(k_fd[(i, j)], data.stiffness()[(i, j)]);
            }
        }
        let c_block = nalgebra::Matrix3::from_fn(|i, j| c_x[(i, j)]);
        let err_t = ((c_block * k_t) - nalgebra::Matrix3::identity()).abs().max();
        println!("n = {n}, symmetric = {symmetric}: |C_t K_t − I| = {err_t:.2e}");
        // Old bound 1e-9; measured worst 4.4e-16.
        assert!(err_t <= 5e-15, "n = {n}: C_t K_t − I = {err_t:e}");
    }
}

#[test]
fn an_indefinite_joint_stiffness_is_an_unstable_equilibrium() {
    let mut rng = config::rng(42);
    let n = 10;
    let mut k_q = Mat::<f64>::identity(n, n);
    k_q[(3, 3)] = -0.5;
    let k_w = Mat::zeros(n, n);
    let j_x = random(&mut rng, 6, n);
    let mut data = EndStiffnessData::new(n);
    let err = end_compliance(k_q.as_ref(), k_w.as_ref(), j_x.as_ref(), &mut data).unwrap_err();
    match err {
        StiffnessError::Unstable { min_eigenvalue } => {
            approx::assert_relative_eq!(min_eigenvalue, -0.5, epsilon = 1e-12)
        }
        other => panic!("expected Unstable, got {other:?}"),
    }
    approx::assert_relative_eq!(
        stability_margin(k_q.as_ref(), k_w.as_ref()).unwrap(),
        -0.5,
        epsilon = 1e-12
    );
}

#[test]
fn a_rank_deficient_jacobian_is_reported_and_keeps_the_compliance() {
    let mut rng = config::rng(43);
    let n = 10;
    let k_q = spd(&mut rng, n);
    let k_w = Mat::zeros(n, n);
    let mut j_x = random(&mut rng, 6, n);
    for c in 0..n {
        j_x[(5, c)] = 0.0; // no joint turns the end about z: rank 5
    }
    let mut data = EndStiffnessData::new(n);
    let err = end_stiffness(k_q.as_ref(), k_w.as_ref(), j_x.as_ref(), &mut data).unwrap_err();
    assert!(matches!(err, StiffnessError::RankDeficient { .. }), "{err:?}");
    // The compliance is still there, with a zero last row and column.
    assert_eq!(data.compliance()[(5, 5)], 0.0);
    assert!(data.translational_stiffness().is_some());
}

#[test]
fn a_singular_translational_block_has_no_translational_stiffness() {
    let mut rng = config::rng(44);
    let n = 10;
    let k_q = spd(&mut rng, n);
    let k_w = Mat::zeros(n, n);
    let mut data = EndStiffnessData::new(n);
    // Joint motions move the end along z only by `scale`: C_x[0:3, 0:3] has a singular value
    // of order scale².
    for (scale, expect_some) in [(1e-3, true), (1e-8, false), (0.0, false)] {
        let mut j_x = random(&mut rng, 6, n);
        for c in 0..n {
            j_x[(2, c)] *= scale;
        }
        end_compliance(k_q.as_ref(), k_w.as_ref(), j_x.as_ref(), &mut data).unwrap();
        let k_t = data.translational_stiffness();
        assert_eq!(k_t.is_some(), expect_some, "scale {scale}: {k_t:?}");
        if let Some(k_t) = k_t {
            // A real inverse of the block.
            let block = nalgebra::Matrix3::from_fn(|i, j| data.compliance()[(i, j)]);
            let err = (k_t * block - nalgebra::Matrix3::identity()).abs().max();
            assert!(err < 1e-8, "scale {scale}: |K_t C - I| = {err:e}");
        }
    }
}

#[test]
fn wrong_sizes_are_errors() {
    let n = 10;
    let mut data = EndStiffnessData::new(n);
    let k = Mat::<f64>::identity(n, n);
    let bad = Mat::<f64>::zeros(5, n);
    let err = end_compliance(k.as_ref(), k.as_ref(), bad.as_ref(), &mut data).unwrap_err();
    assert!(matches!(err, StiffnessError::DimensionMismatch { what: "J_x", .. }), "{err:?}");
    let mut nan = k.clone();
    nan[(2, 2)] = f64::NAN;
    let j = Mat::<f64>::zeros(6, n);
    let err = end_compliance(nan.as_ref(), k.as_ref(), j.as_ref(), &mut data).unwrap_err();
    assert!(matches!(err, StiffnessError::NonFinite { .. }), "{err:?}");
}
