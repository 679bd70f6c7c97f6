//! Degenerate cable sets that users build, on hand-written cable Jacobians `J_c` whose answers
//! are known in closed form: no null space (the tensions unique), a rank-deficient `J_c` (two
//! cables through the same holes), a cable that crosses no joint, a joint with no force
//! closure that can still be held, an unreachable load, bad limits. Each gets a typed answer
//! with the exact numbers or a typed error, never a panic or a NaN.
#![allow(clippy::unwrap_used, clippy::expect_used)]
// `[0..2]` is a list of one joint (its DOF range), as `groups` takes.
#![allow(clippy::single_range_in_vec_init)]

use std::ops::Range;

use faer::Mat;
use sinew_statics::{
    EquilibriumSet, NoEquilibriumCause, StaticsError, TensionPolicy, distribute_with_policy,
};

const LIMITS: [f64; 2] = [20.0, 600.0];

fn jacobian(rows: &[&[f64]]) -> Mat<f64> {
    Mat::from_fn(rows.len(), rows[0].len(), |r, c| rows[r][c])
}

/// Every policy's tensions on the set (`Err` as returned).
fn solve_all(
    set: &EquilibriumSet,
    groups: &[Range<usize>],
) -> Vec<(TensionPolicy, Result<Vec<f64>, StaticsError>)> {
    let names: Vec<String> = (0..set.cable_count()).map(|c| format!("c{}", c + 1)).collect();
    TensionPolicy::ALL
        .into_iter()
        .map(|policy| {
            let mut f = vec![f64::NAN; set.cable_count()];
            let outcome = distribute_with_policy(set, policy, groups, &names, &mut f).map(|d| {
                assert!(d.objective.is_finite(), "{policy:?}: objective {}", d.objective);
                f.clone()
            });
            (policy, outcome)
        })
        .collect()
}

/// `|T0 + J_cᵀ f| / |T0|`.
fn residual(j: &Mat<f64>, t0: &[f64], f: &[f64]) -> f64 {
    let r: f64 = (0..t0.len())
        .map(|d| t0[d] + (0..f.len()).map(|c| j[(c, d)] * f[c]).sum::<f64>())
        .map(|v| v * v)
        .sum();
    r.sqrt() / t0.iter().map(|v| v * v).sum::<f64>().sqrt()
}

#[test]
fn a_set_without_null_space_has_its_unique_tensions_under_every_policy() {
    // Two cables, two DOFs, J_c diagonal: f = −J_c⁻ᵀ T0 = [50, 30] N.
    let j = jacobian(&[&[0.02, 0.0], &[0.0, 0.02]]);
    let groups = [0..1, 1..2];
    let t0 = [-1.0, -0.6];
    let set = EquilibriumSet::new(j.as_ref(), &t0, &[LIMITS; 2], &groups).unwrap();
    assert_eq!(set.dimension(), 0);
    assert!(!set.force_closure().unwrap(), "no null space: no force closure");
    for (policy, outcome) in solve_all(&set, &groups) {
        let f = outcome.unwrap_or_else(|e| panic!("{policy:?}: {e}"));
        assert!((f[0] - 50.0).abs() <= 1e-12 && (f[1] - 30.0).abs() <= 1e-12, "{policy:?}: {f:?}");
        let mut g = vec![0.0; 2];
        let d = distribute_with_policy(&set, policy, &groups, &[], &mut g).unwrap();
        let expected = match policy {
            TensionPolicy::LeastTotal => 80.0,
            TensionPolicy::LeastNorm => 3400.0_f64.sqrt(),
            TensionPolicy::Safest => 10.0,
        };
        assert!((d.objective - expected).abs() <= 1e-12, "{policy:?}: {}", d.objective);
        assert_eq!((d.iterations, d.lambda.len()), (0, 0));
    }
    // 1000 N on cable 1: refused along DOF 1 alone, joint 1 named, with the numbers per unit
    // of joint motion: along δq = −1 the load needs T0 · δq = 20 N m, the cable's torque
    // −J_cᵀ f · δq = 0.02 m × f gives [0.4, 12] N m.
    let t0 = [-20.0, -0.6];
    let set = EquilibriumSet::new(j.as_ref(), &t0, &[LIMITS; 2], &groups).unwrap();
    for (policy, outcome) in solve_all(&set, &groups) {
        let Err(StaticsError::NoEquilibrium(why)) = outcome else {
            panic!("{policy:?}: {outcome:?}");
        };
        assert_eq!(why.joints, vec![0], "{policy:?}: {why}");
        let NoEquilibriumCause::Limits { needed, range, at_max, at_min, direction } = &why.cause
        else {
            panic!("{policy:?}: {why}");
        };
        assert!((needed - 20.0).abs() <= 1e-12, "{policy:?}: needed {needed}");
        assert!((range[0] - 0.4).abs() <= 1e-12 && (range[1] - 12.0).abs() <= 1e-12, "{range:?}");
        assert_eq!((at_max.clone(), at_min.clone()), (vec!["c1".to_owned()], vec![]));
        assert_eq!(direction, &vec![-1.0, 0.0]);
        let message = StaticsError::NoEquilibrium(why).to_string();
        assert!(message.contains("joint 1") && message.contains("c1"), "{message}");
    }
}

#[test]
fn two_cables_through_the_same_holes_share_the_load() {
    // Cable 2 duplicates cable 1 (J_c of rank 2 with 4 cables): a 2-dimensional set. The
    // least-norm tensions split the pair's share equally; every policy balances the load.
    let s = 0.02 * 3.0_f64.sqrt() / 2.0;
    let j = jacobian(&[&[0.02, 0.0], &[0.02, 0.0], &[-0.01, -s], &[-0.01, s]]);
    let groups = [0..2];
    let t0 = [-0.5, 0.2];
    let set = EquilibriumSet::new(j.as_ref(), &t0, &[LIMITS; 4], &groups).unwrap();
    assert_eq!(set.dimension(), 2);
    assert!(set.force_closure().unwrap());
    for (policy, outcome) in solve_all(&set, &groups) {
        let f = outcome.unwrap_or_else(|e| panic!("{policy:?}: {e}"));
        assert!(residual(&j, &t0, &f) <= 1e-12, "{policy:?}: {f:?}");
        assert!(f.iter().all(|&v| (LIMITS[0]..=LIMITS[1]).contains(&v)), "{policy:?}: {f:?}");
        match policy {
            // Σ f: the pair costs the same whichever carries it; the cables 3 and 4 at their
            // least given the pair at 40 N total (cable 3 or 4 at f_min).
            TensionPolicy::LeastTotal => {
                assert!(f[2].min(f[3]) == LIMITS[0], "{f:?}");
                assert!(f[0] + f[1] >= 2.0 * LIMITS[0] - 1e-9, "{f:?}");
            }
            TensionPolicy::LeastNorm => {
                assert!((f[0] - f[1]).abs() <= 1e-9 * f[0], "{f:?}");
            }
            TensionPolicy::Safest => {
                let margin =
                    f.iter().map(|v| (v - LIMITS[0]).min(LIMITS[1] - v)).fold(f64::MAX, f64::min);
                assert!(margin > 100.0, "{f:?}");
            }
        }
    }
}

#[test]
fn a_cable_that_crosses_no_joint_is_free_within_its_limits() {
    // Cable 4 moves no DOF: a zero row of J_c, its own block, its own null direction.
    let s = 0.02 * 3.0_f64.sqrt() / 2.0;
    let j = jacobian(&[&[0.02, 0.0], &[-0.01, -s], &[-0.01, s], &[0.0, 0.0]]);
    let groups = [0..2];
    let t0 = [-0.3, 0.1];
    let set = EquilibriumSet::new(j.as_ref(), &t0, &[LIMITS; 4], &groups).unwrap();
    assert_eq!(set.dimension(), 2);
    assert_eq!(set.particular()[3], 0.0);
    for (policy, outcome) in solve_all(&set, &groups) {
        let f = outcome.unwrap_or_else(|e| panic!("{policy:?}: {e}"));
        assert!(residual(&j, &t0, &f) <= 1e-12, "{policy:?}: {f:?}");
        let expected = match policy {
            TensionPolicy::LeastTotal | TensionPolicy::LeastNorm => LIMITS[0],
            // Any tension with at least the others' margin is safest; the middle is one.
            TensionPolicy::Safest => f[3],
        };
        assert_eq!(f[3], expected, "{policy:?}: {f:?}");
        assert!((LIMITS[0]..=LIMITS[1]).contains(&f[3]));
    }
}

#[test]
fn one_cable_alone_holds_a_torque_that_pulls_it() {
    // One cable on one DOF: no force closure, yet 0.02 m × 50 N holds 1 N m.
    let j = jacobian(&[&[0.02]]);
    let groups = [0..1];
    let set = EquilibriumSet::new(j.as_ref(), &[-1.0], &[LIMITS], &groups).unwrap();
    assert!(!set.force_closure().unwrap());
    for (policy, outcome) in solve_all(&set, &groups) {
        let f = outcome.unwrap_or_else(|e| panic!("{policy:?}: {e}"));
        assert!((f[0] - 50.0).abs() <= 1e-12, "{policy:?}: {f:?}");
    }
    // The opposite torque needs it to push: refused, joint 1, cable at its minimum.
    let set = EquilibriumSet::new(j.as_ref(), &[1.0], &[LIMITS], &groups).unwrap();
    for (policy, outcome) in solve_all(&set, &groups) {
        let Err(StaticsError::NoEquilibrium(why)) = outcome else { panic!("{policy:?}") };
        let NoEquilibriumCause::Limits { needed, range, at_min, direction, .. } = &why.cause else {
            panic!("{why}")
        };
        // Along δq = +1 the load needs T0 · δq = 1 N m; the cable's torque −J_cᵀ f · δq gives
        // −0.02 m × [20, 600] N.
        assert_eq!(direction, &vec![1.0], "{why}");
        assert_eq!(at_min, &vec!["c1".to_owned()], "{why}");
        assert!((needed - 1.0).abs() <= 1e-12, "{why}");
        assert!((range[0] + 12.0).abs() <= 1e-12 && (range[1] + 0.4).abs() <= 1e-12, "{why}");
    }
}

#[test]
fn an_unreachable_load_names_its_joint_and_the_torque_no_cable_makes() {
    // DOF 2 (joint 2) is moved by no cable: 0.3 N m on it cannot be held.
    let j = jacobian(&[&[0.02, 0.0], &[-0.02, 0.0]]);
    let groups = [0..1, 1..2];
    let Err(StaticsError::NoEquilibrium(why)) =
        EquilibriumSet::new(j.as_ref(), &[-0.5, 0.3], &[LIMITS; 2], &groups)
    else {
        panic!("answered");
    };
    assert_eq!(why.joints, vec![1]);
    let NoEquilibriumCause::Unreachable { direction, torque } = &why.cause else { panic!("{why}") };
    assert!((torque - 0.3).abs() <= 1e-15, "{torque}");
    assert_eq!(direction, &vec![0.0, 1.0]);
    assert!(StaticsError::NoEquilibrium(why).to_string().contains("joint 2"));
    // Both DOFs moved only together (rank 1): the difference [0.2, −0.2] is unreachable.
    let j = jacobian(&[&[0.02, 0.02], &[-0.02, -0.02]]);
    let Err(StaticsError::NoEquilibrium(why)) =
        EquilibriumSet::new(j.as_ref(), &[0.3, -0.1], &[LIMITS; 2], &[0..2])
    else {
        panic!("answered");
    };
    let NoEquilibriumCause::Unreachable { direction, torque } = &why.cause else { panic!("{why}") };
    let h = 0.5_f64.sqrt();
    assert!((torque - 0.2 * 2.0_f64.sqrt()).abs() <= 1e-15, "{torque}");
    assert!(
        (direction[0] - h).abs() <= 1e-15 && (direction[1] + h).abs() <= 1e-15,
        "{direction:?}"
    );
    assert_eq!(why.joints, vec![0]);
}

#[test]
fn bad_inputs_of_a_set_are_typed_errors() {
    let j = jacobian(&[&[0.02, 0.0], &[0.0, 0.02]]);
    let groups = [0..2];
    let nan = jacobian(&[&[0.02, f64::NAN], &[0.0, 0.02]]);
    assert!(matches!(
        EquilibriumSet::new(nan.as_ref(), &[0.0; 2], &[LIMITS; 2], &groups),
        Err(StaticsError::NonFiniteInput { .. })
    ));
    assert!(matches!(
        EquilibriumSet::new(j.as_ref(), &[0.0, f64::INFINITY], &[LIMITS; 2], &groups),
        Err(StaticsError::NonFiniteInput { .. })
    ));
    assert!(matches!(
        EquilibriumSet::new(j.as_ref(), &[0.0; 3], &[LIMITS; 2], &groups),
        Err(StaticsError::DimensionMismatch { expected: 2, got: 3, .. })
    ));
    assert!(matches!(
        EquilibriumSet::new(j.as_ref(), &[0.0; 2], &[LIMITS; 3], &groups),
        Err(StaticsError::DimensionMismatch { expected: 2, got: 3, .. })
    ));
    let set = EquilibriumSet::new(j.as_ref(), &[-1.0, -1.0], &[LIMITS; 2], &groups).unwrap();
    let mut short = vec![0.0; 1];
    for policy in TensionPolicy::ALL {
        assert!(matches!(
            distribute_with_policy(&set, policy, &groups, &[], &mut short),
            Err(StaticsError::DimensionMismatch { expected: 2, got: 1, .. })
        ));
    }
    assert!(matches!(
        set.tensions(&[1.0], &mut [0.0; 2]),
        Err(StaticsError::DimensionMismatch { what: "λ", expected: 0, got: 1 })
    ));
    assert!(matches!(
        set.tensions(&[], &mut [0.0; 3]),
        Err(StaticsError::DimensionMismatch { what: "tensions", expected: 2, got: 3 })
    ));
    // Limits the wrong way round (f_min > f_max) leave no tension: refused, not NaN.
    let s = 0.02 * 3.0_f64.sqrt() / 2.0;
    let j = jacobian(&[&[0.02, 0.0], &[-0.01, -s], &[-0.01, s]]);
    let set = EquilibriumSet::new(j.as_ref(), &[-0.1, 0.0], &[[600.0, 20.0]; 3], &groups).unwrap();
    for (policy, outcome) in solve_all(&set, &groups) {
        assert!(matches!(outcome, Err(StaticsError::NoEquilibrium(_))), "{policy:?}: {outcome:?}");
    }
}
