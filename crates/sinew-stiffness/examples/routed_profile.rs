//! A fixed workload for instruction-count profiles of the pipeline `Q → K_x`
//! (docs/performance.md): `cargo build --release -p sinew-stiffness --example routed_profile`,
//! then `valgrind --tool=callgrind target/release/examples/routed_profile JOINTS EVALS [MODEL]`
//! with `MODEL` `routed` (default) or `decoupled`. The chain is the benches' (weightless,
//! unloaded, the same bent configuration); one warm-up evaluation, then `EVALS` more, so the
//! per-evaluation count is `(total(EVALS) − total(0)) / EVALS`.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;

use nalgebra::{Vector3, Vector6};
use sinew_routing::{FrictionModel, PatternModel, Slip};
use sinew_statics::TensionChoice;
use sinew_stiffness::{ArmStiffness, ArmStiffnessData, FrictionArmData, FrictionRegime, History};
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
    let regime = match args.get(4).map(String::as_str) {
        None | Some("none") => None,
        Some("slip") => Some(FrictionRegime::Slip(Slip::Pull)),
        Some("stick") => Some(FrictionRegime::Stick(History::Pull)),
        Some(other) => panic!("unknown friction {other}"),
    };
    let (robot, routing) = cdhrm5::chain(joints, model_kind);
    let robot = robot.with_gravity(Vector3::zeros());
    let model = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&model);
    let q: Vec<f64> = (0..2 * joints).map(|i| 0.05 * ((i as f64) * 0.7).sin()).collect();
    let levels = vec![0.1; joints];
    let f0 = Vector6::zeros();
    let choice = TensionChoice::Levels(&levels);
    if let Some(regime) = regime {
        let friction = FrictionModel::new(&routing).with_friction_coefficient(0.1).unwrap();
        let mut out = FrictionArmData::new(&model, &friction);
        // One warm-up evaluation, then `EVALS` more.
        for _ in 0..=evals {
            let arm = (&friction, regime);
            model
                .evaluate_with_friction(&mut data, &mut out, arm, black_box(&q), &f0, choice)
                .unwrap();
        }
        let k = out.end.stiffness()[(0, 0)];
        println!("{model_kind:?} {} DOF with friction ({regime:?}): K_x[0,0] = {k:e}", 2 * joints);
        return;
    }
    model.evaluate(&mut data, &q, &f0, choice).unwrap();
    for _ in 0..evals {
        model.evaluate(&mut data, black_box(&q), &f0, TensionChoice::Levels(&levels)).unwrap();
    }
    println!("{:?} {} DOF: K_x[0,0] = {:e}", model_kind, 2 * joints, data.stiffness()[(0, 0)]);
}
