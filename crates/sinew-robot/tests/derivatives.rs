//! Every analytic derivative against central finite differences, at 100 seeded random
//! configurations within the limits, on cdhrm5 and a generated 50-joint (100-DOF) chain.
//!
//! Criterion: `max |analytic − numeric| ≤ 1e-6 · max(1, max |analytic|)` (`sinew_testkit::numeric::rel_err`).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use nalgebra::{Vector3, Vector6};
use rand::Rng;
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
fn random_point(robot: &Robot, rng: &mut rand_chacha::ChaCha8Rng) -> BodyPoint {
    let body = rng.random_range(1..robot.bodies().len());
    let point = Vector3::from_fn(|_, _| rng.random_range(-0.05..0.05));
    BodyPoint { body, point }
}

fn jacobian_at(robot: &Robot, data: &mut RobotData, q: &[f64], p: &BodyPoint) -> Mat<f64> {
    robot.forward_kinematics(data, q).unwrap();
    let mut j = Mat::zeros(6, robot.dof());
    robot.point_jacobian(data, p, j.as_mut()).unwrap();
    j
}

#[test]
fn point_jacobian_matches_finite_differences_of_the_pose() {
    for (name, robot) in test_robots() {
        let n = robot.dof();
        let mut data = RobotData::new(&robot);
        let mut rng = rng(11);
        let mut worst: f64 = 0.0;
        for _ in 0..CONFIGURATIONS {
            let q = random_q(&robot, &mut rng);
            let p = if rng.random_bool(0.5) {
                robot.tip_point()
            } else {
                random_point(&robot, &mut rng)
            };
            let analytic = jacobian_at(&robot, &mut data, &q, &p);
            let mut numeric = Mat::zeros(6, n);
            for i in 0..n {
                let (qp, qm) = perturbed(&q, i, H);
                robot.forward_kinematics(&mut data, &qp).unwrap();
                let xp = robot.point_position(&data, &p).unwrap();
                let rp = data.body_pose(p.body).unwrap().rotation;
                robot.forward_kinematics(&mut data, &qm).unwrap();
                let xm = robot.point_position(&data, &p).unwrap();
                let rm = data.body_pose(p.body).unwrap().rotation;
                let v = (xp - xm) / (2.0 * H);
                // Angular velocity: the rotation from the minus to the plus pose, over 2h, read
                // from its skew part (sin θ · axis; acos of the trace would lose digits).
                let m = (rp * rm.inverse()).into_inner();
                let w = Vector3::new(
                    m[(2, 1)] - m[(1, 2)],
                    m[(0, 2)] - m[(2, 0)],
                    m[(1, 0)] - m[(0, 1)],
                ) / (4.0 * H);
                for r in 0..3 {
                    numeric[(r, i)] = v[r];
                    numeric[(r + 3, i)] = w[r];
                }
            }
            worst = worst.max(rel_err(analytic.as_ref(), numeric.as_ref()));
        }
        println!("{name}: point Jacobian worst relative error {worst:.2e}");
        assert!(worst <= RTOL, "{name}: point Jacobian error {worst:e} > {RTOL:e}");
    }
}

#[test]
fn jacobian_derivative_matches_finite_differences_of_the_jacobian() {
    for (name, robot) in test_robots() {
        let n = robot.dof();
        let mut data = RobotData::new(&robot);
        let mut rng = rng(12);
        let mut worst: f64 = 0.0;
        let mut analytic = Mat::zeros(6, n);
        for _ in 0..CONFIGURATIONS {
            let q = random_q(&robot, &mut rng);
            let p = if rng.random_bool(0.5) {
                robot.tip_point()
            } else {
                random_point(&robot, &mut rng)
            };
            for i in 0..n {
                robot.forward_kinematics(&mut data, &q).unwrap();
                robot.point_jacobian_derivative(&data, &p, i, analytic.as_mut()).unwrap();
                let (qp, qm) = perturbed(&q, i, H);
                let jp = jacobian_at(&robot, &mut data, &qp, &p);
                let jm = jacobian_at(&robot, &mut data, &qm, &p);
                let numeric = (jp - jm) * faer::Scale(1.0 / (2.0 * H));
                worst = worst.max(rel_err(analytic.as_ref(), numeric.as_ref()));
            }
        }
        println!("{name}: Jacobian derivative worst relative error {worst:.2e}");
        assert!(worst <= RTOL, "{name}: Jacobian derivative error {worst:e} > {RTOL:e}");
    }
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
    for (name, robot) in test_robots() {
        let n = robot.dof();
        let mut data = RobotData::new(&robot);
        let mut rng = rng(13);
        let mut worst: f64 = 0.0;
        let mut analytic = Mat::zeros(n, n);
        for _ in 0..CONFIGURATIONS {
            let q = random_q(&robot, &mut rng);
            let p = if rng.random_bool(0.5) {
                robot.tip_point()
            } else {
                random_point(&robot, &mut rng)
            };
            let f = Vector6::from_fn(|_, _| rng.random_range(-10.0..10.0));
            robot.forward_kinematics(&mut data, &q).unwrap();
            robot.wrench_torque_derivative(&mut data, &p, &f, analytic.as_mut()).unwrap();
            let numeric =
                central_difference(&q, H, |q| generalized_force(&robot, &mut data, q, &p, &f));
            worst = worst.max(rel_err(analytic.as_ref(), numeric.as_ref()));
        }
        println!("{name}: ∂(JᵀF)/∂Q worst relative error {worst:.2e}");
        assert!(worst <= RTOL, "{name}: ∂(JᵀF)/∂Q error {worst:e} > {RTOL:e}");
    }
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
    for (name, robot) in test_robots() {
        let mut data = RobotData::new(&robot);
        let mut rng = rng(14);
        let mut worst: f64 = 0.0;
        for _ in 0..CONFIGURATIONS {
            let q = random_q(&robot, &mut rng);
            let analytic = gravity_torque(&robot, &mut data, &q);
            // The gradient as a 1 × n row: its transpose is the column of `T_g`.
            let numeric =
                central_difference(&q, H, |q| vec![potential_energy(&robot, &mut data, q)]);
            worst = worst.max(rel_err(column(&analytic).as_ref(), numeric.transpose()));
        }
        println!("{name}: T_g worst relative error {worst:.2e}");
        assert!(worst <= RTOL, "{name}: T_g error {worst:e} > {RTOL:e}");
    }
}

#[test]
fn gravity_torque_derivative_matches_finite_differences_and_is_symmetric() {
    for (name, robot) in test_robots() {
        let n = robot.dof();
        let mut data = RobotData::new(&robot);
        let mut rng = rng(15);
        let mut worst: f64 = 0.0;
        let mut analytic = Mat::zeros(n, n);
        for _ in 0..CONFIGURATIONS {
            let q = random_q(&robot, &mut rng);
            robot.forward_kinematics(&mut data, &q).unwrap();
            robot.gravity_torque_derivative(&mut data, analytic.as_mut()).unwrap();
            let numeric = central_difference(&q, H, |q| gravity_torque(&robot, &mut data, q));
            worst = worst.max(rel_err(analytic.as_ref(), numeric.as_ref()));
            let transpose = analytic.transpose().to_owned();
            assert!(
                rel_err(analytic.as_ref(), transpose.as_ref()) <= 1e-12,
                "{name}: ∂T_g/∂Q not symmetric"
            );
        }
        println!("{name}: ∂T_g/∂Q worst relative error {worst:.2e}");
        assert!(worst <= RTOL, "{name}: ∂T_g/∂Q error {worst:e} > {RTOL:e}");
    }
}

#[test]
fn wrench_torque_is_jacobian_transpose_times_wrench() {
    for (name, robot) in test_robots() {
        let mut data = RobotData::new(&robot);
        let mut rng = rng(16);
        let mut out = vec![0.0; robot.dof()];
        for _ in 0..CONFIGURATIONS {
            let q = random_q(&robot, &mut rng);
            let p = random_point(&robot, &mut rng);
            let f = Vector6::from_fn(|_, _| rng.random_range(-10.0..10.0));
            let expected = generalized_force(&robot, &mut data, &q, &p, &f);
            robot.wrench_torque(&data, &p, &f, &mut out).unwrap();
            let err = rel_err(column(&out).as_ref(), column(&expected).as_ref());
            assert!(err <= 1e-12, "{name}: JᵀF error {err:e}");
        }
    }
}
