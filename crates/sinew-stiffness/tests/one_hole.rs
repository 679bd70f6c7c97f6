//! The directional response of a cable with a single friction hole against its closed form
//! (spec §9, #27): one universal joint, one cable from a hole on the base disc to its anchor on
//! the distal disc, after a pull (the hole on the lower edge of its band, `T₁ = w T₀`,
//! `w = e^{−μθ}`).
//!
//! The closed form, with the actuator held (`δℓ₀ = 0`), `k_s = EA/ℓ_s` and the segment's
//! `J₁ = J_c`, `H₁ = H_c` (the free length does not move):
//! - **stick**, no material through the hole: `δT₁ = k₁ J₁ δq`, `δT₀ = 0`, so
//!   `K = T₁ H₁ + k₁ J₁ᵀ J₁`;
//! - **slide** (toward the actuator), `δs` of cable into segment 1: `δT₀ = k₀ δs`,
//!   `δT₁ = k₁ (J₁ δq − δs)` and `δT₁ = w δT₀ + T₀ ∂w/∂q δq`, so
//!   `K = T₁ H₁ + J₁ᵀ k₁ (w k₀ J₁ + T₀ ∂w/∂q) / (k₁ + w k₀)`, `∂w/∂q = −μ w ∂θ/∂q`.
//!
//! The hole stays inside its band while `δ(T₁ − w T₀) = (k₁ J₁ − T₀ ∂w/∂q) δq ≥ 0`: along a
//! direction `u` the stick solution holds when it keeps that sign, and the hole slides
//! otherwise; along `−u` the roles swap. `θ(q)` and its gradient are taken from eq. (1) alone
//! (the gradient by central differences), not from the library.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use faer::Mat;
use nalgebra::{Matrix2, Point3, Vector2, Vector3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{
    FrictionData, FrictionModel, Order, Routing, RoutingData, Slip, compute_cable_geometry,
    compute_capstan_weights, compute_friction_geometry,
};
use sinew_stiffness::{FrictionStiffnessData, History, directional_response, stick_stiffness};
use sinew_testkit::cdhrm5;
use sinew_testkit::one_joint::{eq1, one_hole_routing};

#[test]
fn a_single_holes_directional_stiffness_is_the_closed_form() {
    let chain = cdhrm5::uniform_chain(1);
    let robot: Robot = chain.build().unwrap();
    let (rho, alpha, mu, t0) = (0.02, 0.3_f64, 0.2, 150.0);
    let entry = Vector3::new(alpha.sin(), 0.0, alpha.cos());
    let text = one_hole_routing(rho, mu, &entry);
    let routing = Routing::from_toml_str(&text, "test/cables.toml", &robot).unwrap();
    let model = FrictionModel::new(&routing);
    let ea = 12.5e9 * std::f64::consts::PI * 1.0e-3_f64.powi(2) / 4.0;
    let r = Vector3::new(rho, 0.0, 0.0);
    let theta = |q: [f64; 2]| {
        let u = (eq1(chain.d1, chain.d2, q) * Point3::from(r)).coords - r;
        entry.cross(&u).norm().atan2(entry.dot(&u))
    };
    let kappa = 5.0; // K_W = κ I: a joint spring keeping every regime stable.
    let (mut rdata, mut geometry) = (RobotData::new(&robot), RoutingData::new(&routing));
    let mut friction = FrictionData::new(&model);
    let mut k_stick = FrictionStiffnessData::new(&model);
    let (mut checked, mut worst) = ([0usize; 2], 0.0_f64);
    for (a, b) in [(0.3, 0.2), (-0.25, 0.4), (0.1, -0.35), (-0.4, -0.1), (0.45, 0.05)] {
        let q = [a, b];
        compute_cable_geometry(&routing, &robot, &mut rdata, &mut geometry, &q, Order::Hessians)
            .unwrap();
        compute_friction_geometry(&model, &routing, &geometry, &mut friction).unwrap();
        compute_capstan_weights(&model, &mut friction, Slip::Pull).unwrap();
        stick_stiffness(&model, &routing, &geometry, &friction, History::Pull, &[t0], &mut k_stick)
            .unwrap();
        // The closed form's pieces.
        let jc = geometry.jacobian().unwrap();
        let j1 = Vector2::new(jc[(0, 0)], jc[(0, 1)]);
        let mut hc = Mat::zeros(2, 2);
        geometry.cable_hessian(&routing, 0, hc.as_mut()).unwrap();
        let h1 = Matrix2::from_fn(|i, j| hc[(i, j)]);
        let l1 = ((eq1(chain.d1, chain.d2, q) * Point3::from(r)).coords - r).norm();
        let (k0, k1) = (ea / 1.0, ea / l1);
        let w = (-mu * theta(q)).exp();
        let eps = 1e-6;
        let dtheta = Vector2::from_fn(|i, _| {
            let (mut p, mut m) = (q, q);
            p[i] += eps;
            m[i] -= eps;
            (theta(p) - theta(m)) / (2.0 * eps)
        });
        let dw = -mu * w * dtheta;
        let t1 = w * t0;
        let stick = t1 * h1 + k1 * j1 * j1.transpose();
        let slide = t1 * h1 + j1 * (k1 * (w * k0 * j1 + t0 * dw) / (k1 + w * k0)).transpose();
        // The library's K_stick is the closed form's.
        let ks = k_stick.stiffness().unwrap();
        let err = (Matrix2::from_fn(|i, j| ks[(i, j)]) - stick).norm() / stick.norm();
        assert!(err <= 1e-12, "{q:?}: K_stick off by {err:e}");
        // The end's position rows and the load direction.
        let mut j_x = Mat::zeros(6, 2);
        robot.point_jacobian(&rdata, &robot.tip_point(), j_x.as_mut()).unwrap();
        let jp = nalgebra::Matrix3x2::from_fn(|i, j| j_x[(i, j)]);
        let u3 = Vector3::new(0.3, -0.8, 0.2).normalize();
        let k_w = Mat::<f64>::identity(2, 2) * kappa;
        let response = |k: &Matrix2<f64>, sign: f64| {
            let a = k + Matrix2::identity() * kappa;
            let dq = a.lu().solve(&(jp.transpose() * (sign * u3))).unwrap();
            let compliance = (sign * u3).dot(&(jp * dq));
            (1.0 / compliance, dq)
        };
        // δ(T₁ − w T₀) per unit α under each state.
        let band = |dq: &Vector2<f64>| (k1 * j1 - t0 * dw).dot(dq);
        let u = Vector6::new(u3.x, u3.y, u3.z, 0.0, 0.0, 0.0);
        let increment = (ks, k_w.as_ref(), j_x.as_ref());
        let [plus, minus] =
            directional_response(&model, &routing, &friction, History::Pull, &[t0], increment, &u)
                .unwrap();
        for (got, sign) in [(&plus, 1.0), (&minus, -1.0)] {
            let (k_st, dq_st) = response(&stick, sign);
            let (k_sl, dq_sl) = response(&slide, sign);
            let (expected, slides) = if band(&dq_st) >= 0.0 {
                (k_st, false)
            } else {
                // Sliding toward the actuator must be consistent with its own motion.
                assert!(band(&dq_sl) < 0.0, "{q:?} {sign}: neither state is consistent");
                (k_sl, true)
            };
            assert_eq!(got.sliding.len(), usize::from(slides), "{q:?} {sign}: {:?}", got.sliding);
            let rel = (got.stiffness - expected).abs() / expected.abs();
            worst = worst.max(rel);
            assert!(
                rel <= 1e-7,
                "{q:?} {sign}: {} vs closed form {expected} ({rel:e})",
                got.stiffness
            );
            checked[usize::from(slides)] += 1;
        }
        // Hysteresis: the two directions differ where one slides.
        assert!((plus.stiffness - minus.stiffness).abs() > 1e-6 * plus.stiffness.abs());
    }
    println!(
        "one hole: {checked:?} (stick, slide) directions, worst relative difference {worst:.1e}"
    );
    assert!(checked[0] > 0 && checked[1] > 0, "{checked:?}: both states must occur");
}
