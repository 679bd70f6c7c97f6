//! Friction at the holes from Python (spec §9, #27): the keyword arguments `friction`,
//! `regime`, `history` and `direction` of `ArmStiffness.evaluate`, and its answer
//! `FrictionResult`: what `sinew arm --friction … --json` prints, as numpy arrays. With μ = 0
//! everywhere (and no stick asked for) `evaluate` takes the frictionless path and answers an
//! `ArmResult`, as the command line does.

use nalgebra::Vector6;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use sinew::routing::{FrictionModel, Routing, Slip, compute_wrap_gradients};
use sinew::statics::TensionChoice;
use sinew::stiffness::{
    ArmStiffness, ArmStiffnessData, BandEdge, DirectionalResponse, EndOutcome, FrictionArmData,
    FrictionRegime, History, HoleEvent, StickLoadLimit, base_directions, directional_response,
    stick_load_limits,
};

use crate::convert::{na2, vec1, vec2, vector};
use crate::errors::{input, library};

/// The friction keyword arguments of `evaluate`, as passed.
#[derive(Debug, Default)]
pub struct FrictionArgs<'a, 'py> {
    /// `friction`: μ at every hole of every cable (overrides the routing file's).
    pub mu: Option<f64>,
    /// `regime`: `"pull"`, `"release"` or `"stick"` (default).
    pub regime: Option<&'a str>,
    /// `history`: `"pull"` (default), `"release"` or `"equal"`; the stick regime's only.
    pub history: Option<&'a str>,
    /// `direction`: the directional response's force direction (3,).
    pub direction: Option<&'a Bound<'py, PyAny>>,
}

/// The stick regime's model and history a plan asks for; `None` for the frictionless plan.
///
/// # Errors
/// As [`requested`]; `InputError` for a slip regime (not planned: its `K_q` is not symmetric
/// and the end stiffness is not concave in the tensions).
pub fn stick_requested(
    args: &FrictionArgs<'_, '_>,
    routing: &Routing,
) -> PyResult<Option<(FrictionModel, History)>> {
    match requested(args, routing)? {
        None => Ok(None),
        Some((_, FrictionRegime::Slip(_))) => Err(input(
            "regime: a slip regime is not planned (its K_q is not symmetric and the end stiffness is not concave in the tensions); plan with regime=\"stick\"",
        )),
        Some((model, FrictionRegime::Stick(history))) => Ok(Some((model, history))),
    }
}

/// The friction model and regime the arguments and the routing file ask for; `None` for the
/// frictionless path (every μ = 0 and neither `regime="stick"` nor `history` given).
///
/// # Errors
/// `InputError` for a negative or non-finite `friction`, an unknown `regime` or `history`,
/// `history` with a slip regime, the stick regime at μ = 0, `direction` without friction.
pub fn requested(
    args: &FrictionArgs<'_, '_>,
    routing: &Routing,
) -> PyResult<Option<(FrictionModel, FrictionRegime)>> {
    let mut model = FrictionModel::new(routing);
    if let Some(mu) = args.mu {
        model = model.with_friction_coefficient(mu).map_err(|e| input(format!("friction: {e}")))?;
    }
    let history = match args.history {
        None | Some("pull") => History::Pull,
        Some("release") => History::Release,
        Some("equal") => History::Equal,
        Some(other) => {
            return Err(input(format!("history: `{other}` is not one of pull, release, equal")));
        }
    };
    let regime = match args.regime {
        Some("pull" | "release") if args.history.is_some() => {
            return Err(input("history: applies to regime=\"stick\" only"));
        }
        Some("pull") => FrictionRegime::Slip(Slip::Pull),
        Some("release") => FrictionRegime::Slip(Slip::Release),
        Some("stick") | None => FrictionRegime::Stick(history),
        Some(other) => {
            return Err(input(format!("regime: `{other}` is not one of pull, release, stick")));
        }
    };
    let frictionless = model.friction_coefficients().iter().all(|&mu| mu == 0.0);
    let stick_asked = args.regime == Some("stick") || args.history.is_some();
    match (frictionless, stick_asked) {
        (true, false) if args.direction.is_some() => {
            Err(input("direction: applies with friction (give friction > 0)"))
        }
        (true, false) => Ok(None),
        (true, true) => Err(input(
            "regime: stick needs μ > 0 (every cable has μ = 0: no band to stick in); give friction > 0",
        )),
        (false, _) => Ok(Some((model, regime))),
    }
}

/// The answer of `ArmStiffness.evaluate` with friction: the regime's tensions along every
/// cable, the dead band, the regime's `K_q`, `C_x`, `K_x`, `K_fd`, and in the stick regime the
/// directional response along ±u and the stick load limits (the twelve signed base directions,
/// then +u and −u). Units as `ArmResult`'s.
#[pyclass(module = "sinew", frozen, get_all)]
#[derive(Debug)]
pub struct FrictionResult {
    /// μ of every cable (m,).
    pub(crate) mu: Py<PyAny>,
    /// `"pull"`, `"release"` or `"stick"`.
    pub(crate) regime: &'static str,
    /// The stick regime's history (`"pull"`, `"release"`, `"equal"`); None in a slip regime.
    pub(crate) history: Option<&'static str>,
    /// The pose (dof,), rad.
    pub(crate) q: Py<PyAny>,
    /// The load F0 (6,).
    pub(crate) wrench: Py<PyAny>,
    /// The equilibrium torques (dof,), N m.
    pub(crate) t0: Py<PyAny>,
    /// The actuator tensions (m,), N.
    pub(crate) tensions: Py<PyAny>,
    /// Per cable: `{"cable", "tensions" (from the actuator to the anchor, N), "wrap_angles"
    /// (every hole but the anchor, rad), "lengths" (the free length, then each segment, m)}`.
    pub(crate) segments: Py<PyAny>,
    /// Per cable `[T₀^release, T₀^pull]` (m, 2), N: the actuator tensions over which the
    /// anchor tension does not move.
    pub(crate) dead_band: Py<PyAny>,
    /// The regime's joint stiffness (dof, dof), N m/rad (a slip regime's is not symmetric).
    pub(crate) k_q: Py<PyAny>,
    /// The Frobenius norm of `K_q`'s skew part (0 in the stick regime).
    pub(crate) k_q_skew_norm: f64,
    /// (dof, dof).
    pub(crate) k_w: Py<PyAny>,
    /// (6, dof).
    pub(crate) j_x: Py<PyAny>,
    /// Whether `K_q + K_W` (its symmetric part) is positive definite.
    pub(crate) stable: bool,
    /// Its smallest eigenvalue, N m/rad.
    pub(crate) min_eigenvalue: f64,
    /// (6, 6); None when unstable.
    pub(crate) c_x: Option<Py<PyAny>>,
    /// (6, 6); None when unstable or rank-deficient.
    pub(crate) k_x: Option<Py<PyAny>>,
    /// (3, 3); None when unstable or rank-deficient.
    pub(crate) k_fd: Option<Py<PyAny>>,
    /// Stick and stable only: `{"direction" (3,), "plus", "minus"}`, each
    /// `{"compliance" (m/N), "stiffness" (N/m), "sliding": [(cable, hole, edge, kinked)]}`.
    pub(crate) directional: Option<Py<PyAny>>,
    /// Stick and stable only: per direction `{"direction" (6,), "magnitude" (N or N m; None
    /// when no hole ever reaches an edge), "first" (the hole, or None), "at_once" (holes pushed
    /// over their edge at once)}`.
    pub(crate) stick_load_limit: Option<Py<PyAny>>,
    /// What the numbers mean where that is not obvious.
    pub(crate) notes: Vec<String>,
}

#[pymethods]
impl FrictionResult {
    fn __repr__(&self) -> String {
        let history = self.history.map(|h| format!(", history={h}")).unwrap_or_default();
        let stable = if self.stable { "True" } else { "False" };
        format!("FrictionResult(regime={}{history}, stable={stable})", self.regime)
    }
}

/// A hole as `(cable name, hole, "lower" | "upper", kinked)`.
type HoleTuple = (String, usize, &'static str, bool);

fn hole(e: &HoleEvent, routing: &Routing) -> HoleTuple {
    let edge = match e.edge {
        BandEdge::Lower => "lower",
        BandEdge::Upper => "upper",
    };
    (routing.cables()[e.cable].name.clone(), e.hole, edge, e.kinked)
}

fn response<'py>(
    py: Python<'py>,
    r: &DirectionalResponse,
    routing: &Routing,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("compliance", r.compliance)?;
    d.set_item("stiffness", r.stiffness)?;
    let sliding: Vec<HoleTuple> = r.sliding.iter().map(|e| hole(e, routing)).collect();
    d.set_item("sliding", sliding)?;
    Ok(d)
}

fn limit<'py>(
    py: Python<'py>,
    l: &StickLoadLimit,
    routing: &Routing,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("direction", vec1(py, l.direction.as_slice()))?;
    d.set_item("magnitude", l.magnitude.is_finite().then_some(l.magnitude))?;
    d.set_item("first", l.first.as_ref().map(|e| hole(e, routing)))?;
    let at_once: Vec<HoleTuple> = l.at_once.iter().map(|e| hole(e, routing)).collect();
    d.set_item("at_once", at_once)?;
    Ok(d)
}

/// The directional response's unit force: `direction`, else the load's force; `None` when
/// neither gives one.
fn force_direction(
    direction: Option<&Bound<'_, PyAny>>,
    f0: &Vector6<f64>,
) -> PyResult<Option<Vector6<f64>>> {
    let u = match direction {
        Some(d) => {
            let u = vector(d, "direction", Some(3))?;
            let norm = u.iter().map(|x| x * x).sum::<f64>().sqrt();
            if !(norm > 0.0 && norm.is_finite()) {
                return Err(input("direction: a zero or non-finite direction"));
            }
            [u[0] / norm, u[1] / norm, u[2] / norm]
        }
        None => {
            let norm = f0.fixed_rows::<3>(0).norm();
            if norm == 0.0 {
                return Ok(None);
            }
            [f0[0] / norm, f0[1] / norm, f0[2] / norm]
        }
    };
    Ok(Some(Vector6::new(u[0], u[1], u[2], 0.0, 0.0, 0.0)))
}

/// The regime's name and, in stick, its history's (`"pull"`, `"release"`, `"stick"`; …).
pub fn name(regime: FrictionRegime) -> (&'static str, Option<&'static str>) {
    match regime {
        FrictionRegime::Slip(Slip::Pull) => ("pull", None),
        FrictionRegime::Slip(Slip::Release) => ("release", None),
        FrictionRegime::Stick(History::Pull) => ("stick", Some("pull")),
        FrictionRegime::Stick(History::Release) => ("stick", Some("release")),
        FrictionRegime::Stick(History::Equal) => ("stick", Some("equal")),
    }
}

/// `evaluate` with friction: the library's `evaluate_with_friction`, then in the stick
/// regime the directional response and the stick load limits.
///
/// # Errors
/// The library's, as exceptions (with `require_stiffness`, unstable and rank-deficient too);
/// `InputError` when the stick regime has no direction (no force in the load and no
/// `direction`).
pub fn evaluate_friction(
    py: Python<'_>,
    (arm, data): (&ArmStiffness, &mut ArmStiffnessData),
    (model, regime): (&FrictionModel, FrictionRegime),
    (q, f0): (&[f64], &Vector6<f64>),
    (choice, require_stiffness): (TensionChoice<'_>, bool),
    direction: Option<&Bound<'_, PyAny>>,
) -> PyResult<FrictionResult> {
    let routing = arm.routing();
    let u = force_direction(direction, f0)?;
    let (regime_name, history_name) = name(regime);
    let history = match regime {
        FrictionRegime::Stick(h) => Some(h),
        FrictionRegime::Slip(_) => None,
    };
    if history.is_some() && u.is_none() {
        return Err(input(
            "direction: required in the stick regime when the wrench has no force (the directional response's direction)",
        ));
    }
    let mut out = FrictionArmData::new(arm, model);
    let computed = py.detach(|| -> PyResult<_> {
        let outcome = arm
            .evaluate_with_friction(data, &mut out, (model, regime), q, f0, choice)
            .map_err(library)?;
        if require_stiffness {
            outcome.into_result().map_err(library)?;
        }
        let k_q = out.stiffness.stiffness().map_err(library)?.to_owned();
        let (k_w, j_x) = (data.k_w().to_owned(), data.j_x().to_owned());
        let stable = !matches!(outcome, EndOutcome::Unstable { .. });
        let mut answers = None;
        if let (Some(history), Some(u), true) = (history, u, stable) {
            let increment = (k_q.as_ref(), k_w.as_ref(), j_x.as_ref());
            compute_wrap_gradients(model, &mut out.friction).map_err(library)?;
            let (f, t) = (&out.friction, &out.actuator);
            let both = directional_response(model, routing, f, history, t, increment, &u)
                .map_err(library)?;
            let mut directions = base_directions().to_vec();
            directions.extend([u, -u]);
            let limits = stick_load_limits(model, routing, f, history, t, increment, &directions)
                .map_err(library)?;
            answers = Some((both, limits));
        }
        Ok((outcome, k_q, k_w, j_x, answers))
    });
    let (outcome, k_q, k_w, j_x, answers) = computed?;
    let stable = !matches!(outcome, EndOutcome::Unstable { .. });
    let full_rank = matches!(outcome, EndOutcome::Stiff);
    let faer2 = |m: faer::MatRef<'_, f64>| -> PyResult<Py<PyAny>> {
        let flat = (0..m.nrows()).flat_map(|i| (0..m.ncols()).map(move |j| m[(i, j)])).collect();
        Ok(vec2(py, m.nrows(), m.ncols(), flat)?.into_any().unbind())
    };
    let mut notes = Vec::new();
    let (mut directional, mut stick_load_limit) = (None, None);
    match (answers, u) {
        (Some(([plus, minus], limits)), Some(u)) => {
            let d = PyDict::new(py);
            d.set_item("direction", vec1(py, &[u[0], u[1], u[2]]))?;
            d.set_item("plus", response(py, &plus, routing)?)?;
            d.set_item("minus", response(py, &minus, routing)?)?;
            directional = Some(d.into_any().unbind());
            let list = PyList::empty(py);
            for l in &limits {
                list.append(limit(py, l, routing)?)?;
            }
            stick_load_limit = Some(list.into_any().unbind());
        }
        _ if history.is_some() => {
            notes.push("unstable: no directional response or stick load limit".to_owned());
        }
        _ => notes.push(
            "slip regime: K_q is the stiffness for motions that keep every hole sliding the same way (not symmetric: see k_q_skew_norm)".to_owned(),
        ),
    }
    let segments = PyList::empty(py);
    for (c, cable) in routing.cables().iter().enumerate() {
        let d = PyDict::new(py);
        d.set_item("cable", &cable.name)?;
        d.set_item("tensions", vec1(py, &out.segments[c]))?;
        d.set_item("wrap_angles", vec1(py, out.friction.wrap_angles(model, c).map_err(library)?))?;
        d.set_item("lengths", vec1(py, out.friction.lengths(model, c).map_err(library)?))?;
        segments.append(d)?;
    }
    let band: Vec<f64> = out.dead_band.iter().flatten().copied().collect();
    Ok(FrictionResult {
        mu: vec1(py, model.friction_coefficients()).into_any().unbind(),
        regime: regime_name,
        history: history_name,
        q: vec1(py, q).into_any().unbind(),
        wrench: vec1(py, f0.as_slice()).into_any().unbind(),
        t0: vec1(py, &data.statics.t0).into_any().unbind(),
        tensions: vec1(py, &out.actuator).into_any().unbind(),
        segments: segments.into_any().unbind(),
        dead_band: vec2(py, out.dead_band.len(), 2, band)?.into_any().unbind(),
        k_q: faer2(k_q.as_ref())?,
        k_q_skew_norm: out.stiffness.skew_norm().map_err(library)?,
        k_w: faer2(k_w.as_ref())?,
        j_x: faer2(j_x.as_ref())?,
        stable,
        min_eigenvalue: out.stability_margin(data).map_err(library)?,
        c_x: stable.then(|| faer2(out.end.compliance())).transpose()?,
        k_x: full_rank.then(|| faer2(out.end.stiffness())).transpose()?,
        k_fd: full_rank.then(|| na2(py, &out.end.k_fd()).into_any().unbind()),
        directional,
        stick_load_limit,
        notes,
    })
}
