//! Forward kinematics against hand-computed values and an independent product of transforms.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use approx::assert_relative_eq;
use nalgebra::{Matrix4, Vector3};
use sinew_robot::RobotData;
use sinew_testkit::{cdhrm5, config};

// The platform's geometry as chosen in robots/cdhrm5/README.md (d1, d2 fitted to Table II by
// `cargo xtask calibrate`: the joint centre on the distal disc).
const D1: f64 = cdhrm5::D1_D2.0;
const D2: f64 = cdhrm5::D1_D2.1;
const LINK: f64 = 0.22;
const JOINTS: usize = 5;

#[test]
fn tip_at_zero_is_the_stacked_lengths() {
    let robot = cdhrm5::robot();
    assert_eq!(robot.dof(), 2 * JOINTS);
    let mut data = RobotData::new(&robot);
    robot.forward_kinematics(&mut data, &[0.0; 10]).unwrap();
    let tip = robot.tip_pose(&data).unwrap();
    // Five times (d1 + d2 + link) along z: 5 × 0.25 m = 1.25 m.
    assert_relative_eq!(tip.translation.vector, Vector3::new(0.0, 0.0, 1.25), epsilon = 1e-12);
    assert_relative_eq!(*tip.rotation.matrix(), nalgebra::Matrix3::identity(), epsilon = 1e-12);
    // Joint axes alternate x, y; joint i's centre sits at d1 + i (d1 + d2 + link).
    for j in 0..10 {
        let axis = if j % 2 == 0 { Vector3::x() } else { Vector3::y() };
        assert_relative_eq!(*data.joint_axis(j).unwrap(), axis, epsilon = 1e-12);
        let z = D1 + (j / 2) as f64 * (D1 + D2 + LINK);
        assert_relative_eq!(
            *data.joint_origin(j).unwrap(),
            Vector3::new(0.0, 0.0, z),
            epsilon = 1e-12
        );
    }
}

fn trans_z(d: f64) -> Matrix4<f64> {
    let mut m = Matrix4::identity();
    m[(2, 3)] = d;
    m
}

fn rot_x(q: f64) -> Matrix4<f64> {
    let (s, c) = q.sin_cos();
    Matrix4::new(1.0, 0.0, 0.0, 0.0, 0.0, c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0)
}

fn rot_y(q: f64) -> Matrix4<f64> {
    let (s, c) = q.sin_cos();
    Matrix4::new(c, 0.0, s, 0.0, 0.0, 1.0, 0.0, 0.0, -s, 0.0, c, 0.0, 0.0, 0.0, 0.0, 1.0)
}

#[test]
fn tip_at_random_q_is_the_product_of_eq1_transforms() {
    let robot = cdhrm5::robot();
    let mut data = RobotData::new(&robot);
    let mut rng = config::rng(1);
    for _ in 0..100 {
        let q = config::random_q(&robot, &mut rng);
        robot.forward_kinematics(&mut data, &q).unwrap();
        let tip = robot.tip_pose(&data).unwrap().to_homogeneous();
        // eq. 1 per joint, then the link from O'_i to the next disc O_{i+1}.
        let mut expected = Matrix4::identity();
        for i in 0..JOINTS {
            expected = expected
                * trans_z(D1)
                * rot_x(q[2 * i])
                * rot_y(q[2 * i + 1])
                * trans_z(D2)
                * trans_z(LINK);
        }
        assert_relative_eq!(tip, expected, epsilon = 1e-12);
    }
}

#[test]
fn link_points_resolve_through_fixed_joints() {
    let robot = cdhrm5::robot();
    let mut data = RobotData::new(&robot);
    let q = [0.2, -0.1, 0.3, 0.05, -0.2, 0.1, 0.0, 0.4, -0.3, 0.25];
    robot.forward_kinematics(&mut data, &q).unwrap();
    // The distal disc of link 2 is the end of link 2: 0.22 m along its z axis.
    let disc = robot.link_point("link2_distal", Vector3::zeros()).unwrap();
    let on_link = robot.link_point("link2", Vector3::new(0.0, 0.0, LINK)).unwrap();
    assert_eq!(disc.body, on_link.body);
    assert_relative_eq!(
        robot.point_position(&data, &disc).unwrap(),
        robot.point_position(&data, &on_link).unwrap(),
        epsilon = 1e-12
    );
}

#[test]
fn mass_is_folded_into_bodies() {
    let robot = cdhrm5::robot();
    assert_relative_eq!(robot.moving_mass(), 1.2, epsilon = 1e-12);
    // Body of joint1_y carries link1: 0.24 kg, centre of mass d2 + 0.11 m beyond the pivot.
    let body = &robot.bodies()[2];
    assert_eq!(body.name, "pivot1");
    assert_relative_eq!(body.mass, 0.24, epsilon = 1e-12);
    assert_relative_eq!(body.com, Vector3::new(0.0, 0.0, D2 + LINK / 2.0), epsilon = 1e-12);
    // Crosses are massless.
    assert_eq!(robot.bodies()[1].mass, 0.0);
}

#[test]
fn gravity_comes_from_the_description() {
    let robot = cdhrm5::robot();
    assert_eq!(robot.gravity(), Vector3::new(0.0, 9.81, 0.0));
    let mut data = RobotData::new(&robot);
    robot.forward_kinematics(&mut data, &[0.0; 10]).unwrap();
    let mut tg = [0.0; 10];
    robot.gravity_torque(&mut data, &mut tg).unwrap();
    // Straight horizontal arm, y pointing down: joint 1's x axis carries every link, link i's
    // centre of mass at z_i − d1 beyond the axis. Rot(x, q) moves (0, 0, z) to
    // (0, −z sin q, z cos q), so V = −9.81 Σ m y has ∂V/∂q = 9.81 Σ m (z_i − d1) at q = 0.
    let mut moment = 0.0;
    for i in 0..JOINTS {
        let z = D1 + D2 + LINK / 2.0 + i as f64 * (D1 + D2 + LINK);
        moment += 0.24 * 9.81 * (z - D1);
    }
    assert_relative_eq!(tg[0], moment, epsilon = 1e-12);
    // About y, gravity (along y) has no moment.
    assert_relative_eq!(tg[1], 0.0, epsilon = 1e-12);
}

#[test]
fn random_geometry_link_poses_match_an_independent_product_of_urdf_transforms() {
    // Random rpy, offsets and unit axes (sinew_testkit::random_chain): every link frame as
    // the robot places it (body pose · body_M_link) against the URDF's numbers composed
    // independently, `pose(child) = pose(parent) · origin · Rot(axis, q)`.
    let mut worst: f64 = 0.0;
    for (joints, seed) in [(5, 1), (12, 2)] {
        let chain = sinew_testkit::random_chain::RandomChain::new(joints, seed);
        let robot = chain.robot();
        assert_eq!(robot.dof(), 2 * joints);
        let mut data = RobotData::new(&robot);
        let mut rng = config::rng(seed);
        for _ in 0..20 {
            let q = config::random_q(&robot, &mut rng);
            robot.forward_kinematics(&mut data, &q).unwrap();
            let expected = chain.link_poses(&q);
            assert_eq!(expected.len(), robot.links().len(), "{}: link count", chain.name);
            for link in robot.links() {
                let got = data.body_pose(link.body).unwrap() * link.body_m_link;
                let want = expected[&link.name].to_matrix();
                let err = (got.to_homogeneous() - want).abs().max();
                worst = worst.max(err);
                assert!(err <= 2e-14, "{} {}: pose off by {err:e} at {q:?}", chain.name, link.name);
            }
        }
    }
    // Measured worst 3.83e-15 (bound 2e-14).
    println!("random chains: worst link pose error {worst:.2e}");
}
