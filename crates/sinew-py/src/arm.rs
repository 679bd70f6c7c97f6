//! `sinew.ArmStiffness`: the whole arm in a pose under a load (eq. 5–21), one configuration
//! (`evaluate`), many in parallel (`evaluate_many`), and the tension planner (`plan`, and
//! `plan_many` over many poses). It pickles by value: its robot and routing, which carry
//! their files' texts (`model.rs`).

use std::sync::{Mutex, OnceLock};

use std::collections::BTreeMap;

use nalgebra::Vector6;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sinew::planner::{Planner, PlannerData};
use sinew::statics::{Chosen, TensionChoice, TensionPolicy};
use sinew::stiffness::ArmStiffnessData;

use crate::batch::BatchChoice;
use crate::batch_out::evaluate_to_numpy;
use crate::convert::{matrix, vector, wrenches};
use crate::errors::{input, library};
use crate::friction::{FrictionArgs, evaluate_friction, requested, stick_requested};
use crate::lazy::LazyArray;
use crate::model::{Robot, Routing};
use crate::plan_along::along_result;
use crate::plan_args::plan_args;
use crate::plan_many::{PlanBatchResult, plan_many};
use crate::pool::{run, threads_arg};
use crate::results::{ArmResult, BatchResult, PlanResult};

/// The model of the pipeline `Q → K_x` for a robot and a routing (Pinocchio's model), with
/// its own workspace (Pinocchio's data) for `evaluate`.
#[pyclass(module = "sinew", frozen)]
#[derive(Debug)]
pub struct ArmStiffness {
    /// What it was built from: what it pickles as.
    robot: Py<Robot>,
    routing: Py<Routing>,
    arm: sinew::stiffness::ArmStiffness,
    data: Mutex<ArmStiffnessData>,
    planner: OnceLock<(Planner, Mutex<PlannerData>)>,
}

/// What `ArmStiffness` pickles as: the class and its constructor's arguments.
type Reduced = (Py<PyAny>, (Py<Robot>, Py<Routing>));

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
    fn new(robot: &Bound<'_, Robot>, routing: &Bound<'_, Routing>) -> PyResult<ArmStiffness> {
        let (r, c) = (robot.get(), routing.get());
        let arm = sinew::stiffness::ArmStiffness::new(&r.inner, &c.inner)
            .map_err(library)?
            .checking_limits();
        let data = Mutex::new(ArmStiffnessData::new(&arm));
        Ok(ArmStiffness {
            robot: robot.clone().unbind(),
            routing: routing.clone().unbind(),
            arm,
            data,
            planner: OnceLock::new(),
        })
    }

    /// Pickling by value: `ArmStiffness(robot, routing)`, whose robot and routing pickle as
    /// their files' texts (never a path). The copy evaluates bit for bit like the original.
    fn __reduce__(&self, py: Python<'_>) -> PyResult<Reduced> {
        let class = py.get_type::<ArmStiffness>().into_any().unbind();
        Ok((class, (self.robot.clone_ref(py), self.routing.clone_ref(py))))
    }

    /// The robot.
    #[getter]
    fn robot(&self, py: Python<'_>) -> Py<Robot> {
        self.robot.clone_ref(py)
    }

    /// The routing.
    #[getter]
    fn routing(&self, py: Python<'_>) -> Py<Routing> {
        self.routing.clone_ref(py)
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
    /// An unstable equilibrium is a result (`stable` False, `c_x`/`k_x`/`k_fd` None), as
    /// `sinew arm` reports it; with `require_stiffness=True` it raises `UnstableError`, and a
    /// rank-deficient `J_x` (`k_x` None) raises `RankDeficientError`, with the library's
    /// message (as Rust's `ArmStiffness::evaluate` returns them).
    ///
    /// With friction at the holes (spec §9): `friction` (μ at every hole, overriding the
    /// routing file's), `regime` (`"pull"`, `"release"` or `"stick"`, the default), `history`
    /// (the stick regime's: `"pull"`, the default, `"release"` or `"equal"`) and `direction`
    /// (the directional response's force, default the load's) answer a `FrictionResult`, as
    /// `sinew arm --friction` does; μ = 0 everywhere without `regime="stick"` is the
    /// frictionless `ArmResult`.
    #[pyo3(signature = (q, wrench = None, levels = None, policy = None, tensions = None, require_stiffness = false, friction = None, regime = None, history = None, direction = None))]
    #[allow(clippy::too_many_arguments)]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        wrench: Option<&Bound<'py, PyAny>>,
        levels: Option<&Bound<'py, PyAny>>,
        policy: Option<&str>,
        tensions: Option<&Bound<'py, PyAny>>,
        require_stiffness: bool,
        friction: Option<f64>,
        regime: Option<&str>,
        history: Option<&str>,
        direction: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Py<PyAny>> {
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
        let asked = FrictionArgs { mu: friction, regime, history, direction };
        if let Some((model, regime)) = requested(&asked, arm.routing())? {
            let (pose, how) = ((&q[..], &f0), (choice, require_stiffness));
            let out = evaluate_friction(py, (arm, data), (&model, regime), pose, how, direction)?;
            return Ok(Py::new(py, out)?.into_any());
        }
        // The Rust part with the GIL released (microseconds for cdhrm5, more for long chains).
        let end = py.detach(|| -> PyResult<_> {
            arm.evaluate_joints(data, &q, &f0, choice).map_err(library)?;
            let end = arm.solve_end(data).map_err(library)?;
            if require_stiffness {
                end.into_result().map_err(library)?;
            }
            let notes: Vec<String> = end.note().iter().map(|n| n.text("None")).collect();
            Ok((end.is_stable(), end.has_end_stiffness(), notes))
        });
        let (stable, full_rank, notes) = end?;
        // The ellipsoid's note is added when the ellipsoid is read (`notes`).
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
        Ok(Py::new(py, result)?.into_any())
    }

    /// Evaluate every row of `Q` (N, dof) under `wrench` (one (6,) for every row, or (N, 6)),
    /// in parallel with the GIL released: on `threads` threads of a pool of its own, or on
    /// every core (rayon's global pool) without. The tensions by `levels` (one per joint, the
    /// same for every row) or `policy`; default as `evaluate`. A row that fails (outside the
    /// limits, NaN, infeasible) is NaN, `ok` False, its error in `errors`; an unstable row is
    /// `ok`, `stable` False. When every row of a non-empty batch fails, the first row's error
    /// is raised (unless `raise_if_all_fail` is False). `out` (a dict of field names to
    /// writable C-contiguous arrays of the result's shapes) receives those fields in place.
    #[pyo3(signature = (Q, wrench = None, levels = None, policy = None, threads = None, raise_if_all_fail = true, out = None))]
    #[allow(non_snake_case)]
    fn evaluate_many<'py>(
        &self,
        py: Python<'py>,
        Q: &Bound<'py, PyAny>,
        wrench: Option<&Bound<'py, PyAny>>,
        levels: Option<&Bound<'py, PyAny>>,
        policy: Option<&str>,
        threads: Option<i64>,
        raise_if_all_fail: bool,
        out: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<BatchResult> {
        let arm = &self.arm;
        let dof = arm.dof();
        let (rows, q) = matrix(Q, "Q", dof)?;
        let f0 = wrenches(wrench, rows)?;
        let threads = threads_arg(threads)?;
        let joints = arm.robot().joint_count();
        let choice = match (levels, policy) {
            (Some(_), Some(_)) => return Err(input("give at most one of levels and policy")),
            (Some(l), None) => BatchChoice::Levels(vector(l, "levels", Some(joints))?),
            (None, Some(p)) => BatchChoice::Policy(self::policy(p)?),
            (None, None) => BatchChoice::Default,
        };
        evaluate_to_numpy(py, arm, &q, &f0, &choice, threads, out, raise_if_all_fail)
    }

    /// The tensions that optimise the end stiffness at `q` under `wrench` (`sinew plan`):
    /// `objective` one of `"stiffness-along"` and `"compliance-along"` (with `direction`),
    /// `"min-stiffness"`, `"volume"`, `"least-tension"`; requirements `k_min` (N/m), `k_des`
    /// (3 × 3, N/m), `margin` (N m/rad), `budget` (N), `joint_budgets` (`{joint: N}`,
    /// 0-based), `fixed_levels` (`{joint: level}`, 0-based, decoupled model); `gap` the
    /// relative gap at which it stops. With friction at the holes (`friction` μ, `history`;
    /// `regime` `"stick"`, the only one planned): the stick regime's plan
    /// (`Planner::plan_in_stick`, as `sinew plan --friction`). The GIL is released while it runs.
    #[pyo3(signature = (q, wrench = None, objective = "min-stiffness", direction = None, k_min = None, k_des = None, margin = 1e-3, budget = None, joint_budgets = None, fixed_levels = None, gap = 1e-6, friction = None, regime = None, history = None))]
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
        joint_budgets: Option<BTreeMap<usize, f64>>,
        fixed_levels: Option<BTreeMap<usize, f64>>,
        gap: f64,
        friction: Option<f64>,
        regime: Option<&str>,
        history: Option<&str>,
    ) -> PyResult<PlanResult> {
        let arm = &self.arm;
        let asked = FrictionArgs { mu: friction, regime, history, direction: None };
        let stick = stick_requested(&asked, arm.routing())?;
        // The planner's pose stage refuses angles outside the limits.
        let q = vector(q, "q", Some(arm.dof()))?;
        let f0 = wrench_of(wrench)?;
        let args = plan_args(
            objective,
            direction,
            k_min,
            k_des,
            margin,
            budget,
            joint_budgets,
            fixed_levels,
            gap,
        )?;
        let (planner, data) = self.planner();
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
                args.plan((planner, data), stick.as_ref(), &q, &f0)
            })
            .map_err(library)?;
        Ok(PlanResult::new(py, &plan))
    }

    /// `plan` at every row of `Q` (N, dof) under `wrench` (one (6,) for every row, or (N, 6)),
    /// with the same objective and requirements: the poses are independent and planned in
    /// parallel with the GIL released, on `threads` threads (a pool of its own) or every core.
    /// One row per pose; a row that fails (outside the limits, infeasible, no stable tensions,
    /// a requirement unreachable) is NaN, `ok` False, its error in `errors`. When every row
    /// of a non-empty batch fails, the first row's error is raised (unless
    /// `raise_if_all_fail` is False).
    #[pyo3(signature = (Q, wrench = None, objective = "min-stiffness", direction = None, k_min = None, k_des = None, margin = 1e-3, budget = None, joint_budgets = None, fixed_levels = None, gap = 1e-6, threads = None, raise_if_all_fail = true))]
    #[allow(non_snake_case)]
    fn plan_many<'py>(
        &self,
        py: Python<'py>,
        Q: &Bound<'py, PyAny>,
        wrench: Option<&Bound<'py, PyAny>>,
        objective: &str,
        direction: Option<&Bound<'py, PyAny>>,
        k_min: Option<f64>,
        k_des: Option<&Bound<'py, PyAny>>,
        margin: f64,
        budget: Option<f64>,
        joint_budgets: Option<BTreeMap<usize, f64>>,
        fixed_levels: Option<BTreeMap<usize, f64>>,
        gap: f64,
        threads: Option<i64>,
        raise_if_all_fail: bool,
    ) -> PyResult<PlanBatchResult> {
        let (rows, q) = matrix(Q, "Q", self.arm.dof())?;
        let f0 = wrenches(wrench, rows)?;
        let threads = threads_arg(threads)?;
        let args = plan_args(
            objective,
            direction,
            k_min,
            k_des,
            margin,
            budget,
            joint_budgets,
            fixed_levels,
            gap,
        )?;
        let (planner, _) = self.planner();
        let batch = py.detach(|| run(threads, || plan_many(planner, &q, &f0, &args)))?;
        let has_levels = self.arm.statics().has_levels();
        PlanBatchResult::new(py, args.objective.name(), batch, has_levels, raise_if_all_fail)
    }

    /// One plan per row of `Q`, each warm-started from the one before; `max_rate` (N/s) and `dt`
    /// (s) bound each cable's change per step (module docs of `plan_along.rs`).
    #[pyo3(signature = (Q, wrench = None, objective = "min-stiffness", direction = None, k_min = None, k_des = None, margin = 1e-3, budget = None, joint_budgets = None, gap = 1e-6, max_rate = None, dt = None))]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    fn plan_along<'py>(
        &self,
        py: Python<'py>,
        Q: &Bound<'py, PyAny>,
        wrench: Option<&Bound<'py, PyAny>>,
        objective: &str,
        direction: Option<&Bound<'py, PyAny>>,
        k_min: Option<f64>,
        k_des: Option<&Bound<'py, PyAny>>,
        margin: f64,
        budget: Option<f64>,
        joint_budgets: Option<BTreeMap<usize, f64>>,
        gap: f64,
        max_rate: Option<f64>,
        dt: Option<f64>,
    ) -> PyResult<PlanBatchResult> {
        let args = plan_args(
            objective,
            direction,
            k_min,
            k_des,
            margin,
            budget,
            joint_budgets,
            None,
            gap,
        )?;
        along_result(py, self.planner(), (Q, wrench), &args, (max_rate, dt))
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

impl ArmStiffness {
    /// The planner of this arm and its workspace for `plan`, made on first use.
    fn planner(&self) -> &(Planner, Mutex<PlannerData>) {
        self.planner.get_or_init(|| {
            let planner = Planner::new(self.arm.clone());
            let data = Mutex::new(PlannerData::new(&planner));
            (planner, data)
        })
    }
}
