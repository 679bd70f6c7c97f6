//! A plan from the pipeline's evaluation of its tensions: the objective's value in its own
//! sense, the certified gap to the method's bound, and the reported matrices. One place for
//! the frictionless plan and the plan in the stick regime.

use nalgebra::{Matrix3, Matrix6};
use sinew_stiffness::{ArmStiffnessData, StiffnessError};

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
    (lambda, tensions): (&[f64], Vec<f64>),
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
        lambda: lambda.to_vec(),
        tensions,
        levels,
        k_fd,
        c_x,
        min_eigenvalue,
        iterations,
    })
}

/// The stability margin of the stable arm in `sd` (its last end stage), as
/// [`sinew_stiffness::Outcome::margin`] defines it, the least eigenvalue of `sym(K_q + K_W)`,
/// by Cholesky trials instead of an eigendecomposition ([`LeastEigen`]; no allocation once
/// `margin` is sized; its last eigenvector starts the next plan's).
pub(crate) fn stable_margin(
    sd: &mut ArmStiffnessData,
    (a, least): &mut (Vec<f64>, LeastEigen),
) -> Result<f64, PlanError> {
    let n = sd.k_q().nrows();
    a.resize(n * n, 0.0);
    let k_q = sd.k_q();
    for (i, row) in a.chunks_exact_mut(n).enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = k_q[(i, j)];
        }
    }
    let k_w = sd.k_w();
    for (i, row) in a.chunks_exact_mut(n).enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v += k_w[(i, j)];
        }
    }
    crate::dense::symmetrise(a, n);
    // Stable: λ_min > 0.
    Ok(least.least(a, n, Some(0.0)).ok_or(StiffnessError::Eigen)?)
}
