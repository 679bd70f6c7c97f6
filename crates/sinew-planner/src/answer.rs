//! A plan from the pipeline's evaluation of its tensions: the objective's value in its own
//! sense, the certified gap to the method's bound, and the reported matrices. One place for
//! the frictionless plan and the plan in the stick regime.

use faer::MatRef;
use nalgebra::{Matrix3, Matrix6};
use sinew_stiffness::StiffnessError;

use crate::error::PlanError;
use crate::least::LeastEigen;
use crate::problem::{Objective, Plan};

/// What the pipeline says at a plan's tensions (`C_x`, `K_fd` symmetrised, the margin).
pub(crate) struct Evaluated {
    pub(crate) c_x: Matrix6<f64>,
    pub(crate) k_fd: Option<Matrix3<f64>>,
    pub(crate) min_eigenvalue: f64,
}

/// The plan at `lambda` (tensions `tensions`) evaluated as `at`, with the method's bound
/// `upper` of the maximised objective (`−uᵀC u`, `−Σ f` for the minimised ones).
///
/// # Errors
/// [`PlanError::NoEndStiffness`] for a `K_fd` objective where `K_x` does not exist.
pub(crate) fn plan_at(
    objective: Objective,
    (lambda, tensions): (Vec<f64>, Vec<f64>),
    at: Evaluated,
    upper: f64,
    iterations: usize,
    levels: Option<Vec<f64>>,
) -> Result<Plan, PlanError> {
    let Evaluated { c_x, k_fd, min_eigenvalue } = at;
    let total: f64 = tensions.iter().sum();
    // The objective in its maximised sense at the answer.
    let maximised = match objective {
        Objective::StiffnessAlong(u) => u.dot(&(k_fd.ok_or(PlanError::NoEndStiffness)? * u)),
        Objective::ComplianceAlong(u) => -u.dot(&(c_x.fixed_view::<3, 3>(0, 0) * u)),
        Objective::MinStiffness => {
            k_fd.ok_or(PlanError::NoEndStiffness)?.symmetric_eigenvalues().min()
        }
        Objective::Volume => {
            let l = k_fd.and_then(|k| k.cholesky()).ok_or(PlanError::NoEndStiffness)?.l();
            2.0 * (0..3).map(|i| l[(i, i)].ln()).sum::<f64>()
        }
        Objective::LeastTension => -total,
    };
    // The bound's own rounding: a few ulps of the value.
    let gap = (upper - maximised).max(0.0) + 8.0 * f64::EPSILON * maximised.abs();
    let value = match objective {
        Objective::ComplianceAlong(_) | Objective::LeastTension => -maximised,
        _ => maximised,
    };
    Ok(Plan {
        objective,
        value,
        gap,
        total_tension: total,
        lambda,
        tensions,
        levels,
        k_fd,
        c_x,
        min_eigenvalue,
        iterations,
    })
}

/// The stability margin of a stable arm, `K_q` of its last tension stage and `K_W` at its pose,
/// as [`sinew_stiffness::Outcome::margin`] defines it, the least eigenvalue of
/// `sym(K_q + K_W)`, by Cholesky trials instead of an eigendecomposition ([`LeastEigen`]; no
/// allocation once `margin` is sized; its last eigenvector starts the next plan's).
pub(crate) fn stable_margin(
    k_q: MatRef<'_, f64>,
    k_w: MatRef<'_, f64>,
    margin: &mut (Vec<f64>, LeastEigen),
) -> Result<f64, PlanError> {
    let n = k_q.nrows();
    margin.0.resize(n * n, 0.0);
    accumulate(&mut margin.0, k_q, false);
    accumulate(&mut margin.0, k_w, true);
    least_symmetric(margin, Some(0.0))
}

/// `a` (row by row, `n × n`) set to `m` (`add`: plus `m`).
pub(crate) fn accumulate(a: &mut [f64], m: MatRef<'_, f64>, add: bool) {
    let n = m.nrows();
    for (i, row) in a.chunks_exact_mut(n).enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = if add { *v + m[(i, j)] } else { m[(i, j)] };
        }
    }
}

/// `λ_min` of the symmetric part of the square matrix in `margin.0` (row by row), by
/// [`LeastEigen`]: the margin of [`stable_margin`], and of a stick plan's `K_stick + K_W`.
/// `below`: a value known to be below it (a stable arm's 0), or `None`.
pub(crate) fn least_symmetric(
    (a, least): &mut (Vec<f64>, LeastEigen),
    below: Option<f64>,
) -> Result<f64, PlanError> {
    let n = a.len().isqrt();
    crate::dense::symmetrise(a, n);
    Ok(least.least(a, n, below).ok_or(StiffnessError::Eigen)?)
}
