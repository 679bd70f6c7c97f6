//! The structured `O(dof)` end solve of the decoupled model against the dense reference
//! (faer's Cholesky/LU of `K_q + K_W`, with `K_W` from sinew-robot's dense
//! `gravity_torque_derivative` + `wrench_torque_derivative`, independent of the generators): `C_x`, `K_x`, the stability verdict and the reported
//! smallest eigenvalue, on cdhrm5 and generated chains of 5, 25 and 100 universal joints,
//! gravity on and off, `F0` zero, a force, a force and a moment; unstable and rank-deficient
//! equilibria; and which solver ran.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use nalgebra::{Vector3, Vector6};
use rand::Rng;
use sinew_robot::{Robot, RobotData};
use sinew_routing::{PatternModel, Routing};
use sinew_statics::{JointEndData, TensionChoice, equilibrium_torque_derivative};
use sinew_stiffness::{
    ArmStiffness, ArmStiffnessData, EndSolver, EndStiffnessData, StiffnessError, end_stiffness,
};
use sinew_testkit::numeric::{max_abs, rel_diff};
use sinew_testkit::{cdhrm5, config};

/// Relative agreement required between the structured solve and the dense reference.
const RTOL: f64 = 1e-10;

/// The kinds of load `F0` exerted by the end-effector.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Load {
    Zero,
    Force,
    ForceAndMoment,
}

/// A decoupled arm and the scale of its loads: gravity (m/s²) and tip force (N) that the
/// cables can hold (long chains carry little: `[20, 600]` N on a 22 mm hole circle).
struct Setup {
    name: String,
    robot: Robot,
    routing: Routing,
    gravity: f64,
    force: f64,
    /// Fraction of the joint limits the random configurations use.
    reach: f64,
}

fn setups() -> Vec<Setup> {
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Decoupled);
    let mut v = vec![Setup {
        name: "cdhrm5".into(),
        robot,
        routing,
        gravity: 9.81,
        force: 5.0,
        reach: 1.0,
    }];
    for (joints, gravity, force, reach) in
        [(5, 9.81, 5.0, 1.0), (25, 0.05, 0.1, 0.3), (100, 0.0005, 0.01, 0.1)]
    {
        let (robot, routing) = cdhrm5::chain(joints, PatternModel::Decoupled);
        v.push(Setup { name: format!("uniform{joints}"), robot, routing, gravity, force, reach });
    }
    v
}

/// `K_W` from sinew-robot's dense derivatives (`∂T_g/∂Q + ∂(J_xᵀF0)/∂Q`), independent of the
/// generators sinew-statics builds it from.
fn dense_k_w(robot: &Robot, rdata: &mut RobotData, f0: &Vector6<f64>) -> Mat<f64> {
    let n = robot.dof();
    let mut k_w = Mat::zeros(n, n);
    robot.gravity_torque_derivative(rdata, k_w.as_mut()).unwrap();
    let mut load = Mat::zeros(n, n);
    robot.wrench_torque_derivative(rdata, &robot.tip_point(), f0, load.as_mut()).unwrap();
    k_w + load
}

/// The dense reference at the configuration last evaluated in `data`: `K_W` from
/// [`dense_k_w`] (independent of the generators), then `end_stiffness`.
fn reference(
    robot: &Robot,
    q: &[f64],
    f0: &Vector6<f64>,
    data: &ArmStiffnessData,
) -> (Mat<f64>, EndStiffnessData, Result<(), StiffnessError>) {
    let n = robot.dof();
    let mut rdata = RobotData::new(robot);
    robot.forward_kinematics(&mut rdata, q).unwrap();
    let k_w = dense_k_w(robot, &mut rdata, f0);
    let mut end = EndStiffnessData::new(n);
    let outcome = end_stiffness(data.k_q(), k_w.as_ref(), data.j_x(), &mut end);
    (k_w, end, outcome)
}

/// Compares one evaluation with the dense reference; returns the verdict's name.
fn compare(
    label: &str,
    robot: &Robot,
    q: &[f64],
    f0: &Vector6<f64>,
    data: &mut ArmStiffnessData,
    outcome: &Result<(), StiffnessError>,
) -> &'static str {
    compare_with_errors(label, robot, q, f0, data, outcome).0
}

/// As [`compare`], with the relative errors of `C_x` and `K_x` (zero when not compared).
fn compare_with_errors(
    label: &str,
    robot: &Robot,
    q: &[f64],
    f0: &Vector6<f64>,
    data: &mut ArmStiffnessData,
    outcome: &Result<(), StiffnessError>,
) -> (&'static str, f64, f64) {
    let (k_w, end, expected) = reference(robot, q, f0, data);
    let err = rel_diff(data.k_w(), k_w.as_ref());
    assert!(err <= 1e-12, "{label}: K_W from the generators off by {err:e}");
    match (outcome, &expected) {
        (Ok(()), Ok(())) => {
            assert_eq!(data.end_solver(), EndSolver::Structured, "{label}: fast path not taken");
            let c_err = rel_diff(data.compliance(), end.compliance());
            assert!(c_err <= RTOL, "{label}: C_x off by {c_err:e}");
            let k_err = rel_diff(data.stiffness(), end.stiffness());
            assert!(k_err <= RTOL, "{label}: K_x off by {k_err:e}");
            assert!(
                data.structured_backward_error() <= 1e-14,
                "{label}: backward error {:e}",
                data.structured_backward_error()
            );
            ("stable", c_err, k_err)
        }
        (
            Err(StiffnessError::Unstable { min_eigenvalue: got }),
            Err(StiffnessError::Unstable { min_eigenvalue: want }),
        ) => {
            assert_eq!(data.end_solver(), EndSolver::Dense, "{label}: unstable goes dense");
            let err = (got - want).abs() / want.abs();
            assert!(err <= RTOL, "{label}: smallest eigenvalue {got} vs {want}");
            ("unstable", 0.0, 0.0)
        }
        (
            Err(StiffnessError::RankDeficient { pivot_ratio: got }),
            Err(StiffnessError::RankDeficient { pivot_ratio: want }),
        ) => {
            assert_eq!(data.end_solver(), EndSolver::Structured, "{label}: fast path not taken");
            assert!(*got <= 1e-10 && *want <= 1e-10, "{label}: pivot ratios {got:e}, {want:e}");
            // The compliance is kept, and agrees (relative to its size).
            let err = rel_diff(data.compliance(), end.compliance());
            assert!(err <= RTOL, "{label}: C_x off by {err:e}");
            ("rank-deficient", err, 0.0)
        }
        (got, want) => panic!("{label}: structured {got:?}, dense reference {want:?}"),
    }
}

fn random_load(rng: &mut impl Rng, kind: Load, force: f64) -> Vector6<f64> {
    let mut f0 = Vector6::zeros();
    if kind != Load::Zero {
        for k in 0..3 {
            f0[k] = rng.random_range(-force..force);
        }
    }
    if kind == Load::ForceAndMoment {
        // A moment of the size of the force times 0.1 m.
        for k in 3..6 {
            f0[k] = rng.random_range(-0.1 * force..0.1 * force);
        }
    }
    f0
}

#[test]
fn the_structured_solve_matches_the_dense_reference() {
    for (index, setup) in setups().into_iter().enumerate() {
        let Setup { name, robot: base, routing, gravity, force, reach } = setup;
        let joints = base.dof() / 2;
        for gravity_on in [true, false] {
            let g = if gravity_on {
                Vector3::new(0.3, 1.0, -0.2).normalize() * gravity
            } else {
                Vector3::zeros()
            };
            let robot = base.with_gravity(g);
            let model = ArmStiffness::new(&robot, &routing).unwrap();
            let mut data = ArmStiffnessData::new(&model);
            for kind in [Load::Zero, Load::Force, Load::ForceAndMoment] {
                let mut rng = config::rng(71 + index as u64);
                let (mut checked, mut infeasible, mut stable) = (0, 0, 0);
                let (mut worst_c, mut worst_k): (f64, f64) = (0.0, 0.0);
                // Stable equilibria (the fast path's results) wanted, per gravity and load.
                let wanted = if joints >= 100 { 20 } else { 40 };
                let mut tries = 0;
                while stable < wanted {
                    tries += 1;
                    assert!(
                        tries < 100 * wanted,
                        "{name} gravity={gravity_on} {kind:?}: {stable} stable of {checked} \
                         ({infeasible} infeasible)"
                    );
                    let q: Vec<f64> = robot
                        .joints()
                        .iter()
                        .map(|j| reach * rng.random_range(j.lower..=j.upper))
                        .collect();
                    let levels: Vec<f64> =
                        (0..joints).map(|_| rng.random_range(0.0..=1.0)).collect();
                    let f0 = random_load(&mut rng, kind, force);
                    let outcome =
                        model.evaluate(&mut data, &q, &f0, TensionChoice::Levels(&levels));
                    if let Err(StiffnessError::Statics(_)) = outcome {
                        infeasible += 1;
                        continue;
                    }
                    let label = format!("{name} g={gravity_on} {kind:?} #{checked}");
                    let (verdict, c_err, k_err) =
                        compare_with_errors(&label, &robot, &q, &f0, &mut data, &outcome);
                    if verdict == "stable" {
                        stable += 1;
                    }
                    (worst_c, worst_k) = (worst_c.max(c_err), worst_k.max(k_err));
                    checked += 1;
                }
                println!(
                    "{name} gravity={gravity_on} {kind:?}: {checked} checked ({stable} stable), \
                     {infeasible} infeasible; worst relative error C_x {worst_c:.1e}, \
                     K_x {worst_k:.1e}"
                );
            }
        }
    }
}

#[test]
fn unstable_equilibria_report_the_reference_smallest_eigenvalue() {
    // A compressive tip force along the straight-ish arm buckles it: K_W (negative) beats the
    // cables' stiffness at low tension levels. Forces from small to large give both verdicts.
    let mut unstable = 0;
    let mut stable = 0;
    for (name, robot, routing) in [
        {
            let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Decoupled);
            ("cdhrm5", robot, routing)
        },
        {
            let (robot, routing) = cdhrm5::chain(5, PatternModel::Decoupled);
            ("uniform5", robot, routing)
        },
    ] {
        let robot = robot.with_gravity(Vector3::zeros());
        let model = ArmStiffness::new(&robot, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        let mut rng = config::rng(5);
        for step in 0..60 {
            let q: Vec<f64> = (0..robot.dof()).map(|_| rng.random_range(-0.05..0.05)).collect();
            let push = 2.0 * step as f64;
            for f0 in [
                Vector6::new(0.0, 0.0, push, 0.0, 0.0, 0.0),
                Vector6::new(0.0, 0.0, -push, 0.0, 0.0, 0.0),
                Vector6::new(0.0, 0.0, -push, 0.0, 0.0, 0.05 * push),
            ] {
                let outcome = model.evaluate(&mut data, &q, &f0, TensionChoice::Levels(&[0.0; 5]));
                if let Err(StiffnessError::Statics(_)) = outcome {
                    continue;
                }
                match compare(&format!("{name} push {push}"), &robot, &q, &f0, &mut data, &outcome)
                {
                    "unstable" => unstable += 1,
                    "stable" => stable += 1,
                    _ => {}
                }
            }
        }
    }
    println!("{unstable} unstable, {stable} stable");
    assert!(unstable >= 20 && stable >= 20, "{unstable} unstable, {stable} stable");
}

#[test]
fn a_straight_arm_is_rank_deficient_on_both_paths() {
    // Universal joints about x and y cannot turn a straight arm about its own axis: J_x has
    // rank 5 at Q = 0, C_x is singular, K_x does not exist.
    for (name, robot, routing) in [
        {
            let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Decoupled);
            ("cdhrm5", robot.with_gravity(Vector3::zeros()), routing)
        },
        {
            let (robot, routing) = cdhrm5::chain(25, PatternModel::Decoupled);
            ("uniform25", robot.with_gravity(Vector3::zeros()), routing)
        },
    ] {
        let model = ArmStiffness::new(&robot, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        let q = vec![0.0; robot.dof()];
        let levels = vec![0.3; robot.dof() / 2];
        for f0 in [Vector6::zeros(), Vector6::new(0.0, 0.0, -1.0, 0.0, 0.0, 0.0)] {
            let outcome = model.evaluate(&mut data, &q, &f0, TensionChoice::Levels(&levels));
            assert!(
                matches!(outcome, Err(StiffnessError::RankDeficient { .. })),
                "{name}: {outcome:?}"
            );
            assert_eq!(compare(name, &robot, &q, &f0, &mut data, &outcome), "rank-deficient");
            // No rotation about z: the last row and column of C_x vanish (to rounding).
            let c = data.compliance();
            assert!(c[(5, 5)].abs() <= 1e-12 * max_abs(c), "{name}: C_x[5,5] = {:e}", c[(5, 5)]);
        }
    }
}

#[test]
fn the_routed_model_and_the_dense_reference_are_the_same_path() {
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Routed);
    let model = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&model);
    assert_eq!(data.end_solver(), EndSolver::NotYet);
    // A loaded pose (E4 rounded: the pose itself does not matter here, only the path).
    let q = cdhrm5::LOADED_POSE;
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    let outcome = model.evaluate(&mut data, &q, &f0, TensionChoice::Levels(&[0.5; 5]));
    // K_q is full (a cable crosses every proximal joint): the dense path. It is exactly
    // symmetric (each product of J_cᵀ K_l J_c computed once), so with a pure force the dense
    // path solves with the Cholesky factor of its verdict.
    assert_eq!(data.end_solver(), EndSolver::Dense);
    assert_eq!(data.k_q().to_owned(), data.k_q().transpose().to_owned());
    let (_, end, expected) = reference(&robot, &q, &f0, &data);
    assert_eq!(outcome.is_ok(), expected.is_ok());
    assert!(rel_diff(data.compliance(), end.compliance()) <= RTOL);
    // The decoupled routing of the same robot takes the structured path.
    let routing = cdhrm5::routing(&robot, PatternModel::Decoupled);
    let model = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&model);
    model.evaluate(&mut data, &q, &f0, TensionChoice::Levels(&[0.5; 5])).unwrap();
    assert_eq!(data.end_solver(), EndSolver::Structured);
}

#[test]
fn k_q_outside_the_joint_blocks_stays_exactly_zero() {
    // The fast path writes only the joints' 2 × 2 blocks of the three joint-stiffness matrices;
    // the rest must stay zero across evaluations, and K_q must equal the public
    // `joint_stiffness` sum.
    let (robot, routing) = cdhrm5::chain(25, PatternModel::Decoupled);
    let robot = robot.with_gravity(Vector3::new(0.0, 0.3, 0.0));
    let model = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&model);
    let n = robot.dof();
    let mut rng = config::rng(9);
    for _ in 0..10 {
        let q: Vec<f64> = (0..n).map(|_| rng.random_range(-0.1..0.1)).collect();
        let levels: Vec<f64> = (0..n / 2).map(|_| rng.random_range(0.0..1.0)).collect();
        model
            .evaluate_joints(&mut data, &q, &Vector6::zeros(), TensionChoice::Levels(&levels))
            .unwrap();
        let mut kc = Mat::<f64>::zeros(n, n);
        let mut ki = Mat::<f64>::zeros(n, n);
        sinew_stiffness::joint_stiffness(
            &routing,
            &data.cables,
            data.tensions(),
            kc.as_mut(),
            ki.as_mut(),
        )
        .unwrap();
        assert_eq!(data.k_controllable().to_owned(), kc);
        assert_eq!(data.k_inherent().to_owned(), ki);
        assert_eq!(data.k_q().to_owned(), &kc + &ki);
    }
}

#[test]
fn the_generators_rebuild_k_w_and_j_x() {
    // sinew-statics' K_W (its generators, filled densely) against sinew-robot's dense
    // derivatives `∂T_g/∂Q + ∂(J_xᵀF0)/∂Q` (an independent computation) at every draw, loads
    // with moments included (non-symmetric K_W); where the tensions are feasible, the
    // pipeline's K_W is that matrix and its J_x is `point_jacobian` (the same arithmetic:
    // equal to the last bit).
    let mut rng = config::rng(23);
    let mut pipeline_checked = 0;
    for setup in setups() {
        let robot = &setup.robot;
        let n = robot.dof();
        let model = ArmStiffness::new(robot, &setup.routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        let mut rdata = RobotData::new(robot);
        let mut joint_end = JointEndData::new(robot);
        let tip = robot.tip_point();
        for _ in 0..20 {
            let q: Vec<f64> = robot
                .joints()
                .iter()
                .map(|j| setup.reach * rng.random_range(j.lower..=j.upper))
                .collect();
            let f0 = Vector6::from_fn(|_, _| rng.random_range(-1.0..1.0));
            robot.forward_kinematics(&mut rdata, &q).unwrap();
            let reference = dense_k_w(robot, &mut rdata, &f0);
            let mut filled = Mat::zeros(n, n);
            equilibrium_torque_derivative(robot, &mut rdata, &mut joint_end, &f0, filled.as_mut())
                .unwrap();
            let err = rel_diff(filled.as_ref(), reference.as_ref());
            assert!(err <= 1e-13, "{}: K_W from the generators off by {err:e}", setup.name);
            let levels = vec![0.5; n / 2];
            if model.evaluate_joints(&mut data, &q, &f0, TensionChoice::Levels(&levels)).is_ok() {
                pipeline_checked += 1;
                let mut j_x = Mat::zeros(6, n);
                robot.point_jacobian(&rdata, &tip, j_x.as_mut()).unwrap();
                assert_eq!(data.j_x().to_owned(), j_x, "{}: J_x", setup.name);
                assert_eq!(data.k_w(), filled.as_ref(), "{}: the pipeline's K_W", setup.name);
            }
        }
    }
    assert!(pipeline_checked >= 20, "only {pipeline_checked} feasible draws");
}

#[test]
fn a_workspace_made_for_another_arm_is_a_typed_mismatch() {
    let robot = cdhrm5::robot();
    let load = |model| cdhrm5::routing(&robot, model);
    let decoupled = ArmStiffness::new(&robot, &load(PatternModel::Decoupled)).unwrap();
    let routed = ArmStiffness::new(&robot, &load(PatternModel::Routed)).unwrap();
    let (chain_robot, chain_routing) = cdhrm5::chain(10, PatternModel::Decoupled);
    let longer = ArmStiffness::new(&chain_robot, &chain_routing).unwrap();
    let mut data = ArmStiffnessData::new(&decoupled);
    let (q, f0, levels) = ([0.1; 10], Vector6::zeros(), [0.5; 5]);
    decoupled.evaluate_joints(&mut data, &q, &f0, TensionChoice::Levels(&levels)).unwrap();
    assert!(decoupled.check(&data).is_ok());
    for arm in [&routed, &longer] {
        assert!(matches!(arm.check(&data), Err(StiffnessError::WorkspaceMismatch { .. })));
        let err = arm.evaluate(&mut data, &q, &f0, TensionChoice::Levels(&levels)).unwrap_err();
        assert!(matches!(err, StiffnessError::WorkspaceMismatch { .. }), "{err:?}");
    }
    // A routing built for another robot is refused when the model is made.
    let err = ArmStiffness::new(&chain_robot, &load(PatternModel::Decoupled)).unwrap_err();
    assert!(matches!(err, StiffnessError::Routing(_)), "{err:?}");
}
