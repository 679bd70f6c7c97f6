//! The joint stiffness with friction at the holes (spec §9, #27): the slip regimes against the
//! central difference of the torque of a nonlinear model built from library *values* only, the
//! stick regime against the second differences of the segment springs' energy, the
//! Cauchy–Schwarz bound `K_stick ⪰ K_frictionless`, the μ → 0⁺ limit and μ = 0 bit for bit.
//!
//! Criterion for each comparison, per case over its configurations: `max |analytic − FD| ≤
//! tol · max |analytic|`, `tol` a few times the worst error measured (beside each bound;
//! `--nocapture` prints them). Cases: cdhrm5 in both routing files and seeded random-geometry
//! chains (pattern routings, decoupled and routed, an explicit routing, and one with two cables
//! that run back toward the base), μ = 0.2.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::{Mat, MatRef};
use nalgebra::DMatrix;
use sinew_robot::{Robot, RobotData};
use sinew_routing::{
    FrictionData, FrictionModel, Order, Routing, RoutingData, Slip, compute_cable_geometry,
    compute_capstan_weights, compute_friction_geometry,
};
use sinew_stiffness::{
    FrictionRegime, FrictionStiffnessData, History, StiffnessError, joint_stiffness,
    slip_stiffness, stick_stiffness,
};
use sinew_testkit::cdhrm5;
use sinew_testkit::config::{random_qs, rng};
use sinew_testkit::numeric::{H, max_diff_and_scale, perturbed};
use sinew_testkit::random_chain::RandomChain;

use rand::Rng;

const MU: f64 = 0.2;

/// Everything at one configuration.
struct At {
    geometry: RoutingData,
    friction: FrictionData,
}

fn evaluate(robot: &Robot, routing: &Routing, model: &FrictionModel, q: &[f64]) -> At {
    let mut rdata = RobotData::new(robot);
    let mut geometry = RoutingData::new(routing);
    compute_cable_geometry(routing, robot, &mut rdata, &mut geometry, q, Order::Hessians).unwrap();
    let mut friction = FrictionData::new(model);
    compute_friction_geometry(model, routing, &geometry, &mut friction).unwrap();
    At { geometry, friction }
}

/// `(name, robot, routing, tolerances [slip vs FD of τ, stick vs FD of the energy])`, each a
/// few times the worst measured: slip 2.6e-9 (cdhrm5), 2.2e-9 (random chains), 1.8e-9 (turning
/// back); stick 2.2e-8 (cdhrm5), 5.4e-8 (random chains; second differences of the energy at
/// h = 1e-4), 4.7e-8 (turning back).
fn cases() -> Vec<(String, Robot, Routing, [f64; 2])> {
    let mut out = Vec::new();
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        out.push((format!("cdhrm5 {model:?}"), robot, routing, [1e-8, 1e-7]));
    }
    for seed in [3, 4] {
        let chain = RandomChain::new(3, seed);
        let robot = chain.robot();
        for model in cdhrm5::MODELS {
            let routing = chain.routing(&robot, &chain.pattern_spec(model));
            out.push((format!("{} {model:?}", chain.name), robot.clone(), routing, [1e-8, 2e-7]));
        }
        let routing = chain.routing(&robot, &chain.explicit_spec(seed));
        out.push((format!("{} explicit", chain.name), robot, routing, [1e-8, 2e-7]));
    }
    // Two cables that run back toward the base, two of their segments across one DOF: the only
    // case where the slip stiffness's running sum `G_k` adds two segments' `J_s` on one DOF (a
    // sum that overwrote instead of adding passed every other case).
    let chain = RandomChain::new(2, 5);
    let robot = chain.robot();
    let mut spec = chain.explicit_spec(5);
    spec.cables.extend(RandomChain::turning_back_cables());
    let routing = chain.routing(&robot, &spec);
    out.push(("turning back".to_owned(), robot, routing, [1e-8, 2e-7]));
    out
}

fn tensions(routing: &Routing, seed: u64) -> Vec<f64> {
    let mut r = rng(seed);
    (0..routing.cable_count()).map(|_| r.random_range(20.0..120.0)).collect()
}

fn report(case: &str, what: &str, (diff, scale): (f64, f64), tol: f64) {
    let rel = diff / scale;
    println!("{case}: {what}: worst |analytic − FD| / max |analytic| = {rel:.2e}");
    assert!(scale > 0.0, "{case}: {what} is zero: nothing checked");
    assert!(rel <= tol, "{case}: {what}: {rel:.2e} > {tol:.0e}");
}

fn worst(acc: &mut (f64, f64), a: MatRef<'_, f64>, b: MatRef<'_, f64>) {
    let (d, s) = max_diff_and_scale(a, b);
    *acc = (acc.0.max(d), acc.1.max(s));
}

/// The slip regime's torque from values only: each cable's actuator tension from the series
/// springs frozen at `q0` (compliance `c_s = ℓ_s(q0)/(E A)`, material conserved, tensions tied
/// by the weights at `q`), `τ = −Σ_c T_0(q) J̃_c(q)ᵀ`.
struct SlipTorque<'a> {
    robot: &'a Robot,
    routing: &'a Routing,
    model: &'a FrictionModel,
    slip: Slip,
    /// Per cable: `ℓ_s(q0)` and `T_0(q0) w_s(q0)`.
    reference: Vec<(Vec<f64>, Vec<f64>)>,
}

impl SlipTorque<'_> {
    fn torque(&self, q: &[f64]) -> Vec<f64> {
        let mut at = evaluate(self.robot, self.routing, self.model, q);
        compute_capstan_weights(self.model, &mut at.friction, self.slip).unwrap();
        let ea = self.routing.youngs_modulus() * self.routing.area();
        let j_tilde = at.friction.effective_jacobian().unwrap();
        let mut tau = vec![0.0; q.len()];
        for (c, (l0, t0)) in self.reference.iter().enumerate() {
            let l = at.friction.lengths(self.model, c).unwrap();
            let w = at.friction.weights(self.model, c).unwrap();
            let (mut top, mut bottom) = (0.0, 0.0);
            for s in 0..l.len() {
                top += (l[s] - l0[s]) + t0[s] * l0[s] / ea;
                bottom += w[s] * l0[s] / ea;
            }
            // A cable without friction: eq. 13's spring on the whole cable (today's model).
            let t_0 = if self.model.friction_coefficients()[c] == 0.0 {
                let moved: f64 = (1..l.len()).map(|s| l[s] - l0[s]).sum();
                t0[0] + self.routing.cables()[c].stiffness * moved
            } else {
                top / bottom
            };
            for (i, t) in tau.iter_mut().enumerate() {
                *t -= t_0 * j_tilde[(c, i)];
            }
        }
        tau
    }
}

#[test]
fn slip_stiffness_matches_the_central_difference_of_the_torque() {
    for (case, robot, routing, [tol, _]) in cases() {
        let model = FrictionModel::new(&routing).with_friction_coefficient(MU).unwrap();
        check_slip(&case, &robot, &routing, &model, tol);
    }
}

/// A routing whose first cable has no friction (today's eq. 13 spring) among cables with μ =
/// 0.2 and 0.05: each cable takes its own path.
#[test]
fn slip_stiffness_with_a_frictionless_cable_among_others() {
    let chain = RandomChain::new(3, 3);
    let robot = chain.robot();
    let mut spec = chain.explicit_spec(3);
    for (c, cable) in spec.cables.iter_mut().enumerate() {
        cable.friction_coefficient = Some([0.0, 0.2, 0.05][c % 3]);
    }
    let routing = chain.routing(&robot, &spec);
    let model = FrictionModel::new(&routing);
    assert_eq!(&model.friction_coefficients()[..3], &[0.0, 0.2, 0.05]);
    // Measured 1.6e-9.
    check_slip("mixed μ", &robot, &routing, &model, 1e-8);
}

fn check_slip(case: &str, robot: &Robot, routing: &Routing, model: &FrictionModel, tol: f64) {
    {
        let mut out = FrictionStiffnessData::new(model);
        for slip in [Slip::Pull, Slip::Release] {
            let (mut acc, mut skew) = ((0.0, 0.0), 0.0_f64);
            for (k, q) in random_qs(robot, 11, 3).iter().enumerate() {
                let mut at = evaluate(robot, routing, model, q);
                assert!(
                    routing.cables().iter().enumerate().all(|(c, _)| {
                        !at.friction.kinked(model, c).unwrap().iter().any(|&b| b)
                    })
                );
                compute_capstan_weights(model, &mut at.friction, slip).unwrap();
                let t = tensions(routing, k as u64);
                slip_stiffness(model, routing, &at.geometry, &at.friction, slip, &t, &mut out)
                    .unwrap();
                assert_eq!(out.regime(), Some(FrictionRegime::Slip(slip)));
                let reference = (0..routing.cable_count())
                    .map(|c| {
                        let l = at.friction.lengths(model, c).unwrap().to_vec();
                        let w = at.friction.weights(model, c).unwrap();
                        (l, w.iter().map(|w| t[c] * w).collect())
                    })
                    .collect();
                let torque = SlipTorque { robot, routing, model, slip, reference };
                // The model reproduces the tensions at q0.
                let tau0 = torque.torque(q);
                let mut direct = vec![0.0; q.len()];
                sinew_statics::slip_torques(&at.friction, &t, &mut direct).unwrap();
                for (a, b) in tau0.iter().zip(&direct) {
                    assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{case}: τ(q0) {a} vs {b}");
                }
                let mut fd = Mat::zeros(q.len(), q.len());
                for j in 0..q.len() {
                    let (plus, minus) = perturbed(q, j, H);
                    let (tp, tm) = (torque.torque(&plus), torque.torque(&minus));
                    for i in 0..q.len() {
                        fd[(i, j)] = -(tp[i] - tm[i]) / (2.0 * H);
                    }
                }
                let k_slip = out.stiffness().unwrap();
                worst(&mut acc, k_slip, fd.as_ref());
                // The symmetric part and the skew norm are those of K.
                let mut s = 0.0;
                for j in 0..q.len() {
                    for i in 0..q.len() {
                        let sym = out.symmetric_part().unwrap()[(i, j)];
                        assert_eq!(sym, 0.5 * (k_slip[(i, j)] + k_slip[(j, i)]));
                        s += (0.5 * (k_slip[(i, j)] - k_slip[(j, i)])).powi(2);
                    }
                }
                assert!((s.sqrt() - out.skew_norm().unwrap()).abs() <= 1e-12 * s.sqrt());
                skew = skew.max(out.skew_norm().unwrap() / acc.1);
            }
            report(case, &format!("K_slip {slip:?}"), acc, tol);
            println!("{case}: K_slip {slip:?}: |skew part|_F / max |K| up to {skew:.2e}");
            // Friction makes it non-symmetric by far more than rounding.
            assert!(skew > 1e-6, "{case}: {slip:?}: K_slip is symmetric ({skew:.1e})");
        }
    }
}

/// Second differences of `energy` at `q` (step `h`): the dense Hessian.
fn hessian_of(q: &[f64], h: f64, mut energy: impl FnMut(&[f64]) -> f64) -> Mat<f64> {
    let n = q.len();
    let e0 = energy(q);
    let mut out = Mat::zeros(n, n);
    let at = |d: &[(usize, f64)]| {
        let mut p = q.to_vec();
        for &(i, s) in d {
            p[i] += s * h;
        }
        p
    };
    for i in 0..n {
        out[(i, i)] = (energy(&at(&[(i, 1.0)])) - 2.0 * e0 + energy(&at(&[(i, -1.0)]))) / (h * h);
        for j in 0..i {
            let v = (energy(&at(&[(i, 1.0), (j, 1.0)]))
                - energy(&at(&[(i, 1.0), (j, -1.0)]))
                - energy(&at(&[(i, -1.0), (j, 1.0)]))
                + energy(&at(&[(i, -1.0), (j, -1.0)])))
                / (4.0 * h * h);
            out[(i, j)] = v;
            out[(j, i)] = v;
        }
    }
    out
}

/// The step of the energy's second differences: balances truncation (h²) against round-off
/// (ε ℓ T / h²).
const H_ENERGY: f64 = 1e-4;

#[test]
fn stick_stiffness_matches_the_hessian_of_the_segment_springs_energy() {
    for (case, robot, routing, [_, tol]) in cases() {
        let model = FrictionModel::new(&routing).with_friction_coefficient(MU).unwrap();
        let ea = routing.youngs_modulus() * routing.area();
        let mut out = FrictionStiffnessData::new(&model);
        let mut twice = FrictionStiffnessData::new(&model);
        for history in [History::Pull, History::Release, History::Equal] {
            let mut acc = (0.0, 0.0);
            for (k, q) in random_qs(&robot, 12, 2).iter().enumerate() {
                let mut at = evaluate(&robot, &routing, &model, q);
                if let Some(slip) = history.slip() {
                    compute_capstan_weights(&model, &mut at.friction, slip).unwrap();
                }
                let t = tensions(&routing, 50 + k as u64);
                let args = (&model, &routing, &at.geometry, &at.friction, history);
                stick_stiffness(args.0, args.1, args.2, args.3, args.4, &t, &mut out).unwrap();
                // Segment tensions and spring constants frozen at q0.
                let frozen: Vec<(Vec<f64>, Vec<f64>)> = (0..routing.cable_count())
                    .map(|c| {
                        let l = at.friction.lengths(&model, c).unwrap().to_vec();
                        let ts = match history {
                            History::Equal => vec![t[c]; l.len()],
                            _ => at
                                .friction
                                .weights(&model, c)
                                .unwrap()
                                .iter()
                                .map(|w| t[c] * w)
                                .collect(),
                        };
                        (l, ts)
                    })
                    .collect();
                let energy = |p: &[f64]| {
                    let at = evaluate(&robot, &routing, &model, p);
                    let mut v = 0.0;
                    for (c, (l0, ts)) in frozen.iter().enumerate() {
                        let l = at.friction.lengths(&model, c).unwrap();
                        for s in 1..l.len() {
                            let d = l[s] - l0[s];
                            v += ts[s] * d + 0.5 * (ea / l0[s]) * d * d;
                        }
                    }
                    v
                };
                let fd = hessian_of(q, H_ENERGY, energy);
                let k_stick = out.stiffness().unwrap();
                worst(&mut acc, k_stick, fd.as_ref());
                // Exactly symmetric, and affine in the actuator tensions: the controllable part
                // doubles with them, the inherent part does not move.
                // (Checked on K itself: the workspace takes a stick K's symmetry as given.)
                assert_eq!(k_stick, k_stick.transpose(), "{case}: {history:?}");
                assert_eq!(out.symmetric_part().unwrap(), k_stick, "{case}: {history:?}");
                assert_eq!(out.skew_norm().unwrap(), 0.0, "{case}: {history:?}");
                let t2: Vec<f64> = t.iter().map(|t| 2.0 * t).collect();
                stick_stiffness(args.0, args.1, args.2, args.3, args.4, &t2, &mut twice).unwrap();
                assert_eq!(twice.inherent().unwrap(), out.inherent().unwrap());
                let (d, s) =
                    max_diff_and_scale(twice.controllable().unwrap(), out.controllable().unwrap());
                let doubled = Mat::from_fn(q.len(), q.len(), |i, j| {
                    2.0 * out.controllable().unwrap()[(i, j)]
                });
                let (d2, _) = max_diff_and_scale(twice.controllable().unwrap(), doubled.as_ref());
                assert!(d > 0.1 * s && d2 <= 1e-14 * s, "{case}: not linear in T: {d2:.1e}");
            }
            report(&case, &format!("K_stick after {history:?}"), acc, tol);
        }
    }
}

fn min_eigenvalue(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> f64 {
    let d = DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)] - b[(i, j)]);
    let d = 0.5 * (&d + d.transpose());
    d.symmetric_eigen().eigenvalues.min()
}

/// `Σ_f H` (from `joint_stiffness`) + `Σ_c k_c J_cᵀ J_c` for the springs `k` (N/m).
fn frictionless_with(routing: &Routing, at: &At, t: &[f64], k: &[f64]) -> (Mat<f64>, Mat<f64>) {
    let n = routing.dof();
    let (mut kc, mut ki) = (Mat::zeros(n, n), Mat::zeros(n, n));
    joint_stiffness(routing, &at.geometry, t, kc.as_mut(), ki.as_mut()).unwrap();
    let j_c = at.geometry.jacobian().unwrap();
    let with = Mat::from_fn(n, n, |i, j| {
        kc[(i, j)] + (0..k.len()).map(|c| k[c] * j_c[(c, i)] * j_c[(c, j)]).sum::<f64>()
    });
    let today = Mat::from_fn(n, n, |i, j| kc[(i, j)] + ki[(i, j)]);
    (with, today)
}

/// Each cable's series spring at the pose, `E A / (ℓ_free + L_c(Q))` (N/m).
fn pose_springs(routing: &Routing, model: &FrictionModel, at: &At) -> Vec<f64> {
    let ea = routing.youngs_modulus() * routing.area();
    (0..routing.cable_count())
        .map(|c| ea / at.friction.lengths(model, c).unwrap().iter().sum::<f64>())
        .collect()
}

#[test]
fn stick_is_at_least_the_frictionless_stiffness_at_equal_tensions() {
    for (case, robot, routing, _) in cases() {
        let model = FrictionModel::new(&routing).with_friction_coefficient(MU).unwrap();
        let mut out = FrictionStiffnessData::new(&model);
        let (mut worst_pose, mut worst_today, mut gain) =
            (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        for (k, q) in random_qs(&robot, 13, 4).iter().enumerate() {
            let at = evaluate(&robot, &routing, &model, q);
            let t = tensions(&routing, 80 + k as u64);
            stick_stiffness(
                &model,
                &routing,
                &at.geometry,
                &at.friction,
                History::Equal,
                &t,
                &mut out,
            )
            .unwrap();
            let k_stick = out.stiffness().unwrap();
            let scale = max_diff_and_scale(k_stick, k_stick).1;
            let (pose, today) =
                frictionless_with(&routing, &at, &t, &pose_springs(&routing, &model, &at));
            // Equal tensions: the controllable parts agree (Σ_s H_s = H_c).
            let n = routing.dof();
            let mut kc = Mat::zeros(n, n);
            let mut ki = Mat::zeros(n, n);
            joint_stiffness(&routing, &at.geometry, &t, kc.as_mut(), ki.as_mut()).unwrap();
            let (d, s) = max_diff_and_scale(out.controllable().unwrap(), kc.as_ref());
            assert!(d <= 1e-13 * s, "{case}: Σ_s T H_s ≠ f H_c at equal tensions: {d:.1e}");
            worst_pose = worst_pose.min(min_eigenvalue(k_stick, pose.as_ref()) / scale);
            worst_today = worst_today.min(min_eigenvalue(k_stick, today.as_ref()) / scale);
            // How much stiffer: the smallest eigenvalue of each.
            let e = |m: MatRef<'_, f64>| min_eigenvalue(m, Mat::<f64>::zeros(n, n).as_ref());
            gain = gain.min(e(k_stick) / e(today.as_ref()));
        }
        println!(
            "{case}: λ_min(K_stick − K_pose) / max|K| ≥ {worst_pose:.2e}, λ_min(K_stick − K_q) / max|K| ≥ {worst_today:.2e}, λ_min(K_stick)/λ_min(K_q) ≥ {gain:.1}"
        );
        // Cauchy–Schwarz, exact: nothing below rounding.
        assert!(worst_pose >= -1e-13, "{case}: K_stick ⋡ K_pose: {worst_pose:.2e}");
        // Against eq. 13 (l_c at Q0): the free length dominates both sides' difference.
        assert!(worst_today >= -1e-13, "{case}: K_stick ⋡ K_q: {worst_today:.2e}");
        if case.starts_with("cdhrm5") {
            // The free length stops counting: one to two orders of magnitude (issue #27).
            assert!(gain > 10.0, "{case}: λ_min(K_stick)/λ_min(K_q) = {gain:.1}");
        }
    }
}

#[test]
fn slip_tends_to_the_whole_cable_in_series_as_mu_vanishes() {
    for (case, robot, routing, _) in cases() {
        let q = &random_qs(&robot, 14, 1)[0];
        let t = tensions(&routing, 90);
        let mut out = FrictionStiffnessData::new(&FrictionModel::new(&routing));
        let mut gaps = Vec::new();
        for mu in [1e-9, 1e-6, 1e-5] {
            let model = FrictionModel::new(&routing).with_friction_coefficient(mu).unwrap();
            let mut at = evaluate(&robot, &routing, &model, q);
            compute_capstan_weights(&model, &mut at.friction, Slip::Pull).unwrap();
            slip_stiffness(&model, &routing, &at.geometry, &at.friction, Slip::Pull, &t, &mut out)
                .unwrap();
            let springs = pose_springs(&routing, &model, &at);
            let (limit, today) = frictionless_with(&routing, &at, &t, &springs);
            let (d, s) = max_diff_and_scale(out.stiffness().unwrap(), limit.as_ref());
            gaps.push(d / s);
            if mu == 1e-9 {
                // Eq. 13 takes l_c at Q0: the limit differs from today's K_q by
                // Σ_c (k_pose − k_c) J_cᵀ J_c, |k_pose / k_c − 1| = |L_c(Q0) − L_c(Q)| / (ℓ_free + L_c(Q)).
                let mut order: f64 = 0.0;
                for (c, cable) in routing.cables().iter().enumerate() {
                    let l = at.friction.lengths(&model, c).unwrap();
                    let moved = (cable.routed_length - l[1..].iter().sum::<f64>()).abs();
                    let rel = (springs[c] / cable.stiffness - 1.0).abs();
                    assert!(
                        (rel - moved / l.iter().sum::<f64>()).abs() <= 1e-12,
                        "{case}: cable {c}"
                    );
                    order = order.max(rel);
                }
                let (d, s) = max_diff_and_scale(limit.as_ref(), today.as_ref());
                println!(
                    "{case}: μ → 0⁺ limit vs eq. 13: max |ΔL_c| / l_c = {order:.2e}, |K_lim − K_q| / max|K_q| = {:.2e}",
                    d / s
                );
                if case.starts_with("cdhrm5") {
                    // Millimetres (up to a centimetre at the joint limits) against the 3.2 m
                    // free length: measured 3.1e-3 (decoupled).
                    assert!(order < 5e-3, "{case}: {order:.1e}");
                }
                let (d2, _) = max_diff_and_scale(out.stiffness().unwrap(), today.as_ref());
                assert!(
                    d2 <= d + 1e-7 * s,
                    "{case}: K_slip(0⁺) − K_q beyond the L_c(Q) − L_c(Q0) term"
                );
            }
        }
        println!(
            "{case}: |K_slip(μ) − K_lim| / max|K_lim| at μ = 1e-9, 1e-6, 1e-5: {:.2e} {:.2e} {:.2e}",
            gaps[0], gaps[1], gaps[2]
        );
        assert!(gaps[0] <= 1e-8, "{case}: {:.1e}", gaps[0]);
        let ratio = gaps[2] / gaps[1];
        assert!((8.0..12.0).contains(&ratio), "{case}: not first order in μ: {ratio}");
    }
}

#[test]
fn mu_zero_is_todays_stiffness_bit_for_bit() {
    for (case, robot, routing, _) in cases() {
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.0).unwrap();
        let mut out = FrictionStiffnessData::new(&model);
        let n = routing.dof();
        for (k, q) in random_qs(&robot, 15, 2).iter().enumerate() {
            let mut at = evaluate(&robot, &routing, &model, q);
            let t = tensions(&routing, 95 + k as u64);
            let (mut kc, mut ki) = (Mat::zeros(n, n), Mat::zeros(n, n));
            joint_stiffness(&routing, &at.geometry, &t, kc.as_mut(), ki.as_mut()).unwrap();
            let k_q = Mat::from_fn(n, n, |i, j| kc[(i, j)] + ki[(i, j)]);
            for slip in [Slip::Pull, Slip::Release] {
                compute_capstan_weights(&model, &mut at.friction, slip).unwrap();
                slip_stiffness(&model, &routing, &at.geometry, &at.friction, slip, &t, &mut out)
                    .unwrap();
                assert_eq!(out.controllable().unwrap(), kc.as_ref(), "{case}: {slip:?}");
                assert_eq!(out.inherent().unwrap(), ki.as_ref(), "{case}: {slip:?}");
                assert_eq!(out.stiffness().unwrap(), k_q.as_ref(), "{case}: {slip:?}");
                assert_eq!(out.skew_norm().unwrap(), 0.0);
            }
            // Stick needs a band: a typed refusal, and the workspace holds nothing.
            for history in [History::Pull, History::Release, History::Equal] {
                let e = stick_stiffness(
                    &model,
                    &routing,
                    &at.geometry,
                    &at.friction,
                    history,
                    &t,
                    &mut out,
                );
                assert!(
                    matches!(e, Err(StiffnessError::StickWithoutFriction { cable: 0 })),
                    "{case}"
                );
                assert!(out.stiffness().is_err() && out.regime().is_none());
            }
        }
    }
}

#[test]
fn the_weights_of_the_other_regime_are_refused() {
    let (robot, routing) = cdhrm5::robot_and_routing(cdhrm5::MODELS[1]);
    let model = FrictionModel::new(&routing).with_friction_coefficient(MU).unwrap();
    let q = &random_qs(&robot, 16, 1)[0];
    let mut at = evaluate(&robot, &routing, &model, q);
    let t = tensions(&routing, 1);
    let mut out = FrictionStiffnessData::new(&model);
    let e = slip_stiffness(&model, &routing, &at.geometry, &at.friction, Slip::Pull, &t, &mut out);
    assert!(matches!(
        e,
        Err(StiffnessError::WrongCapstanWeights { needs: Slip::Pull, computed: None })
    ));
    compute_capstan_weights(&model, &mut at.friction, Slip::Release).unwrap();
    let e =
        stick_stiffness(&model, &routing, &at.geometry, &at.friction, History::Pull, &t, &mut out);
    let Err(e) = e else { panic!("stick after pull on release weights") };
    assert!(e.to_string().contains("Release"), "{e}");
    assert_eq!(e.kind(), sinew_robot::ErrorKind::Input);
    // Equal needs no weights; the wrong number of tensions is a size error.
    stick_stiffness(&model, &routing, &at.geometry, &at.friction, History::Equal, &t, &mut out)
        .unwrap();
    let e = stick_stiffness(
        &model,
        &routing,
        &at.geometry,
        &at.friction,
        History::Equal,
        &t[1..],
        &mut out,
    );
    assert!(matches!(e, Err(StiffnessError::DimensionMismatch { what: "actuator tensions", .. })));
}
