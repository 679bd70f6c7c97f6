//! A fixed workload for instruction-count profiles of the pipeline `Q → K_x`
//! (docs/performance.md): `cargo build --release -p sinew-stiffness --example routed_profile`,
//! then `valgrind --tool=callgrind target/release/examples/routed_profile JOINTS EVALS [MODEL]`
//! with `MODEL` `routed` (default) or `decoupled`. The chain is the benches' (weightless,
//! unloaded, the same bent configuration); one warm-up evaluation, then `EVALS` more, so the
//! per-evaluation count is `(total(EVALS) − total(0)) / EVALS`.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;

use nalgebra::{Vector3, Vector6};
use sinew_routing::PatternModel;
use sinew_statics::TensionChoice;
use sinew_stiffness::{ArmStiffness, ArmStiffnessData};
use sinew_testkit::cdhrm5;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let joints: usize = args.get(1).map_or(25, |s| s.parse().expect("JOINTS"));
    let evals: usize = args.get(2).map_or(10, |s| s.parse().expect("EVALS"));
    let model_kind = match args.get(3).map(String::as_str) {
        None | Some("routed") => PatternModel::Routed,
        Some("decoupled") => PatternModel::Decoupled,
        Some(other) => panic!("unknown model {other}"),
    };
    let (robot, routing) = cdhrm5::chain(joints, model_kind);
    let robot = robot.with_gravity(Vector3::zeros());
    let model = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&model);
    let q: Vec<f64> = (0..2 * joints).map(|i| 0.05 * ((i as f64) * 0.7).sin()).collect();
    let levels = vec![0.1; joints];
    let f0 = Vector6::zeros();
    model.evaluate(&mut data, &q, &f0, TensionChoice::Levels(&levels)).unwrap();
    for _ in 0..evals {
        model.evaluate(&mut data, black_box(&q), &f0, TensionChoice::Levels(&levels)).unwrap();
    }
    println!("{:?} {} DOF: K_x[0,0] = {:e}", model_kind, 2 * joints, data.stiffness()[(0, 0)]);
}
