//! The Rust loop `evaluate_many` is measured against: the same batch kernel
//! (`_sinew::batch::evaluate_many`, rayon, one workspace per thread) on 10 000 seeded
//! configurations of cdhrm5 at E4's load and levels 0.5, no Python. Prints the best of 10 runs.
//!
//! `cargo run --release -p sinew-py --example batch_loop` (numbers in docs/performance.md;
//! `crates/sinew-py/bench/bench.py` times the Python side on the same configurations).

use std::time::Instant;

use _sinew::batch::{BatchChoice, evaluate_many};
use nalgebra::Vector6;
use sinew::paper::E4_F0;
use sinew::stiffness::ArmStiffness;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/cdhrm5");
    let robot = sinew::robot::load(&root)?;
    let routing = sinew::routing::load(root.join(sinew::routing::ROUTING_FILE), &robot)?;
    let arm = ArmStiffness::new(&robot, &routing)?;
    let (rows, dof) = (10_000, robot.dof());
    // The same configurations as bench.py: a linear congruential sequence in the middle half
    // of each joint's range.
    let mut state: u64 = 12345;
    let mut q = Vec::with_capacity(rows * dof);
    for _ in 0..rows {
        for j in robot.joints() {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let u = (state >> 11) as f64 / (1u64 << 53) as f64;
            q.push(j.lower + (j.upper - j.lower) * (0.25 + 0.5 * u));
        }
    }
    let f0 = Vector6::from_column_slice(&E4_F0);
    let choice = BatchChoice::Levels(vec![0.5; robot.joint_count()]);
    let mut best = f64::INFINITY;
    let mut ok = 0;
    for _ in 0..10 {
        let start = Instant::now();
        let batch = evaluate_many(&arm, &q, &[f0], &choice);
        best = best.min(start.elapsed().as_secs_f64());
        ok = batch.ok.iter().filter(|&&o| o).count();
    }
    println!(
        "rust batch kernel: {rows} configurations in {:.2} ms (best of 10; {ok} ok), {:.3} µs per row, {} threads",
        best * 1e3,
        best * 1e6 / rows as f64,
        rayon::current_num_threads()
    );
    Ok(())
}
