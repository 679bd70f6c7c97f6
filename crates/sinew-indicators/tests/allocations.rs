//! Evaluating the indicators allocates nothing once the workspace exists: `JointProbe`
//! evaluations (σ_x, σ_y, the stiffness at a level; eq. 20, 22–23) and the stiffness ellipsoid
//! of `K_fd` with every quantity it reports (eq. 21). An infeasible evaluation allocates one
//! thing, its boxed error: counted exactly below.
//!
//! A counting global allocator (this test binary only) counts every allocation made while the
//! per-configuration functions run.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Matrix3, Vector3, Vector6};
use sinew_indicators::{JointProbe, StiffnessEllipsoid};
use sinew_routing::{FrictionModel, Slip};
use sinew_statics::TensionChoice;
use sinew_stiffness::{ArmStiffness, ArmStiffnessData, FrictionRegime, History};
use sinew_testkit::alloc::{CountingAllocator, assert_counting, count};
use sinew_testkit::{cdhrm5, config};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// The probe (feasible, then infeasible), then the ellipsoid.
fn evaluating_the_indicators_allocates_nothing() {
    assert_counting();
    probe_evaluations_allocate_nothing();
    probes_with_friction_allocate_nothing();
    an_infeasible_probe_allocates_only_its_boxed_error();
    the_ellipsoid_allocates_nothing();
}

fn probe_evaluations_allocate_nothing() {
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let name = cdhrm5::routing_file(model);
        let qs = config::random_qs(&robot, 5, 10);
        for joint in 0..robot.dof() / 2 {
            let mut probe = JointProbe::new(&robot, &routing, joint).unwrap();
            let tau = [-1.0, 0.5];
            // Warm-up: one evaluation.
            probe.evaluate(&robot, &routing, [0.1, -0.1], tau).unwrap();

            let (allocations, (feasible, checksum)) = count(|| {
                let (mut feasible, mut checksum) = (0, 0.0);
                for q in &qs {
                    probe.set_configuration(q).unwrap();
                    let angles = [q[2 * joint], q[2 * joint + 1]];
                    // Random angles may ask for more than the cables give: both outcomes count.
                    if let Ok(range) = probe.evaluate(&robot, &routing, angles, tau) {
                        feasible += 1;
                        checksum += range.sigma_x().delta + range.sigma_y().range[1];
                        checksum += range.at_level(0.5)[(0, 0)];
                    }
                }
                (feasible, checksum)
            });
            assert!(checksum.is_finite());
            assert_eq!(
                allocations,
                0,
                "{name}, joint {}: {allocations} allocations in 10 probe evaluations ({feasible} feasible)",
                joint + 1
            );
        }
    }
}

fn probes_with_friction_allocate_nothing() {
    // Every regime (the friction geometry, the capstan weights, the actuator interval, the
    // regime's joint stiffness): the workspaces are the probe's.
    let regimes = [
        FrictionRegime::Slip(Slip::Pull),
        FrictionRegime::Slip(Slip::Release),
        FrictionRegime::Stick(History::Pull),
        FrictionRegime::Stick(History::Equal),
    ];
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let friction = FrictionModel::new(&routing).with_friction_coefficient(0.1).unwrap();
        let qs = config::random_qs(&robot, 6, 10);
        for regime in regimes {
            let probe = JointProbe::new(&robot, &routing, 3).unwrap();
            let mut probe = probe.with_friction(&routing, friction.clone(), regime).unwrap();
            let tau = [-1.0, 0.5];
            probe.evaluate(&robot, &routing, [0.1, -0.1], tau).unwrap();
            let (allocations, feasible) = count(|| {
                let mut feasible = 0;
                for q in &qs {
                    probe.set_configuration(q).unwrap();
                    let angles = [q[6], q[7]];
                    feasible += usize::from(probe.evaluate(&robot, &routing, angles, tau).is_ok());
                }
                feasible
            });
            assert!(feasible > 0);
            assert_eq!(allocations, 0, "{model:?}, {regime:?}: {allocations} allocations");
        }
    }
}

fn an_infeasible_probe_allocates_only_its_boxed_error() {
    // Apart from the feasible evaluations, so that a failure says which path allocates.
    let (robot, routing) = cdhrm5::robot_and_routing(cdhrm5::MODELS[0]);
    let mut probe = JointProbe::new(&robot, &routing, 0).unwrap();
    probe.evaluate(&robot, &routing, [0.1, -0.1], [-1.0, 0.5]).unwrap();
    let (allocations, result) =
        count(|| probe.evaluate(&robot, &routing, [0.1, -0.1], [500.0, 500.0]).is_err());
    assert!(result, "500 N m is more than cdhrm5's cables hold");
    // Known, and counted exactly so that a change shows: the evaluation itself allocates
    // nothing, but its error does, once: `impl From<StaticsError> for IndicatorError` boxes the
    // statics error (`IndicatorError::Statics(Box<StaticsError>)`, src/error.rs). A sweep pays
    // it at every infeasible cell. When the error stops boxing, this count becomes 0.
    assert_eq!(
        allocations, 1,
        "{allocations} allocations for one infeasible evaluation (1 expected: the boxed error)"
    );
}

fn the_ellipsoid_allocates_nothing() {
    // K_fd: the translational block of K_x at a loaded pose of cdhrm5 (and a made-up matrix).
    let (robot, routing) = cdhrm5::robot_and_routing(cdhrm5::MODELS[0]);
    let arm = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&arm);
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    arm.evaluate(&mut data, &cdhrm5::LOADED_POSE, &f0, TensionChoice::Levels(&[0.5; 5])).unwrap();
    let k_x = data.stiffness();
    let k_fd = Matrix3::from_fn(|r, c| k_x[(r, c)]);
    let other = Matrix3::new(3.0, 0.5, 0.0, 0.5, 2.0, 0.1, 0.0, 0.1, 1.0);
    let u = Vector3::new(1.0, 1.0, 0.0).normalize();
    // Warm-up.
    StiffnessEllipsoid::new(&k_fd).unwrap();

    let (allocations, checksum) = count(|| {
        let mut checksum = 0.0;
        for k in [&k_fd, &other] {
            let e = StiffnessEllipsoid::new(k).unwrap();
            checksum += e.lambda_min() + e.directional_stiffness(&u).unwrap();
            checksum += e.semi_axes().map_or(0.0, |a| a[0]);
            checksum += e.condition_number().unwrap_or(0.0) + e.volume().unwrap_or(0.0);
            checksum += f64::from(u8::from(e.is_positive_definite()));
        }
        checksum
    });
    assert!(checksum.is_finite());
    assert_eq!(allocations, 0, "{allocations} allocations in 2 ellipsoids");
}

/// The checks one after another, in a plain binary (`harness = false` in Cargo.toml): the
/// counter is global, and a test harness's own thread allocates for its bookkeeping (starting a
/// test, recording its result) while a test runs, which the counter would count.
fn main() {
    evaluating_the_indicators_allocates_nothing();
}
