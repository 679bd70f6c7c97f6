//! `K_W = ∂T0/∂Q` against central finite differences of `T0(Q)`, with gravity on and off and
//! `F0` zero and non-zero, on cdhrm5, a generated 50-joint chain and a random-geometry chain
//! (`sinew_testkit::random_chain`: random rpy, axes, offsets, inertials, gravity direction),
//! 100 random Q each, bounded per robot at a few times the measured worst (h = 1e-6).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use nalgebra::{Vector3, Vector6};
use rand::Rng;
use sinew_robot::{Robot, RobotData};
use sinew_statics::{JointEndData, equilibrium_torque_derivative, equilibrium_torques};
use sinew_testkit::numeric::{H, central_difference, rel_err};
use sinew_testkit::random_chain::RandomChain;
use sinew_testkit::{cdhrm5, config};

fn robots() -> Vec<Robot> {
    vec![cdhrm5::robot(), cdhrm5::chain_robot(50), RandomChain::new(5, 1).robot()]
}

/// The bound of the `K_W` check per robot of [`robots`], over gravity on/off and `F0` zero or
/// not (was 1e-6 for all). Measured worst: cdhrm5 1.62e-9, uniform50 1.69e-9, random5s1
/// 4.89e-10; with neither gravity nor load, `T0` and `K_W` are exact zeros (measured 0).
const K_W_TOL: [f64; 3] = [5e-9, 5e-9, 2e-9];

fn t0_at(
    robot: &Robot,
    rdata: &mut RobotData,
    data: &mut JointEndData,
    q: &[f64],
    f0: &Vector6<f64>,
) -> Vec<f64> {
    robot.forward_kinematics(rdata, q).unwrap();
    let mut t0 = vec![0.0; robot.dof()];
    equilibrium_torques(robot, rdata, data, f0, &mut t0).unwrap();
    t0
}

#[test]
fn k_w_matches_finite_differences_of_t0() {
    for (base, tol) in robots().into_iter().zip(K_W_TOL) {
        for gravity in [true, false] {
            let robot = if gravity { base.clone() } else { base.with_gravity(Vector3::zeros()) };
            for loaded in [false, true] {
                let n = robot.dof();
                let mut rdata = RobotData::new(&robot);
                let mut data = JointEndData::new(&robot);
                let mut rng = config::rng(31);
                let mut k_w = Mat::zeros(n, n);
                let mut worst: f64 = 0.0;
                for _ in 0..100 {
                    let q: Vec<f64> = config::random_q(&robot, &mut rng);
                    let f0 = if loaded {
                        Vector6::from_fn(|_, _| rng.random_range(-5.0..5.0))
                    } else {
                        Vector6::zeros()
                    };
                    robot.forward_kinematics(&mut rdata, &q).unwrap();
                    equilibrium_torque_derivative(&robot, &mut rdata, &mut data, &f0, k_w.as_mut())
                        .unwrap();
                    let numeric =
                        central_difference(&q, H, |q| t0_at(&robot, &mut rdata, &mut data, q, &f0));
                    worst = worst.max(rel_err(k_w.as_ref(), numeric.as_ref()));
                }
                println!(
                    "{} gravity={gravity} F0≠0={loaded}: worst relative error {worst:.2e}",
                    robot.name()
                );
                assert!(worst <= tol, "{}: K_W error {worst:e}", robot.name());
                if !gravity && !loaded {
                    assert_eq!(worst, 0.0, "{}: unloaded K_W not exactly zero", robot.name());
                }
            }
        }
    }
}

#[test]
fn k_w_is_symmetric_for_forces_and_not_for_moments() {
    let robot = &robots()[0];
    let n = robot.dof();
    let mut rdata = RobotData::new(robot);
    let mut data = JointEndData::new(robot);
    let q = cdhrm5::LOADED_POSE;
    robot.forward_kinematics(&mut rdata, &q).unwrap();
    let mut k_w = Mat::zeros(n, n);
    let asymmetry = |k: &Mat<f64>| {
        (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .map(|(i, j)| (k[(i, j)] - k[(j, i)]).abs())
            .fold(0.0, f64::max)
    };
    equilibrium_torque_derivative(robot, &mut rdata, &mut data, &Vector6::zeros(), k_w.as_mut())
        .unwrap();
    assert!(asymmetry(&k_w) <= 1e-12, "gravity alone: K_W is a Hessian, symmetric");
    // A force fixed in the base frame is conservative (potential −F·p(Q)): still a Hessian.
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    equilibrium_torque_derivative(robot, &mut rdata, &mut data, &f0, k_w.as_mut()).unwrap();
    assert!(asymmetry(&k_w) <= 1e-12, "a pure force keeps K_W symmetric");
    // A moment fixed in the base frame is not conservative: K_W loses its symmetry.
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.5, 0.0, 0.0);
    equilibrium_torque_derivative(robot, &mut rdata, &mut data, &f0, k_w.as_mut()).unwrap();
    assert!(asymmetry(&k_w) > 1e-3, "a base-fixed moment makes K_W non-symmetric");
}

#[test]
fn t0_is_gravity_plus_the_load() {
    let robot = &robots()[0];
    let mut rdata = RobotData::new(robot);
    let mut data = JointEndData::new(robot);
    let q = [0.0; 10];
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    let t0 = t0_at(robot, &mut rdata, &mut data, &q, &f0);
    // Straight arm along z, tip at 1.25 m: 5 N along y at the tip needs, at joint 1's x axis
    // (at z = d1 = 0.03 m), the torque (p − p_j) × F · x = −(1.25 − 0.03) · 5 N m.
    let zero_g = robot.with_gravity(Vector3::zeros());
    let mut rdata0 = RobotData::new(&zero_g);
    let load = t0_at(&zero_g, &mut rdata0, &mut data, &q, &f0);
    approx::assert_relative_eq!(load[0], -(1.25 - 0.03) * 5.0, epsilon = 1e-12);
    approx::assert_relative_eq!(load[1], 0.0, epsilon = 1e-12);
    let gravity = t0_at(robot, &mut rdata, &mut data, &q, &Vector6::zeros());
    for j in 0..10 {
        approx::assert_relative_eq!(t0[j], gravity[j] + load[j], epsilon = 1e-12);
    }
}
