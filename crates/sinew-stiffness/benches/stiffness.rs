//! `cargo bench -p sinew-stiffness`: one joint's stiffness, and the whole pipeline `Q → K_x`
//! (kinematics, cable geometry with Hessians, T0, tensions, K_q, K_W, J_x, factorisations) for
//! cdhrm5 at a loaded pose (E4 rounded) and generated chains of 25, 50 and 100 universal
//! joints (50, 100, 200 DOF),
//! and the 200-DOF decoupled chain once more with gravity and a tip wrench (non-zero,
//! non-symmetric `K_W`). docs/performance.md has the table.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::Mat;
use nalgebra::{Vector3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, PatternModel, Routing, RoutingData, compute_cable_geometry};
use sinew_statics::TensionChoice;
use sinew_stiffness::{ArmStiffness, ArmStiffnessData, EndSolver, joint_stiffness};
use sinew_testkit::cdhrm5;

fn chain(joints: usize, model: PatternModel) -> (Robot, Routing) {
    let (robot, routing) = cdhrm5::chain(joints, model);
    // Weightless and unloaded: long chains cannot carry their own weight on [20, 600] N cables;
    // the cost does not depend on the load.
    (robot.with_gravity(Vector3::zeros()), routing)
}

fn bench_joint(c: &mut Criterion) {
    // One universal joint: its kinematics, its three cables' lengths, J_c and Hessians, then
    // K = Σ f H + Jᵀ K_l J (2 × 2, both parts).
    let (robot, routing) = chain(1, PatternModel::Decoupled);
    let mut rdata = RobotData::new(&robot);
    let mut g = RoutingData::new(&routing);
    let mut kc = Mat::<f64>::zeros(2, 2);
    let mut ki = Mat::<f64>::zeros(2, 2);
    let q = [std::f64::consts::PI / 7.0, -std::f64::consts::PI / 9.0];
    let f = [131.0, 20.0, 78.3];
    c.bench_function("joint stiffness (one joint: geometry + K)", |b| {
        b.iter(|| {
            compute_cable_geometry(
                &routing,
                &robot,
                &mut rdata,
                &mut g,
                black_box(&q),
                Order::Hessians,
            )
            .unwrap();
            joint_stiffness(&routing, &g, black_box(&f), kc.as_mut(), ki.as_mut()).unwrap();
        })
    });
}

fn bench_pipeline(c: &mut Criterion) {
    let mut group = c.benchmark_group("pipeline Q -> K_x");
    group.sample_size(30);
    let cdhrm5 = cdhrm5::robot();
    // E4 rounded to 0.01 rad: the pose E4 itself is the facade's (`sinew::paper::E4_Q`), out of
    // this crate's reach; the path and the cost are the same.
    let pose = cdhrm5::LOADED_POSE;
    for model_kind in cdhrm5::MODELS {
        let routing = cdhrm5::routing(&cdhrm5, model_kind);
        let label = format!("{model_kind:?}").to_lowercase();
        let model = ArmStiffness::new(&cdhrm5, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        model.evaluate(&mut data, &pose, &f0, TensionChoice::Levels(&[0.5; 5])).unwrap();
        group.bench_with_input(
            BenchmarkId::new(format!("cdhrm5 loaded {label}"), 10),
            &pose,
            |b, q| {
                b.iter(|| {
                    model
                        .evaluate(&mut data, black_box(q), &f0, TensionChoice::Levels(&[0.5; 5]))
                        .unwrap()
                })
            },
        );
    }
    for joints in [25, 50, 100] {
        for model_kind in [PatternModel::Decoupled, PatternModel::Routed] {
            let (robot, routing) = chain(joints, model_kind);
            let model = ArmStiffness::new(&robot, &routing).unwrap();
            let mut data = ArmStiffnessData::new(&model);
            let q: Vec<f64> = (0..2 * joints).map(|i| 0.05 * ((i as f64) * 0.7).sin()).collect();
            let levels = vec![0.1; joints];
            let f0 = Vector6::zeros();
            model.evaluate(&mut data, &q, &f0, TensionChoice::Levels(&levels)).unwrap();
            let label = format!("uniform {model_kind:?}").to_lowercase();
            group.bench_with_input(BenchmarkId::new(label, 2 * joints), &q, |b, q| {
                b.iter(|| {
                    model
                        .evaluate(&mut data, black_box(q), &f0, TensionChoice::Levels(&levels))
                        .unwrap()
                })
            });
        }
    }
    // The 200-DOF decoupled chain with a non-zero, non-symmetric K_W: slight gravity and a tip
    // force with a moment (the general structured sweep, after its verdict sweep).
    {
        let (robot, routing) = chain(100, PatternModel::Decoupled);
        let robot = robot.with_gravity(Vector3::new(0.0, 5e-4, 0.0));
        let model = ArmStiffness::new(&robot, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        let q: Vec<f64> = (0..200).map(|i| 0.05 * ((i as f64) * 0.7).sin()).collect();
        let levels = vec![0.1; 100];
        let f0 = Vector6::new(0.0, 0.005, 0.0, 0.0, 0.0, 0.0005);
        model.evaluate(&mut data, &q, &f0, TensionChoice::Levels(&levels)).unwrap();
        assert_eq!(data.end_solver(), EndSolver::Structured);
        group.bench_with_input(BenchmarkId::new("uniform decoupled loaded", 200), &q, |b, q| {
            b.iter(|| {
                model
                    .evaluate(&mut data, black_box(q), &f0, TensionChoice::Levels(&levels))
                    .unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_joint, bench_pipeline);
criterion_main!(benches);
