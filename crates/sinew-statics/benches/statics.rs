//! `cargo bench -p sinew-statics`: the closed-form tension interval of one joint (target
//! ≤ 200 ns on the 2-core CI machine), and the general path on cdhrm5 (15 cables, 10 DOF) at
//! the E4 pose and load: the equilibrium set (SVD of J_c) and each policy's distribution
//! (target ≤ 100 µs each, set included).
#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Matrix3x2, Vector2};
use sinew_statics::{TensionLimits, tension_interval};

fn bench_interval(c: &mut Criterion) {
    // E2's joint (q = [π/7, −π/9]) with holes at 25 mm, 120° apart: a realistic block.
    let rho = 0.025;
    let jacobian = Matrix3x2::from_fn(|k, col| {
        let theta = k as f64 * std::f64::consts::TAU / 3.0 + 0.3;
        if col == 0 { rho * theta.sin() } else { -rho * theta.cos() * 0.93 }
    });
    let tau = Vector2::new(-1.0, 0.5);
    let limits = TensionLimits { f_min: 20.0, f_max: 600.0 };
    tension_interval(0, &jacobian, &tau, limits).unwrap();
    c.bench_function("tension_interval (one joint)", |b| {
        b.iter(|| tension_interval(0, black_box(&jacobian), black_box(&tau), limits))
    });
}

fn bench_policies(c: &mut Criterion) {
    use nalgebra::Vector6;
    use sinew_robot::RobotData;
    use sinew_routing::{Order, PatternModel, RoutingData, compute_cable_geometry};
    use sinew_statics::{ArmStatics, EquilibriumSet, TensionChoice, TensionPolicy};
    use sinew_testkit::cdhrm5;

    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let statics = ArmStatics::new(&routing);
        let mut rdata = RobotData::new(&robot);
        let mut geometry = RoutingData::new(&routing);
        let mut data = statics.data(&robot);
        let q = cdhrm5::LOADED_POSE;
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        compute_cable_geometry(&routing, &robot, &mut rdata, &mut geometry, &q, Order::Jacobian)
            .unwrap();
        statics.solve(&robot, &mut rdata, &geometry, &mut data, &f0, &[0.0; 5]).unwrap();
        let name = match model {
            PatternModel::Decoupled => "decoupled",
            PatternModel::Routed => "routed",
        };
        c.bench_function(&format!("equilibrium set, cdhrm5 {name}"), |b| {
            b.iter(|| {
                EquilibriumSet::new(
                    black_box(&geometry).jacobian().unwrap(),
                    &data.t0,
                    statics.cable_limits(),
                    statics.joint_groups(),
                )
                .unwrap()
            })
        });
        for policy in TensionPolicy::ALL {
            c.bench_function(&format!("policy {}, cdhrm5 {name}", policy.name()), |b| {
                b.iter(|| {
                    statics
                        .solve_with(
                            &robot,
                            &mut rdata,
                            &geometry,
                            &mut data,
                            black_box(&f0),
                            TensionChoice::Policy(policy),
                        )
                        .unwrap()
                })
            });
        }
    }
}

criterion_group!(benches, bench_interval, bench_policies);
criterion_main!(benches);
