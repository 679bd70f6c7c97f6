//! `sinew.ArmStiffness`: the whole arm in a pose under a load (eq. 5–21), one configuration
//! (`evaluate`), many in parallel (`evaluate_many`), and the tension planner (`plan`).

use std::sync::{Mutex, OnceLock};

use nalgebra::{Matrix3, Vector3, Vector6};
use numpy::PyArray1;
use pyo3::prelude::*;
use sinew::planner::{Objective, PlanSettings, Planner, PlannerData, Requirements};
use sinew::statics::{Chosen, TensionChoice, TensionPolicy};
use sinew::stiffness::ArmStiffnessData;

use crate::batch::{BatchChoice, evaluate_many};
use crate::convert::{finite, matrix, na2, reshape, vec1, vector};
use crate::errors::{exception, input, library};
use crate::lazy::LazyArray;
use crate::model::{Robot, Routing};
use crate::results::{ArmResult, BatchResult, PlanResult};

/// The model of the pipeline `Q → K_x` for a robot and a routing (Pinocchio's model), with
/// its own workspace (Pinocchio's data) for `evaluate`.
#[pyclass(module = "sinew", frozen)]
#[derive(Debug)]
pub struct ArmStiffness {
    arm: sinew::stiffness::ArmStiffness,
    data: Mutex<ArmStiffnessData>,
    planner: OnceLock<(Planner, Mutex<PlannerData>)>,
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
        arm.evaluate_joints(data, &q, &f0, choice).map_err(library)?;
        let end = arm.solve_end(data).map_err(library)?;
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
