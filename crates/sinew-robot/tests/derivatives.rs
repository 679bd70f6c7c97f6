//! Every analytic derivative against central finite differences, at 100 seeded random
//! configurations within the limits, on cdhrm5, a generated 50-joint (100-DOF) chain and two
//! seeded random-geometry chains (`sinew_testkit::random_chain`: random rpy, offsets, unit
//! axes, centres of mass and inertias; cdhrm5 and the uniform chain are axis-aligned).
//!
//! Criterion: `max |analytic − numeric| ≤ tol · max(1, max |analytic|)`
//! (`sinew_testkit::numeric::rel_err`), `tol` per robot at a few times the worst error
//! measured with h = 1e-6 (printed with `--nocapture`; the measured worst is beside each
//! bound). Central differences with h = 1e-6 reach ~1e-9 here, where round-off (ε/h) sits; the
//! old common bound 1e-6 would have let an error a thousand times the method's pass.
//! `point_jacobian_error_decays_as_h_squared` checks the h² decay itself.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use nalgebra::{Vector3, Vector6};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use sinew_robot::{BodyPoint, Robot, RobotData};
use sinew_testkit::cdhrm5;
use sinew_testkit::config::{random_q, rng};
use sinew_testkit::numeric::{H, central_difference, column, perturbed, rel_err};
use sinew_testkit::random_chain::RandomChain;

const CONFIGURATIONS: usize = 100;

/// The robots the derivative tests run on: cdhrm5, a generated 50-joint chain and two random
/// geometries (5 and 12 universal joints).
fn test_robots() -> Vec<(String, Robot)> {
    let mut robots = vec![
        ("cdhrm5".to_owned(), cdhrm5::robot()),
        ("uniform50".to_owned(), cdhrm5::chain_robot(50)),
    ];
    for (joints, seed) in RANDOM_CHAINS {
        let chain = RandomChain::new(joints, seed);
        robots.push((chain.name.clone(), chain.robot()));
    }
    robots
}

/// The random-geometry chains under test: (universal joints, seed).
const RANDOM_CHAINS: [(usize, u64); 2] = [(5, 1), (12, 2)];

/// A random point within 5 cm of a random moving body's origin.
fn random_point(robot: &Robot, rng: &mut ChaCha8Rng) -> BodyPoint {
    let body = rng.random_range(1..robot.bodies().len());
    let point = Vector3::from_fn(|_, _| rng.random_range(-0.05..0.05));
    BodyPoint { body, point }
}

/// The tip or, as often, a random point.
fn tip_or_random_point(robot: &Robot, rng: &mut ChaCha8Rng) -> BodyPoint {
    if rng.random_bool(0.5) { robot.tip_point() } else { random_point(robot, rng) }
}

/// The worst error `check` returns at [`CONFIGURATIONS`] random configurations of each test
/// robot, drawn from a generator seeded with `seed` (`check` gets it for its own draws after
/// `Q`'s), printed and asserted `≤ tol[r]` for robot `r` of [`test_robots`].
fn check_worst(
    seed: u64,
    what: &str,
    tol: [f64; 4],
    mut check: impl FnMut(&Robot, &mut RobotData, &mut ChaCha8Rng, &[f64]) -> f64,
) {
    for ((name, robot), tol) in test_robots().into_iter().zip(tol) {
        let mut data = RobotData::new(&robot);
        let mut rng = rng(seed);
        let mut worst: f64 = 0.0;
        for _ in 0..CONFIGURATIONS {
            let q = random_q(&robot, &mut rng);
            worst = worst.max(check(&robot, &mut data, &mut rng, &q));
        }
        println!("{name}: {what} worst relative error {worst:.2e}");
        assert!(worst <= tol, "{name}: {what} error {worst:e} > {tol:e}");
    }
}

fn jacobian_at(robot: &Robot, data: &mut RobotData, q: &[f64], p: &BodyPoint) -> Mat<f64> {
    robot.forward_kinematics(data, q).unwrap();
    let mut j = Mat::zeros(6, robot.dof());
    robot.point_jacobian(data, p, j.as_mut()).unwrap();
    j
}

/// The central-difference Jacobian of the pose of `p` with step `h`: linear velocity from the
/// point's positions, angular velocity from the rotation between the minus and plus poses.
fn fd_pose_jacobian(
    robot: &Robot,
    data: &mut RobotData,
    q: &[f64],
    p: &BodyPoint,
    h: f64,
) -> Mat<f64> {
    let mut numeric = Mat::zeros(6, robot.dof());
    for i in 0..robot.dof() {
        let (qp, qm) = perturbed(q, i, h);
        robot.forward_kinematics(data, &qp).unwrap();
        let xp = robot.point_position(data, p).unwrap();
        let rp = data.body_pose(p.body).unwrap().rotation;
        robot.forward_kinematics(data, &qm).unwrap();
        let xm = robot.point_position(data, p).unwrap();
        let rm = data.body_pose(p.body).unwrap().rotation;
        let v = (xp - xm) / (2.0 * h);
        // Angular velocity: the rotation from the minus to the plus pose, over 2h, read
        // from its skew part (sin θ · axis; acos of the trace would lose digits).
        let m = (rp * rm.inverse()).into_inner();
        let w = Vector3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)])
            / (4.0 * h);
        for r in 0..3 {
            numeric[(r, i)] = v[r];
            numeric[(r + 3, i)] = w[r];
        }
    }
    numeric
}

#[test]
fn point_jacobian_matches_finite_differences_of_the_pose() {
    // Measured worst: 2.67e-10, 8.36e-10, 2.67e-10, 4.96e-10 (was 1e-6 for all).
    check_worst(11, "point Jacobian", [1e-9, 3e-9, 1e-9, 2e-9], |robot, data, rng, q| {
        let p = tip_or_random_point(robot, rng);
        let analytic = jacobian_at(robot, data, q, &p);
        let numeric = fd_pose_jacobian(robot, data, q, &p, H);
        rel_err(analytic.as_ref(), numeric.as_ref())
    });
}

/// The step-halving check: with steps large enough that truncation (∝ h²) dominates round-off,
/// the error of the central difference against the analytic Jacobian falls by 4 each time h
/// halves. An analytic Jacobian off by any fixed amount (a wrong term, a transposed frame)
/// would make the error level off instead, however small the bound of the test above.
#[test]
fn point_jacobian_error_decays_as_h_squared() {
    let steps = [8e-3, 4e-3, 2e-3, 1e-3];
    for (name, robot) in test_robots() {
        let mut data = RobotData::new(&robot);
        let mut rng = rng(17);
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for _ in 0..5 {
            let q = random_q(&robot, &mut rng);
            let p = tip_or_random_point(&robot, &mut rng);
            let analytic = jacobian_at(&robot, &mut data, &q, &p);
            let errors: Vec<f64> = steps
                .iter()
                .map(|&h| {
                    let numeric = fd_pose_jacobian(&robot, &mut data, &q, &p, h);
                    rel_err(analytic.as_ref(), numeric.as_ref())
                })
                .collect();
            for pair in errors.windows(2) {
                let ratio = pair[0] / pair[1];
                lo = lo.min(ratio);
                hi = hi.max(ratio);
            }
        }
        println!("{name}: error(h)/error(h/2) within [{lo:.3}, {hi:.3}]");
        // Measured: 4.000 for every robot (to 3 decimals).
        assert!(lo >= 3.95 && hi <= 4.05, "{name}: error(h)/error(h/2) within [{lo}, {hi}], not 4");
    }
}

#[test]
fn jacobian_derivative_matches_finite_differences_of_the_jacobian() {
    // Measured worst: 2.99e-10, 2.58e-9, 4.09e-10, 8.15e-10 (was 1e-6 for all).
    check_worst(12, "Jacobian derivative", [1e-9, 1e-8, 2e-9, 3e-9], |robot, data, rng, q| {
        let p = tip_or_random_point(robot, rng);
        let mut analytic = Mat::zeros(6, robot.dof());
        let mut worst: f64 = 0.0;
        for i in 0..robot.dof() {
            robot.forward_kinematics(data, q).unwrap();
            robot.point_jacobian_derivative(data, &p, i, analytic.as_mut()).unwrap();
            let (qp, qm) = perturbed(q, i, H);
            let jp = jacobian_at(robot, data, &qp, &p);
            let jm = jacobian_at(robot, data, &qm, &p);
            let numeric = (jp - jm) * faer::Scale(1.0 / (2.0 * H));
            worst = worst.max(rel_err(analytic.as_ref(), numeric.as_ref()));
        }
        worst
    });
}

/// `J(Q)ᵀ F` for a wrench fixed in the base frame.
fn generalized_force(
    robot: &Robot,
    data: &mut RobotData,
    q: &[f64],
    p: &BodyPoint,
    f: &Vector6<f64>,
) -> Vec<f64> {
    let j = jacobian_at(robot, data, q, p);
    (0..robot.dof()).map(|c| (0..6).map(|r| j[(r, c)] * f[r]).sum()).collect()
}

#[test]
fn wrench_torque_derivative_matches_finite_differences() {
    // Measured worst: 4.27e-10, 1.15e-9, 6.98e-10, 8.07e-10 (was 1e-6 for all).
    check_worst(13, "∂(JᵀF)/∂Q", [2e-9, 5e-9, 3e-9, 3e-9], |robot, data, rng, q| {
        let p = tip_or_random_point(robot, rng);
        let f = Vector6::from_fn(|_, _| rng.random_range(-10.0..10.0));
        let n = robot.dof();
        let mut analytic = Mat::zeros(n, n);
        robot.forward_kinematics(data, q).unwrap();
        robot.wrench_torque_derivative(data, &p, &f, analytic.as_mut()).unwrap();
        let numeric = central_difference(q, H, |q| generalized_force(robot, data, q, &p, &f));
        rel_err(analytic.as_ref(), numeric.as_ref())
    });
}

/// The gravitational potential energy, written independently of the library's sweep:
/// `V = −Σ_b m_b g · c_b`.
fn potential_energy(robot: &Robot, data: &mut RobotData, q: &[f64]) -> f64 {
    robot.forward_kinematics(data, q).unwrap();
    let g = robot.gravity();
    robot
        .bodies()
        .iter()
        .enumerate()
        .map(|(b, body)| {
            let c = robot.point_position(data, &BodyPoint { body: b, point: body.com }).unwrap();
            -body.mass * g.dot(&c)
        })
        .sum()
}

fn gravity_torque(robot: &Robot, data: &mut RobotData, q: &[f64]) -> Vec<f64> {
    robot.forward_kinematics(data, q).unwrap();
    let mut t = vec![0.0; robot.dof()];
    robot.gravity_torque(data, &mut t).unwrap();
    t
}

#[test]
fn gravity_torque_is_the_gradient_of_the_potential_energy() {
    // Measured worst: 3.30e-10, 2.05e-9, 5.94e-10, 1.31e-9 (was 1e-6 for all).
    check_worst(14, "T_g", [1e-9, 1e-8, 2e-9, 5e-9], |robot, data, _, q| {
        let analytic = gravity_torque(robot, data, q);
        // The gradient as a 1 × n row: its transpose is the column of `T_g`.
        let numeric = central_difference(q, H, |q| vec![potential_energy(robot, data, q)]);
        rel_err(column(&analytic).as_ref(), numeric.transpose())
    });
}

#[test]
fn gravity_torque_derivative_matches_finite_differences_and_is_symmetric() {
    // Measured worst: 1.48e-9, 1.35e-9, 4.33e-10, 5.47e-10 (was 1e-6 for all).
    check_worst(15, "∂T_g/∂Q", [5e-9, 5e-9, 2e-9, 2e-9], |robot, data, _, q| {
        let n = robot.dof();
        let mut analytic = Mat::zeros(n, n);
        robot.forward_kinematics(data, q).unwrap();
        robot.gravity_torque_derivative(data, analytic.as_mut()).unwrap();
        let numeric = central_difference(q, H, |q| gravity_torque(robot, data, q));
        let transpose = analytic.transpose().to_owned();
        assert!(
            rel_err(analytic.as_ref(), transpose.as_ref()) <= 1e-12,
            "{}: ∂T_g/∂Q not symmetric",
            robot.name()
        );
        rel_err(analytic.as_ref(), numeric.as_ref())
    });
}

#[test]
fn wrench_torque_is_jacobian_transpose_times_wrench() {
    check_worst(16, "JᵀF", [1e-12; 4], |robot, data, rng, q| {
        let p = random_point(robot, rng);
        let f = Vector6::from_fn(|_, _| rng.random_range(-10.0..10.0));
        let expected = generalized_force(robot, data, q, &p, &f);
        let mut out = vec![0.0; robot.dof()];
        robot.wrench_torque(data, &p, &f, &mut out).unwrap();
        rel_err(column(&out).as_ref(), column(&expected).as_ref())
    });
}
