//! `sinew.ArmStiffness`: the whole arm in a pose under a load (eq. 5–21), one configuration
//! (`evaluate`), many in parallel (`evaluate_many`), and the tension planner (`plan`).

use std::sync::{Mutex, OnceLock};

use faer::MatRef;
use nalgebra::{Matrix3, Vector3, Vector6};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use sinew::indicators::StiffnessEllipsoid;
use sinew::planner::{Objective, PlanSettings, Planner, PlannerData, Requirements};
use sinew::statics::{Chosen, TensionChoice, TensionPolicy};
use sinew::stiffness::{ArmStiffnessData, OutcomeNote, stability_margin};

use crate::batch::{BatchChoice, evaluate_many};
use crate::convert::{finite, matrix, na2, reshape, vec1, vector};
use crate::errors::{exception, input, library};
use crate::lazy::{LazyArray, optional};
use crate::model::{Robot, Routing};

/// The model of the pipeline `Q → K_x` for a robot and a routing (Pinocchio's model), with
/// its own workspace (Pinocchio's data) for `evaluate`.
#[pyclass(module = "sinew", frozen)]
#[derive(Debug)]
pub struct ArmStiffness {
    arm: sinew::stiffness::ArmStiffness,
    data: Mutex<ArmStiffnessData>,
    planner: OnceLock<(Planner, Mutex<PlannerData>)>,
}

/// The result of `ArmStiffness.evaluate`: numpy arrays (SI units) and floats. The numbers are
/// copied out of the workspace when `evaluate` returns; each array is made on its first read
/// (then the same object), and `min_eigenvalue` and the ellipsoid are computed on their first
/// read, so a call pays only for what is used.
#[pyclass(module = "sinew", frozen)]
#[derive(Debug)]
pub struct ArmResult {
    /// The configuration, rad (dof,).
    q: LazyArray,
    /// The wrench the end exerts, base frame, force first (6,).
    wrench: LazyArray,
    /// `"levels"`, `"given"` or the policy's name.
    #[pyo3(get)]
    policy: &'static str,
    /// The tension levels (joints,), or None.
    levels: Option<LazyArray>,
    /// The policy's objective (Σ f, |f| or the least distance to a limit, N), or None.
    #[pyo3(get)]
    policy_objective: Option<f64>,
    /// `T0 = T_g + J_xᵀ F0`, N m (dof,).
    t0: LazyArray,
    /// Tensions, N, routing order (cables,).
    tensions: LazyArray,
    /// Per joint `[λ_min, λ_max]` of the closed form (joints, 2), or None.
    lambda_intervals: Option<LazyArray>,
    /// `Σ f_c H_c` (dof, dof).
    k_controllable: LazyArray,
    /// `J_cᵀ K_l J_c` (dof, dof).
    k_inherent: LazyArray,
    /// `K_q`, N m/rad (dof, dof).
    k_q: LazyArray,
    /// `K_W = ∂T0/∂Q`, N m/rad (dof, dof).
    k_w: LazyArray,
    /// `J_x`, linear rows first, base frame (6, dof).
    j_x: LazyArray,
    /// Whether `K_q + K_W` is positive definite.
    #[pyo3(get)]
    stable: bool,
    /// `λ_min` of the symmetric part of `K_q + K_W`, N m/rad (computed on first read).
    min_eigenvalue: OnceLock<f64>,
    /// `C_x` (6, 6), or None when unstable.
    c_x: Option<LazyArray>,
    /// `K_x = C_x⁻¹` (6, 6), or None when unstable or `J_x` is rank-deficient.
    k_x: Option<LazyArray>,
    /// `K_fd = K_x[0:3, 0:3]`, N/m (3, 3), or None.
    k_fd: Option<(Matrix3<f64>, LazyArray)>,
    /// The ellipsoid of `K_fd` (computed on first read; None without `K_fd`).
    ellipsoid: OnceLock<Option<Ellipsoid>>,
    /// Why some results are None (without the ellipsoid's note).
    notes: Vec<String>,
}

/// The stiffness ellipsoid's numbers as `ArmResult` gives them.
#[derive(Debug)]
struct Ellipsoid {
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
    ok: Py<PyAny>,
    /// Whether `K_q + K_W` is positive definite (N,) bool.
    stable: Py<PyAny>,
    /// (N,).
    min_eigenvalue: Py<PyAny>,
    /// (N, dof).
    t0: Py<PyAny>,
    /// (N, cables).
    tensions: Py<PyAny>,
    /// (N, 6, 6), NaN where unstable.
    c_x: Py<PyAny>,
    /// (N, 6, 6), NaN where unstable or rank-deficient.
    k_x: Py<PyAny>,
    /// (N, 3, 3).
    k_fd: Py<PyAny>,
    /// `(row, kind, message)` of every failed row.
    errors: Vec<(usize, String, String)>,
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
    objective: &'static str,
    /// The objective's value at the answer.
    value: f64,
    /// Certified: the optimum is within `gap` of `value`.
    gap: f64,
    /// The coordinates `λ` of the tensions in the equilibrium set.
    lambda_: Py<PyArray1<f64>>,
    /// Tension levels, when the routing has them, else None.
    levels: Option<Py<PyArray1<f64>>>,
    /// Tensions, N (cables,).
    tensions: Py<PyArray1<f64>>,
    /// Σ f, N.
    total_tension: f64,
    /// `K_fd` (3, 3), or None.
    k_fd: Option<Py<PyArray2<f64>>>,
    /// `C_x` (6, 6).
    c_x: Py<PyArray2<f64>>,
    /// `λ_min(K_q + K_W)`.
    min_eigenvalue: f64,
    /// Whether `min_eigenvalue > 0`.
    stable: bool,
    /// Iterations of the bundle method.
    iterations: usize,
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

/// A policy by its name.
pub fn policy(name: &str) -> PyResult<TensionPolicy> {
    TensionPolicy::ALL.into_iter().find(|p| p.name() == name).ok_or_else(|| {
        input(format!("policy: `{name}` is not one of least-total, least-norm, safest"))
    })
}

fn wrench_of(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Vector6<f64>> {
    match obj {
        Some(w) => Ok(Vector6::from_column_slice(&vector(w, "wrench", Some(6))?)),
        None => Ok(Vector6::zeros()),
    }
}

#[pymethods]
impl ArmStiffness {
    /// The model of `robot` with `routing`.
    #[new]
    fn new(robot: &Robot, routing: &Routing) -> PyResult<ArmStiffness> {
        let arm = sinew::stiffness::ArmStiffness::new(&robot.inner, &routing.inner)
            .map_err(library)?
            .checking_limits();
        let data = Mutex::new(ArmStiffnessData::new(&arm));
        Ok(ArmStiffness { arm, data, planner: OnceLock::new() })
    }

    /// Degrees of freedom.
    #[getter]
    fn dof(&self) -> usize {
        self.arm.dof()
    }

    /// The number of joints (the length of `levels`).
    #[getter]
    fn joints(&self) -> usize {
        self.arm.robot().joint_count()
    }

    /// The number of cables.
    #[getter]
    fn cables(&self) -> usize {
        self.arm.routing().cable_count()
    }

    /// Whether the routing takes the paper's tension levels (three cables per universal
    /// joint, common limits): the default of `evaluate` is then levels all 0.
    #[getter]
    fn has_levels(&self) -> bool {
        self.arm.statics().has_levels()
    }

    /// Evaluate the arm at `q` (rad) under `wrench` (N, N m; exerted by the end, base frame),
    /// the tensions chosen by one of `levels` (the closed form), `policy` (`"least-total"`,
    /// `"least-norm"`, `"safest"`) or `tensions` (given, checked); by default levels all 0
    /// where the routing takes them, else least-total, like `sinew arm`.
    ///
    /// An unstable equilibrium is a result (`stable` False, `c_x`/`k_x`/`k_fd` None).
    #[pyo3(signature = (q, wrench = None, levels = None, policy = None, tensions = None))]
    fn evaluate<'py>(
        &self,
        q: &Bound<'py, PyAny>,
        wrench: Option<&Bound<'py, PyAny>>,
        levels: Option<&Bound<'py, PyAny>>,
        policy: Option<&str>,
        tensions: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<ArmResult> {
        let arm = &self.arm;
        let q = vector(q, "q", Some(arm.dof()))?;
        let f0 = wrench_of(wrench)?;
        let joints = arm.robot().joint_count();
        let given = [levels.is_some(), policy.is_some(), tensions.is_some()];
        if given.iter().filter(|&&g| g).count() > 1 {
            return Err(input("give at most one of levels, policy and tensions"));
        }
        let levels = match levels {
            Some(l) => Some(vector(l, "levels", Some(joints))?),
            None => None,
        };
        let given_tensions = match tensions {
            Some(t) => Some(vector(t, "tensions", Some(arm.routing().cable_count()))?),
            None => None,
        };
        let choice = match (&levels, &given_tensions, policy) {
            (Some(l), _, _) => TensionChoice::Levels(l),
            (None, Some(t), _) => TensionChoice::Given(t),
            (None, None, Some(name)) => TensionChoice::Policy(self::policy(name)?),
            (None, None, None) => TensionChoice::Default,
        };
        let mut fresh;
        let mut guard = self.data.try_lock();
        let data: &mut ArmStiffnessData = match guard.as_deref_mut() {
            Ok(data) => data,
            Err(_) => {
                fresh = ArmStiffnessData::new(arm);
                &mut fresh
            }
        };
        let end = arm
            .evaluate_joints(data, &q, &f0, choice)
            .and_then(|()| arm.solve_end(data))
            .map_err(library)?;
        let (stable, full_rank) = (end.is_stable(), end.has_end_stiffness());
        // The ellipsoid's note is added when the ellipsoid is read (`notes`).
        let notes = end.note().iter().map(|n| n.text("None")).collect();
        let chosen = data.statics.chosen();
        // The default in closed form is every joint at level 0.
        let levels = match chosen {
            Chosen::Levels => Some(levels.unwrap_or_else(|| vec![0.0; joints])),
            _ => None,
        };
        let policy_name = chosen.name();
        let k_fd = full_rank.then(|| data.k_fd());
        let result = ArmResult {
            q: LazyArray::vector(&q),
            wrench: LazyArray::vector(f0.as_slice()),
            policy: policy_name,
            levels: levels.as_deref().map(LazyArray::vector),
            policy_objective: data.statics.distribution.as_ref().map(|d| d.objective),
            t0: LazyArray::vector(&data.statics.t0),
            tensions: LazyArray::vector(data.tensions()),
            lambda_intervals: levels.is_some().then(|| {
                let iv = data.intervals();
                let flat = iv.iter().flat_map(|i| [i.lambda_min, i.lambda_max]).collect();
                LazyArray::new(vec![iv.len(), 2], flat)
            }),
            k_controllable: LazyArray::faer(data.k_controllable()),
            k_inherent: LazyArray::faer(data.k_inherent()),
            k_q: LazyArray::faer(data.k_q()),
            k_w: LazyArray::faer(data.k_w()),
            j_x: LazyArray::faer(data.j_x()),
            stable,
            min_eigenvalue: OnceLock::new(),
            c_x: stable.then(|| LazyArray::faer(data.compliance())),
            k_x: full_rank.then(|| LazyArray::faer(data.stiffness())),
            k_fd: k_fd.map(|k| (k, LazyArray::nalgebra(&k))),
            ellipsoid: OnceLock::new(),
            notes,
        };
        Ok(result)
    }

    /// Evaluate every row of `Q` (N, dof) under one `wrench`, in parallel (the GIL released),
    /// the tensions by `levels` (one per joint, the same for every row) or `policy`; default
    /// as `evaluate`. A row that fails (outside the limits, NaN, infeasible) is NaN, `ok`
    /// False, its error in `errors`; an unstable row is `ok`, `stable` False. When every row
    /// of a non-empty batch fails, the first row's error is raised.
    #[pyo3(signature = (Q, wrench = None, levels = None, policy = None))]
    #[allow(non_snake_case)]
    fn evaluate_many<'py>(
        &self,
        py: Python<'py>,
        Q: &Bound<'py, PyAny>,
        wrench: Option<&Bound<'py, PyAny>>,
        levels: Option<&Bound<'py, PyAny>>,
        policy: Option<&str>,
    ) -> PyResult<BatchResult> {
        let arm = &self.arm;
        let dof = arm.dof();
        let (rows, q) = matrix(Q, "Q", dof)?;
        let f0 = wrench_of(wrench)?;
        let joints = arm.robot().joint_count();
        let choice = match (levels, policy) {
            (Some(_), Some(_)) => return Err(input("give at most one of levels and policy")),
            (Some(l), None) => BatchChoice::Levels(vector(l, "levels", Some(joints))?),
            (None, Some(p)) => BatchChoice::Policy(self::policy(p)?),
            (None, None) => BatchChoice::Default,
        };
        let batch = py.detach(|| evaluate_many(arm, &q, &f0, &choice));
        if let Some((_, kind, message)) = batch.errors.first()
            && batch.errors.len() == rows
        {
            return Err(exception(*kind, format!("every row failed; row 0: {message}")));
        }
        let cables = batch.cables;
        let bools = |v: &[bool]| numpy_bool(py, v);
        Ok(BatchResult {
            ok: bools(&batch.ok)?,
            stable: bools(&batch.stable)?,
            min_eigenvalue: vec1(py, &batch.min_eigenvalue).into_any().unbind(),
            t0: reshape(vec1(py, &batch.t0), &[rows, dof])?.unbind(),
            tensions: reshape(vec1(py, &batch.tensions), &[rows, cables])?.unbind(),
            c_x: reshape(vec1(py, &batch.c_x), &[rows, 6, 6])?.unbind(),
            k_x: reshape(vec1(py, &batch.k_x), &[rows, 6, 6])?.unbind(),
            k_fd: reshape(vec1(py, &batch.k_fd), &[rows, 3, 3])?.unbind(),
            errors: batch
                .errors
                .into_iter()
                .map(|(r, kind, message)| (r, kind.to_string(), message))
                .collect(),
        })
    }

    /// The tensions that optimise the end stiffness at `q` under `wrench` (`sinew plan`):
    /// `objective` one of `"stiffness-along"` and `"compliance-along"` (with `direction`),
    /// `"min-stiffness"`, `"volume"`, `"least-tension"`; requirements `k_min` (N/m), `k_des`
    /// (3 × 3, N/m), `margin` (N m/rad), `budget` (N), `joint_budgets` (`{joint: N}`,
    /// 0-based), `fixed_levels` (`{joint: level}`, 0-based, decoupled model); `gap` the
    /// relative gap at which it stops. The GIL is released while it runs.
    #[pyo3(signature = (q, wrench = None, objective = "min-stiffness", direction = None, k_min = None, k_des = None, margin = 1e-3, budget = None, joint_budgets = None, fixed_levels = None, gap = 1e-6))]
    fn plan<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        wrench: Option<&Bound<'py, PyAny>>,
        objective: &str,
        direction: Option<&Bound<'py, PyAny>>,
        k_min: Option<f64>,
        k_des: Option<&Bound<'py, PyAny>>,
        margin: f64,
        budget: Option<f64>,
        joint_budgets: Option<std::collections::BTreeMap<usize, f64>>,
        fixed_levels: Option<std::collections::BTreeMap<usize, f64>>,
        gap: f64,
    ) -> PyResult<PlanResult> {
        let arm = &self.arm;
        // The planner's pose stage refuses angles outside the limits.
        let q = vector(q, "q", Some(arm.dof()))?;
        let f0 = wrench_of(wrench)?;
        let direction = match direction {
            Some(d) => {
                let u = vector(d, "direction", Some(3))?;
                let u = Vector3::new(u[0], u[1], u[2]);
                let n = u.norm();
                if !(n.is_finite() && n > 0.0) {
                    return Err(input("direction: must be a finite, non-zero vector"));
                }
                Some(u / n)
            }
            None => None,
        };
        let need = |what: &str| {
            direction.ok_or_else(|| input(format!("objective {what} needs a direction")))
        };
        let objective = match objective {
            "stiffness-along" => Objective::StiffnessAlong(need("stiffness-along")?),
            "compliance-along" => Objective::ComplianceAlong(need("compliance-along")?),
            "min-stiffness" => Objective::MinStiffness,
            "volume" => Objective::Volume,
            "least-tension" => Objective::LeastTension,
            other => {
                return Err(input(format!(
                    "objective: `{other}` is not one of stiffness-along, compliance-along, min-stiffness, volume, least-tension"
                )));
            }
        };
        let k_des = match k_des {
            Some(k) => {
                let (rows, v) = matrix(k, "k_des", 3)?;
                if rows != 3 {
                    return Err(input(format!("k_des: expected shape (3, 3), got ({rows}, 3)")));
                }
                finite(&v, "k_des")?;
                Some(Matrix3::from_row_slice(&v))
            }
            None => None,
        };
        let requirements = Requirements {
            margin,
            budget,
            k_min,
            k_des,
            joint_budgets: joint_budgets.unwrap_or_default().into_iter().collect(),
            fixed_levels: fixed_levels.unwrap_or_default().into_iter().collect(),
        };
        let settings = PlanSettings { relative_gap: gap, ..PlanSettings::default() };
        let (planner, data) = self.planner.get_or_init(|| {
            let planner = Planner::new(arm.clone());
            let data = Mutex::new(PlannerData::new(&planner));
            (planner, data)
        });
        let plan = py
            .detach(|| {
                let mut fresh;
                let mut guard = data.try_lock();
                let data: &mut PlannerData = match guard.as_deref_mut() {
                    Ok(data) => data,
                    Err(_) => {
                        fresh = PlannerData::new(planner);
                        &mut fresh
                    }
                };
                planner.plan(data, &q, &f0, objective, &requirements, &settings)
            })
            .map_err(library)?;
        Ok(PlanResult {
            objective: objective.name(),
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
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "sinew.ArmStiffness(robot={:?}, dof={}, cables={}, decoupled={})",
            self.arm.robot().name(),
            self.arm.dof(),
            self.arm.routing().cable_count(),
            self.arm.routing().is_decoupled()
        )
    }
}

/// A numpy bool array from a slice.
fn numpy_bool(py: Python<'_>, v: &[bool]) -> PyResult<Py<PyAny>> {
    Ok(PyArray1::from_slice(py, v).into_any().unbind())
}
