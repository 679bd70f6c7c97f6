//! Planning over many poses (`ArmStiffness.plan_many`): the kernel in plain Rust (rayon, one
//! planner workspace per thread, [`Planner::plan`] per row) and its Python result, stacked
//! arrays with one row per pose and a typed failure per row, as `evaluate_many` has.

use nalgebra::Vector6;
use numpy::PyArray1;
use pyo3::prelude::*;
use rayon::prelude::*;
use sinew::ErrorKind;
use sinew::planner::{Planner, PlannerData};

use crate::batch::wrench_of_row;
use crate::convert::{reshape, vec1};
use crate::errors::exception;
use crate::plan_args::PlanArgs;

/// Rows per parallel task (a plan takes far longer than an evaluation: small tasks balance).
const CHUNK: usize = 4;

/// One row's plan, or its failure.
pub type RowPlan = Result<sinew::planner::Plan, (ErrorKind, String)>;

/// The plans of a batch, row-major; a failed row is NaN (0 iterations), `ok` false and its
/// error in `errors`.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanBatch {
    /// Rows.
    pub rows: usize,
    /// Cables.
    pub cables: usize,
    /// Joints (the columns of `levels`).
    pub joints: usize,
    /// Whether the row has a certified plan.
    pub ok: Vec<bool>,
    /// The objective's value.
    pub value: Vec<f64>,
    /// The certified gap.
    pub gap: Vec<f64>,
    /// Tensions (rows × cables).
    pub tensions: Vec<f64>,
    /// Σ f.
    pub total_tension: Vec<f64>,
    /// Levels (rows × joints), NaN where the routing has none.
    pub levels: Vec<f64>,
    /// `K_fd` (rows × 9), NaN where `J_x` has rank < 6.
    pub k_fd: Vec<f64>,
    /// `C_x` (rows × 36).
    pub c_x: Vec<f64>,
    /// `λ_min(K_q + K_W)`.
    pub min_eigenvalue: Vec<f64>,
    /// Iterations.
    pub iterations: Vec<u64>,
    /// `(row, kind, message)` of every failed row, in row order.
    pub errors: Vec<(usize, ErrorKind, String)>,
}

/// Plan every row of `q` (rows × dof, row-major) under `f0` (one wrench, or one per row), in
/// parallel on the rayon pool it is called in.
pub fn plan_many(planner: &Planner, q: &[f64], f0: &[Vector6<f64>], args: &PlanArgs) -> PlanBatch {
    let arm = planner.arm();
    let dof = arm.dof();
    let rows = q.len().checked_div(dof).unwrap_or(0);
    let mut plans: Vec<Option<RowPlan>> = vec![None; rows];
    plans.par_chunks_mut(CHUNK).zip(q.par_chunks(CHUNK * dof.max(1))).enumerate().for_each_init(
        || PlannerData::new(planner),
        |data, (chunk, (out, q))| {
            for (r, out) in out.iter_mut().enumerate() {
                let qr = &q[r * dof..(r + 1) * dof];
                let f0 = wrench_of_row(f0, chunk * CHUNK + r);
                let plan =
                    planner.plan(data, qr, f0, args.objective, &args.requirements, &args.settings);
                *out = Some(plan.map_err(crate::errors::message));
            }
        },
    );
    stack(planner, plans)
}

/// The plans of the rows stacked into a [`PlanBatch`] (`None`: a row never planned).
pub fn stack(planner: &Planner, plans: Vec<Option<RowPlan>>) -> PlanBatch {
    let arm = planner.arm();
    let (cables, joints) = (arm.routing().cable_count(), arm.robot().joint_count());
    let rows = plans.len();
    let nan = |n: usize| vec![f64::NAN; rows * n];
    let mut batch = PlanBatch {
        rows,
        cables,
        joints,
        ok: vec![false; rows],
        value: nan(1),
        gap: nan(1),
        tensions: nan(cables),
        total_tension: nan(1),
        levels: nan(joints),
        k_fd: nan(9),
        c_x: nan(36),
        min_eigenvalue: nan(1),
        iterations: vec![0; rows],
        errors: Vec::new(),
    };
    for (r, plan) in plans.into_iter().enumerate() {
        match plan {
            Some(Ok(p)) => {
                batch.ok[r] = true;
                batch.value[r] = p.value;
                batch.gap[r] = p.gap;
                batch.tensions[r * cables..(r + 1) * cables].copy_from_slice(&p.tensions);
                batch.total_tension[r] = p.total_tension;
                if let Some(levels) = &p.levels {
                    batch.levels[r * joints..(r + 1) * joints].copy_from_slice(levels);
                }
                if let Some(k) = &p.k_fd {
                    for i in 0..3 {
                        for j in 0..3 {
                            batch.k_fd[r * 9 + 3 * i + j] = k[(i, j)];
                        }
                    }
                }
                for i in 0..6 {
                    for j in 0..6 {
                        batch.c_x[r * 36 + 6 * i + j] = p.c_x[(i, j)];
                    }
                }
                batch.min_eigenvalue[r] = p.min_eigenvalue;
                batch.iterations[r] = p.iterations as u64;
            }
            Some(Err((kind, message))) => batch.errors.push((r, kind, message)),
            None => {}
        }
    }
    batch
}

/// The result of `ArmStiffness.plan_many`: stacked arrays, one row per pose; a failed row is
/// NaN (0 iterations), `ok` False, its error in `errors`.
#[pyclass(module = "sinew", frozen, get_all)]
#[derive(Debug)]
pub struct PlanBatchResult {
    /// The objective's name.
    pub(crate) objective: &'static str,
    /// Whether the row has a certified plan (N,) bool.
    pub(crate) ok: Py<PyAny>,
    /// The objective's value (N,).
    pub(crate) value: Py<PyAny>,
    /// The certified gap (N,).
    pub(crate) gap: Py<PyAny>,
    /// Tensions, N (N, cables).
    pub(crate) tensions: Py<PyAny>,
    /// Σ f, N (N,).
    pub(crate) total_tension: Py<PyAny>,
    /// Tension levels (N, joints), or None when the routing has none.
    pub(crate) levels: Option<Py<PyAny>>,
    /// `K_fd`, N/m (N, 3, 3), NaN where `J_x` has rank < 6.
    pub(crate) k_fd: Py<PyAny>,
    /// `C_x` (N, 6, 6).
    pub(crate) c_x: Py<PyAny>,
    /// `λ_min(K_q + K_W)`, N m/rad (N,).
    pub(crate) min_eigenvalue: Py<PyAny>,
    /// Whether `min_eigenvalue > 0` (N,) bool.
    pub(crate) stable: Py<PyAny>,
    /// Iterations of the method (N,) int64, 0 where the row failed.
    pub(crate) iterations: Py<PyAny>,
    /// `(row, kind, message)` of every failed row.
    pub(crate) errors: Vec<(usize, String, String)>,
    /// `plan_along` only: whether each step's warm-started answer was accepted (N,) bool;
    /// None for `plan_many`.
    pub(crate) warm: Option<Py<PyAny>>,
}

#[pymethods]
impl PlanBatchResult {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.ok.bind(py).len()
    }
}

impl PlanBatchResult {
    /// The Python result of `batch`; the first row's error when every row of a non-empty
    /// batch failed and `raise_if_all_fail`.
    pub fn new(
        py: Python<'_>,
        objective: &'static str,
        batch: PlanBatch,
        has_levels: bool,
        raise_if_all_fail: bool,
    ) -> PyResult<PlanBatchResult> {
        let rows = batch.rows;
        if let Some((_, kind, message)) = batch.errors.first()
            && batch.errors.len() == rows
            && raise_if_all_fail
        {
            return Err(exception(*kind, format!("every row failed; row 0: {message}")));
        }
        let flat = |v: &[f64]| vec1(py, v).into_any().unbind();
        let shaped = |v: &[f64], shape: &[usize]| -> PyResult<Py<PyAny>> {
            Ok(reshape(vec1(py, v), shape)?.unbind())
        };
        let stable: Vec<bool> = batch.min_eigenvalue.iter().map(|&m| m > 0.0).collect();
        let iterations: Vec<i64> =
            batch.iterations.iter().map(|&i| i64::try_from(i).unwrap_or(i64::MAX)).collect();
        Ok(PlanBatchResult {
            objective,
            ok: PyArray1::from_slice(py, &batch.ok).into_any().unbind(),
            value: flat(&batch.value),
            gap: flat(&batch.gap),
            tensions: shaped(&batch.tensions, &[rows, batch.cables])?,
            total_tension: flat(&batch.total_tension),
            levels: if has_levels {
                Some(shaped(&batch.levels, &[rows, batch.joints])?)
            } else {
                None
            },
            k_fd: shaped(&batch.k_fd, &[rows, 3, 3])?,
            c_x: shaped(&batch.c_x, &[rows, 6, 6])?,
            min_eigenvalue: flat(&batch.min_eigenvalue),
            stable: PyArray1::from_slice(py, &stable).into_any().unbind(),
            iterations: PyArray1::from_slice(py, &iterations).into_any().unbind(),
            errors: batch
                .errors
                .into_iter()
                .map(|(r, kind, message)| (r, kind.to_string(), message))
                .collect(),
            warm: None,
        })
    }
}
