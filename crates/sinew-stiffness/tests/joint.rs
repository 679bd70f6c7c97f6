//! Joint stiffness against finite differences of the cable torques with elastic cables
//! (spec §3), its structure, symmetry, and the tension slope; decoupled and routed.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use nalgebra::{Vector3, Vector6};
use rand::Rng;
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, PatternModel, Routing, RoutingData, compute_cable_geometry};
use sinew_statics::TensionChoice;
use sinew_stiffness::{ArmStiffness, ArmStiffnessData, joint_stiffness};
use sinew_testkit::newton::elastic_cable_torque;
use sinew_testkit::numeric::{H, central_difference, max_abs};
use sinew_testkit::random_chain::RandomChain;
use sinew_testkit::{cdhrm5, config};

#[test]
fn k_is_minus_the_derivative_of_the_cable_torque() {
    // Bounds per case (cdhrm5 and uniform10, decoupled then routed), a few times the measured
    // worst: 4.72e-9, 1.29e-8, 1.93e-9, 4.06e-9 (h = 1e-6; was 1e-6 for all).
    let tols = [2e-8, 5e-8, 8e-9, 2e-8];
    for ((name, robot, routing), tol) in cdhrm5::cases(10).into_iter().zip(tols) {
        let robot = robot.with_gravity(Vector3::zeros());
        let model = ArmStiffness::new(&robot, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        let n = robot.dof();
        let joints = n / 2;
        let mut rng = config::rng(61);
        let (mut worst, mut worst_asym) = (0.0_f64, 0.0_f64);
        let (mut checked, mut drawn) = (0, 0);
        while checked < 20 && drawn < 2000 {
            drawn += 1;
            let q: Vec<f64> = config::random_q(&robot, &mut rng);
            let levels: Vec<f64> = (0..joints).map(|_| rng.random_range(0.0..0.3)).collect();
            if model
                .evaluate_joints(&mut data, &q, &Vector6::zeros(), TensionChoice::Levels(&levels))
                .is_err()
            {
                continue;
            }
            checked += 1;
            let f0 = data.tensions().to_vec();
            let l0 = data.cables.lengths().unwrap().to_vec();
            // K is restoring: minus the derivative of the cable torque.
            let numeric =
                -central_difference(&q, H, |q| elastic_cable_torque(&robot, &routing, q, &f0, &l0));
            let k = data.k_q();
            let err = max_abs((k.to_owned() - &numeric).as_ref()) / max_abs(k).max(1.0);
            worst = worst.max(err);
            // Symmetric, both parts.
            let asym = max_abs((k.to_owned() - k.transpose()).as_ref()) / max_abs(k);
            worst_asym = worst_asym.max(asym);
            // Old bound 1e-9; measured worst exactly 0 (both parts are built symmetric).
            assert!(asym <= 1e-14, "{name}: K not symmetric ({asym:e})");
        }
        println!(
            "{name}: K vs −∂τ/∂Q worst relative error {worst:.2e}, worst asymmetry {worst_asym:.2e} ({checked} of {drawn})"
        );
        assert_eq!(checked, 20, "{name}: too few feasible configurations");
        assert!(worst <= tol, "{name}: K error {worst:e}");
    }
}

/// `K = Σ_c f_c H_c + J_cᵀ K_l J_c` at the tensions `f` (the library's free function).
fn k_at_tensions(robot: &Robot, routing: &Routing, q: &[f64], f: &[f64]) -> Mat<f64> {
    let n = robot.dof();
    let mut rdata = RobotData::new(robot);
    let mut g = RoutingData::new(routing);
    compute_cable_geometry(routing, robot, &mut rdata, &mut g, q, Order::Hessians).unwrap();
    let (mut controllable, mut inherent) = (Mat::zeros(n, n), Mat::zeros(n, n));
    joint_stiffness(routing, &g, f, controllable.as_mut(), inherent.as_mut()).unwrap();
    controllable + inherent
}

#[test]
fn k_at_any_tensions_is_minus_the_derivative_of_the_cable_torque_on_random_geometry() {
    // A random-geometry chain (sinew_testkit::random_chain) with its pattern routings and its
    // explicit routing (segments skipping discs, holes on the cross links and off the disc
    // plane): its cables need not balance any load, so `K` is checked at random tensions in
    // the limits rather than at a feasible level.
    let chain = RandomChain::new(5, 1);
    let robot = chain.robot();
    let mut cases = Vec::new();
    for model in cdhrm5::MODELS {
        cases.push((format!("{model:?}"), chain.routing(&robot, &chain.pattern_spec(model))));
    }
    cases.push(("explicit".to_owned(), chain.routing(&robot, &chain.explicit_spec(1))));
    // Measured worst: decoupled 3.55e-9, routed 7.93e-10, explicit 1.07e-9 (h = 1e-6).
    for ((name, routing), tol) in cases.into_iter().zip([1.5e-8, 3e-9, 4e-9]) {
        let mut rng = config::rng(62);
        let mut worst: f64 = 0.0;
        for _ in 0..20 {
            let q = config::random_q(&robot, &mut rng);
            let f0: Vec<f64> =
                (0..routing.cable_count()).map(|_| rng.random_range(20.0..600.0)).collect();
            let l0 = {
                let mut rdata = RobotData::new(&robot);
                let mut g = RoutingData::new(&routing);
                compute_cable_geometry(&routing, &robot, &mut rdata, &mut g, &q, Order::Lengths)
                    .unwrap();
                g.lengths().unwrap().to_vec()
            };
            let k = k_at_tensions(&robot, &routing, &q, &f0);
            let numeric =
                -central_difference(&q, H, |q| elastic_cable_torque(&robot, &routing, q, &f0, &l0));
            worst =
                worst.max(max_abs((k.clone() - &numeric).as_ref()) / max_abs(k.as_ref()).max(1.0));
        }
        println!("{} {name}: K vs −∂τ/∂Q worst relative error {worst:.2e}", chain.name);
        assert!(worst <= tol, "{} {name}: K error {worst:e}", chain.name);
    }
}

#[test]
fn decoupled_k_q_is_block_diagonal_and_routed_is_not() {
    for (name, robot, routing) in cdhrm5::cases(10) {
        let robot = robot.with_gravity(Vector3::zeros());
        let model = ArmStiffness::new(&robot, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        let n = robot.dof();
        let q: Vec<f64> = (0..n).map(|i| 0.1 * ((i as f64) * 1.7).sin()).collect();
        model
            .evaluate_joints(
                &mut data,
                &q,
                &Vector6::zeros(),
                TensionChoice::Levels(&vec![0.0; n / 2]),
            )
            .unwrap();
        let k = data.k_q();
        let mut off_block: f64 = 0.0;
        for j in 0..n {
            for i in 0..n {
                if i / 2 != j / 2 {
                    off_block = off_block.max(k[(i, j)].abs());
                }
            }
        }
        if name.contains("routed") || name.contains("Routed") {
            assert!(off_block > 1e-3, "{name}: routed K_q should couple joints");
        } else {
            assert_eq!(off_block, 0.0, "{name}: decoupled K_q must be block diagonal");
        }
        // K_{i,x}, K_{i,y} are the diagonal of joint i's block.
        let block = data.joint_stiffness(1).unwrap();
        assert_eq!(block[(0, 0)], k[(2, 2)]);
        assert_eq!(block[(1, 1)], k[(3, 3)]);
    }
}

#[test]
fn the_stiffness_slope_predicts_a_change_of_tension_level() {
    // Decoupled: moving joint i's level moves only its λ; K_q is affine in it.
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Decoupled);
    let model = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&model);
    let q = [0.3, -0.2, 0.1, 0.25, -0.4, 0.1, 0.2, -0.3, 0.05, 0.15];
    let f0 = Vector6::new(0.0, 1.0, 0.0, 0.0, 0.0, 0.0);
    for joint in 0..5 {
        let mut levels = [0.2; 5];
        model.evaluate_joints(&mut data, &q, &f0, TensionChoice::Levels(&levels)).unwrap();
        let k_before = data.k_q().to_owned();
        let lambda_before = data.intervals()[joint].lambda_at_level(0.2);
        let mut slope = Mat::zeros(10, 10);
        model.stiffness_slope(&mut data, joint, slope.as_mut()).unwrap();
        levels[joint] = 0.9;
        model.evaluate_joints(&mut data, &q, &f0, TensionChoice::Levels(&levels)).unwrap();
        let delta = data.intervals()[joint].lambda_at_level(0.9) - lambda_before;
        let predicted = &k_before + &slope * faer::Scale(delta);
        let err = max_abs((data.k_q().to_owned() - &predicted).as_ref()) / max_abs(data.k_q());
        println!("decoupled joint {joint}: slope prediction error {err:.2e}");
        // Old bound 1e-12; measured worst 2.5e-16.
        assert!(err <= 1e-15, "joint {joint}: slope prediction off by {err:e}");
        assert!(slope[(2 * joint, 2 * joint)].abs() > 0.0);
    }
}

/// Moves joint `joint`'s level to `level` and re-levels the joints proximal to it so that
/// their `λ` stay where they were (routed: a proximal interval moves with the distal tensions,
/// so holding a level is not holding `λ`). Solving runs from the tip, so joint `k`'s interval
/// is final once every joint distal to it is set. Returns the levels used.
fn move_level_holding_proximal_lambdas(
    model: &ArmStiffness,
    data: &mut ArmStiffnessData,
    q: &[f64],
    f0: &Vector6<f64>,
    levels: &[f64],
    joint: usize,
    level: f64,
) -> Vec<f64> {
    model.evaluate_joints(data, q, f0, TensionChoice::Levels(levels)).unwrap();
    let held: Vec<f64> =
        (0..joint).map(|k| data.intervals()[k].lambda_at_level(levels[k])).collect();
    let mut levels = levels.to_vec();
    levels[joint] = level;
    for k in (0..joint).rev() {
        model.evaluate_joints(data, q, f0, TensionChoice::Levels(&levels)).unwrap();
        let interval = &data.intervals()[k];
        levels[k] = (held[k] - interval.lambda_min) / interval.width();
        assert!((0.0..=1.0).contains(&levels[k]), "joint {k}: held λ leaves the interval");
    }
    model.evaluate_joints(data, q, f0, TensionChoice::Levels(&levels)).unwrap();
    levels
}

/// `λ` of joint `k` read back from its tensions (`n · f`, the particular part being ⟂ `n`).
fn lambda_of(data: &ArmStiffnessData, k: usize) -> f64 {
    let f = Vector3::from_column_slice(&data.tensions()[3 * k..3 * k + 3]);
    data.intervals()[k].null.dot(&f)
}

#[test]
fn routed_tension_sensitivity_keeps_every_joint_balanced_and_proximal_lambdas_held() {
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Routed);
    let model = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&model);
    let q = [0.3, -0.2, 0.1, 0.25, -0.4, 0.1, 0.2, -0.3, 0.05, 0.15];
    let levels = [0.1; 5];
    let (mut worst_torque, mut worst_held, mut worst_finite) = (0.0_f64, 0.0_f64, 0.0_f64);
    let mut worst_moved = 0.0_f64;
    for joint in 0..5 {
        model
            .evaluate_joints(&mut data, &q, &Vector6::zeros(), TensionChoice::Levels(&levels))
            .unwrap();
        let mut delta = vec![0.0; 15];
        model
            .statics()
            .tension_sensitivity(&data.cables, &data.statics, joint, &mut delta)
            .unwrap();
        let j = data.cables.jacobian().unwrap();
        for d in 0..10 {
            let torque: f64 = (0..15).map(|c| j[(c, d)] * delta[c]).sum();
            worst_torque = worst_torque.max(torque.abs());
            // Old bound 1e-9; measured worst 3.5e-18 (per unit λ, |J_c| ~ 0.02 m).
            assert!(torque.abs() <= 1e-16, "joint {joint}: δf unbalances DOF {d} by {torque:e}");
        }
        // Distal joints' tensions do not move.
        assert!(delta[3 * (joint + 1)..].iter().all(|&x| x == 0.0));
        // Joint `joint` moves along its own null direction, a unit vector.
        let own = Vector3::from_column_slice(&delta[3 * joint..3 * joint + 3]);
        assert_eq!(own, data.intervals()[joint].null);
        // Proximal joints hold their λ: their change is orthogonal to their null direction
        // (the minimum-norm balance of the distal change).
        for k in 0..joint {
            let dk = Vector3::from_column_slice(&delta[3 * k..3 * k + 3]);
            let along = data.intervals()[k].null.dot(&dk);
            worst_held = worst_held.max(along.abs());
            // Measured worst 5.2e-18 (per unit λ).
            assert!(along.abs() <= 3e-17, "joint {joint}: proximal λ_{k} moves by {along:e}");
        }
        if joint > 0 {
            assert!(
                delta[..3 * joint].iter().any(|&x| x.abs() > 1e-6),
                "routed: proximal tensions follow"
            );
        }
        // Independently: a finite change of λ_joint, the proximal λ held by re-levelling, a
        // full re-solve; the tensions move by δλ · ∂f/∂λ (the map is affine: exact).
        let before = data.tensions().to_vec();
        let lambda_before = lambda_of(&data, joint);
        let lambdas_before: Vec<f64> = (0..joint).map(|k| lambda_of(&data, k)).collect();
        move_level_holding_proximal_lambdas(
            &model,
            &mut data,
            &q,
            &Vector6::zeros(),
            &levels,
            joint,
            0.3,
        );
        let d_lambda = lambda_of(&data, joint) - lambda_before;
        assert!(d_lambda > 10.0, "joint {joint}: λ moved by {d_lambda}");
        for k in 0..joint {
            let moved = (lambda_of(&data, k) - lambdas_before[k]).abs();
            worst_moved = worst_moved.max(moved / lambdas_before[k].abs());
            // Measured worst 1.1e-16 (relative).
            assert!(moved <= 1e-15 * lambdas_before[k].abs(), "λ_{k} not held: {moved:e}");
        }
        for c in 0..15 {
            let err = (data.tensions()[c] - before[c] - d_lambda * delta[c]).abs();
            worst_finite = worst_finite.max(err);
            // Measured worst 9.9e-14 N (tensions up to ~300 N).
            assert!(err <= 5e-13, "joint {joint}, cable {c}: δf off by {err:e} N");
        }
    }
    println!(
        "worst |J_cᵀ δf| = {worst_torque:.2e}, worst |n_k · δf_k| = {worst_held:.2e}, worst \
         finite-change error {worst_finite:.2e} N, held λ moved by {worst_moved:.2e} (relative)"
    );
}

#[test]
fn routed_stiffness_slope_predicts_a_change_of_tension_level() {
    // Routed: the slope goes through the proximal joints' balancing tensions; checked against
    // a full re-evaluation after a finite change of λ_i with every other λ held.
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Routed);
    let model = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&model);
    let q = [0.3, -0.2, 0.1, 0.25, -0.4, 0.1, 0.2, -0.3, 0.05, 0.15];
    let f0 = Vector6::new(0.0, 0.5, 0.0, 0.0, 0.0, 0.0);
    let levels = [0.1; 5];
    let mut worst: f64 = 0.0;
    for joint in 0..5 {
        model.evaluate_joints(&mut data, &q, &f0, TensionChoice::Levels(&levels)).unwrap();
        let k_before = data.k_q().to_owned();
        let lambda_before = lambda_of(&data, joint);
        let mut slope = Mat::zeros(10, 10);
        model.stiffness_slope(&mut data, joint, slope.as_mut()).unwrap();
        move_level_holding_proximal_lambdas(&model, &mut data, &q, &f0, &levels, joint, 0.3);
        let delta = lambda_of(&data, joint) - lambda_before;
        let predicted = &k_before + &slope * faer::Scale(delta);
        let err = max_abs((data.k_q().to_owned() - &predicted).as_ref()) / max_abs(data.k_q());
        worst = worst.max(err);
        // Measured worst 1.4e-16.
        assert!(err <= 1e-15, "joint {joint}: routed slope prediction off by {err:e}");
        if joint > 0 {
            // The slope reaches the proximal blocks (the decoupled one would not).
            let proximal = (0..2 * joint)
                .flat_map(|i| (0..2 * joint).map(move |j| (i, j)))
                .map(|(i, j)| slope[(i, j)].abs())
                .fold(0.0, f64::max);
            assert!(proximal > 1e-6, "joint {joint}: routed slope has no proximal part");
        }
    }
    println!("routed slope: worst relative prediction error {worst:.2e}");
}
