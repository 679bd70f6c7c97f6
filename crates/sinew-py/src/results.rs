//! The result types of `ArmStiffness`'s calls (`ArmResult`, `BatchResult`, `PlanResult`):
//! numbers copied out of the workspace when the call returns, turned into numpy arrays on
//! first read. They convert; they decide nothing.

use std::sync::OnceLock;

use faer::MatRef;
use nalgebra::Matrix3;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use sinew::indicators::StiffnessEllipsoid;
use sinew::stiffness::{OutcomeNote, stability_margin};

use crate::errors::library;
use crate::lazy::{LazyArray, optional};

/// The result of `ArmStiffness.evaluate`: numpy arrays (SI units) and floats. The numbers are
/// copied out of the workspace when `evaluate` returns; each array is made on its first read
/// (then the same object), and `min_eigenvalue` and the ellipsoid are computed on their first
/// read, so a call pays only for what is used.
#[pyclass(module = "sinew", frozen)]
#[derive(Debug)]
pub struct ArmResult {
    /// The configuration, rad (dof,).
    pub(crate) q: LazyArray,
    /// The wrench the end exerts, base frame, force first (6,).
    pub(crate) wrench: LazyArray,
    /// `"levels"`, `"given"` or the policy's name.
    #[pyo3(get)]
    pub(crate) policy: &'static str,
    /// The tension levels (joints,), or None.
    pub(crate) levels: Option<LazyArray>,
    /// The policy's objective (Σ f, |f| or the least distance to a limit, N), or None.
    #[pyo3(get)]
    pub(crate) policy_objective: Option<f64>,
    /// `T0 = T_g + J_xᵀ F0`, N m (dof,).
    pub(crate) t0: LazyArray,
    /// Tensions, N, routing order (cables,).
    pub(crate) tensions: LazyArray,
    /// Per joint `[λ_min, λ_max]` of the closed form (joints, 2), or None.
    pub(crate) lambda_intervals: Option<LazyArray>,
    /// `Σ f_c H_c` (dof, dof).
    pub(crate) k_controllable: LazyArray,
    /// `J_cᵀ K_l J_c` (dof, dof).
    pub(crate) k_inherent: LazyArray,
    /// `K_q`, N m/rad (dof, dof).
    pub(crate) k_q: LazyArray,
    /// `K_W = ∂T0/∂Q`, N m/rad (dof, dof).
    pub(crate) k_w: LazyArray,
    /// `J_x`, linear rows first, base frame (6, dof).
    pub(crate) j_x: LazyArray,
    /// Whether `K_q + K_W` is positive definite.
    #[pyo3(get)]
    pub(crate) stable: bool,
    /// `λ_min` of the symmetric part of `K_q + K_W`, N m/rad (computed on first read).
    pub(crate) min_eigenvalue: OnceLock<f64>,
    /// `C_x` (6, 6), or None when unstable.
    pub(crate) c_x: Option<LazyArray>,
    /// `K_x = C_x⁻¹` (6, 6), or None when unstable or `J_x` is rank-deficient.
    pub(crate) k_x: Option<LazyArray>,
    /// `K_fd = K_x[0:3, 0:3]`, N/m (3, 3), or None.
    pub(crate) k_fd: Option<(Matrix3<f64>, LazyArray)>,
    /// The ellipsoid of `K_fd` (computed on first read; None without `K_fd`).
    pub(crate) ellipsoid: OnceLock<Option<Ellipsoid>>,
    /// Why some results are None (without the ellipsoid's note).
    pub(crate) notes: Vec<String>,
}

/// The stiffness ellipsoid's numbers as `ArmResult` gives them.
#[derive(Debug)]
pub(crate) struct Ellipsoid {
    /// Eigenvalues of `K_fd`, ascending, N/m (3,).
    eigenvalues: LazyArray,
    /// Row k: the unit principal direction of `eigenvalues[k]` (3, 3).
    directions: LazyArray,
    /// `1/λ_k`, m/N (3,), None unless `K_fd` is positive definite.
    semi_axes: Option<LazyArray>,
    /// `λ_max / λ_min`.
    condition_number: Option<f64>,
    /// `4π/3 · Π 1/λ_k`, m³/N³.
    volume: Option<f64>,
}

impl ArmResult {
    fn ellipsoid(&self) -> PyResult<Option<&Ellipsoid>> {
        if let Some(e) = self.ellipsoid.get() {
            return Ok(e.as_ref());
        }
        let computed = match &self.k_fd {
            None => None,
            Some((k_fd, _)) => {
                let e = StiffnessEllipsoid::new(k_fd).map_err(library)?;
                Some(Ellipsoid {
                    eigenvalues: LazyArray::vector(e.eigenvalues.as_slice()),
                    directions: LazyArray::nalgebra(&e.directions.transpose()),
                    semi_axes: e.semi_axes().map(|a| LazyArray::vector(a.as_slice())),
                    condition_number: e.condition_number(),
                    volume: e.volume(),
                })
            }
        };
        Ok(self.ellipsoid.get_or_init(|| computed).as_ref())
    }
}

#[pymethods]
impl ArmResult {
    /// The configuration, rad (dof,).
    #[getter]
    fn q(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.q.get(py)
    }

    /// The wrench the end exerts, base frame, force first (6,).
    #[getter]
    fn wrench(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.wrench.get(py)
    }

    /// The tension levels (joints,), or None.
    #[getter]
    fn levels(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        optional(py, self.levels.as_ref())
    }

    /// `T0 = T_g + J_xᵀ F0`, N m (dof,).
    #[getter]
    fn t0(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.t0.get(py)
    }

    /// Tensions, N, routing order (cables,).
    #[getter]
    fn tensions(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.tensions.get(py)
    }

    /// Per joint `[λ_min, λ_max]` of the closed form (joints, 2), or None.
    #[getter]
    fn lambda_intervals(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        optional(py, self.lambda_intervals.as_ref())
    }

    /// `Σ f_c H_c` (dof, dof).
    #[getter]
    fn k_controllable(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.k_controllable.get(py)
    }

    /// `J_cᵀ K_l J_c` (dof, dof).
    #[getter]
    fn k_inherent(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.k_inherent.get(py)
    }

    /// `K_q`, N m/rad (dof, dof).
    #[getter]
    fn k_q(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.k_q.get(py)
    }

    /// `K_W = ∂T0/∂Q`, N m/rad (dof, dof).
    #[getter]
    fn k_w(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.k_w.get(py)
    }

    /// `J_x`, linear rows first, base frame (6, dof).
    #[getter]
    fn j_x(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.j_x.get(py)
    }

    /// `λ_min` of the symmetric part of `K_q + K_W`, N m/rad.
    #[getter]
    fn min_eigenvalue(&self) -> PyResult<f64> {
        if let Some(&m) = self.min_eigenvalue.get() {
            return Ok(m);
        }
        let n = self.k_q.values().len().isqrt();
        let k_q = MatRef::from_row_major_slice(self.k_q.values(), n, n);
        let k_w = MatRef::from_row_major_slice(self.k_w.values(), n, n);
        let m = stability_margin(k_q, k_w).map_err(library)?;
        Ok(*self.min_eigenvalue.get_or_init(|| m))
    }

    /// `C_x` (6, 6), or None when unstable.
    #[getter]
    fn c_x(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        optional(py, self.c_x.as_ref())
    }

    /// `K_x = C_x⁻¹` (6, 6), or None when unstable or `J_x` is rank-deficient.
    #[getter]
    fn k_x(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        optional(py, self.k_x.as_ref())
    }

    /// `K_fd = K_x[0:3, 0:3]`, N/m (3, 3), or None.
    #[getter]
    fn k_fd(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        optional(py, self.k_fd.as_ref().map(|(_, a)| a))
    }

    /// The ellipsoid's eigenvalues of `K_fd`, ascending, N/m (3,), or None.
    #[getter]
    fn eigenvalues(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        optional(py, self.ellipsoid()?.map(|e| &e.eigenvalues))
    }

    /// `directions[k]`: the unit principal direction of `eigenvalues[k]` (3, 3), or None.
    #[getter]
    fn directions(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        optional(py, self.ellipsoid()?.map(|e| &e.directions))
    }

    /// `1/λ_k`, m/N (3,), or None unless `K_fd` is positive definite.
    #[getter]
    fn semi_axes(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        optional(py, self.ellipsoid()?.and_then(|e| e.semi_axes.as_ref()))
    }

    /// `λ_max / λ_min` of `K_fd`, or None.
    #[getter]
    fn condition_number(&self) -> PyResult<Option<f64>> {
        Ok(self.ellipsoid()?.and_then(|e| e.condition_number))
    }

    /// `4π/3 · Π 1/λ_k`, m³/N³, or None.
    #[getter]
    fn volume(&self) -> PyResult<Option<f64>> {
        Ok(self.ellipsoid()?.and_then(|e| e.volume))
    }

    /// Why some results are None.
    #[getter]
    fn notes(&self) -> PyResult<Vec<String>> {
        let mut notes = self.notes.clone();
        if let Some(e) = self.ellipsoid()?
            && e.semi_axes.is_none()
        {
            notes.push(OutcomeNote::IndefiniteKfd.text("None"));
        }
        Ok(notes)
    }

    fn __repr__(&self) -> PyResult<String> {
        Ok(format!(
            "sinew.ArmResult(stable={}, min_eigenvalue={:e}, policy={:?})",
            self.stable,
            self.min_eigenvalue()?,
            self.policy
        ))
    }
}

/// The result of `ArmStiffness.evaluate_many`: stacked arrays, one row per configuration.
#[pyclass(module = "sinew", frozen, get_all)]
#[derive(Debug)]
pub struct BatchResult {
    /// Whether the row evaluated (N,) bool; false rows are NaN everywhere.
    pub(crate) ok: Py<PyAny>,
    /// Whether `K_q + K_W` is positive definite (N,) bool.
    pub(crate) stable: Py<PyAny>,
    /// (N,).
    pub(crate) min_eigenvalue: Py<PyAny>,
    /// (N, dof).
    pub(crate) t0: Py<PyAny>,
    /// (N, cables).
    pub(crate) tensions: Py<PyAny>,
    /// (N, 6, 6), NaN where unstable.
    pub(crate) c_x: Py<PyAny>,
    /// (N, 6, 6), NaN where unstable or rank-deficient.
    pub(crate) k_x: Py<PyAny>,
    /// (N, 3, 3).
    pub(crate) k_fd: Py<PyAny>,
    /// `(row, kind, message)` of every failed row.
    pub(crate) errors: Vec<(usize, String, String)>,
}

#[pymethods]
impl BatchResult {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.ok.bind(py).len()
    }
}

/// The result of `ArmStiffness.plan`.
#[pyclass(module = "sinew", frozen, get_all)]
#[derive(Debug)]
pub struct PlanResult {
    /// The objective's name.
    pub(crate) objective: &'static str,
    /// The objective's value at the answer.
    pub(crate) value: f64,
    /// Certified: the optimum is within `gap` of `value`.
    pub(crate) gap: f64,
    /// The coordinates `λ` of the tensions in the equilibrium set.
    pub(crate) lambda_: Py<PyArray1<f64>>,
    /// Tension levels, when the routing has them, else None.
    pub(crate) levels: Option<Py<PyArray1<f64>>>,
    /// Tensions, N (cables,).
    pub(crate) tensions: Py<PyArray1<f64>>,
    /// Σ f, N.
    pub(crate) total_tension: f64,
    /// `K_fd` (3, 3), or None.
    pub(crate) k_fd: Option<Py<PyArray2<f64>>>,
    /// `C_x` (6, 6).
    pub(crate) c_x: Py<PyArray2<f64>>,
    /// `λ_min(K_q + K_W)`.
    pub(crate) min_eigenvalue: f64,
    /// Whether `min_eigenvalue > 0`.
    pub(crate) stable: bool,
    /// Iterations of the method (interior point by default), all phases.
    pub(crate) iterations: usize,
}

impl PlanResult {
    /// The Python result of a plan.
    pub(crate) fn new(py: Python<'_>, plan: &sinew::planner::Plan) -> PlanResult {
        use crate::convert::{na2, vec1};
        PlanResult {
            objective: plan.objective.name(),
            value: plan.value,
            gap: plan.gap,
            lambda_: vec1(py, &plan.lambda).unbind(),
            levels: plan.levels.as_ref().map(|l| vec1(py, l).unbind()),
            tensions: vec1(py, &plan.tensions).unbind(),
            total_tension: plan.total_tension,
            k_fd: plan.k_fd.map(|k| na2(py, &k).unbind()),
            c_x: na2(py, &plan.c_x).unbind(),
            min_eigenvalue: plan.min_eigenvalue,
            stable: plan.min_eigenvalue > 0.0,
            iterations: plan.iterations,
        }
    }
}

#[pymethods]
impl PlanResult {
    /// `λ` (a keyword in Python, hence also `lambda_`).
    #[getter(r#lambda)]
    fn lambda_alias(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.lambda_.clone_ref(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "sinew.PlanResult(objective={:?}, value={:e}, gap={:e}, total_tension={})",
            self.objective, self.value, self.gap, self.total_tension
        )
    }
}
