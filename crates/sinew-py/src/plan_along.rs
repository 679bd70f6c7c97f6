//! Re-planning along a trajectory (`ArmStiffness.plan_along`): [`Planner::plan_along`] over the
//! rows of `Q`, each step warm-started from the one before, with an optional rate limit; the
//! result stacked as `plan_many`'s, with whether each step's warm answer was accepted (`warm`,
//! (N,) bool). A failed step is typed in its row (NaN, `ok` False) and the next starts cold.

use nalgebra::Vector6;
use numpy::PyArray1;
use pyo3::prelude::*;
use sinew::planner::{PlanError, Planner, PlannerData, RateLimit, Step};

use crate::batch::wrench_of_row;
use crate::convert::{matrix, wrenches};
use crate::errors::{input, library};
use crate::plan_args::PlanArgs;
use crate::plan_many::{PlanBatch, PlanBatchResult, stack};

/// The steps of `q` (rows × dof) under `f0` (one wrench, or one per row), planned in order.
///
/// # Errors
/// [`PlanError::InvalidInput`] for a rate or time step that is not finite and positive.
pub fn plan_along(
    planner: &Planner,
    data: &mut PlannerData,
    q: &[f64],
    f0: &[Vector6<f64>],
    args: &PlanArgs,
    rate: Option<RateLimit>,
) -> Result<(PlanBatch, Vec<bool>), PlanError> {
    let dof = planner.arm().dof();
    let steps: Vec<Step> = q
        .chunks(dof.max(1))
        .enumerate()
        .map(|(r, q)| Step { q: q.to_vec(), f0: *wrench_of_row(f0, r) })
        .collect();
    let along = planner.plan_along(
        data,
        &steps,
        args.objective,
        &args.requirements,
        &args.settings,
        rate,
    )?;
    let warm = along.iter().map(|s| s.warm).collect();
    let plans = along.into_iter().map(|s| Some(s.plan.map_err(crate::errors::message))).collect();
    Ok((stack(planner, plans), warm))
}

/// `ArmStiffness.plan_along` (its docs): the steps of `Q` under `wrench`, with the rate
/// limit `(max_rate, dt)`, planned with the GIL released; `plan_many`'s result with `warm`.
pub fn along_result(
    py: Python<'_>,
    (planner, _): &(Planner, std::sync::Mutex<PlannerData>),
    (q, wrench): (&Bound<'_, PyAny>, Option<&Bound<'_, PyAny>>),
    args: &PlanArgs,
    (max_rate, dt): (Option<f64>, Option<f64>),
) -> PyResult<PlanBatchResult> {
    let (rows, q) = matrix(q, "Q", planner.arm().dof())?;
    let f0 = wrenches(wrench, rows)?;
    let rate = match (max_rate, dt) {
        (Some(max_rate), Some(dt)) => Some(RateLimit { max_rate, dt }),
        (None, None) => None,
        _ => return Err(input("max_rate and dt: give both or neither")),
    };
    let (batch, warm) = py
        .detach(|| {
            let mut data = PlannerData::new(planner);
            plan_along(planner, &mut data, &q, &f0, args, rate)
        })
        .map_err(library)?;
    let has_levels = planner.arm().statics().has_levels();
    let mut result = PlanBatchResult::new(py, args.objective.name(), batch, has_levels, false)?;
    result.warm = Some(PyArray1::from_slice(py, &warm).into_any().unbind());
    Ok(result)
}
