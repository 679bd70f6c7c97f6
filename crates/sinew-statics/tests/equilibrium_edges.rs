//! The equilibrium set's own accessors on hand-written cable Jacobians `J_c`, each checked
//! against an independent computation (nalgebra, closed forms): the null basis is block
//! diagonal over independent joints, `f_p` is the minimum-norm balance, `coordinates` inverts
//! `tensions`, `joint_motion` is `J_c⁺`, and an unreachable load names exactly the joints that
//! carry a tenth of its largest component. Written for the mutants that survived on
//! `equilibrium.rs` (#25): each test fails a realistic bug of that kind.
#![allow(clippy::unwrap_used, clippy::expect_used)]
// `[0..2]` is a list of one joint (its DOF range), as `groups` takes.
#![allow(clippy::single_range_in_vec_init)]

use std::ops::Range;

use faer::Mat;
use nalgebra::{DMatrix, DVector};
use sinew_statics::{EquilibriumSet, NoEquilibriumCause, StaticsError};

const LIMITS: [f64; 2] = [20.0, 600.0];

fn jacobian(rows: &[&[f64]]) -> Mat<f64> {
    Mat::from_fn(rows.len(), rows[0].len(), |r, c| rows[r][c])
}

fn to_nalgebra(j: &Mat<f64>) -> DMatrix<f64> {
    DMatrix::from_fn(j.nrows(), j.ncols(), |r, c| j[(r, c)])
}

/// Two universal joints with three cables each, not crossing each other (rows 0–2 move DOFs
/// 0–1, rows 3–5 DOFs 2–3), the holes off the symmetric 120° layout so that each joint's block
/// has two distinct singular values, and a seventh cable that crosses no joint.
fn two_joints() -> (Mat<f64>, [Range<usize>; 2]) {
    let j = jacobian(&[
        &[0.02, 0.0, 0.0, 0.0],
        &[-0.01, -0.01, 0.0, 0.0],
        &[-0.01, 0.03, 0.0, 0.0],
        &[0.0, 0.0, 0.015, 0.005],
        &[0.0, 0.0, -0.02, 0.01],
        &[0.0, 0.0, 0.004, -0.025],
        &[0.0, 0.0, 0.0, 0.0],
    ]);
    (j, [0..2, 2..4])
}

#[test]
fn the_null_basis_is_block_diagonal_and_the_particular_tensions_are_the_least_norm_balance() {
    let (j, groups) = two_joints();
    let t0 = [-0.4, 0.3, 0.2, -0.5];
    let set = EquilibriumSet::new(j.as_ref(), &t0, &[LIMITS; 7], &groups).unwrap();
    assert_eq!(set.cable_count(), 7);
    // One null direction per joint (3 cables, rank 2) and one for the free cable.
    assert_eq!(set.dimension(), 3);
    let n = set.null_basis();
    assert_eq!((n.nrows(), n.ncols()), (7, 3));
    let blocks: [&[usize]; 3] = [&[0, 1, 2], &[3, 4, 5], &[6]];
    // Each column lives on one block's cables: exact zeros elsewhere (the SVD is taken block
    // by block; one SVD of the whole J_c would mix the two joints' directions).
    let mut seen = [false; 3];
    for col in 0..3 {
        let block = blocks
            .iter()
            .position(|b| b.iter().any(|&c| n[(c, col)].abs() > 1e-3))
            .unwrap_or_else(|| panic!("column {col} is empty"));
        seen[block] = true;
        for c in (0..7).filter(|c| !blocks[block].contains(c)) {
            assert_eq!(n[(c, col)], 0.0, "column {col} leaks onto cable {c}");
        }
    }
    assert_eq!(seen, [true; 3], "one column per block");
    // Orthonormal, and in null(J_cᵀ).
    let jn = to_nalgebra(&j);
    let nn = DMatrix::from_fn(7, 3, |r, c| n[(r, c)]);
    assert!((nn.transpose() * &nn - DMatrix::identity(3, 3)).abs().max() <= 1e-14);
    assert!((jn.transpose() * &nn).abs().max() <= 1e-17);
    // Joint 1's null direction is ±(2, 3, 1)/√14 (0.02 f1 = 0.01 (f2 + f3), f2 = 3 f3).
    let col = (0..3).find(|&c| n[(0, c)] != 0.0).unwrap();
    let sign = n[(0, col)].signum();
    for (c, expected) in [2.0, 3.0, 1.0].into_iter().enumerate() {
        let v = sign * n[(c, col)];
        assert!((v - expected / 14.0_f64.sqrt()).abs() <= 1e-15, "cable {c}: {v}");
    }
    // f_p = −J_c (J_cᵀ J_c)⁻¹ T0 (J_c has full column rank): the least-norm balance.
    let t = DVector::from_column_slice(&t0);
    let jtj = jn.transpose() * &jn;
    let expected = -(&jn * jtj.lu().solve(&t).unwrap());
    for c in 0..7 {
        let p = set.particular()[c];
        assert!((p - expected[c]).abs() <= 1e-12 * expected.amax(), "f_p[{c}] = {p}");
    }
    assert_eq!(set.particular()[6], 0.0);
    assert_eq!((set.lower(), set.upper()), (&[20.0; 7][..], &[600.0; 7][..]));
}

#[test]
fn coordinates_invert_tensions() {
    let (j, groups) = two_joints();
    let t0 = [-0.4, 0.3, 0.2, -0.5];
    let set = EquilibriumSet::new(j.as_ref(), &t0, &[LIMITS; 7], &groups).unwrap();
    let n = set.null_basis();
    for lambda in [[0.0, 0.0, 0.0], [30.0, -12.5, 7.0], [-3.0, 250.0, 0.25]] {
        let mut f = vec![0.0; 7];
        set.tensions(&lambda, &mut f).unwrap();
        // f = f_p + N λ, computed here.
        for (c, fc) in f.iter().enumerate() {
            let expected: f64 =
                set.particular()[c] + (0..3).map(|i| n[(c, i)] * lambda[i]).sum::<f64>();
            assert!((fc - expected).abs() <= 1e-12, "f[{c}] = {fc}, expected {expected}");
        }
        let back = set.coordinates(&f);
        assert_eq!(back.len(), 3);
        for i in 0..3 {
            assert!((back[i] - lambda[i]).abs() <= 1e-12, "λ {lambda:?} came back as {back:?}");
        }
    }
    // A tension vector that does not balance the load: its part in the set, Nᵀ (f − f_p).
    let f = [100.0, 50.0, 80.0, 30.0, 20.0, 90.0, 42.0];
    let back = set.coordinates(&f);
    for (i, b) in back.iter().enumerate() {
        let expected: f64 = (0..7).map(|c| n[(c, i)] * (f[c] - set.particular()[c])).sum();
        assert!((b - expected).abs() <= 1e-12, "λ[{i}] = {b}, expected {expected}");
    }
    // The free cable's coordinate is its tension (its null direction is ±e_7, f_p = 0).
    let free = (0..3).find(|&i| n[(6, i)] != 0.0).unwrap();
    assert!((back[free] - 42.0 * n[(6, free)]).abs() <= 1e-12 && n[(6, free)].abs() == 1.0);
}

#[test]
fn joint_motion_is_the_pseudoinverse_of_the_cable_jacobian() {
    let (j, groups) = two_joints();
    let set =
        EquilibriumSet::new(j.as_ref(), &[-0.4, 0.3, 0.2, -0.5], &[LIMITS; 7], &groups).unwrap();
    let jn = to_nalgebra(&j);
    // J_c⁺ (J_c δq) = δq: J_c has full column rank (distinct singular values in each block).
    for dq in [[1.0, 0.0, 0.0, 0.0], [0.3, -0.7, 0.1, 0.9], [0.0, 0.0, -2.0, 0.5]] {
        let w = &jn * DVector::from_column_slice(&dq);
        let back = set.joint_motion(w.as_slice());
        assert_eq!(back.len(), 4);
        for d in 0..4 {
            assert!((back[d] - dq[d]).abs() <= 1e-12, "δq {dq:?} came back as {back:?}");
        }
    }
    // Cable weights in null(J_cᵀ) (the set's own directions) move no joint.
    let n = set.null_basis();
    let w: Vec<f64> = (0..7).map(|c| n[(c, 0)] + 2.0 * n[(c, 1)] - n[(c, 2)]).collect();
    assert!(set.joint_motion(&w).iter().all(|v| v.abs() <= 1e-12));
    // Any w: J_c⁺ w = (J_cᵀ J_c)⁻¹ J_cᵀ w.
    let w = DVector::from_column_slice(&[1.0, -2.0, 0.5, 3.0, 0.0, -1.0, 7.0]);
    let expected = (jn.transpose() * &jn).lu().solve(&(jn.transpose() * &w)).unwrap();
    let got = set.joint_motion(w.as_slice());
    for d in 0..4 {
        assert!((got[d] - expected[d]).abs() <= 1e-10 * expected.amax(), "{got:?}");
    }
}

#[test]
fn joint_motion_of_a_rank_deficient_block_is_the_least_norm_one() {
    // J_c = u σ vᵀ with u = (1, −1)/√2, v = (1, 1)/√2, σ = 2a: J_c⁺ e_1 = v (uᵀ e_1)/σ =
    // (1, 1)/(4a).
    let a = 0.02;
    let j = jacobian(&[&[a, a], &[-a, -a]]);
    let set = EquilibriumSet::new(j.as_ref(), &[-0.5, -0.5], &[LIMITS; 2], &[0..2]).unwrap();
    assert_eq!(set.dimension(), 1);
    let dq = set.joint_motion(&[1.0, 0.0]);
    for v in dq {
        assert!((v - 1.0 / (4.0 * a)).abs() <= 1e-12, "{v}");
    }
    // f_p: J_cᵀ f = (a (f1 − f2)) (1, 1) = −T0 = (0.5, 0.5): f1 − f2 = 25, least norm ±12.5.
    assert!(
        (set.particular()[0] - 12.5).abs() <= 1e-12 && (set.particular()[1] + 12.5).abs() <= 1e-12
    );
}

#[test]
fn an_unreachable_load_names_the_joints_with_a_tenth_of_its_largest_component() {
    // One cable that crosses no joint: every torque is unreachable, along T0 / |T0|. With
    // T0 = (7, −7, 1, 0.5) the unit direction is (0.7, −0.7, 0.1, 0.05)/0.995: joints 1–3 carry
    // at least a tenth of the largest component (0.0704), joint 4 does not.
    let j = jacobian(&[&[0.0, 0.0, 0.0, 0.0]]);
    let groups = [0..1, 1..2, 2..3, 3..4];
    let t0 = [7.0, -7.0, 1.0, 0.5];
    let Err(StaticsError::NoEquilibrium(why)) =
        EquilibriumSet::new(j.as_ref(), &t0, &[LIMITS], &groups)
    else {
        panic!("answered");
    };
    let size = 99.25_f64.sqrt();
    let NoEquilibriumCause::Unreachable { direction, torque } = &why.cause else { panic!("{why}") };
    assert!((torque - size).abs() <= 1e-13, "{torque}");
    for d in 0..4 {
        assert!((direction[d] - t0[d] / size).abs() <= 1e-15, "{direction:?}");
    }
    assert_eq!(why.joints, vec![0, 1, 2]);
}

#[test]
fn a_set_copied_into_another_ones_buffers_equals_it() {
    // `clone_from` reuses the target's storage (a planner along a trajectory): whatever the
    // target held before (another load, other blocks, another size), the copy equals the source.
    let (j, groups) = two_joints();
    let coupled = jacobian(&[
        &[0.02, 0.01, 0.0, 0.0],
        &[-0.01, -0.01, 0.01, 0.0],
        &[-0.01, 0.03, 0.0, 0.02],
        &[0.0, 0.0, 0.015, 0.005],
        &[0.0, 0.0, -0.02, 0.01],
        &[0.0, 0.0, 0.004, -0.025],
        &[0.0, 0.0, 0.0, 0.0],
    ]);
    let a =
        EquilibriumSet::new(j.as_ref(), &[-0.4, 0.3, 0.2, -0.5], &[LIMITS; 7], &groups).unwrap();
    let b = EquilibriumSet::new(j.as_ref(), &[0.1, 0.2, -0.3, 0.4], &[[10.0, 90.0]; 7], &groups)
        .unwrap();
    let c = EquilibriumSet::new(coupled.as_ref(), &[0.1, 0.2, -0.3, 0.4], &[LIMITS; 7], &groups)
        .unwrap();
    let (small, small_groups) =
        (jacobian(&[&[0.02, 0.0], &[-0.01, -0.01], &[-0.01, 0.03]]), [0..2]);
    let d = EquilibriumSet::new(small.as_ref(), &[0.1, -0.2], &[LIMITS; 3], &small_groups).unwrap();
    assert_ne!(a, b);
    assert_ne!(a, c);
    for source in [&a, &b, &c, &d] {
        for target in [&a, &b, &c, &d] {
            let mut copy = target.clone();
            copy.clone_from(source);
            assert_eq!(&copy, source);
        }
    }
}
