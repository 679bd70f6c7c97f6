//! The joint stiffness with friction at the holes (spec §9, #27): the slip regimes against the
//! central difference of the torque of a nonlinear model built from library *values* only, the
//! stick regime against the second differences of the segment springs' energy, the
//! Cauchy–Schwarz bound `K_stick ⪰ K_frictionless`, the μ → 0⁺ limit and μ = 0 bit for bit.
//!
//! Criterion for each comparison, per case over its configurations: `max |analytic − FD| ≤
//! tol · max |analytic|`, `tol` a few times the worst error measured (beside each bound;
//! `--nocapture` prints them). Cases: cdhrm5 in both routing files and seeded random-geometry
//! chains (pattern routings, decoupled and routed, and an explicit routing), μ = 0.2.
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

/// `(name, robot, routing, tolerances [slip vs FD of τ, stick vs FD of the energy])`.
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
            out.push((format!("{} {model:?}", chain.name), robot.clone(), routing, [1e-8, 1e-7]));
        }
        let routing = chain.routing(&robot, &chain.explicit_spec(seed));
        out.push((format!("{} explicit", chain.name), robot, routing, [1e-8, 1e-7]));
    }
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
            let t_0 = top / bottom;
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
        let mut out = FrictionStiffnessData::new(&model);
        for slip in [Slip::Pull, Slip::Release] {
            let (mut acc, mut skew) = ((0.0, 0.0), 0.0_f64);
            for (k, q) in random_qs(&robot, 11, 3).iter().enumerate() {
                let mut at = evaluate(&robot, &routing, &model, q);
                assert!(
                    routing.cables().iter().enumerate().all(|(c, _)| {
                        !at.friction.kinked(&model, c).unwrap().iter().any(|&b| b)
                    })
                );
                compute_capstan_weights(&model, &mut at.friction, slip).unwrap();
                let t = tensions(&routing, k as u64);
                slip_stiffness(&model, &routing, &at.geometry, &at.friction, slip, &t, &mut out)
                    .unwrap();
                assert_eq!(out.regime(), Some(FrictionRegime::Slip(slip)));
                let reference = (0..routing.cable_count())
                    .map(|c| {
                        let l = at.friction.lengths(&model, c).unwrap().to_vec();
                        let w = at.friction.weights(&model, c).unwrap();
                        (l, w.iter().map(|w| t[c] * w).collect())
                    })
                    .collect();
                let torque =
                    SlipTorque { robot: &robot, routing: &routing, model: &model, slip, reference };
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
            report(&case, &format!("K_slip {slip:?}"), acc, tol);
            println!("{case}: K_slip {slip:?}: |skew part|_F / max |K| up to {skew:.2e}");
            // Friction makes it non-symmetric by far more than rounding.
            assert!(skew > 1e-6, "{case}: {slip:?}: K_slip is symmetric ({skew:.1e})");
        }
    }
}
