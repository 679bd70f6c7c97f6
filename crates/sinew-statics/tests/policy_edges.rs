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
        20.0 + 6e-7, // kept: just beyond 5.8e-7 (a width of f_max + f_min, 620 N, would snap it)
    ];
    let expected = [20.0, 20.0 + 1e-6, 600.0, 600.0 - 1e-6, 600.0, 20.0, 300.0, 20.0 + 6e-7];
    let (set, groups) = diagonal(&wanted, LIMITS);
    for policy in TensionPolicy::ALL {
        let mut f = vec![f64::NAN; 8];
        let d = distribute_with_policy(&set, policy, &groups, &names(8), &mut f).unwrap();
        for c in [0, 2, 4, 5] {
            assert_eq!(f[c], expected[c], "{policy:?}: cable {c} at {}", f[c]);
        }
        for c in [1, 3, 6, 7] {
            assert!((f[c] - expected[c]).abs() <= 1e-12, "{policy:?}: cable {c} at {}", f[c]);
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
    // f = (10, 650) N: cable 2 is 50 N above f_max, farther out than cable 1 (10 N below
    // f_min); along cable 2 alone the shortfall is 50 N per newton, more than along DOF 2
    // alone (60/√2 ≈ 42 N). Reported along δq = (−1, 1): T0 · δq = 2a f_2 = 26 N m, cable 2
    // gives 2a [20, 600] = [0.8, 24] N m.
    let f = [10.0, 650.0];
    let t0 = [-a * (f[0] + f[1]), -a * (f[0] - f[1])];
    let set = EquilibriumSet::new(j.as_ref(), &t0, &[LIMITS; 2], &groups).unwrap();
    let why = refusal(&set, &groups);
    let NoEquilibriumCause::Limits { direction, needed, range, at_max, at_min } = &why.cause else {
        panic!("{why}")
    };
    assert!(
        (direction[0] + 1.0).abs() <= 1e-12 && (direction[1] - 1.0).abs() <= 1e-12,
        "{direction:?}"
    );
    assert!((needed - 26.0).abs() <= 1e-10, "{needed}");
    assert!((range[0] - 0.8).abs() <= 1e-10 && (range[1] - 24.0).abs() <= 1e-10, "{range:?}");
    assert_eq!((at_max, at_min), (&vec!["c2".to_owned()], &vec![]));
    // f = (−30, 660) N: 50 N below and 60 N above. Along DOF 2 alone (w ∝ (1, −1), both
    // cables) the shortfall per newton, 110/√2 ≈ 78 N, beats cable 2 alone (60 N): reported
    // along δq = (0, 1), T0 · δq = −a (f_1 − f_2) = 13.8 N m, the cables give ±2a × 290 N =
    // ±11.6 N m, cable 2 at f_max and cable 1 at f_min.
    let f = [-30.0, 660.0];
    let t0 = [-a * (f[0] + f[1]), -a * (f[0] - f[1])];
    let set = EquilibriumSet::new(j.as_ref(), &t0, &[LIMITS; 2], &groups).unwrap();
    let why = refusal(&set, &groups);
    let NoEquilibriumCause::Limits { direction, needed, range, at_max, at_min } = &why.cause else {
        panic!("{why}")
    };
    assert!(direction[0].abs() <= 1e-12 && (direction[1] - 1.0).abs() <= 1e-12, "{direction:?}");
    assert!((needed - 13.8).abs() <= 1e-10, "{needed}");
    assert!((range[0] + 11.6).abs() <= 1e-10 && (range[1] - 11.6).abs() <= 1e-10, "{range:?}");
    assert_eq!((at_max, at_min), (&vec!["c2".to_owned()], &vec!["c1".to_owned()]));
}

#[test]
fn every_objective_is_the_one_of_the_answer() {
    // Unique tensions (580, 300, 45) N: Σ f = 925 N, |f| = √(580² + 300² + 45²) N, and the
    // least distance to a limit is 20 N (cable 1 to f_max; cable 3 is 25 N above f_min).
    let (set, groups) = diagonal(&[580.0, 300.0, 45.0], LIMITS);
    for policy in TensionPolicy::ALL {
        let mut f = vec![f64::NAN; 3];
        let d = distribute_with_policy(&set, policy, &groups, &names(3), &mut f).unwrap();
        let expected = match policy {
            TensionPolicy::LeastTotal => 925.0,
            TensionPolicy::LeastNorm => (580.0_f64 * 580.0 + 300.0 * 300.0 + 45.0 * 45.0).sqrt(),
            TensionPolicy::Safest => 20.0,
        };
        assert!((d.objective - expected).abs() <= 1e-12 * expected, "{policy:?}: {}", d.objective);
    }
}

/// The cables' torque `−J_cᵀ f · δq` over the box of limits: `[least, greatest]`.
fn torque_range(j: &Mat<f64>, dq: &[f64], limits: [f64; 2]) -> [f64; 2] {
    let (mut lo, mut hi) = (0.0, 0.0);
    for c in 0..j.nrows() {
        let w: f64 = (0..dq.len()).map(|d| j[(c, d)] * dq[d]).sum();
        let (a, b) = (-w * limits[0], -w * limits[1]);
        lo += a.min(b);
        hi += a.max(b);
    }
    [lo, hi]
}

#[test]
fn every_policy_refuses_a_load_beyond_the_limits_with_the_least_total_certificate() {
    // One universal joint with three cables at 120° (a set of dimension 1) and a second one
    // beside it, holding 0.5 N m: loads of 15 N m on joint 1 need more than 600 N of a cable.
    // The safest program is feasible (its margin goes negative), so its answer is outside the
    // limits and its refusal reads the least-total program's certificate: every policy then
    // reports the same, and it is a true one (recomputed here from J_c, T0 and the limits).
    let s = 0.02 * 3.0_f64.sqrt() / 2.0;
    let rows: [[f64; 2]; 3] = [[0.02, 0.0], [-0.01, -s], [-0.01, s]];
    let j = Mat::from_fn(6, 4, |r, c| if (r < 3) == (c < 2) { rows[r % 3][c % 2] } else { 0.0 });
    let groups = [0..2, 2..4];
    for t0 in [[-15.0, 0.0, 0.5, 0.0], [-12.0, -12.0, 0.0, -0.5], [3.0, 16.0, 0.2, 0.2]] {
        let set = EquilibriumSet::new(j.as_ref(), &t0, &[LIMITS; 6], &groups).unwrap();
        assert_eq!(set.dimension(), 2);
        let mut answers = Vec::new();
        for policy in TensionPolicy::ALL {
            let mut f = vec![f64::NAN; 6];
            let Err(StaticsError::NoEquilibrium(why)) =
                distribute_with_policy(&set, policy, &groups, &names(6), &mut f)
            else {
                panic!("{t0:?} {policy:?}: answered {f:?}");
            };
            assert_eq!(why.joints, vec![0], "{t0:?} {policy:?}: {why}");
            let NoEquilibriumCause::Limits { direction, needed, range, .. } = &why.cause else {
                panic!("{why}")
            };
            // Largest component 1, in the sign of T0, joint 2 still.
            let largest = direction.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            assert!((largest - 1.0).abs() <= 1e-12, "{direction:?}");
            assert!(direction[2..].iter().all(|&v| v == 0.0), "{direction:?}");
            let demand: f64 = (0..4).map(|d| t0[d] * direction[d]).sum();
            assert!((needed - demand).abs() <= 1e-9 * demand.abs(), "{needed} vs {demand}");
            let expected = torque_range(&j, direction, LIMITS);
            for k in 0..2 {
                assert!((range[k] - expected[k]).abs() <= 1e-9, "{range:?} vs {expected:?}");
            }
            assert!(*needed > range[1] + 1e-3 || *needed < range[0] - 1e-3, "{why}");
            answers.push(why);
        }
        assert_eq!(answers[0], answers[2], "{t0:?}: safest and least total differ");
    }
}

#[test]
fn a_load_just_beyond_one_face_is_refused_along_that_face_s_normal() {
    // Three cables at 120° on one universal joint (a set of dimension 1). The torques within
    // the limits form a hexagon; the face where cable 1 is at f_min and cable 3 at f_max (cable
    // 2 anywhere) has the normal n ⊥ J_c row 2, n = (√3/2, −1/2). A load 0.05 N m beyond the
    // middle of that face is refused along n and nowhere else within 1°: the face is 11.6 N m
    // long, and neither DOF alone (60° and 30° away) certifies it. The solver's certificate
    // is then the one reported: its cable weights must be read as w = z_upper − z_lower.
    let s = 0.02 * 3.0_f64.sqrt() / 2.0;
    let rows: [[f64; 2]; 3] = [[0.02, 0.0], [-0.01, -s], [-0.01, s]];
    let j = Mat::from_fn(3, 2, |r, c| rows[r][c]);
    let n = [3.0_f64.sqrt() / 2.0, -0.5];
    // The middle of the face: tensions (20, 310, 600), torque −J_cᵀ f.
    let middle = [20.0, 310.0, 600.0];
    let torque = |d: usize| -(0..3).map(|c| rows[c][d] * middle[c]).sum::<f64>();
    let t0 = [torque(0) + 0.05 * n[0], torque(1) + 0.05 * n[1]];
    let groups = [0..2];
    let set = EquilibriumSet::new(j.as_ref(), &t0, &[LIMITS; 3], &groups).unwrap();
    assert_eq!(set.dimension(), 1);
    for policy in TensionPolicy::ALL {
        let mut f = vec![f64::NAN; 3];
        let Err(StaticsError::NoEquilibrium(why)) =
            distribute_with_policy(&set, policy, &groups, &names(3), &mut f)
        else {
            panic!("{policy:?}: answered {f:?}");
        };
        assert_eq!(why.joints, vec![0], "{policy:?}: {why}");
        let NoEquilibriumCause::Limits { direction, needed, range, at_max, at_min } = &why.cause
        else {
            panic!("{why}")
        };
        let size = direction[0].hypot(direction[1]);
        let cos = (direction[0] * n[0] + direction[1] * n[1]) / size;
        assert!(cos >= 1f64.to_radians().cos(), "{policy:?}: {direction:?} is not along {n:?}");
        let demand = t0[0] * direction[0] + t0[1] * direction[1];
        assert!((needed - demand).abs() <= 1e-9 * demand.abs(), "{needed} vs {demand}");
        let expected = torque_range(&j, direction, LIMITS);
        for k in 0..2 {
            assert!((range[k] - expected[k]).abs() <= 1e-9, "{range:?} vs {expected:?}");
        }
        // Beyond the top by about 0.05 N m per unit of |δq|.
        let beyond = (needed - range[1]) / size;
        assert!((0.03..=0.05 + 1e-9).contains(&beyond), "{policy:?}: {why}");
        // Pulling harder on cable 1 and slacking cable 3 gives more torque along n: cable 1 at
        // f_min and cable 3 at f_max hold back. Cable 2 does not move along n.
        assert_eq!((at_max, at_min), (&vec!["c3".to_owned()], &vec!["c1".to_owned()]), "{why}");
    }
}

#[test]
fn the_least_norm_tensions_inside_the_limits_are_exactly_the_particular_ones() {
    // Two cables pulling the same way on one DOF (J_c = [0.02; 0.02]) hold 4 N m with
    // f_p = (100, 100) N, inside the limits: the least |f| is f_p itself, λ = 0 exactly (the
    // polish of an answer with no limit active), not the solver's λ ≈ 0.
    let j = Mat::from_fn(2, 1, |_, _| 0.02);
    let groups = [0..1];
    let set = EquilibriumSet::new(j.as_ref(), &[-4.0], &[LIMITS; 2], &groups).unwrap();
    assert_eq!(set.dimension(), 1);
    for c in 0..2 {
        assert!((set.particular()[c] - 100.0).abs() <= 1e-12, "{:?}", set.particular());
    }
    let mut f = vec![f64::NAN; 2];
    let d =
        distribute_with_policy(&set, TensionPolicy::LeastNorm, &groups, &names(2), &mut f).unwrap();
    assert_eq!(d.lambda, vec![0.0]);
    assert_eq!(f, set.particular());
    assert!(d.iterations > 0);
    assert!((d.objective - 200.0_f64.sqrt() * 10.0).abs() <= 1e-12, "{}", d.objective);
    // The safest tensions are the same (80 N from f_min each, any shift brings one closer).
    let d =
        distribute_with_policy(&set, TensionPolicy::Safest, &groups, &names(2), &mut f).unwrap();
    assert!(f.iter().all(|v| (v - 100.0).abs() <= 1e-9), "{f:?}");
    assert!((d.objective - 80.0).abs() <= 1e-9, "{}", d.objective);
}

#[test]
fn the_least_total_answer_is_on_its_vertex_exactly_with_wide_limits() {
    // Three cables at 120° with limits [20, 20 000] N (the snap band, 1e-9 of the width, is
    // 2e-5 N here). The least total is f_p + s (1, 1, 1) with the least tension at f_min
    // exactly, put there by the polish (f_p from J_c (J_cᵀ J_c)⁻¹ here).
    let s = 0.02 * 3.0_f64.sqrt() / 2.0;
    let rows: [[f64; 2]; 3] = [[0.02, 0.0], [-0.01, -s], [-0.01, s]];
    let j = Mat::from_fn(3, 2, |r, c| rows[r][c]);
    let groups = [0..2];
    let limits = [20.0, 20_000.0];
    for t0 in [[-50.0, 30.0], [120.0, -7.5], [-3.0, -260.0]] {
        let set = EquilibriumSet::new(j.as_ref(), &t0, &[limits; 3], &groups).unwrap();
        // J_cᵀ J_c = 6e-4 I: f_p = −J_c T0 / 6e-4.
        let fp: Vec<f64> =
            (0..3).map(|c| -(rows[c][0] * t0[0] + rows[c][1] * t0[1]) / 6e-4).collect();
        let shift = limits[0] - fp.iter().fold(f64::INFINITY, |a, &v| a.min(v));
        let mut f = vec![f64::NAN; 3];
        let d = distribute_with_policy(&set, TensionPolicy::LeastTotal, &groups, &names(3), &mut f)
            .unwrap();
        assert_eq!(f.iter().fold(f64::INFINITY, |a, &v| a.min(v)), limits[0], "{t0:?}: {f:?}");
        for c in 0..3 {
            assert!((f[c] - (fp[c] + shift)).abs() <= 1e-9, "{t0:?}: {f:?}");
        }
        assert!((d.objective - f.iter().sum::<f64>()).abs() <= 1e-9, "{t0:?}");
    }
}

#[test]
fn the_single_dof_candidates_move_one_dof_of_one_joint() {
    // The geometry of the refusal above with a third DOF, joint 2, and its own cable at 300 N:
    // f = (−30, 660, 300). The candidates are each DOF alone, so the answer is DOF 2 again
    // (joint 1 only): moving DOF 2 and DOF 3 together would fall shorter per newton (170/√3
    // ≈ 98 N) but is not a motion of one DOF.
    let a = 0.02;
    let j = Mat::from_fn(3, 3, |r, c| match (r, c) {
        (0, 0) | (0, 1) | (1, 0) | (2, 2) => a,
        (1, 1) => -a,
        _ => 0.0,
    });
    let f = [-30.0, 660.0, 300.0];
    let t0: Vec<f64> = (0..3).map(|d| -(0..3).map(|c| j[(c, d)] * f[c]).sum::<f64>()).collect();
    let groups = [0..2, 2..3];
    let set = EquilibriumSet::new(j.as_ref(), &t0, &[LIMITS; 3], &groups).unwrap();
    let why = refusal(&set, &groups);
    assert_eq!(why.joints, vec![0], "{why}");
    let NoEquilibriumCause::Limits { direction, needed, range, at_max, at_min } = &why.cause else {
        panic!("{why}")
    };
    assert!(
        direction[0].abs() <= 1e-12 && (direction[1] - 1.0).abs() <= 1e-12 && direction[2] == 0.0,
        "{direction:?}"
    );
    assert!((needed - 13.8).abs() <= 1e-10, "{needed}");
    assert!((range[0] + 11.6).abs() <= 1e-10 && (range[1] - 11.6).abs() <= 1e-10, "{range:?}");
    assert_eq!((at_max, at_min), (&vec!["c2".to_owned()], &vec!["c1".to_owned()]));
}

#[test]
fn a_candidate_must_fall_short_by_more_than_a_billionth_of_the_largest_limit() {
    // Limits [1000, 1000.5] N (width floored to 1 N) and the geometry of the refusals above:
    // f = (1000 − 5e-7, 1000.5 + 6e-7) N is refused (6e-7 of the width out), but no single DOF
    // and no cable alone falls short by more than 1e-9 × 1000.5 N per newton (DOF 2 alone:
    // 1.1e-6/√2 ≈ 7.8e-7): the refusal reads the cable farthest out, cable 2, alone. Along
    // δq = (−1, 1) the load needs 2a f_2, cable 2 gives 2a [1000, 1000.5] N.
    let a = 0.02;
    let j = Mat::from_fn(2, 2, |r, c| if r == 1 && c == 1 { -a } else { a });
    let limits = [1000.0, 1000.5];
    let f = [1000.0 - 5e-7, 1000.5 + 6e-7];
    let t0 = [-a * (f[0] + f[1]), -a * (f[0] - f[1])];
    let groups = [0..2];
    let set = EquilibriumSet::new(j.as_ref(), &t0, &[limits; 2], &groups).unwrap();
    let why = refusal(&set, &groups);
    let NoEquilibriumCause::Limits { direction, needed, range, at_max, at_min } = &why.cause else {
        panic!("{why}")
    };
    assert!(
        (direction[0] + 1.0).abs() <= 1e-9 && (direction[1] - 1.0).abs() <= 1e-9,
        "{direction:?}"
    );
    assert!((needed - 2.0 * a * f[1]).abs() <= 1e-10, "{needed}");
    assert!((range[0] - 40.0).abs() <= 1e-10 && (range[1] - 40.02).abs() <= 1e-10, "{range:?}");
    assert_eq!((at_max, at_min), (&vec!["c2".to_owned()], &vec![]));
}
