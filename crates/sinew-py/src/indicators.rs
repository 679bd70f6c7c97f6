//! The single joint alone (`sinew.joint_range`, eq. 20–23) and its Fig. 5 maps over a grid of
//! its two angles (`sinew.sweep`, in parallel with the GIL released).

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use sinew::indicators::{AngleGrid, JointProbe, sweep_probe};

use crate::convert::{na2, vec1, vec2, vector};
use crate::errors::{input, library};
use crate::friction::{FrictionArgs, name, requested};
use crate::model::{Robot, Routing};
use crate::pool::{run, threads_arg};

/// The most grid points per axis (as `sinew sweep`).
const MAX_GRID_POINTS: usize = 1001;

/// One universal joint alone (the other joints at 0), over its feasible tension interval.
#[pyclass(module = "sinew", frozen, get_all)]
#[derive(Debug)]
pub struct JointRange {
    /// 0-based.
    joint: usize,
    /// The joint's own three cables (the order of `tensions`' columns).
    cables: Vec<String>,
    /// `[q1, q2]`, rad.
    q: Py<PyArray1<f64>>,
    /// `[T1, T2]`, N m.
    torque: Py<PyArray1<f64>>,
    /// `[λ_min, λ_max]`.
    lambda_: Py<PyArray1<f64>>,
    /// `f_p`, the minimum-norm tensions, N (3,).
    particular: Py<PyArray1<f64>>,
    /// The unit null direction of `J_cᵀ` (3,).
    null_direction: Py<PyArray1<f64>>,
    /// Whether the cables are in force closure here.
    force_closure: bool,
    /// Tensions at `λ_min` (row 0) and `λ_max` (row 1), N (2, 3).
    tensions: Py<PyArray2<f64>>,
    /// `K` at `λ_min`, N m/rad (2, 2).
    k_at_min: Py<PyArray2<f64>>,
    /// `K` at `λ_max`, N m/rad (2, 2).
    k_at_max: Py<PyArray2<f64>>,
    /// The inherent part `J_cᵀ K_l J_c` (2, 2).
    k_inherent: Py<PyArray2<f64>>,
    /// `σ_x`: `[K_x min, K_x max]`, N m/rad (eq. 20).
    sigma_x: Py<PyArray1<f64>>,
    /// `σ_y`: `[K_y min, K_y max]`, N m/rad.
    sigma_y: Py<PyArray1<f64>>,
    /// `Δk` of `σ_x`.
    delta_x: f64,
    /// `Δk` of `σ_y`.
    delta_y: f64,
}

#[pymethods]
impl JointRange {
    /// `[λ_min, λ_max]`.
    #[getter(r#lambda)]
    fn lambda_alias(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.lambda_.clone_ref(py)
    }
}

/// The Fig. 5 maps of one joint: `k_x_min[a, b]` at `q = [angles[a], angles[b]]`, NaN where
/// the torque cannot be held.
#[pyclass(module = "sinew", frozen, get_all)]
#[derive(Debug)]
pub struct SweepResult {
    /// 0-based.
    joint: usize,
    /// `[T1, T2]`, N m.
    torque: Py<PyArray1<f64>>,
    /// The grid's angles, rad (points,), the same on both axes.
    angles: Py<PyArray1<f64>>,
    /// Where the torque can be held (points, points) bool.
    feasible: Py<PyAny>,
    /// (points, points), N m/rad.
    k_x_min: Py<PyArray2<f64>>,
    /// (points, points).
    k_x_max: Py<PyArray2<f64>>,
    /// (points, points).
    k_y_min: Py<PyArray2<f64>>,
    /// (points, points).
    k_y_max: Py<PyArray2<f64>>,
    /// With friction at the holes: `"pull"`, `"release"` or `"stick"`; `None` without.
    regime: Option<&'static str>,
    /// The stick regime's history (`"pull"`, `"release"`, `"equal"`), else `None`.
    history: Option<&'static str>,
    /// μ of each cable with friction (m,), `None` without.
    mu: Option<Py<PyArray1<f64>>>,
}

fn torque_of(torque: &Bound<'_, PyAny>) -> PyResult<[f64; 2]> {
    let t = vector(torque, "torque", Some(2))?;
    Ok([t[0], t[1]])
}

/// Universal joint `joint` (0-based) alone at its angles `q` (2,) under `torque` (2,):
/// the feasible tension interval, `K` at both ends, `σ_x`, `σ_y` (`sinew joint`).
#[pyfunction]
pub fn joint_range(
    py: Python<'_>,
    robot: &Robot,
    routing: &Routing,
    joint: usize,
    q: &Bound<'_, PyAny>,
    torque: &Bound<'_, PyAny>,
) -> PyResult<JointRange> {
    let (r, c) = (&*robot.inner, &*routing.inner);
    let mut probe = JointProbe::new(r, c, joint).map_err(library)?;
    let qv = vector(q, "q", Some(2))?;
    let tau = torque_of(torque)?;
    let range = probe.evaluate(r, c, [qv[0], qv[1]], tau).map_err(library)?;
    let iv = &range.interval;
    let [lo, hi] = range.tensions;
    let cables = probe.tensioned_cables().map(|k| c.cables()[k].name.clone()).collect();
    let tensions: Vec<f64> = lo.iter().chain(hi.iter()).copied().collect();
    let (sx, sy) = (range.sigma_x(), range.sigma_y());
    Ok(JointRange {
        joint,
        cables,
        q: vec1(py, &qv).unbind(),
        torque: vec1(py, &tau).unbind(),
        lambda_: vec1(py, &[iv.lambda_min, iv.lambda_max]).unbind(),
        particular: vec1(py, iv.particular.as_slice()).unbind(),
        null_direction: vec1(py, iv.null.as_slice()).unbind(),
        force_closure: iv.force_closure(),
        tensions: vec2(py, 2, lo.len(), tensions)?.unbind(),
        k_at_min: na2(py, &range.k_at_min).unbind(),
        k_at_max: na2(py, &range.k_at_max).unbind(),
        k_inherent: na2(py, &range.inherent).unbind(),
        sigma_x: vec1(py, &sx.range).unbind(),
        sigma_y: vec1(py, &sy.range).unbind(),
        delta_x: sx.delta,
        delta_y: sy.delta,
    })
}

/// The maps of joint `joint` (0-based) over a `points × points` grid of its two angles under
/// `torque` (Fig. 5; `sinew sweep`), in parallel with the GIL released. The grid spans the
/// range both of the joint's axes allow, unless `lower`/`upper` (rad) narrow it. On `threads`
/// threads (a pool of its own), or every core (rayon's global pool) without. With friction at
/// the holes (`friction` μ, `regime`, `history`, or μ from the routing file: spec §9), the
/// regime's statics (actuator tensions) and joint stiffness, as `sinew sweep --friction`.
#[pyfunction]
#[pyo3(signature = (robot, routing, joint, torque, points = 41, lower = None, upper = None, threads = None, friction = None, regime = None, history = None))]
#[allow(clippy::too_many_arguments)]
pub fn sweep(
    py: Python<'_>,
    robot: &Robot,
    routing: &Routing,
    joint: usize,
    torque: &Bound<'_, PyAny>,
    points: usize,
    lower: Option<f64>,
    upper: Option<f64>,
    threads: Option<i64>,
    friction: Option<f64>,
    regime: Option<&str>,
    history: Option<&str>,
) -> PyResult<SweepResult> {
    let threads = threads_arg(threads)?;
    let (r, c) = (&*robot.inner, &*routing.inner);
    let asked = FrictionArgs { mu: friction, regime, history, direction: None };
    let friction = requested(&asked, c)?;
    let tau = torque_of(torque)?;
    if points > MAX_GRID_POINTS {
        return Err(input(format!(
            "points {points}: at most {MAX_GRID_POINTS} points per axis (time and memory grow as points²)"
        )));
    }
    let mut probe = JointProbe::new(r, c, joint).map_err(library)?;
    let mu = friction.as_ref().map(|(model, _)| vec1(py, model.friction_coefficients()).unbind());
    let (regime, history) = friction.as_ref().map_or((None, None), |&(_, regime)| {
        let (regime, history) = name(regime);
        (Some(regime), history)
    });
    if let Some((model, regime)) = friction {
        probe = probe.with_friction(c, model, regime).map_err(library)?;
    }
    let (jx, jy) = (&r.joints()[2 * joint], &r.joints()[2 * joint + 1]);
    let grid = AngleGrid {
        lower: lower.unwrap_or(jx.lower.max(jy.lower)),
        upper: upper.unwrap_or(jx.upper.min(jy.upper)),
        points,
    };
    let maps = py
        .detach(|| run(threads, || sweep_probe(&probe, r, c, tau, grid, &|_, _| ())))?
        .map_err(library)?;
    let n = points;
    let map = |f: fn(&sinew::indicators::SweepCell) -> f64| -> PyResult<Py<PyArray2<f64>>> {
        let data = maps.cells.iter().map(|cell| cell.as_ref().map_or(f64::NAN, f)).collect();
        Ok(vec2(py, n, n, data)?.unbind())
    };
    let feasible: Vec<bool> = maps.cells.iter().map(Option::is_some).collect();
    let feasible = PyArray1::from_vec(py, feasible).reshape([n, n])?.into_any().unbind();
    Ok(SweepResult {
        joint,
        torque: vec1(py, &tau).unbind(),
        angles: vec1(py, &(0..n).map(|k| grid.angle(k)).collect::<Vec<_>>()).unbind(),
        feasible,
        k_x_min: map(|c| c.k_x.range[0])?,
        k_x_max: map(|c| c.k_x.range[1])?,
        k_y_min: map(|c| c.k_y.range[0])?,
        k_y_max: map(|c| c.k_y.range[1])?,
        regime,
        history,
        mu,
    })
}
