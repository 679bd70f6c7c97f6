//! `cargo bench -p sinew-stiffness --bench friction`: what friction at the holes costs (issue
//! #27, "friction adds at most 2× to the routed pipeline at 10 and 50 DOF"), measured in one
//! run beside the frictionless step it extends, on the routed cdhrm5 (10 DOF, E4 rounded) and
//! the routed 25-joint chain (50 DOF), μ = 0.1 on every cable:
//!
//! - `frictionless`: the cable geometry with Hessians and today's joint stiffness `K_q`
//!   ([`joint_stiffness`]), the step the friction code extends;
//! - `slip`: the same, then the friction geometry, the pull regime's capstan weights and the
//!   slip stiffness;
//! - `slip + stick`: the same, then the stick stiffness after a pull history;
//! - `pipeline`: the whole frictionless `Q → K_x` ([`ArmStiffness::evaluate`], as in
//!   `benches/stiffness.rs`; its `K_q` is accumulated over the layout's blocks), alone. (Until
//!   session 21 it also ran the cable geometry with Hessians once more, so its times, and the
//!   ratios to it in docs/performance.md's sessions 10–20, were those of more than the
//!   pipeline: the ratios were understated.)
//! - `pipeline + slip`, `pipeline + slip + stick`: the pipeline, then what a caller adds today
//!   for friction with the public API: the cable geometry with Hessians once more (the
//!   pipeline's own is not exposed), the friction geometry, weights, slip (and stick) stiffness;
//! - `evaluate_with_friction slip pull`, `… stick pull`: the whole pipeline with friction
//!   ([`ArmStiffness::evaluate_with_friction`], levels), what the acceptance's "≤ 2× the
//!   routed pipeline" compares with `pipeline`;
//! - `part: …`: each friction step alone, on a geometry computed before timing; the stick load
//!   limit after `equal` along 1 and 13 directions beside one solve of `K_stick + K_W` (the
//!   acceptance: "at most one extra solve per direction").
//!
//! Every step keeps the segment directions, as `evaluate_with_friction` does
//! (`RoutingData::keep_segment_directions`). Until session 26 the steps did not, so their
//! friction geometry recomputed each direction: `part: friction geometry` measured 93.5 µs at
//! 50 DOF, 56.4 µs with the directions kept (docs/performance.md, session 26).
//!
//! The tensions are the pipeline's own at the pose (their values do not change the cost).
//! docs/performance.md ("Issue #27: what friction costs") has the numbers.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::Mat;
use faer::linalg::solvers::Solve;
use nalgebra::Vector6;
use sinew_robot::{Robot, RobotData};
use sinew_routing::{
    FrictionData, FrictionModel, Order, PatternModel, Routing, RoutingData, Slip,
    compute_cable_geometry, compute_capstan_weights, compute_friction_geometry,
};
use sinew_statics::TensionChoice;
use sinew_stiffness::{
    ArmStiffness, ArmStiffnessData, FrictionArmData, FrictionRegime, FrictionStiffnessData,
    History, base_directions, joint_stiffness, slip_stiffness, stick_load_limits, stick_stiffness,
};
use sinew_testkit::cdhrm5;

const MU: f64 = 0.1;

/// One arm at one pose, with every workspace the three steps need.
struct Case {
    robot: Robot,
    routing: Routing,
    model: FrictionModel,
    q: Vec<f64>,
    tensions: Vec<f64>,
    rdata: RobotData,
    geometry: RoutingData,
    kc: Mat<f64>,
    ki: Mat<f64>,
    friction: FrictionData,
    out: FrictionStiffnessData,
}

/// Which parts of a step run: the frictionless pipeline (`pipeline`, run by the caller), the
/// cable geometry with Hessians (with any of the others) and `K_q` (`k_q`), the friction
/// geometry, weights and slip stiffness (`slip`), and the stick stiffness after them (`stick`).
#[derive(Clone, Copy)]
struct Parts {
    pipeline: bool,
    k_q: bool,
    slip: bool,
    stick: bool,
}

impl Case {
    fn new(robot: Robot, routing: Routing, q: Vec<f64>, tensions: Vec<f64>) -> Case {
        let model = FrictionModel::new(&routing).with_friction_coefficient(MU).unwrap();
        let n = routing.dof();
        // The segment directions kept, as `evaluate_with_friction` keeps them: the friction
        // geometry reads them instead of recomputing each (about half its time at 50 DOF).
        let mut geometry = RoutingData::new(&routing);
        geometry.keep_segment_directions(true);
        Case {
            rdata: RobotData::new(&robot),
            geometry,
            kc: Mat::zeros(n, n),
            ki: Mat::zeros(n, n),
            friction: FrictionData::new(&model),
            out: FrictionStiffnessData::new(&model),
            robot,
            routing,
            model,
            q,
            tensions,
        }
    }

    fn step(&mut self, parts: Parts) {
        let (routing, model, t) = (&self.routing, &self.model, &self.tensions[..]);
        if !(parts.k_q || parts.slip || parts.stick) {
            return; // `pipeline` alone: `ArmStiffness::evaluate` and nothing else.
        }
        compute_cable_geometry(
            routing,
            &self.robot,
            &mut self.rdata,
            &mut self.geometry,
            black_box(&self.q),
            Order::Hessians,
        )
        .unwrap();
        if parts.k_q {
            let (kc, ki) = (self.kc.as_mut(), self.ki.as_mut());
            joint_stiffness(routing, &self.geometry, black_box(t), kc, ki).unwrap();
        }
        if parts.slip {
            compute_friction_geometry(model, routing, &self.geometry, &mut self.friction).unwrap();
            compute_capstan_weights(model, &mut self.friction, Slip::Pull).unwrap();
            let (g, f) = (&self.geometry, &self.friction);
            slip_stiffness(model, routing, g, f, Slip::Pull, t, &mut self.out).unwrap();
        }
        if parts.stick {
            let (g, f) = (&self.geometry, &self.friction);
            stick_stiffness(model, routing, g, f, History::Pull, t, &mut self.out).unwrap();
        }
    }
}

/// The routed arm at `dof` DOF: `(robot, routing, pose, levels, load)` as in
/// `benches/stiffness.rs` (cdhrm5 at E4 rounded with its load, the chain weightless, unloaded).
fn arm(dof: usize) -> (Robot, Routing, Vec<f64>, Vec<f64>, Vector6<f64>) {
    if dof == 10 {
        let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Routed);
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        (robot, routing, cdhrm5::LOADED_POSE.to_vec(), vec![0.5; 5], f0)
    } else {
        let joints = dof / 2;
        let (robot, routing) = cdhrm5::chain(joints, PatternModel::Routed);
        let robot = robot.with_gravity(nalgebra::Vector3::zeros());
        let q = (0..dof).map(|i| 0.05 * ((i as f64) * 0.7).sin()).collect();
        (robot, routing, q, vec![0.1; joints], Vector6::zeros())
    }
}

fn bench_friction(c: &mut Criterion) {
    let mut group = c.benchmark_group("friction routed");
    group.sample_size(30);
    for dof in [10, 50] {
        let (robot, routing, q, levels, f0) = arm(dof);
        let pipeline = ArmStiffness::new(&robot, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&pipeline);
        let choice = TensionChoice::Levels(&levels);
        pipeline.evaluate(&mut data, &q, &f0, choice).unwrap();
        let mut case = Case::new(robot, routing, q.clone(), data.tensions().to_vec());
        let steps = [
            ("frictionless", Parts { pipeline: false, k_q: true, slip: false, stick: false }),
            ("slip", Parts { pipeline: false, k_q: true, slip: true, stick: false }),
            ("slip + stick", Parts { pipeline: false, k_q: true, slip: true, stick: true }),
            ("pipeline", Parts { pipeline: true, k_q: false, slip: false, stick: false }),
            ("pipeline + slip", Parts { pipeline: true, k_q: false, slip: true, stick: false }),
            (
                "pipeline + slip + stick",
                Parts { pipeline: true, k_q: false, slip: true, stick: true },
            ),
        ];
        for (name, parts) in steps {
            let mut run = || {
                if parts.pipeline {
                    pipeline.evaluate(&mut data, black_box(&q), &f0, choice).unwrap();
                }
                case.step(parts);
            };
            run(); // Warm and checked once before timing.
            group.bench_function(BenchmarkId::new(name, dof), |b| b.iter(&mut run));
        }
        // The whole pipeline with friction, as `sinew arm --friction` runs it: the pose stage,
        // the friction geometry, the regime's tensions (here the paper's levels on each joint's
        // interval of actuator tensions), its K_q, the end stage.
        let model = case.model.clone();
        let mut out = FrictionArmData::new(&pipeline, &model);
        for (name, regime) in [
            ("evaluate_with_friction slip pull", FrictionRegime::Slip(Slip::Pull)),
            ("evaluate_with_friction stick pull", FrictionRegime::Stick(History::Pull)),
        ] {
            let mut run = || {
                let arm = (&model, regime);
                pipeline.evaluate_with_friction(&mut data, &mut out, arm, &q, &f0, choice).unwrap()
            };
            run();
            group.bench_function(BenchmarkId::new(name, dof), |b| b.iter(&mut run));
        }
        // The friction steps one by one, on the geometry of the last step (not timed).
        let (model, routing, g) = (&case.model, &case.routing, &case.geometry);
        let (t, friction, out) = (&case.tensions[..], &mut case.friction, &mut case.out);
        group.bench_function(BenchmarkId::new("part: friction geometry", dof), |b| {
            b.iter(|| compute_friction_geometry(model, routing, g, friction).unwrap())
        });
        group.bench_function(BenchmarkId::new("part: capstan weights", dof), |b| {
            b.iter(|| compute_capstan_weights(model, friction, Slip::Pull).unwrap())
        });
        let f = &*friction;
        group.bench_function(BenchmarkId::new("part: slip stiffness", dof), |b| {
            b.iter(|| slip_stiffness(model, routing, g, f, Slip::Pull, black_box(t), out).unwrap())
        });
        group.bench_function(BenchmarkId::new("part: stick stiffness", dof), |b| {
            b.iter(|| {
                stick_stiffness(model, routing, g, f, History::Pull, black_box(t), out).unwrap()
            })
        });
        // The stick load limit after `equal` (every band has room): one factorisation of
        // K_stick + K_W, one solve per direction (none for a mirror `−u`) and one walk over
        // the holes, then per direction the holes that may be reached first. One direction,
        // then the twelve base directions and the load's; and one solve alone.
        stick_stiffness(model, routing, g, f, History::Equal, t, out).unwrap();
        let (k_stick, k_w, j_x) = (out.stiffness().unwrap(), data.k_w().to_owned(), data.j_x());
        let mut directions = base_directions().to_vec();
        directions.push(Vector6::new(0.3, 1.0, -0.2, 0.0, 0.0, 0.0));
        let mats = (k_stick, k_w.as_ref(), j_x);
        for count in [1, 13] {
            let name = format!("part: stick load limits, {count} directions");
            let dirs = &directions[..count];
            group.bench_function(BenchmarkId::new(name, dof), |b| {
                b.iter(|| {
                    stick_load_limits(model, routing, f, History::Equal, t, mats, dirs).unwrap()
                })
            });
        }
        let lu = Mat::from_fn(dof, dof, |i, j| k_stick[(i, j)] + k_w[(i, j)]).partial_piv_lu();
        let rhs = Mat::from_fn(dof, 1, |i, _| j_x[(1, i)]);
        group.bench_function(BenchmarkId::new("part: one solve of K_stick + K_W", dof), |b| {
            b.iter(|| lu.solve(black_box(&rhs)))
        });
    }
    group.finish();
}

criterion_group!(benches, bench_friction);
criterion_main!(benches);
