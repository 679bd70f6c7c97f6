//! Batch throughput of the pipeline `Q → K_x` (issue #16, docs/performance.md): cdhrm5 in
//! both models at E4's load and levels 0.5, over 20 000 seeded configurations (the middle half
//! of every joint's range), with rayon: chunks of configurations, one reusable workspace per
//! task (`map_init`), on 1 thread and on every core. Prints configurations per second, best
//! of 5 runs.
//!
//! `cargo run --release -p sinew-stiffness --example throughput`
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use nalgebra::Vector6;
use rayon::prelude::*;
use sinew_routing::PatternModel;
use sinew_statics::TensionChoice;
use sinew_stiffness::{ArmStiffness, ArmStiffnessData};
use sinew_testkit::cdhrm5;

const ROWS: usize = 20_000;
const CHUNK: usize = 64;

/// Seconds to evaluate every row of `q` (row-major), and how many were stable.
fn run(arm: &ArmStiffness, q: &[f64], f0: &Vector6<f64>, levels: &[f64]) -> (f64, usize) {
    let dof = arm.dof();
    let start = Instant::now();
    let stable: usize = q
        .par_chunks(CHUNK * dof)
        .map_init(
            || ArmStiffnessData::new(arm),
            |data, rows| {
                rows.chunks_exact(dof)
                    .filter(|q| arm.evaluate(data, q, f0, TensionChoice::Levels(levels)).is_ok())
                    .count()
            },
        )
        .sum();
    (start.elapsed().as_secs_f64(), stable)
}

fn main() {
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let arm = ArmStiffness::new(&robot, &routing).unwrap();
        let mut state: u64 = 12345;
        let mut q = Vec::with_capacity(ROWS * robot.dof());
        for _ in 0..ROWS {
            for j in robot.joints() {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                let u = (state >> 11) as f64 / (1u64 << 53) as f64;
                q.push(j.lower + (j.upper - j.lower) * (0.25 + 0.5 * u));
            }
        }
        let levels = vec![0.5; robot.joint_count()];
        for threads in [1, cores] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let (best, stable) = pool.install(|| {
                (0..5)
                    .map(|_| run(&arm, &q, &f0, &levels))
                    .fold((f64::INFINITY, 0), |(b, _), (t, s)| (b.min(t), s))
            });
            let name = if model == PatternModel::Decoupled { "decoupled" } else { "routed" };
            println!(
                "cdhrm5 {name:9}: {threads} thread(s): {:>9.0} configurations/s ({:.2} µs each; {stable} of {ROWS} stable)",
                ROWS as f64 / best,
                best * 1e6 / ROWS as f64
            );
        }
    }
}
