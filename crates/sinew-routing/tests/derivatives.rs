//! Analytic lengths, cable Jacobian and Hessians against eq. (2) and central finite differences.
//!
//! Criterion: for `J_c` and for each cable's Hessian `H_c`, at 100 seeded-random configurations
//! within the limits, `max |analytic − FD| ≤ tol · max |analytic|` (the error relative to the
//! matrix's largest entry, h = 1e-6), `tol` per case at a few times the worst error measured
//! (beside each bound; run with `--nocapture` to see them). The old common bound was 1e-6.
//!
//! Cases: cdhrm5 and a 50-joint uniform chain (axis-aligned, holes at z = 0, each segment
//! crossing one joint), and random-geometry chains (`sinew_testkit::random_chain`) with the
//! pattern routings and with an explicit routing whose segments skip discs, pass through the
//! massless link between the two revolutes of a universal joint, and whose holes have z ≠ 0;
//! on the explicit routing the routed lengths are also compared with an independent sum of
//! segments between hole positions from the URDF's transforms.
#![allow(clippy::unwrap_used, clippy::expect_used, non_snake_case)]

use faer::Mat;
use nalgebra::{Isometry3, Point3, Vector3};
use sinew_robot::RobotData;
use sinew_routing::{Order, PatternModel, Routing, RoutingData, compute_cable_geometry};
use sinew_testkit::cdhrm5;
use sinew_testkit::config::{random_q, rng};
use sinew_testkit::numeric::{H, max_abs, max_diff_and_scale};
use sinew_testkit::one_joint::eq1;
use sinew_testkit::random_chain::RandomChain;

/// eq. (2): `|r_j − T · r'_j|`, `r_j` in `O_i`, `r'_j` in `O'_i`.
fn eq2(r: Vector3<f64>, r_prime: Vector3<f64>, T: &Isometry3<f64>) -> f64 {
    (r - (T * Point3::from(r_prime)).coords).norm()
}

#[test]
fn one_joint_length_is_eq_2() {
    // A generated single joint, holes computed here from the pattern's constants.
    let chain = cdhrm5::uniform_chain(1);
    let robot = chain.build().unwrap();
    let routing =
        Routing::new(&robot, &cdhrm5::chain_routing_spec(&chain, PatternModel::Decoupled), "<1>")
            .unwrap();
    let mut rdata = RobotData::new(&robot);
    let mut data = RoutingData::new(&routing);
    let rho = cdhrm5::HOLE_RADIUS;
    let mut rng = rng(1);
    let mut worst: f64 = 0.0;
    for _ in 0..100 {
        let q = random_q(&robot, &mut rng);
        compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &q, Order::Lengths)
            .unwrap();
        let T = eq1(chain.d1, chain.d2, [q[0], q[1]]);
        for k in 0..3 {
            let theta = cdhrm5::THETA0 + std::f64::consts::TAU * k as f64 / 3.0;
            let r = Vector3::new(rho * theta.cos(), rho * theta.sin(), 0.0);
            let expected = eq2(r, r, &T);
            let got = data.lengths().unwrap()[k];
            worst = worst.max((got - expected).abs());
            assert!(
                (got - expected).abs() <= 1e-14,
                "cable {k} at {q:?}: {got} vs eq. (2) {expected}"
            );
        }
    }
    println!("single joint: worst |L − eq. (2)| = {worst:.2e} m");
}

#[test]
fn every_cdhrm5_joint_length_is_eq_2() {
    // Every joint of the platform: the holes as the routing file places them (link frames of
    // the proximal and distal discs are O_i and O'_i), T from that joint's two angles only.
    let robot = cdhrm5::robot();
    let routing = cdhrm5::routing(&robot, PatternModel::Decoupled);
    let mut rdata = RobotData::new(&robot);
    let mut data = RoutingData::new(&routing);
    let mut rng = rng(2);
    for _ in 0..100 {
        let q = random_q(&robot, &mut rng);
        compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &q, Order::Lengths)
            .unwrap();
        for (c, cable) in routing.cables().iter().enumerate() {
            let i = cable.joint;
            assert_eq!(cable.holes.len(), 2);
            // d1 = 30 mm, d2 = 0: the calibrated platform (robots/cdhrm5/README.md).
            let T = eq1(0.03, 0.0, [q[2 * i], q[2 * i + 1]]);
            let expected = eq2(cable.holes[0].point, cable.holes[1].point, &T);
            let got = data.lengths().unwrap()[c];
            assert!((got - expected).abs() <= 1e-14, "{}: {got} vs eq. (2) {expected}", cable.name);
        }
    }
}

/// Check `J_c` and every `H_c` of one case against central differences at 100 configurations.
///
/// The differences of `L_c` are taken segment by segment (`Σ_s (L_s(q + h) − L_s(q − h)) / 2h`,
/// the same number as the difference of the sums without the round-off of summing a 13 m cable
/// before subtracting); the Hessians are central differences of the analytic `J_c`, compared
/// column by column over the rows of the cable's joints.
fn check_against_finite_differences(
    name: &str,
    robot: &sinew_robot::Robot,
    routing: &Routing,
    j_tol: f64,
    h_tol: f64,
) {
    let (n, m) = (robot.dof(), routing.cable_count());
    let mut rdata = RobotData::new(robot);
    let mut data = RoutingData::new(routing);
    let mut plus = RoutingData::new(routing);
    let mut minus = RoutingData::new(routing);
    let mut fd_jacobian = Mat::<f64>::zeros(m, n);
    let mut hessians: Vec<Mat<f64>> = (0..m).map(|_| Mat::zeros(n, n)).collect();
    let mut hessian_scale = vec![0.0; m];
    let mut rng = rng(7);
    let (mut worst_j, mut worst_j_abs, mut worst_h, mut worst_h_abs) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for _ in 0..100 {
        let q = random_q(robot, &mut rng);
        compute_cable_geometry(routing, robot, &mut rdata, &mut data, &q, Order::Hessians).unwrap();
        for c in 0..m {
            data.cable_hessian(routing, c, hessians[c].as_mut()).unwrap();
            let own = max_abs(hessians[c].as_ref());
            assert!(own > 0.0, "{name}: cable {c} has a zero Hessian");
            // The Hessian is a difference of J_c: its round-off floor scales with the cable's
            // own Jacobian row (m/rad), which also floors the scale when H_c is nearly zero
            // (a joint centre on a disc, d1·d2 = 0, makes H_c small near Q = 0).
            let j = data.jacobian().unwrap();
            let row = routing.cables()[c].dofs.clone().map(|k| j[(c, k)].abs()).fold(0.0, f64::max);
            hessian_scale[c] = own.max(row);
        }
        let mut hessian_diff = vec![0.0f64; m];
        let mut qh = q.clone();
        for i in 0..n {
            qh[i] = q[i] + H;
            compute_cable_geometry(routing, robot, &mut rdata, &mut plus, &qh, Order::Jacobian)
                .unwrap();
            qh[i] = q[i] - H;
            compute_cable_geometry(routing, robot, &mut rdata, &mut minus, &qh, Order::Jacobian)
                .unwrap();
            qh[i] = q[i];
            let (sp, sm) = (plus.segment_lengths().unwrap(), minus.segment_lengths().unwrap());
            let (jp, jm) = (plus.jacobian().unwrap(), minus.jacobian().unwrap());
            for c in 0..m {
                fd_jacobian[(c, i)] =
                    routing.cables()[c].segments.clone().map(|s| (sp[s] - sm[s]) / (2.0 * H)).sum();
                // H_c[k, i] = ∂J[c, k]/∂q_i. Outside the cable's joints (`cable.dofs`), J[c, k]
                // and H_c[k, ·] are exact zeros at every Q (tests/structure.rs): skip them.
                let h = &hessians[c];
                for k in routing.cables()[c].dofs.clone() {
                    let fd = (jp[(c, k)] - jm[(c, k)]) / (2.0 * H);
                    hessian_diff[c] = hessian_diff[c].max((h[(k, i)] - fd).abs());
                }
            }
        }
        let (diff, scale) = max_diff_and_scale(data.jacobian().unwrap(), fd_jacobian.as_ref());
        assert!(
            diff <= j_tol * scale,
            "{name}: J_c off by {diff:.3e} (scale {scale:.3e}) at {q:?}"
        );
        worst_j = worst_j.max(diff / scale);
        worst_j_abs = worst_j_abs.max(diff);
        for c in 0..m {
            let (diff, scale) = (hessian_diff[c], hessian_scale[c]);
            assert!(
                diff <= h_tol * scale,
                "{name}: H of cable {} off by {diff:.3e} (scale {scale:.3e}) at {q:?}",
                routing.cables()[c].name
            );
            worst_h = worst_h.max(diff / scale);
            worst_h_abs = worst_h_abs.max(diff);
        }
    }
    println!(
        "{name}: worst J_c error {worst_j:.2e} relative ({worst_j_abs:.2e} m/rad), worst Hessian error {worst_h:.2e} relative ({worst_h_abs:.2e} m/rad²)"
    );
}

#[test]
fn cdhrm5_decoupled_matches_finite_differences() {
    let robot = cdhrm5::robot();
    let routing = cdhrm5::routing(&robot, PatternModel::Decoupled);
    // Measured worst: J_c 7.36e-9, Hessians 6.90e-9 (both were 1e-6).
    check_against_finite_differences("cdhrm5 decoupled", &robot, &routing, 3e-8, 3e-8);
}

#[test]
fn cdhrm5_routed_matches_finite_differences() {
    let robot = cdhrm5::robot();
    let routing = cdhrm5::routing(&robot, PatternModel::Routed);
    // Measured worst: J_c 1.10e-8, Hessians 6.59e-9 (both were 1e-6).
    check_against_finite_differences("cdhrm5 routed", &robot, &routing, 4e-8, 3e-8);
}

// The 50-joint chain's cables run ~12 m from the base: the round-off of the hole positions,
// ε·12 m / h ≈ 2e-9 m/rad, against J_c entries of ~2e-2 m/rad, is the ~1e-7 level measured.
#[test]
fn chain50_decoupled_matches_finite_differences() {
    let (robot, routing) = cdhrm5::chain(50, PatternModel::Decoupled);
    // Measured worst: J_c 9.57e-8, Hessians 1.01e-7 (both were 1e-6).
    check_against_finite_differences("uniform50 decoupled", &robot, &routing, 3e-7, 3e-7);
}

#[test]
fn chain50_routed_matches_finite_differences() {
    let (robot, routing) = cdhrm5::chain(50, PatternModel::Routed);
    // Measured worst: J_c 2.52e-7, Hessians 8.41e-8 (both were 1e-6).
    check_against_finite_differences("uniform50 routed", &robot, &routing, 8e-7, 3e-7);
}

/// The random-geometry chains under test: (universal joints, seed).
const RANDOM_CHAINS: [(usize, u64); 2] = [(5, 1), (12, 2)];

#[test]
fn random_geometry_pattern_routings_match_finite_differences() {
    let mut tols = TOLS_PATTERN.iter();
    for (joints, seed) in RANDOM_CHAINS {
        let chain = RandomChain::new(joints, seed);
        let robot = chain.robot();
        for model in cdhrm5::MODELS {
            let routing = chain.routing(&robot, &chain.pattern_spec(model));
            let (j_tol, h_tol) = tols.next().unwrap();
            let name = format!("{} {model:?}", chain.name);
            check_against_finite_differences(&name, &robot, &routing, *j_tol, *h_tol);
        }
    }
}

#[test]
fn random_geometry_explicit_routings_match_finite_differences() {
    let mut tols = TOLS_EXPLICIT.iter();
    for (joints, seed) in RANDOM_CHAINS {
        let chain = RandomChain::new(joints, seed);
        let robot = chain.robot();
        let routing = chain.routing(&robot, &chain.explicit_spec(seed));
        assert_explicit_routing_is_general(&chain.name, &robot, &routing);
        let (j_tol, h_tol) = tols.next().unwrap();
        let name = format!("{} explicit", chain.name);
        check_against_finite_differences(&name, &robot, &routing, *j_tol, *h_tol);
    }
}

// (J_c, Hessian) bounds, a few times the measured worst noted beside each.
const TOLS_PATTERN: [(f64, f64); 4] = [
    (1e-8, 2e-8), // random5s1 decoupled: measured 2.43e-9, 4.40e-9
    (3e-8, 2e-8), // random5s1 routed: measured 8.28e-9, 4.24e-9
    (2e-8, 5e-8), // random12s2 decoupled: measured 4.99e-9, 1.44e-8
    (1e-7, 2e-8), // random12s2 routed: measured 2.78e-8, 4.32e-9
];
const TOLS_EXPLICIT: [(f64, f64); 2] = [
    (2e-8, 1e-8), // random5s1 explicit: measured 4.24e-9, 2.36e-9
    (2e-8, 2e-8), // random12s2 explicit: measured 5.30e-9, 4.13e-9
];

/// The explicit routing holds what the pattern cannot: a segment crossing more than one
/// revolute joint, a hole on a `cross` link (between the two revolutes of a pair), and holes
/// off the disc plane.
fn assert_explicit_routing_is_general(name: &str, robot: &sinew_robot::Robot, routing: &Routing) {
    let multi = routing.segments().iter().filter(|s| s.dofs.len() > 1).count();
    let cross = routing
        .cables()
        .iter()
        .flat_map(|c| &c.holes)
        .filter(|h| h.link.starts_with("cross"))
        .count();
    let off_plane = routing.cables().iter().flat_map(|c| &c.holes).all(|h| h.point.z != 0.0);
    println!(
        "{name} explicit: {} cables, {} segments, {multi} crossing several joints, {cross} holes on cross links",
        routing.cable_count(),
        routing.segments().len()
    );
    assert!(multi > 0 && cross > 0 && off_plane, "{name}: the explicit routing is not general");
    assert!(routing.segments().iter().any(|s| s.dofs.len() > 2), "{name}: no segment skips a disc");
    assert_eq!(routing.dof(), robot.dof());
}

#[test]
fn explicit_routed_lengths_are_an_independent_sum_of_segments() {
    // Hole positions from the URDF's transforms composed in the testkit (no sinew-robot or
    // sinew-routing code), Σ |p_{k+1} − p_k| per cable, at random Q.
    let mut worst: f64 = 0.0;
    for (joints, seed) in RANDOM_CHAINS {
        let chain = RandomChain::new(joints, seed);
        let robot = chain.robot();
        let spec = chain.explicit_spec(seed);
        let routing = chain.routing(&robot, &spec);
        let mut rdata = RobotData::new(&robot);
        let mut data = RoutingData::new(&routing);
        let mut rng = rng(seed + 100);
        for _ in 0..50 {
            let q = random_q(&robot, &mut rng);
            compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &q, Order::Lengths)
                .unwrap();
            let poses = chain.link_poses(&q);
            for cable in &spec.cables {
                let points: Vec<Point3<f64>> = cable
                    .holes
                    .iter()
                    .map(|h| poses[&h.link] * Point3::from(Vector3::from(h.point)))
                    .collect();
                let expected: f64 = points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
                let c = routing.cable_index(&cable.name).unwrap();
                let got = data.lengths().unwrap()[c];
                let err = (got - expected).abs();
                worst = worst.max(err);
                // Measured worst 4.00e-15 m (cables up to ~3.5 m long).
                assert!(
                    err <= 2e-14,
                    "{} {}: L = {got} vs Σ segments {expected}",
                    chain.name,
                    cable.name
                );
            }
        }
    }
    println!("explicit routings: worst |L − Σ segments| = {worst:.2e} m");
}

#[test]
fn hessians_are_symmetric_and_sum_as_weighted() {
    for (name, robot, routing) in cdhrm5::cases(50) {
        let (n, m) = (robot.dof(), routing.cable_count());
        let mut rdata = RobotData::new(&robot);
        let mut data = RoutingData::new(&routing);
        let mut rng = rng(11);
        let q = random_q(&robot, &mut rng);
        compute_cable_geometry(&routing, &robot, &mut rdata, &mut data, &q, Order::Hessians)
            .unwrap();
        let f: Vec<f64> = (0..m).map(|_| rng.random_range(20.0..600.0)).collect();
        // Start from a non-zero matrix: add_weighted_hessians adds.
        let start = Mat::<f64>::from_fn(n, n, |i, j| (i * n + j) as f64 * 1e-3);
        let mut sum = start.clone();
        data.add_weighted_hessians(&routing, &f, sum.as_mut()).unwrap();
        let mut expected = start.clone();
        let mut h = Mat::<f64>::zeros(n, n);
        for c in 0..m {
            data.cable_hessian(&routing, c, h.as_mut()).unwrap();
            for j in 0..n {
                for i in 0..n {
                    assert_eq!(h[(i, j)], h[(j, i)], "{name}: H of cable {c} not symmetric");
                    expected[(i, j)] += f[c] * h[(i, j)];
                }
            }
        }
        let (diff, scale) = max_diff_and_scale(sum.as_ref(), expected.as_ref());
        assert!(diff <= 1e-12 * scale, "{name}: Σ f_c H_c off by {diff:.3e}");
    }
}

use rand::Rng as _;

/// Central differences of the lengths (for `J_c`) and of the analytic `J_c` (for the Hessians,
/// the largest entry error over every cable) with step `h`: `(max |J_c − FD|, max |H − FD|)`.
fn fd_errors(robot: &sinew_robot::Robot, routing: &Routing, q: &[f64], h: f64) -> (f64, f64) {
    let (n, m) = (robot.dof(), routing.cable_count());
    let mut rdata = RobotData::new(robot);
    let mut data = RoutingData::new(routing);
    let (mut plus, mut minus) = (RoutingData::new(routing), RoutingData::new(routing));
    compute_cable_geometry(routing, robot, &mut rdata, &mut data, q, Order::Hessians).unwrap();
    let hessians: Vec<Mat<f64>> = (0..m)
        .map(|c| {
            let mut hc = Mat::zeros(n, n);
            data.cable_hessian(routing, c, hc.as_mut()).unwrap();
            hc
        })
        .collect();
    let j = data.jacobian().unwrap();
    let (mut j_err, mut h_err) = (0.0f64, 0.0f64);
    let mut qh = q.to_vec();
    for i in 0..n {
        qh[i] = q[i] + h;
        compute_cable_geometry(routing, robot, &mut rdata, &mut plus, &qh, Order::Jacobian)
            .unwrap();
        qh[i] = q[i] - h;
        compute_cable_geometry(routing, robot, &mut rdata, &mut minus, &qh, Order::Jacobian)
            .unwrap();
        qh[i] = q[i];
        let (sp, sm) = (plus.segment_lengths().unwrap(), minus.segment_lengths().unwrap());
        let (jp, jm) = (plus.jacobian().unwrap(), minus.jacobian().unwrap());
        for c in 0..m {
            let fd: f64 =
                routing.cables()[c].segments.clone().map(|s| (sp[s] - sm[s]) / (2.0 * h)).sum();
            j_err = j_err.max((j[(c, i)] - fd).abs());
            for k in 0..n {
                let fd = (jp[(c, k)] - jm[(c, k)]) / (2.0 * h);
                h_err = h_err.max((hessians[c][(k, i)] - fd).abs());
            }
        }
    }
    (j_err, h_err)
}

/// Step halving: with steps where truncation (∝ h²) dominates round-off, the errors of the
/// central differences of `J_c` and of the Hessians fall by 4 each time h halves. A wrong term
/// in the analytic derivative (a sign in a Hessian, a missing segment) makes them level off.
#[test]
fn jacobian_and_hessian_errors_decay_as_h_squared() {
    let steps = [8e-3, 4e-3, 2e-3, 1e-3];
    let chain = RandomChain::new(5, 1);
    let random = chain.robot();
    let mut cases = vec![
        ("cdhrm5 routed".to_owned(), cdhrm5::robot_and_routing(PatternModel::Routed)),
        ("cdhrm5 decoupled".to_owned(), cdhrm5::robot_and_routing(PatternModel::Decoupled)),
    ];
    let explicit = chain.routing(&random, &chain.explicit_spec(1));
    cases.push((format!("{} explicit", chain.name), (random, explicit)));
    for (name, (robot, routing)) in cases {
        let mut rng = rng(19);
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for _ in 0..5 {
            let q = random_q(&robot, &mut rng);
            let errors: Vec<(f64, f64)> =
                steps.iter().map(|&h| fd_errors(&robot, &routing, &q, h)).collect();
            for pair in errors.windows(2) {
                for ratio in [pair[0].0 / pair[1].0, pair[0].1 / pair[1].1] {
                    lo = lo.min(ratio);
                    hi = hi.max(ratio);
                }
            }
        }
        println!("{name}: error(h)/error(h/2) of J_c and Hessians within [{lo:.3}, {hi:.3}]");
        // Measured: within [3.999, 4.000] on every case.
        assert!(lo >= 3.95 && hi <= 4.05, "{name}: error(h)/error(h/2) within [{lo}, {hi}], not 4");
    }
}
