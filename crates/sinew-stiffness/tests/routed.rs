//! The routed model's pipeline (`K_q` full: the dense solve, the inherent part by its staircase
//! kernel) against an independent reference: `K_q` from the public [`joint_stiffness`] (cable
//! by cable over each cable's joint range), `K_W` from sinew-robot's dense derivatives, then
//! [`end_stiffness`]. At 10 (cdhrm5), 50 and 200 DOF; and the stability verdict on both sides of
//! the stability boundary.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use nalgebra::{Vector3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, PatternModel, Routing, RoutingData, compute_cable_geometry};
use sinew_statics::TensionChoice;
use sinew_stiffness::{
    ArmStiffness, ArmStiffnessData, EndSolver, EndStiffnessData, StiffnessError, end_stiffness,
    joint_stiffness,
};
use sinew_testkit::numeric::rel_diff;
use sinew_testkit::{cdhrm5, config};

/// Relative agreement required with the reference.
const RTOL: f64 = 1e-12;

struct Reference {
    k_inherent: Mat<f64>,
    k_q: Mat<f64>,
    end: EndStiffnessData,
    outcome: Result<(), StiffnessError>,
}

/// The reference at `q` with the tensions the pipeline found (`data`).
fn reference(
    robot: &Robot,
    routing: &Routing,
    q: &[f64],
    f0: &Vector6<f64>,
    data: &ArmStiffnessData,
) -> Reference {
    let n = robot.dof();
    let mut rdata = RobotData::new(robot);
    let mut geometry = RoutingData::new(routing);
    compute_cable_geometry(routing, robot, &mut rdata, &mut geometry, q, Order::Hessians).unwrap();
    let mut k_controllable = Mat::zeros(n, n);
    let mut k_inherent = Mat::zeros(n, n);
    joint_stiffness(
        routing,
        &geometry,
        data.tensions(),
        k_controllable.as_mut(),
        k_inherent.as_mut(),
    )
    .unwrap();
    let k_q = &k_controllable + &k_inherent;
    let mut k_w = Mat::zeros(n, n);
    robot.gravity_torque_derivative(&mut rdata, k_w.as_mut()).unwrap();
    let mut load = Mat::zeros(n, n);
    robot.wrench_torque_derivative(&mut rdata, &robot.tip_point(), f0, load.as_mut()).unwrap();
    let k_w = k_w + load;
    let mut end = EndStiffnessData::new(n);
    let outcome = end_stiffness(k_q.as_ref(), k_w.as_ref(), data.j_x(), &mut end);
    Reference { k_inherent, k_q, end, outcome }
}

fn arms() -> Vec<(String, Robot, Routing, Vec<f64>)> {
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Routed);
    let mut v = vec![("cdhrm5".to_string(), robot, routing, cdhrm5::LOADED_POSE.to_vec())];
    for joints in [25, 100] {
        let (robot, routing) = cdhrm5::chain(joints, PatternModel::Routed);
        let robot = robot.with_gravity(Vector3::new(0.0, 1e-4, 0.0));
        let q = (0..2 * joints).map(|i| 0.05 * ((i as f64) * 0.7).sin()).collect();
        v.push((format!("uniform{joints}"), robot, routing, q));
    }
    v
}

#[test]
fn the_routed_pipeline_matches_the_reference_at_10_50_and_200_dof() {
    for (name, robot, routing, centre) in arms() {
        let n = robot.dof();
        let model = ArmStiffness::new(&robot, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        let mut rng = config::rng(23);
        let f = if n == 10 { 5.0 } else { 1e-3 };
        let loads = [
            Vector6::zeros(),
            Vector6::new(0.0, f, 0.0, 0.0, 0.0, 0.0),
            Vector6::new(f, 0.0, 0.0, 0.0, 0.0, 0.02 * f),
        ];
        let mut checked = 0;
        for k in 0..6 {
            let q = if k == 0 { centre.clone() } else { config::near(&centre, 0.02, &mut rng) };
            let levels = vec![0.2 + 0.1 * k as f64; n / 2];
            for f0 in &loads {
                let outcome = model.evaluate(&mut data, &q, f0, TensionChoice::Levels(&levels));
                if let Err(StiffnessError::Statics(_)) = outcome {
                    continue;
                }
                assert_eq!(data.end_solver(), EndSolver::Dense, "{name}");
                let r = reference(&robot, &routing, &q, f0, &data);
                let label = format!("{name} #{k} F0 = {:?}", f0.as_slice());
                // The same sums in the same order (the tiles' extra terms are exact zeros, the
                // batched segment Hessians summed in routing order): equal, not only close.
                assert!(
                    data.k_inherent() == r.k_inherent.as_ref(),
                    "{label}: J_cᵀ K_l J_c differs"
                );
                assert!(data.k_q() == r.k_q.as_ref(), "{label}: K_q differs");
                let err = rel_diff(data.k_inherent(), r.k_inherent.as_ref());
                assert!(err <= RTOL, "{label}: J_cᵀ K_l J_c off by {err:e}");
                let err = rel_diff(data.k_q(), r.k_q.as_ref());
                assert!(err <= RTOL, "{label}: K_q off by {err:e}");
                assert_eq!(data.k_q().to_owned(), data.k_q().transpose().to_owned(), "{label}");
                match (&outcome, &r.outcome) {
                    (Ok(()), Ok(())) => {
                        let err = rel_diff(data.compliance(), r.end.compliance());
                        assert!(err <= RTOL, "{label}: C_x off by {err:e}");
                        let err = rel_diff(data.stiffness(), r.end.stiffness());
                        assert!(err <= RTOL, "{label}: K_x off by {err:e}");
                        checked += 1;
                    }
                    (
                        Err(StiffnessError::Unstable { min_eigenvalue: got }),
                        Err(StiffnessError::Unstable { min_eigenvalue: want }),
                    ) => assert!((got - want).abs() <= RTOL * want.abs(), "{label}"),
                    (got, want) => panic!("{label}: pipeline {got:?}, reference {want:?}"),
                }
            }
        }
        assert!(checked >= 6, "{name}: only {checked} stable configurations compared");
    }
}

#[test]
fn batched_and_segment_by_segment_geometry_give_the_same_arm_bit_for_bit() {
    for (name, robot, routing, centre) in arms() {
        assert!(routing.is_batched(), "{name}");
        let reference = routing.unbatched();
        let (batched, plain) = (
            ArmStiffness::new(&robot, &routing).unwrap(),
            ArmStiffness::new(&robot, &reference).unwrap(),
        );
        let (mut a, mut b) = (ArmStiffnessData::new(&batched), ArmStiffnessData::new(&plain));
        let mut rng = config::rng(5);
        let f0 = Vector6::new(0.0, 1e-3, 0.0, 0.0, 0.0, 0.0);
        for k in 0..4 {
            let q = if k == 0 { centre.clone() } else { config::near(&centre, 0.02, &mut rng) };
            let levels = vec![0.3; robot.dof() / 2];
            let (ra, rb) = (
                batched.evaluate(&mut a, &q, &f0, TensionChoice::Levels(&levels)),
                plain.evaluate(&mut b, &q, &f0, TensionChoice::Levels(&levels)),
            );
            assert_eq!(format!("{ra:?}"), format!("{rb:?}"), "{name} #{k}");
            assert!(a.k_controllable() == b.k_controllable(), "{name} #{k}: K_c");
            assert!(a.k_inherent() == b.k_inherent(), "{name} #{k}: K_i");
            if ra.is_ok() {
                assert!(a.compliance() == b.compliance(), "{name} #{k}: C_x");
                assert!(a.stiffness() == b.stiffness(), "{name} #{k}: K_x");
            }
        }
    }
}

/// The stability verdict of an outcome, as a name (near the boundary `C_x` grows without
/// bound and `K_x` may be rank-deficient: still a stable equilibrium).
fn verdict(outcome: &Result<(), StiffnessError>) -> &'static str {
    match outcome {
        Ok(()) | Err(StiffnessError::RankDeficient { .. }) => "stable",
        Err(StiffnessError::Unstable { .. }) => "unstable",
        Err(StiffnessError::Statics(_)) => "infeasible",
        Err(_) => "other",
    }
}

#[test]
fn the_stability_verdict_agrees_on_both_sides_of_the_boundary() {
    // Gravity along −z, scaled until the arm buckles (cdhrm5 between 8 and 16 m/s², the
    // 50-DOF chain between 1 and 2 m/s², before the tensions become infeasible), then bisected
    // to the boundary: just below it both sides must say stable, just above both unstable.
    for (name, robot, routing, q, mut lo, mut hi) in
        [(0, 8.0, 16.0), (1, 1.0, 2.0)].map(|(k, lo, hi)| {
            let (name, robot, routing, q) = arms().swap_remove(k);
            (name, robot, routing, q, lo, hi)
        })
    {
        let levels = vec![0.5; robot.dof() / 2];
        let at = |g: f64| {
            let robot = robot.with_gravity(Vector3::new(0.0, 0.0, -g));
            let model = ArmStiffness::new(&robot, &routing).unwrap();
            let mut data = ArmStiffnessData::new(&model);
            let outcome =
                model.evaluate(&mut data, &q, &Vector6::zeros(), TensionChoice::Levels(&levels));
            let r = reference(&robot, &routing, &q, &Vector6::zeros(), &data);
            (verdict(&outcome), verdict(&r.outcome))
        };
        assert_eq!(at(lo), ("stable", "stable"), "{name} at {lo}");
        assert_eq!(at(hi), ("unstable", "unstable"), "{name} at {hi}");
        while hi - lo > 1e-12 * hi {
            let mid = 0.5 * (lo + hi);
            match at(mid) {
                ("stable", "stable") => lo = mid,
                ("unstable", "unstable") => hi = mid,
                (got, want) => panic!("{name} at {mid}: pipeline {got}, reference {want}"),
            }
        }
        println!("{name}: stable at g = {lo}, unstable at g = {hi} m/s²");
    }
}
