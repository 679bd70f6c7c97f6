//! Wall-clock time of each phase of the routed pipeline (docs/performance.md, issue #16):
//! `cargo run --release -p sinew-stiffness --example phase_times [JOINTS...]`. The benches'
//! chain (weightless, unloaded, the same bent configuration); each phase is timed on its own,
//! repeated, best of 7 runs: the geometry (forward kinematics, lengths, `J_c`, Hessians; also
//! by order), the statics alone (`T0` and the tensions, from the geometry), the joint level
//! (geometry, statics and `K_q`), faer's Cholesky of `K_q` alone, and the whole pipeline; then
//! the whole pipeline for the benches' 10-DOF case (cdhrm5 loaded) in both models.
//! `GEOMETRY_ONLY=lengths|jacobian|hessians [JOINTS=n]` instead loops over the geometry alone,
//! a target for `perf record`.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;
use std::time::Instant;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt;
use faer::{Mat, Par};
use nalgebra::{Vector3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, PatternModel, Routing, RoutingData, compute_cable_geometry};
use sinew_statics::TensionChoice;
use sinew_stiffness::{ArmStiffness, ArmStiffnessData};
use sinew_testkit::cdhrm5;

fn best(reps: usize, mut f: impl FnMut()) -> f64 {
    (0..7)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..reps {
                f();
            }
            t.elapsed().as_secs_f64() / reps as f64
        })
        .fold(f64::INFINITY, f64::min)
}

/// One evaluation of the cable geometry up to `order`.
fn geometry_at(
    robot: &Robot,
    routing: &Routing,
    rdata: &mut RobotData,
    geometry: &mut RoutingData,
    q: &[f64],
    order: Order,
) {
    compute_cable_geometry(routing, robot, rdata, geometry, black_box(q), order).unwrap();
}

fn main() {
    if let Ok(order) = std::env::var("GEOMETRY_ONLY") {
        // perf target: only the geometry at one order, for a while.
        let order = match order.as_str() {
            "lengths" => Order::Lengths,
            "jacobian" => Order::Jacobian,
            _ => Order::Hessians,
        };
        let joints: usize =
            std::env::var("JOINTS").ok().and_then(|j| j.parse().ok()).unwrap_or(100);
        let (robot, routing) = cdhrm5::chain(joints, PatternModel::Routed);
        let q: Vec<f64> = (0..2 * joints).map(|i| 0.05 * ((i as f64) * 0.7).sin()).collect();
        let mut rdata = RobotData::new(&robot);
        let mut geometry = RoutingData::new(&routing);
        for _ in 0..(4_000_000 / joints / joints) {
            geometry_at(&robot, &routing, &mut rdata, &mut geometry, &q, order);
        }
        return;
    }
    let args: Vec<usize> = std::env::args().skip(1).map(|s| s.parse().expect("JOINTS")).collect();
    let sizes = if args.is_empty() { vec![5, 25, 50, 100] } else { args };
    println!(
        "{:>5} {:>12} {:>12} {:>12} {:>12} {:>12}",
        "DOF", "geometry", "statics", "joint level", "faer chol", "pipeline"
    );
    for joints in sizes {
        let (robot, routing) = cdhrm5::chain(joints, PatternModel::Routed);
        let robot = robot.with_gravity(Vector3::zeros());
        let n = robot.dof();
        let q: Vec<f64> = (0..n).map(|i| 0.05 * ((i as f64) * 0.7).sin()).collect();
        let reps = (2_000_000 / (n * n)).max(20);
        let mut rdata = RobotData::new(&robot);
        let mut geometry = RoutingData::new(&routing);
        let [lengths, jacobian, geo] =
            [Order::Lengths, Order::Jacobian, Order::Hessians].map(|order| {
                best(reps, || geometry_at(&robot, &routing, &mut rdata, &mut geometry, &q, order))
            });
        let fk = best(reps, || {
            robot.forward_kinematics(&mut rdata, black_box(&q)).unwrap();
        });
        println!(
            "      geometry by order: kinematics {:.2} µs, lengths {:.2} µs, + J_c {:.2} µs, + Hessians {:.2} µs",
            fk * 1e6,
            lengths * 1e6,
            jacobian * 1e6,
            geo * 1e6
        );
        let model = ArmStiffness::new(&robot, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        let levels = vec![0.1; joints];
        model.evaluate(&mut data, &q, &Vector6::zeros(), TensionChoice::Levels(&levels)).unwrap();
        let joint = best(reps, || {
            model
                .evaluate_joints(
                    &mut data,
                    black_box(&q),
                    &Vector6::zeros(),
                    TensionChoice::Levels(&levels),
                )
                .unwrap();
        });
        let statics = best(reps, || {
            let ArmStiffnessData { robot: r, cables, statics, .. } = &mut data;
            model
                .statics()
                .solve_with(
                    model.robot(),
                    r,
                    cables,
                    statics,
                    &Vector6::zeros(),
                    TensionChoice::Levels(&levels),
                )
                .unwrap();
        });
        let k_q = data.k_q().to_owned();
        let mut work: Mat<f64> = k_q.clone();
        let mut buffer = MemBuffer::new(llt::factor::cholesky_in_place_scratch::<f64>(
            n,
            Par::Seq,
            Default::default(),
        ));
        let chol = best(reps, || {
            work.copy_from(&k_q);
            let stack = MemStack::new(&mut buffer);
            let r = llt::factor::cholesky_in_place(
                work.as_mut(),
                Default::default(),
                Par::Seq,
                stack,
                Default::default(),
            );
            black_box(r.is_ok());
        });
        let pipe = best(reps, || {
            model
                .evaluate(
                    &mut data,
                    black_box(&q),
                    &Vector6::zeros(),
                    TensionChoice::Levels(&levels),
                )
                .unwrap();
        });
        let us = |t: f64| format!("{:.2} µs", t * 1e6);
        println!(
            "{:>5} {:>12} {:>12} {:>12} {:>12} {:>12}",
            n,
            us(geo),
            us(statics),
            us(joint),
            us(chol),
            us(pipe)
        );
    }
    // The benches' 10-DOF case: cdhrm5 itself at the loaded pose (gravity, a tip force), both
    // models, best of 7 like the rows above.
    let robot = cdhrm5::robot();
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    let pose = cdhrm5::LOADED_POSE;
    for kind in cdhrm5::MODELS {
        let routing = cdhrm5::routing(&robot, kind);
        let model = ArmStiffness::new(&robot, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        model.evaluate(&mut data, &pose, &f0, TensionChoice::Levels(&[0.5; 5])).unwrap();
        let pipe = best(20_000, || {
            model
                .evaluate(&mut data, black_box(&pose), &f0, TensionChoice::Levels(&[0.5; 5]))
                .unwrap();
        });
        println!("cdhrm5 loaded, {kind:?}: pipeline {:.2} µs", pipe * 1e6);
    }
}
