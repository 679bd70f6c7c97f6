//! A fixed workload for instruction counts of the stick load limit (#27, "the stick load limit
//! costs at most one extra solve per direction"; `scripts/stick-limit-instructions`):
//! `stick_limit_profile DOF CALLS WHAT [HISTORY]` with `DOF` 10 (routed cdhrm5 at E4 rounded,
//! with its load) or 50 (the routed 25-joint chain, weightless, unloaded), as in
//! `benches/friction.rs`; `WHAT` the number of directions (the first of the twelve base
//! directions, all twelve and the load's for 13) or `solve` (one LU solve of `K_stick + K_W`
//! with one right-hand side); `HISTORY` `equal` (default) or `pull`. Everything is set up,
//! one warm-up call made, then `CALLS` more, so a call's count is
//! `(total(CALLS) − total(0)) / CALLS`.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;

use faer::Mat;
use faer::linalg::solvers::Solve;
use nalgebra::{Vector3, Vector6};
use sinew_robot::RobotData;
use sinew_routing::{
    FrictionData, FrictionModel, Order, PatternModel, RoutingData, Slip, compute_cable_geometry,
    compute_capstan_weights, compute_friction_geometry,
};
use sinew_statics::TensionChoice;
use sinew_stiffness::{
    ArmStiffness, ArmStiffnessData, FrictionStiffnessData, History, base_directions,
    stick_load_limits, stick_stiffness,
};
use sinew_testkit::cdhrm5;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dof: usize = args.get(1).map_or(50, |s| s.parse().expect("DOF"));
    let calls: usize = args.get(2).map_or(10, |s| s.parse().expect("CALLS"));
    let what = args.get(3).map_or("13", String::as_str);
    let history = match args.get(4).map(String::as_str) {
        None | Some("equal") => History::Equal,
        Some("pull") => History::Pull,
        Some(other) => panic!("unknown history {other}"),
    };
    let ((robot, routing), q, levels, f0) = if dof == 10 {
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        let arm = cdhrm5::robot_and_routing(PatternModel::Routed);
        (arm, cdhrm5::LOADED_POSE.to_vec(), vec![0.5; 5], f0)
    } else {
        let (robot, routing) = cdhrm5::chain(dof / 2, PatternModel::Routed);
        let q = (0..dof).map(|i| 0.05 * ((i as f64) * 0.7).sin()).collect();
        ((robot.with_gravity(Vector3::zeros()), routing), q, vec![0.1; dof / 2], Vector6::zeros())
    };
    let pipeline = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&pipeline);
    pipeline.evaluate(&mut data, &q, &f0, TensionChoice::Levels(&levels)).unwrap();
    let t = data.tensions().to_vec();
    let model = FrictionModel::new(&routing).with_friction_coefficient(0.1).unwrap();
    let mut rdata = RobotData::new(&robot);
    let mut geometry = RoutingData::new(&routing);
    compute_cable_geometry(&routing, &robot, &mut rdata, &mut geometry, &q, Order::Hessians)
        .unwrap();
    let mut friction = FrictionData::new(&model);
    compute_friction_geometry(&model, &routing, &geometry, &mut friction).unwrap();
    compute_capstan_weights(&model, &mut friction, Slip::Pull).unwrap();
    let mut out = FrictionStiffnessData::new(&model);
    stick_stiffness(&model, &routing, &geometry, &friction, history, &t, &mut out).unwrap();
    let (k_stick, k_w, j_x) = (out.stiffness().unwrap(), data.k_w().to_owned(), data.j_x());
    let mut directions = base_directions().to_vec();
    directions.push(Vector6::new(0.3, 1.0, -0.2, 0.0, 0.0, 0.0));
    let mats = (k_stick, k_w.as_ref(), j_x);
    if what == "solve" {
        let lu = Mat::from_fn(dof, dof, |i, j| k_stick[(i, j)] + k_w[(i, j)]).partial_piv_lu();
        let rhs = Mat::from_fn(dof, 1, |i, _| j_x[(1, i)]);
        let mut sum = 0.0;
        for _ in 0..=calls {
            sum += lu.solve(black_box(&rhs))[(0, 0)];
        }
        println!("{dof} DOF: one solve, δQ_0 summed {sum:e}");
        return;
    }
    let count: usize = what.parse().expect("WHAT: a number of directions or `solve`");
    let dirs = &directions[..count.min(directions.len())];
    let mut least = f64::INFINITY;
    for _ in 0..=calls {
        let limits =
            stick_load_limits(&model, &routing, &friction, history, &t, mats, black_box(dirs))
                .unwrap();
        least = limits.iter().map(|l| l.magnitude).fold(least, f64::min);
    }
    println!("{dof} DOF, {history:?}, {} directions: least limit {least:e}", dirs.len());
}
