//! The tension policies' edges on hand-written cable Jacobians `J_c` whose answers are known in
//! closed form: the policies' names, the tolerances that accept a tension a hair outside its
//! limits (and put it on the limit) or refuse it, the snap of a tension a hair inside, the
//! width floor of 1 N, and which cable and joint a refusal names. Written for the mutants that
//! survived on `policy.rs` (#25): each test fails a realistic bug of that kind.
#![allow(clippy::unwrap_used, clippy::expect_used)]
// `[0..2]` is a list of one joint (its DOF range), as `groups` takes.
#![allow(clippy::single_range_in_vec_init)]

use std::ops::Range;

use faer::Mat;
use sinew_statics::{
    EquilibriumSet, NoEquilibrium, NoEquilibriumCause, StaticsError, TensionPolicy,
    distribute_with_policy,
};

const LIMITS: [f64; 2] = [20.0, 600.0];

/// A diagonal `J_c` of one cable per DOF, each DOF its own joint, radius 0.02 m, loaded so that
/// the (unique) tensions are `f`: `T0 = −J_cᵀ f`.
fn diagonal(f: &[f64], limits: [f64; 2]) -> (EquilibriumSet, Vec<Range<usize>>) {
    let n = f.len();
    let j = Mat::from_fn(n, n, |r, c| if r == c { 0.02 } else { 0.0 });
    let t0: Vec<f64> = f.iter().map(|v| -0.02 * v).collect();
    let groups: Vec<Range<usize>> = (0..n).map(|d| d..d + 1).collect();
    let set = EquilibriumSet::new(j.as_ref(), &t0, &vec![limits; n], &groups).unwrap();
    assert_eq!(set.dimension(), 0);
    (set, groups)
}

fn names(m: usize) -> Vec<String> {
    (0..m).map(|c| format!("c{}", c + 1)).collect()
}

/// The refusal of every policy (they coincide on a set of dimension 0).
fn refusal(set: &EquilibriumSet, groups: &[Range<usize>]) -> Box<NoEquilibrium> {
    let mut first: Option<Box<NoEquilibrium>> = None;
    for policy in TensionPolicy::ALL {
        let mut f = vec![f64::NAN; set.cable_count()];
        match distribute_with_policy(set, policy, groups, &names(set.cable_count()), &mut f) {
            Err(StaticsError::NoEquilibrium(why)) => match &first {
                Some(w) => assert_eq!(w, &why, "{policy:?}"),
                None => first = Some(why),
            },
            other => panic!("{policy:?}: {other:?} {f:?}"),
        }
    }
    first.unwrap()
}

#[test]
fn the_policies_have_the_names_the_command_line_and_the_json_use() {
    let names: Vec<&str> = TensionPolicy::ALL.iter().map(|p| p.name()).collect();
    assert_eq!(names, ["least-total", "least-norm", "safest"]);
}

#[test]
fn a_tension_a_hair_off_its_limit_is_put_on_it_and_one_clearly_inside_is_kept() {
    // Bound width 580 N: a polished tension within 1e-9 × 580 N = 5.8e-7 N of a limit is put on
    // it; one outside by less than 1e-7 × 580 N = 5.8e-5 N is rounding, clamped onto it.
    let wanted = [
        20.0 + 1e-7,  // snapped to f_min
        20.0 + 1e-6,  // kept
        600.0 - 1e-7, // snapped to f_max
        600.0 - 1e-6, // kept
        600.0 + 1e-5, // outside by rounding: f_max
        20.0 - 1e-5,  // outside by rounding: f_min
        300.0,
    ];
    let expected = [20.0, 20.0 + 1e-6, 600.0, 600.0 - 1e-6, 600.0, 20.0, 300.0];
    let (set, groups) = diagonal(&wanted, LIMITS);
    for policy in TensionPolicy::ALL {
        let mut f = vec![f64::NAN; 7];
        let d = distribute_with_policy(&set, policy, &groups, &names(7), &mut f).unwrap();
        for c in [0, 2, 4, 5] {
            assert_eq!(f[c], expected[c], "{policy:?}: cable {c} at {}", f[c]);
        }
        for c in [1, 3, 6] {
            assert!((f[c] - expected[c]).abs() <= 1e-11, "{policy:?}: cable {c} at {}", f[c]);
            assert!(f[c] != LIMITS[0] && f[c] != LIMITS[1], "{policy:?}: cable {c} snapped");
        }
        let objective = match policy {
            TensionPolicy::LeastTotal => expected.iter().sum::<f64>(),
            TensionPolicy::LeastNorm => expected.iter().map(|v| v * v).sum::<f64>().sqrt(),
            // Cables on a limit: no margin.
            TensionPolicy::Safest => 0.0,
        };
        assert!((d.objective - objective).abs() <= 1e-12 * objective.max(1.0), "{policy:?}");
        assert_eq!((d.policy, d.iterations, d.lambda.len()), (policy, 0, 0));
    }
}

#[test]
fn a_tension_outside_by_more_than_rounding_is_refused_naming_its_cable() {
    // 1e-4 N beyond f_max is 1.7e-7 of the width 580 N: more than rounding.
    let (set, groups) = diagonal(&[300.0, 600.0 + 1e-4, 300.0], LIMITS);
    let why = refusal(&set, &groups);
    assert_eq!(why.joints, vec![1], "{why}");
    let NoEquilibriumCause::Limits { direction, needed, range, at_max, at_min } = &why.cause else {
        panic!("{why}")
    };
    // Along δq = −e_2 the load needs T0 · δq = 0.02 × 600.0001 N m; the cable gives
    // 0.02 m × [20, 600] N.
    assert_eq!(direction, &vec![0.0, -1.0, 0.0]);
    assert!((needed - 0.02 * (600.0 + 1e-4)).abs() <= 1e-13, "{needed}");
    assert!((range[0] - 0.4).abs() <= 1e-13 && (range[1] - 12.0).abs() <= 1e-13, "{range:?}");
    assert_eq!((at_max, at_min), (&vec!["c2".to_owned()], &vec![]));
}

#[test]
fn the_outside_tolerance_scales_with_the_width_floored_at_one_newton() {
    // Limits [−0.5, 0] N (width 0.5 N, floored to 1 N) and J_c = [1]: the tension is −T0
    // exactly. 1e-7 N over f_max is 1e-7 of the floored width, at the tolerance: accepted and
    // put on f_max (without the floor it would be 2e-7 of the width and refused).
    let j = Mat::from_fn(1, 1, |_, _| 1.0);
    let groups = [0..1];
    let set = EquilibriumSet::new(j.as_ref(), &[-1e-7], &[[-0.5, 0.0]], &groups).unwrap();
    assert_eq!(set.particular(), &[1e-7]);
    for policy in TensionPolicy::ALL {
        let mut f = [f64::NAN];
        distribute_with_policy(&set, policy, &groups, &names(1), &mut f).unwrap();
        assert_eq!(f, [0.0], "{policy:?}");
    }
    // Twice that is beyond the tolerance: refused.
    let set = EquilibriumSet::new(j.as_ref(), &[-2e-7], &[[-0.5, 0.0]], &groups).unwrap();
    let why = refusal(&set, &groups);
    assert_eq!(why.joints, vec![0], "{why}");
}

#[test]
fn a_refusal_names_the_cable_farthest_outside_its_limits() {
    // J_c = a [[1, 1], [1, −1]] (one joint of two DOFs), f = (−500, 650) N: cable 1 is 520 N
    // below f_min, cable 2 50 N above f_max. Along cable 1 alone (w = −e_1, δq = J_c⁺ w ∝
    // (−1, −1)) the shortfall per newton of weight is 520 N, more than along either DOF alone
    // (DOF 2: w ∝ (1, −1), 570/√2 ≈ 403 N) or along cable 2 alone (50 N).
    let a = 0.02;
    let j = Mat::from_fn(2, 2, |r, c| if r == 1 && c == 1 { -a } else { a });
    let f = [-500.0, 650.0];
    // T0 = −J_cᵀ f = −(a (f1 + f2), a (f1 − f2)) = (−3, 23).
    let t0 = [-a * (f[0] + f[1]), -a * (f[0] - f[1])];
    let groups = [0..2];
    let set = EquilibriumSet::new(j.as_ref(), &t0, &[LIMITS; 2], &groups).unwrap();
    assert_eq!(set.dimension(), 0);
    let why = refusal(&set, &groups);
    assert_eq!(why.joints, vec![0], "{why}");
    let NoEquilibriumCause::Limits { direction, needed, range, at_max, at_min } = &why.cause else {
        panic!("{why}")
    };
    // Reported along δq = (1, 1): the load needs T0 · δq = 20 N m, cable 1's torque
    // −J_cᵀ f · δq = −2a f_1 ranges over −2a [600, 20] = [−24, −0.8] N m.
    for (d, v) in direction.iter().enumerate() {
        assert!((v - 1.0).abs() <= 1e-12, "direction[{d}] = {v}");
    }
    assert!((needed - 20.0).abs() <= 1e-10, "{needed}");
    assert!((range[0] + 24.0).abs() <= 1e-10 && (range[1] + 0.8).abs() <= 1e-10, "{range:?}");
    assert_eq!((at_max, at_min), (&vec![], &vec!["c1".to_owned()]));
}
