//! The closed-form tension interval of one joint: equilibrium, exact ends, typed failures.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Matrix3x2, Vector2, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use sinew_statics::{InfeasibleReason, StaticsError, TensionLimits, tension_interval};
use sinew_testkit::config;

const LIMITS: TensionLimits = TensionLimits { f_min: 20.0, f_max: 600.0 };

/// A cable Jacobian block of three cables through holes at radius ρ, 120° apart, for a joint
/// bent by small angles: rows ≈ ∂L/∂q = [ρ sin θ_k, −ρ cos θ_k] plus a perturbation.
fn joint_block(rng: &mut ChaCha8Rng) -> Matrix3x2<f64> {
    let rho = rng.random_range(0.01..0.03);
    let theta0 = rng.random_range(0.0..std::f64::consts::TAU);
    Matrix3x2::from_fn(|k, c| {
        let theta = theta0 + k as f64 * std::f64::consts::TAU / 3.0;
        let base = if c == 0 { rho * theta.sin() } else { -rho * theta.cos() };
        base * (1.0 + rng.random_range(-0.2..0.2))
    })
}

#[test]
fn every_level_balances_the_torque_and_the_ends_are_exact() {
    let mut rng = config::rng(21);
    let mut checked = 0;
    let mut overshoot = f64::NEG_INFINITY;
    let (mut worst_residual, mut worst_limit, mut narrowest) = (0.0_f64, 0.0_f64, f64::INFINITY);
    let outside = |f: Vector3<f64>| f.iter().any(|x| !(LIMITS.f_min..=LIMITS.f_max).contains(x));
    for _ in 0..1000 {
        let jacobian = joint_block(&mut rng);
        let tau = Vector2::new(rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0));
        let Ok(interval) = tension_interval(0, &jacobian, &tau, LIMITS) else { continue };
        checked += 1;
        // A feasible interval is a segment, not a point: `lambda_min <= lambda_max` alone
        // would accept a collapsed one.
        assert!(interval.width() > 0.0, "collapsed interval {interval:?}");
        narrowest = narrowest.min(interval.width());
        assert!(interval.null.min() > 0.0);
        // The null direction is one: J_cᵀ n = 0, |n| = 1.
        assert!((jacobian.transpose() * interval.null).norm() <= 1e-15, "Jᵀ n ≠ 0");
        for s in [0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 1.0] {
            let f = interval.tensions_at_level(s);
            let residual = (tau + jacobian.transpose() * f).norm();
            worst_residual = worst_residual.max(residual);
            // Old bound 1e-9 N m; measured worst 7.1e-15 (|Jᵀ f| ≤ ~20 N m, ε ≈ 2.2e-16).
            assert!(residual <= 1e-13, "residual {residual:e} at level {s}");
            for k in 0..3 {
                overshoot = overshoot.max(LIMITS.f_min - f[k]).max(f[k] - LIMITS.f_max);
                // Old bound 1e-9 N; measured worst 1.1e-13 N.
                assert!(f[k] >= LIMITS.f_min - 1e-12 && f[k] <= LIMITS.f_max + 1e-12, "f = {f:?}");
            }
        }
        let (low, high) = interval.ends();
        let distance_to_limit = |f: Vector3<f64>| {
            f.iter()
                .map(|&x| (x - LIMITS.f_min).abs().min((x - LIMITS.f_max).abs()))
                .fold(f64::INFINITY, f64::min)
        };
        worst_limit = worst_limit.max(distance_to_limit(low)).max(distance_to_limit(high));
        // Old bound 1e-9 N; measured worst 1.1e-13 N (600 N · ε).
        assert!(
            distance_to_limit(low) <= 1e-12 && distance_to_limit(high) <= 1e-12,
            "ends {low:?} {high:?} not on a limit"
        );
        // The ends are the widest: one step beyond either leaves the limits.
        let step = 1e-6 * (1.0 + interval.lambda_max.abs().max(interval.lambda_min.abs()));
        assert!(outside(interval.tensions(interval.lambda_min - step)), "λ_min is not the end");
        assert!(outside(interval.tensions(interval.lambda_max + step)), "λ_max is not the end");
        // The lower end has the least total tension.
        assert!(low.sum() < high.sum());
    }
    println!(
        "{checked} feasible: worst |τ + Jᵀ f| = {worst_residual:.2e} N m, worst end-to-limit \
         distance {worst_limit:.2e} N, narrowest width {narrowest:.2e}"
    );
    println!("largest step beyond a limit {overshoot:.2e} N");
    assert!(checked > 500, "only {checked} of 1000 random joints were feasible");
}

#[test]
fn a_torque_beyond_the_limits_is_infeasible_and_names_the_joint() {
    let mut rng = config::rng(22);
    let jacobian = joint_block(&mut rng);
    let tau = Vector2::new(100.0, 0.0);
    let err = tension_interval(3, &jacobian, &tau, LIMITS).unwrap_err();
    assert!(
        matches!(
            err,
            StaticsError::Infeasible {
                joint: 3,
                reason: InfeasibleReason::OutsideLimits { .. },
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().starts_with("joint 4 cannot hold torque"), "{err}");
}

#[test]
fn lost_force_closure_is_reported_not_refused() {
    // Null direction of Jᵀ along [1, −1, 0]: cables 1 and 2 pull the same way, so raising one
    // slackens the other; cable 3 keeps its tension whatever λ.
    let jacobian = Matrix3x2::new(0.02, 0.0, 0.02, 0.0, 0.0, -0.02);
    // A torque these cables hold within [20, 600] N: an interval, not an error.
    let tau = Vector2::new(-4.0, 2.0);
    let interval = tension_interval(0, &jacobian, &tau, LIMITS).unwrap();
    assert!(!interval.force_closure());
    assert!(interval.null[2].abs() < 1e-15 && interval.null.sum() >= 0.0, "{:?}", interval.null);
    assert!(interval.width() > 0.0);
    for lambda in [
        interval.lambda_min,
        0.5 * (interval.lambda_min + interval.lambda_max),
        interval.lambda_max,
    ] {
        let f = interval.tensions(lambda);
        assert!(f.iter().all(|&v| (LIMITS.f_min..=LIMITS.f_max).contains(&v)), "{f:?}");
        let residual = tau + jacobian.transpose() * f;
        assert!(residual.norm() <= 1e-12 * tau.norm(), "{residual:?}");
    }
    // Each end has one cable on a limit: cable 1 or 2 on f_min or f_max.
    let (low, high) = interval.ends();
    let on_limit = |f: Vector3<f64>| f.iter().any(|&v| v == LIMITS.f_min || v == LIMITS.f_max);
    assert!(on_limit(low) && on_limit(high), "{low:?} {high:?}");
    // Cable 3 must keep 100 N, whatever λ: a torque needing 1000 N is refused, naming it.
    let err = tension_interval(0, &jacobian, &Vector2::new(-4.0, 20.0), LIMITS).unwrap_err();
    assert!(
        matches!(
            err,
            StaticsError::Infeasible {
                reason: InfeasibleReason::FixedTension { cable: 2, .. },
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("cable 3 must keep the tension 1000 N"), "{err}");
}

#[test]
fn a_rank_deficient_block_is_a_typed_outcome() {
    let jacobian = Matrix3x2::new(0.02, 0.04, -0.01, -0.02, -0.01, -0.02);
    let err = tension_interval(1, &jacobian, &Vector2::new(0.1, 0.1), LIMITS).unwrap_err();
    assert!(
        matches!(
            err,
            StaticsError::Infeasible { joint: 1, reason: InfeasibleReason::RankDeficient, .. }
        ),
        "{err:?}"
    );
}

#[test]
fn a_nan_torque_is_an_error_not_a_nan() {
    let mut rng = config::rng(23);
    let jacobian = joint_block(&mut rng);
    let err = tension_interval(0, &jacobian, &Vector2::new(f64::NAN, 0.0), LIMITS).unwrap_err();
    assert!(matches!(err, StaticsError::NonFiniteTorque { .. }), "{err:?}");
}

#[test]
fn tensions_at_a_limit_are_exactly_on_it() {
    // Within the interval no tension leaves [f_min, f_max] even by rounding, and at the ends
    // the limiting cable is exactly at its limit (not 19.999999999999996).
    let mut rng = config::rng(22);
    let mut checked = 0;
    for _ in 0..1000 {
        let jacobian = joint_block(&mut rng);
        let tau = Vector2::new(rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0));
        let Ok(interval) = tension_interval(0, &jacobian, &tau, LIMITS) else { continue };
        checked += 1;
        let (lo, hi) = interval.ends();
        assert_eq!(lo.min(), LIMITS.f_min, "{lo:?}");
        assert_eq!(hi.max(), LIMITS.f_max, "{hi:?}");
        assert_eq!(interval.tensions_at_level(0.0), lo);
        assert_eq!(interval.tensions_at_level(1.0), hi);
        for s in [0.0, 0.3, 0.7, 1.0] {
            let f = interval.tensions_at_level(s);
            assert!(f.min() >= LIMITS.f_min && f.max() <= LIMITS.f_max, "{f:?} at level {s}");
        }
    }
    assert!(checked > 100, "only {checked} feasible cases");
}

#[test]
fn actuator_intervals_with_limits_of_their_own() {
    use sinew_statics::actuator_interval;
    let mut rng = config::rng(22);
    let common = [LIMITS.f_min, LIMITS.f_max];
    let (mut checked, mut swapped) = (0, 0);
    for _ in 0..400 {
        let block = joint_block(&mut rng);
        let tau = Vector2::new(rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
        // With the common limits: the closed form, bit for bit.
        if let Ok(plain) = tension_interval(3, &block, &tau, LIMITS) {
            let same = actuator_interval((3, 9), &block, &tau, LIMITS, [common; 3]).unwrap();
            assert_eq!(same.scaled, plain);
            assert_eq!(same.ends(), plain.ends());
        }
        // Limits of their own: balanced, within each cable's limits, a cable on a limit at
        // each end, the least total first.
        let limits: [[f64; 2]; 3] = std::array::from_fn(|_| {
            let lo = rng.random_range(20.0..60.0);
            [lo, rng.random_range(200.0..600.0)]
        });
        let Ok(interval) = actuator_interval((3, 9), &block, &tau, LIMITS, limits) else {
            continue;
        };
        let (low, high) = interval.ends();
        for f in [low, high] {
            let residual = tau + block.transpose() * f;
            assert!(residual.norm() <= 1e-12 * (1.0 + tau.norm()), "{residual}");
            for (c, l) in limits.iter().enumerate() {
                assert!(f[c] >= l[0] - 1e-9 && f[c] <= l[1] + 1e-9, "cable {c}: {} in {l:?}", f[c]);
            }
            let tight =
                (0..3).any(|c| (f[c] - limits[c][0]).abs().min((f[c] - limits[c][1]).abs()) < 1e-9);
            assert!(tight, "{f}");
        }
        assert!(low.sum() <= high.sum());
        swapped += usize::from(interval.alpha.dot(&interval.scaled.null) < 0.0);
        checked += 1;
    }
    assert!(checked > 100, "{checked} feasible cases");
    // An empty cable interval is refused, naming the cable in the routing.
    let block = joint_block(&mut rng);
    let err = actuator_interval(
        (3, 9),
        &block,
        &Vector2::zeros(),
        LIMITS,
        [common, [50.0, 40.0], common],
    );
    assert!(matches!(err, Err(StaticsError::EmptyActuatorInterval { cable: 10, .. })), "{err:?}");
    assert_eq!(swapped, 0, "random blocks are in force closure");
    // Not in force closure, null direction ∝ (1, 1, −3), the first two cables' limits narrow:
    // the scaled direction (∝ (10, 10, −3)) has a positive sum, the actuator tensions' total
    // falls along λ, so the ends swap.
    let block = Matrix3x2::new(0.01, 0.03, -0.01, 0.0, 0.0, 0.01);
    let held = Vector3::new(50.0, 50.0, 300.0);
    let tau = -(block.transpose() * held);
    let limits = [[20.0, 80.0], [20.0, 80.0], common];
    let interval = actuator_interval((0, 0), &block, &tau, LIMITS, limits).unwrap();
    assert!(interval.alpha.dot(&interval.scaled.null) < 0.0);
    let (low, high) = interval.ends();
    assert!(low.sum() < high.sum() - 1.0, "{low} {high}");
    assert_eq!(high, interval.tensions(interval.scaled.lambda_min));
}
