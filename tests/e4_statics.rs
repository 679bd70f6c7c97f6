//! The arm's statics at the paper's E4 pose (spec §6), decoupled and routed: the documented
//! mounting holds E4's load, and a load it cannot hold names the first joint that fails.
//! Moved from sinew-statics' tests/arm.rs so that they read the pose from its one owner,
//! `sinew::paper::E4_Q` (the statics crate's tests cannot depend on the facade).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::Vector6;
use sinew::paper::{E4_F0, E4_Q};
use sinew::robot::RobotData;
use sinew::routing::{PatternModel, RoutingData};
use sinew::statics::{ArmStatics, ArmStaticsData, InfeasibleReason, StaticsError};
use sinew_testkit::cdhrm5;

/// Solve cdhrm5's statics at E4 under `f0`, every tension level 0.
fn solve_at_e4(
    model: PatternModel,
    f0: &Vector6<f64>,
) -> (ArmStaticsData, Result<(), StaticsError>) {
    let (robot, routing) = cdhrm5::robot_and_routing(model);
    let statics = ArmStatics::new(&routing);
    let mut rdata = RobotData::new(&robot);
    let mut gdata = RoutingData::new(&routing);
    let mut data = statics.data(&robot);
    let result =
        statics.solve_at(&robot, &routing, &mut rdata, &mut gdata, &mut data, &E4_Q, f0, &[0.0; 5]);
    (data, result)
}

#[test]
fn e4_under_the_documented_mounting() {
    for model in cdhrm5::MODELS {
        let file = cdhrm5::routing_file(model);
        let (data, result) = solve_at_e4(model, &Vector6::from(E4_F0));
        println!("E4 {file}: T0 = {:.3?}", data.t0);
        match &result {
            Ok(()) => {
                for i in &data.intervals {
                    let (lo, hi) = i.ends();
                    println!("  joint {}: f(λ_min) = {lo:.1?}, f(λ_max) = {hi:.1?}", i.joint + 1);
                }
            }
            Err(e) => println!("  {e}"),
        }
        result.unwrap();
    }
}

#[test]
fn a_load_that_cannot_be_held_names_the_first_joint_that_fails() {
    for model in cdhrm5::MODELS {
        let file = cdhrm5::routing_file(model);
        let (_, result) = solve_at_e4(model, &Vector6::new(0.0, 100.0, 0.0, 0.0, 0.0, 0.0));
        let err = result.unwrap_err();
        println!("100 N, {file}: {err}");
        let StaticsError::Infeasible { joint, reason, .. } = err else { panic!("{err:?}") };
        assert!(matches!(reason, InfeasibleReason::OutsideLimits { .. }));
        // Decoupled: solved from the base, joint 1 fails first. Routed: solved from the tip,
        // the most distal joint that cannot hold its share fails first.
        if model == PatternModel::Decoupled {
            assert_eq!(joint, 0);
        }
    }
}
