//! Every analytic derivative against central finite differences, at 100 seeded random
//! configurations within the limits, on cdhrm5 and a generated 50-joint (100-DOF) chain.
//!
//! Criterion: `max |analytic − numeric| ≤ 1e-6 · max(1, max |analytic|)`
//! (`sinew_testkit::numeric::rel_err`).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use nalgebra::{Vector3, Vector6};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use sinew_robot::{BodyPoint, Robot, RobotData};
use sinew_testkit::cdhrm5;
use sinew_testkit::config::{random_q, rng};
use sinew_testkit::numeric::{H, RTOL, central_difference, column, perturbed, rel_err};

const CONFIGURATIONS: usize = 100;

/// The robots the derivative tests run on: cdhrm5 and a generated 50-joint chain.
fn test_robots() -> Vec<(&'static str, Robot)> {
    vec![("cdhrm5", cdhrm5::robot()), ("uniform50", cdhrm5::chain_robot(50))]
}

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
/// `Q`'s), printed and asserted `≤ tol`.
fn check_worst(
    seed: u64,
    what: &str,
    tol: f64,
    mut check: impl FnMut(&Robot, &mut RobotData, &mut ChaCha8Rng, &[f64]) -> f64,
) {
    for (name, robot) in test_robots() {
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

#[test]
fn point_jacobian_matches_finite_differences_of_the_pose() {
    check_worst(11, "point Jacobian", RTOL, |robot, data, rng, q| {
        let p = tip_or_random_point(robot, rng);
        let analytic = jacobian_at(robot, data, q, &p);
        let mut numeric = Mat::zeros(6, robot.dof());
        for i in 0..robot.dof() {
            let (qp, qm) = perturbed(q, i, H);
            robot.forward_kinematics(data, &qp).unwrap();
            let xp = robot.point_position(data, &p).unwrap();
            let rp = data.body_pose(p.body).unwrap().rotation;
            robot.forward_kinematics(data, &qm).unwrap();
            let xm = robot.point_position(data, &p).unwrap();
            let rm = data.body_pose(p.body).unwrap().rotation;
            let v = (xp - xm) / (2.0 * H);
            // Angular velocity: the rotation from the minus to the plus pose, over 2h, read
            // from its skew part (sin θ · axis; acos of the trace would lose digits).
            let m = (rp * rm.inverse()).into_inner();
            let w =
                Vector3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)])
                    / (4.0 * H);
            for r in 0..3 {
                numeric[(r, i)] = v[r];
                numeric[(r + 3, i)] = w[r];
            }
        }
        rel_err(analytic.as_ref(), numeric.as_ref())
    });
}

#[test]
fn jacobian_derivative_matches_finite_differences_of_the_jacobian() {
    check_worst(12, "Jacobian derivative", RTOL, |robot, data, rng, q| {
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
    check_worst(13, "∂(JᵀF)/∂Q", RTOL, |robot, data, rng, q| {
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
    check_worst(14, "T_g", RTOL, |robot, data, _, q| {
        let analytic = gravity_torque(robot, data, q);
        // The gradient as a 1 × n row: its transpose is the column of `T_g`.
        let numeric = central_difference(q, H, |q| vec![potential_energy(robot, data, q)]);
        rel_err(column(&analytic).as_ref(), numeric.transpose())
    });
}

#[test]
fn gravity_torque_derivative_matches_finite_differences_and_is_symmetric() {
    check_worst(15, "∂T_g/∂Q", RTOL, |robot, data, _, q| {
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
    check_worst(16, "JᵀF", 1e-12, |robot, data, rng, q| {
        let p = random_point(robot, rng);
        let f = Vector6::from_fn(|_, _| rng.random_range(-10.0..10.0));
        let expected = generalized_force(robot, data, q, &p, &f);
        let mut out = vec![0.0; robot.dof()];
        robot.wrench_torque(data, &p, &f, &mut out).unwrap();
        rel_err(column(&out).as_ref(), column(&expected).as_ref())
    });
}
