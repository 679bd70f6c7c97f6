//! Python bindings of Sinew: `import sinew` (built with maturin; the Python package, its type
//! stubs and `py.typed` are in `python/sinew/`).
//!
//! In the spirit of Pinocchio's: immutable models (`Robot`, `Routing`, `ArmStiffness`) with
//! their workspaces inside, numpy arrays in and out, SI units, the conventions and joint
//! numbering of the Rust crates (0-based; joint `i` owns `q[2i]`, `q[2i+1]` when universal).
//! Errors are Python exceptions (`errors.rs`); nothing a user passes reaches a panic.

use pyo3::prelude::*;

mod arm;
pub mod batch;
mod batch_out;
mod convert;
mod errors;
mod export;
mod friction;
mod indicators;
mod lazy;
mod model;
mod plan_along;
mod plan_args;
mod plan_many;
mod pool;
mod results;

/// The number of threads a batch call with `threads` runs on (`None`: rayon's global pool),
/// read by rayon inside the pool the call would use: how the tests see that `threads=n`
/// means n threads.
#[pyfunction]
#[pyo3(name = "_pool_threads", signature = (threads = None))]
fn pool_threads(py: Python<'_>, threads: Option<i64>) -> PyResult<usize> {
    let threads = pool::threads_arg(threads)?;
    py.detach(|| pool::run(threads, pool::current_threads))
}

/// The extension module `sinew._sinew`, re-exported by the `sinew` package.
#[pymodule]
fn _sinew(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<model::Robot>()?;
    m.add_class::<model::Routing>()?;
    m.add_class::<arm::ArmStiffness>()?;
    m.add_class::<results::ArmResult>()?;
    m.add_class::<friction::FrictionResult>()?;
    m.add_class::<results::BatchResult>()?;
    m.add_class::<results::PlanResult>()?;
    m.add_class::<plan_many::PlanBatchResult>()?;
    m.add_class::<indicators::JointRange>()?;
    m.add_class::<indicators::SweepResult>()?;
    m.add_function(wrap_pyfunction!(model::load_robot, m)?)?;
    m.add_function(wrap_pyfunction!(model::load_routing, m)?)?;
    m.add_function(wrap_pyfunction!(indicators::joint_range, m)?)?;
    m.add_function(wrap_pyfunction!(indicators::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(pool_threads, m)?)?;
    m.add_function(wrap_pyfunction!(export::to_mjcf, m)?)?;
    m.add_function(wrap_pyfunction!(export::cable_geometry, m)?)?;
    m.add("SinewError", py.get_type::<errors::SinewError>())?;
    m.add("InputError", py.get_type::<errors::InputError>())?;
    m.add("InfeasibleError", py.get_type::<errors::InfeasibleError>())?;
    m.add("UnstableError", py.get_type::<errors::UnstableError>())?;
    m.add("RankDeficientError", py.get_type::<errors::RankDeficientError>())?;
    m.add("NumericalError", py.get_type::<errors::NumericalError>())?;
    Ok(())
}
