//! `cargo bench -p sinew-stiffness`: one joint's stiffness, and the whole pipeline `Q → K_x`
//! (kinematics, cable geometry with Hessians, T0, tensions, K_q, K_W, J_x, factorisations) for
//! cdhrm5 at E4 and generated chains of 25, 50 and 100 universal joints (50, 100, 200 DOF),
//! and the 200-DOF decoupled chain once more with gravity and a tip wrench (non-zero,
//! non-symmetric `K_W`). docs/performance.md has the table.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::Mat;
use nalgebra::{Vector3, Vector6};
use sinew_robot::{Robot, RobotData, UniformChain};
use sinew_routing::{
    Order, PatternModel, Routing, RoutingData, RoutingSpec, compute_cable_geometry,
};
use sinew_stiffness::{ArmStiffness, ArmStiffnessData, EndSolver, joint_stiffness};

fn chain(joints: usize, model: PatternModel) -> (Robot, Routing) {
    let chain = UniformChain::like_cdhrm5(joints);
    // Weightless and unloaded: long chains cannot carry their own weight on [20, 600] N cables;
    // the cost does not depend on the load.
    let robot = chain.build().unwrap().with_gravity(Vector3::zeros());
    let routing =
        Routing::new(&robot, &RoutingSpec::for_uniform_chain(&chain, model), "<bench>").unwrap();
    (robot, routing)
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
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/cdhrm5");
    let cdhrm5 = sinew_robot::load(dir).unwrap();
    let pi = std::f64::consts::PI;
    let e4 = [
        -pi / 7.0,
        -pi / 9.0,
        -pi / 9.0,
        -pi / 11.0,
        pi / 6.0,
        pi / 7.0,
        pi / 8.0,
        -pi / 15.0,
        -pi / 12.0,
        -pi / 10.0,
    ];
    for (label, file) in
        [("decoupled", sinew_routing::ROUTING_FILE), ("routed", sinew_routing::ROUTED_ROUTING_FILE)]
    {
        let routing = sinew_routing::load(format!("{dir}/{file}"), &cdhrm5).unwrap();
        let model = ArmStiffness::new(&cdhrm5, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&model);
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        model.evaluate(&mut data, &e4, &f0, &[0.5; 5]).unwrap();
        group.bench_with_input(BenchmarkId::new(format!("cdhrm5 E4 {label}"), 10), &e4, |b, q| {
            b.iter(|| model.evaluate(&mut data, black_box(q), &f0, &[0.5; 5]).unwrap())
        });
    }
    for joints in [25, 50, 100] {
        for model_kind in [PatternModel::Decoupled, PatternModel::Routed] {
            let (robot, routing) = chain(joints, model_kind);
            let model = ArmStiffness::new(&robot, &routing).unwrap();
            let mut data = ArmStiffnessData::new(&model);
            let q: Vec<f64> = (0..2 * joints).map(|i| 0.05 * ((i as f64) * 0.7).sin()).collect();
            let levels = vec![0.1; joints];
            let f0 = Vector6::zeros();
            model.evaluate(&mut data, &q, &f0, &levels).unwrap();
            let label = format!("uniform {model_kind:?}").to_lowercase();
            group.bench_with_input(BenchmarkId::new(label, 2 * joints), &q, |b, q| {
                b.iter(|| model.evaluate(&mut data, black_box(q), &f0, &levels).unwrap())
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
        model.evaluate(&mut data, &q, &f0, &levels).unwrap();
        assert_eq!(data.end_solver(), EndSolver::Structured);
        group.bench_with_input(BenchmarkId::new("uniform decoupled loaded", 200), &q, |b, q| {
            b.iter(|| model.evaluate(&mut data, black_box(q), &f0, &levels).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench_joint, bench_pipeline);
criterion_main!(benches);
