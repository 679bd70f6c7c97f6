//! `sinew.ArmStiffness`: the whole arm in a pose under a load (eq. 5–21), one configuration
//! (`evaluate`), many in parallel (`evaluate_many`), and the tension planner (`plan`).

use std::sync::{Mutex, OnceLock};

use nalgebra::{Matrix3, Vector3, Vector6};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use sinew::indicators::StiffnessEllipsoid;
use sinew::planner::{Objective, PlanSettings, Planner, PlannerData, Requirements};
use sinew::statics::{TensionChoice, TensionPolicy};
use sinew::stiffness::{ArmStiffnessData, StiffnessError};

use crate::batch::{BatchChoice, evaluate_many};
use crate::convert::{faer2, finite, matrix, na2, reshape, vec1, vector};
use crate::errors::{exception, input, library};
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

/// The result of `ArmStiffness.evaluate`: numpy arrays (SI units) and floats.
#[pyclass(module = "sinew", frozen, get_all)]
#[derive(Debug)]
pub struct ArmResult {
    /// The configuration, rad (dof,).
    q: Py<PyArray1<f64>>,
    /// The wrench the end exerts, base frame, force first (6,).
    wrench: Py<PyArray1<f64>>,
    /// `"levels"`, `"given"` or the policy's name.
    policy: &'static str,
    /// The tension levels (joints,), or None.
    levels: Option<Py<PyArray1<f64>>>,
    /// The policy's objective (Σ f, |f| or the least distance to a limit, N), or None.
    policy_objective: Option<f64>,
    /// `T0 = T_g + J_xᵀ F0`, N m (dof,).
    t0: Py<PyArray1<f64>>,
    /// Tensions, N, routing order (cables,).
    tensions: Py<PyArray1<f64>>,
    /// Per joint `[λ_min, λ_max]` of the closed form (joints, 2), or None.
    lambda_intervals: Option<Py<PyArray2<f64>>>,
    /// `Σ f_c H_c` (dof, dof).
    k_controllable: Py<PyArray2<f64>>,
    /// `J_cᵀ K_l J_c` (dof, dof).
    k_inherent: Py<PyArray2<f64>>,
    /// `K_q`, N m/rad (dof, dof).
    k_q: Py<PyArray2<f64>>,
    /// `K_W = ∂T0/∂Q`, N m/rad (dof, dof).
    k_w: Py<PyArray2<f64>>,
    /// `J_x`, linear rows first, base frame (6, dof).
    j_x: Py<PyArray2<f64>>,
    /// Whether `K_q + K_W` is positive definite.
    stable: bool,
    /// `λ_min` of the symmetric part of `K_q + K_W`, N m/rad.
    min_eigenvalue: f64,
    /// `C_x` (6, 6), or None when unstable.
    c_x: Option<Py<PyArray2<f64>>>,
    /// `K_x = C_x⁻¹` (6, 6), or None when unstable or `J_x` is rank-deficient.
    k_x: Option<Py<PyArray2<f64>>>,
    /// `K_fd = K_x[0:3, 0:3]`, N/m (3, 3), or None.
    k_fd: Option<Py<PyArray2<f64>>>,
    /// The ellipsoid's eigenvalues of `K_fd`, ascending, N/m (3,), or None.
    eigenvalues: Option<Py<PyArray1<f64>>>,
    /// `directions[k]`: the unit principal direction of `eigenvalues[k]` (3, 3), or None.
    directions: Option<Py<PyArray2<f64>>>,
    /// `1/λ_k`, m/N (3,), or None unless `K_fd` is positive definite.
    semi_axes: Option<Py<PyArray1<f64>>>,
    /// `λ_max / λ_min` of `K_fd`, or None.
    condition_number: Option<f64>,
    /// `4π/3 · Π 1/λ_k`, m³/N³, or None.
    volume: Option<f64>,
    /// Why some results are None.
    notes: Vec<String>,
}

#[pymethods]
impl ArmResult {
    fn __repr__(&self) -> String {
        format!(
            "sinew.ArmResult(stable={}, min_eigenvalue={:e}, policy={:?})",
            self.stable, self.min_eigenvalue, self.policy
        )
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
        let arm =
            sinew::stiffness::ArmStiffness::new(&robot.inner, &routing.inner).map_err(library)?;
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
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        wrench: Option<&Bound<'py, PyAny>>,
        levels: Option<&Bound<'py, PyAny>>,
        policy: Option<&str>,
        tensions: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<ArmResult> {
        let arm = &self.arm;
        let q = vector(q, "q", Some(arm.dof()))?;
        arm.robot().check_limits(&q).map_err(library)?;
        let f0 = wrench_of(wrench)?;
        let joints = arm.robot().joint_count();
        let given = [levels.is_some(), policy.is_some(), tensions.is_some()];
        if given.iter().filter(|&&g| g).count() > 1 {
            return Err(input("give at most one of levels, policy and tensions"));
        }
        let levels = match levels {
            Some(l) => Some(vector(l, "levels", Some(joints))?),
            None if policy.is_none() && tensions.is_none() && arm.statics().has_levels() => {
                Some(vec![0.0; joints])
            }
            None => None,
        };
        let given_tensions = match tensions {
            Some(t) => Some(vector(t, "tensions", Some(arm.routing().cable_count()))?),
            None => None,
        };
        let chosen_policy = match policy {
            Some(name) => self::policy(name)?,
            None => TensionPolicy::LeastTotal,
        };
        let (choice, policy_name) = match (&levels, &given_tensions) {
            (Some(l), _) => (TensionChoice::Levels(l), "levels"),
            (None, Some(t)) => (TensionChoice::Given(t), "given"),
            (None, None) => (TensionChoice::Policy(chosen_policy), chosen_policy.name()),
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
        let mut notes = Vec::new();
        let (stable, full_rank) = match arm.evaluate_with(data, &q, &f0, choice) {
            Ok(()) => (true, true),
            Err(StiffnessError::Unstable { .. }) => {
                notes.push(
                    "unstable equilibrium: K_q + K_W is not positive definite (min_eigenvalue < 0), \
                     so C_x, K_x, K_fd and the ellipsoid do not exist"
                        .to_owned(),
                );
                (false, false)
            }
            Err(e @ StiffnessError::RankDeficient { .. }) => {
                notes.push(format!("{e}: k_x, k_fd and the ellipsoid are None"));
                (true, false)
            }
            Err(e) => return Err(library(e)),
        };
        let min_eigenvalue = data.stability_margin().map_err(library)?;
        let unbind = |a: Bound<'py, PyArray2<f64>>| a.unbind();
        let c_x = stable.then(|| unbind(faer2(py, data.compliance())));
        let mut result = ArmResult {
            q: vec1(py, &q).unbind(),
            wrench: vec1(py, f0.as_slice()).unbind(),
            policy: policy_name,
            levels: levels.as_ref().map(|l| vec1(py, l).unbind()),
            policy_objective: data.statics.distribution.as_ref().map(|d| d.objective),
            t0: vec1(py, &data.statics.t0).unbind(),
            tensions: vec1(py, data.tensions()).unbind(),
            lambda_intervals: None,
            k_controllable: unbind(faer2(py, data.k_controllable())),
            k_inherent: unbind(faer2(py, data.k_inherent())),
            k_q: unbind(faer2(py, data.k_q())),
            k_w: unbind(faer2(py, data.k_w())),
            j_x: unbind(faer2(py, data.j_x())),
            stable,
            min_eigenvalue,
            c_x,
            k_x: None,
            k_fd: None,
            eigenvalues: None,
            directions: None,
            semi_axes: None,
            condition_number: None,
            volume: None,
            notes,
        };
        if levels.is_some() {
            let iv = data.intervals();
            let flat = iv.iter().flat_map(|i| [i.lambda_min, i.lambda_max]).collect();
            result.lambda_intervals = Some(crate::convert::vec2(py, iv.len(), 2, flat)?.unbind());
        }
        if full_rank {
            let k_fd = data.k_fd();
            let ellipsoid = StiffnessEllipsoid::new(&k_fd).map_err(library)?;
            result.k_x = Some(unbind(faer2(py, data.stiffness())));
            result.k_fd = Some(unbind(na2(py, &k_fd)));
            result.eigenvalues = Some(vec1(py, ellipsoid.eigenvalues.as_slice()).unbind());
            result.directions = Some(unbind(na2(py, &ellipsoid.directions.transpose())));
            result.semi_axes = ellipsoid.semi_axes().map(|a| vec1(py, a.as_slice()).unbind());
            result.condition_number = ellipsoid.condition_number();
            result.volume = ellipsoid.volume();
            if !ellipsoid.is_positive_definite() {
                result.notes.push(
                    "K_fd is not positive definite: the ellipsoid's semi-axes, condition number and volume are None"
                        .to_owned(),
                );
            }
        }
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
            (None, None) if arm.statics().has_levels() => BatchChoice::Levels(vec![0.0; joints]),
            (None, None) => BatchChoice::Policy(TensionPolicy::LeastTotal),
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
        let q = vector(q, "q", Some(arm.dof()))?;
        arm.robot().check_limits(&q).map_err(library)?;
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
