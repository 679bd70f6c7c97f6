//! The pipeline with friction at the holes (`ArmStiffness::evaluate_with_friction`, spec §9,
//! #27) on cdhrm5 at the loaded pose, both routings, μ = 0.1: the tensions of each regime
//! balance the load through the regime's Jacobian, the dead band's ends reproduce the pull and
//! release distributions, `K_q` is the regime's, `C_x` is `J_x (K_q + K_W)⁻¹ J_xᵀ` on it (and
//! `end_stiffness`'s on the dense `K_W`, bit for bit, for a load without and with a moment), and
//! the levels, given tensions and μ = 0 are refused or checked as documented; a sliding set that
//! is itself unstable, and one that makes the increment singular, are typed refusals.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use faer::linalg::solvers::Solve;
use nalgebra::Vector6;
use sinew_routing::{FrictionModel, RoutingError, Slip, compute_wrap_gradients};
use sinew_statics::{StaticsError, TensionChoice, TensionPolicy};
use sinew_stiffness::{
    ArmStiffness, ArmStiffnessData, BandEdge, EndOutcome, EndStiffnessData, FrictionArmData,
    FrictionRegime, History, HoleEvent, StiffnessError, base_directions, directional_response,
    end_stiffness, sliding_response, stick_load_limits,
};
use sinew_testkit::cdhrm5;

const MU: f64 = 0.1;
const F0: [f64; 6] = [0.0, 5.0, 0.0, 0.0, 0.0, 0.0];

fn regimes() -> [FrictionRegime; 5] {
    [
        FrictionRegime::Slip(Slip::Pull),
        FrictionRegime::Slip(Slip::Release),
        FrictionRegime::Stick(History::Pull),
        FrictionRegime::Stick(History::Release),
        FrictionRegime::Stick(History::Equal),
    ]
}

#[test]
fn each_regime_balances_the_load_and_ends_on_its_own_stiffness() {
    let f0 = Vector6::from(F0);
    let q = cdhrm5::LOADED_POSE;
    for pattern in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(pattern);
        let arm = ArmStiffness::new(&robot, &routing).unwrap();
        let model = FrictionModel::new(&routing).with_friction_coefficient(MU).unwrap();
        let mut data = ArmStiffnessData::new(&arm);
        let mut out = FrictionArmData::new(&arm, &model);
        let n = arm.dof();
        // E4's load, then one with a moment: a non-symmetric `K_W`, the end stage's general
        // branch for the symmetric stick `K_q` as for the slip one.
        let loads = [f0, Vector6::new(0.0, 5.0, 0.0, 0.3, 0.0, 0.2)];
        for (load, regime) in loads.iter().flat_map(|l| regimes().map(move |r| (l, r))) {
            let choice = TensionChoice::Policy(TensionPolicy::Safest);
            let outcome = arm
                .evaluate_with_friction(&mut data, &mut out, (&model, regime), &q, load, choice)
                .unwrap();
            assert_eq!(outcome, EndOutcome::Stiff, "{pattern:?} {regime:?}");
            // Balance: −Σ_s T_s J_sᵀ = T0, from the segment tensions and the segment rows.
            let t0 = &data.statics.t0;
            let mut tau = vec![0.0; n];
            for (c, segments) in out.segments.iter().enumerate() {
                for (s, t) in segments.iter().enumerate().skip(1) {
                    let j_s = out.friction.segment_jacobian(&model, c, s).unwrap();
                    for (v, d) in j_s.values.iter().zip(j_s.dofs) {
                        tau[d] -= t * v;
                    }
                }
            }
            let scale = t0.iter().map(|x| x.abs()).fold(0.0, f64::max);
            let worst = tau.iter().zip(t0).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(worst <= 1e-9 * scale, "{pattern:?} {regime:?}: residual {worst:.1e}");
            // The dead band's ends are the pull and release distributions' actuator tensions.
            for (c, band) in out.dead_band.iter().enumerate() {
                let t = out.actuator[c];
                assert!(band[0] <= t * (1.0 + 1e-12) && t <= band[1] * (1.0 + 1e-12));
                let end = match regime {
                    FrictionRegime::Slip(Slip::Pull) | FrictionRegime::Stick(History::Pull) => {
                        band[1]
                    }
                    FrictionRegime::Slip(Slip::Release)
                    | FrictionRegime::Stick(History::Release) => band[0],
                    _ => continue,
                };
                assert!(
                    (end - t).abs() <= 1e-12 * t,
                    "{pattern:?} {regime:?} cable {c}: {end} vs {t}"
                );
            }
            // C_x = J_x (K_q + K_W)⁻¹ J_xᵀ with the regime's K_q.
            let k_q = out.stiffness.stiffness().unwrap().to_owned();
            assert_eq!(out.stiffness.regime(), Some(regime));
            let k_w = data.k_w().to_owned();
            assert_eq!(k_w == k_w.transpose(), load[3] == 0.0, "{pattern:?}: K_W's symmetry");
            let j_x = data.j_x().to_owned();
            let a = Mat::from_fn(n, n, |i, j| k_q[(i, j)] + k_w[(i, j)]);
            let x = a.partial_piv_lu().solve(j_x.transpose().to_owned());
            let c_x = &j_x * &x;
            let got = out.end.compliance();
            let scale = (0..6).map(|i| c_x[(i, i)].abs()).fold(0.0, f64::max);
            for i in 0..6 {
                for j in 0..6 {
                    assert!(
                        (got[(i, j)] - c_x[(i, j)]).abs() <= 1e-10 * scale,
                        "{pattern:?} {regime:?}"
                    );
                }
            }
            assert!(out.stability_margin(&mut data).unwrap() > 0.0);
            // The pipeline's end stage (K_W from its generators) is `end_stiffness` on the
            // dense K_W, bit for bit.
            same_end_as_dense(&out, &mut data, &format!("{pattern:?} {regime:?} {load:?}"));
        }
        // Stick after equal takes the frictionless statics' tensions (any choice, levels too).
        let levels = TensionChoice::Levels(&[0.5; 5]);
        let equal = (&model, FrictionRegime::Stick(History::Equal));
        arm.evaluate_with_friction(&mut data, &mut out, equal, &q, &f0, levels).unwrap();
        assert_eq!(out.actuator, data.tensions());
        // Levels under pull are the closed form on J̃ with the actuator limits: in the
        // decoupled model level 0 is the least total (the default policy); given actuator
        // tensions are checked through J̃.
        let pull = (&model, FrictionRegime::Slip(Slip::Pull));
        let lowest = TensionChoice::Levels(&[0.0; 5]);
        arm.evaluate_with_friction(&mut data, &mut out, pull, &q, &f0, lowest).unwrap();
        let at_level_0 = out.actuator.clone();
        arm.evaluate_with_friction(&mut data, &mut out, pull, &q, &f0, TensionChoice::Default)
            .unwrap();
        if routing.is_decoupled() {
            for (a, b) in at_level_0.iter().zip(&out.actuator) {
                assert!((a - b).abs() <= 1e-8 * b, "{pattern:?}: {a} vs {b}");
            }
        }
        arm.evaluate_with_friction(&mut data, &mut out, pull, &q, &f0, levels).unwrap();
        assert!(out.stability_margin(&mut data).unwrap().is_finite());
        arm.evaluate_with_friction(&mut data, &mut out, pull, &q, &f0, TensionChoice::Default)
            .unwrap();
        let chosen = out.actuator.clone();
        let given = TensionChoice::Given(&chosen);
        arm.evaluate_with_friction(&mut data, &mut out, pull, &q, &f0, given).unwrap();
        assert_eq!(out.actuator, chosen);
        let mut off = chosen.clone();
        off[0] += 1.0;
        let e = arm
            .evaluate_with_friction(&mut data, &mut out, pull, &q, &f0, TensionChoice::Given(&off))
            .unwrap_err();
        assert!(matches!(e, StiffnessError::Statics(StaticsError::NotBalanced(_))), "{e}");
        // No band at μ = 0: the stick regime is refused.
        let frictionless = FrictionModel::new(&routing);
        let mut out0 = FrictionArmData::new(&arm, &frictionless);
        let stick0 = (&frictionless, FrictionRegime::Stick(History::Equal));
        let e = arm
            .evaluate_with_friction(&mut data, &mut out0, stick0, &q, &f0, TensionChoice::Default)
            .unwrap_err();
        assert!(matches!(e, StiffnessError::StickWithoutFriction { cable: 0 }), "{e}");
    }
}

/// `out.end` is `end_stiffness` on the regime's `K_q` and the dense `K_W`, bit for bit.
fn same_end_as_dense(out: &FrictionArmData, data: &mut ArmStiffnessData, what: &str) {
    let k_q = out.stiffness.stiffness().unwrap().to_owned();
    let (k_w, j_x) = (data.k_w().to_owned(), data.j_x().to_owned());
    let mut dense = EndStiffnessData::new(k_q.nrows());
    end_stiffness(k_q.as_ref(), k_w.as_ref(), j_x.as_ref(), &mut dense).unwrap();
    assert_eq!(dense.compliance(), out.end.compliance(), "{what}");
    assert_eq!(dense.stiffness(), out.end.stiffness(), "{what}");
}

/// Sticking holes hold an arm the frictionless model finds unstable (E4's load at the lowest
/// levels); after a pull a load increment makes some of them slide, and on cdhrm5 the arm they
/// leave is still stable. A destabilising load stiffness `−c I` added to `K_W` (measured on
/// this arm: answers up to `c ≈ 0.1 λ`, λ the stick arm's least eigenvalue; no consistent set
/// of sliding holes from `0.375 λ` to `2.15 λ`, where some sliding sets leave an indefinite
/// arm; beyond, a consistent set whose arm is unstable) turns each answer into its typed
/// refusal. The same hole named twice makes the increment's system singular.
#[test]
fn an_unstable_or_singular_sliding_set_is_refused() {
    let f0 = Vector6::from(F0);
    let q = cdhrm5::LOADED_POSE;
    let (robot, routing) = cdhrm5::robot_and_routing(sinew_routing::PatternModel::Decoupled);
    let arm = ArmStiffness::new(&robot, &routing).unwrap();
    let model = FrictionModel::new(&routing).with_friction_coefficient(MU).unwrap();
    let mut data = ArmStiffnessData::new(&arm);
    let mut out = FrictionArmData::new(&arm, &model);
    let lowest = TensionChoice::Levels(&[0.0; 5]);
    arm.evaluate_joints(&mut data, &q, &f0, lowest).unwrap();
    let outcome = arm.solve_end(&mut data).unwrap();
    assert!(matches!(outcome, EndOutcome::Unstable { .. }), "{outcome:?}");
    let after_pull = (&model, FrictionRegime::Stick(History::Pull));
    let outcome =
        arm.evaluate_with_friction(&mut data, &mut out, after_pull, &q, &f0, lowest).unwrap();
    assert_eq!(outcome, EndOutcome::Stiff, "sticking holes hold the arm");
    let k_q = out.stiffness.stiffness().unwrap().to_owned();
    let (k_w, j_x) = (data.k_w().to_owned(), data.j_x().to_owned());
    let n = k_q.nrows();
    let u = Vector6::new(0.0, 1.0, 0.0, 0.0, 0.0, 0.0);
    // The stick evaluation computes no wrap gradient; what needs them says so until
    // `compute_wrap_gradients` adds them.
    let increment = (k_q.as_ref(), k_w.as_ref(), j_x.as_ref());
    let (f, t) = (&out.friction, &out.actuator);
    let e = directional_response(&model, &routing, f, History::Pull, t, increment, &u).unwrap_err();
    let missing = |e: &StiffnessError| {
        matches!(e, StiffnessError::Routing(RoutingError::FrictionNotComputed { what, .. })
            if *what == "wrap gradients")
    };
    assert!(missing(&e), "{e}");
    let base = base_directions();
    let e = stick_load_limits(&model, &routing, f, History::Pull, t, increment, &base).unwrap_err();
    assert!(missing(&e), "{e}");
    compute_wrap_gradients(&model, &mut out.friction).unwrap();
    let (f, t) = (&out.friction, &out.actuator);
    let stick = Mat::from_fn(n, n, |i, j| 0.5 * (k_q[(i, j)] + k_q[(j, i)]) + k_w[(i, j)]);
    let least = stick.self_adjoint_eigenvalues(faer::Side::Lower).unwrap()[0];
    assert!(least > 0.0);
    let respond = |c: f64| {
        let softer = Mat::from_fn(n, n, |i, j| k_w[(i, j)] - if i == j { c } else { 0.0 });
        let increment = (k_q.as_ref(), softer.as_ref(), j_x.as_ref());
        directional_response(&model, &routing, f, History::Pull, t, increment, &u).map_err(Box::new)
    };
    let [plus, minus] = respond(0.0).unwrap();
    assert!(plus.stiffness > 0.0 && minus.stiffness > 0.0 && plus.stiffness != minus.stiffness);
    // A zero direction, or one with a NaN, is bad input (each alone: cargo mutants found the
    // check with `&&` for `||` unnoticed, which lets both through).
    for bad in [Vector6::zeros(), Vector6::new(0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0)] {
        let e = directional_response(&model, &routing, f, History::Pull, t, increment, &bad)
            .unwrap_err();
        assert!(matches!(e, StiffnessError::InvalidWrenchDirection { .. }), "{e}");
        assert_eq!(e.kind(), sinew_robot::ErrorKind::Input);
    }
    let e = *respond(least).unwrap_err();
    assert!(matches!(e, StiffnessError::NoConsistentSliding { passes } if passes > 0), "{e}");
    let e = *respond(3.0 * least).unwrap_err();
    let StiffnessError::UnstableSliding { holes, min_eigenvalue } = e else { panic!("{e}") };
    assert!(holes > 0 && min_eigenvalue < 0.0, "{e}");
    assert_eq!(e.kind(), sinew_robot::ErrorKind::Unstable);
    // One hole named twice: two equal columns.
    let increment = (k_q.as_ref(), k_w.as_ref(), j_x.as_ref());
    let event = HoleEvent { cable: 0, hole: 0, edge: BandEdge::Lower, kinked: false };
    let twice = [event, event];
    let e =
        sliding_response(&model, &routing, f, History::Pull, t, increment, &u, &twice).unwrap_err();
    assert!(matches!(e, StiffnessError::NoConsistentSliding { .. }), "{e}");
}
