//! What a plan is asked and what it answers: the objectives, the requirements, the settings,
//! the certified [`Plan`], and the check of every input before a plan starts.

use nalgebra::{Matrix3, Vector3, Vector6};

use crate::error::{InputProblem, PlanError};

/// What to optimise (one per plan).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Objective {
    /// Maximise `uᵀ K_fd u`: the stiffness along the unit direction `u` with the end's
    /// rotation held (`K_fd = K_x[0:3, 0:3]`, eq. 21).
    StiffnessAlong(Vector3<f64>),
    /// Minimise `uᵀ C_x[0:3, 0:3] u`: the compliance along `u` with rotations free (how far the
    /// end moves along `u` per newton along `u`). Defined also where `K_x` is not (a planar
    /// arm); the value reported is the compliance, m/N.
    ComplianceAlong(Vector3<f64>),
    /// Maximise `λ_min(K_fd)`: the softest direction made as stiff as possible.
    MinStiffness,
    /// Maximise `log det K_fd`: the smallest deformation ellipsoid.
    Volume,
    /// Minimise the total tension `Σ f` subject to [`Requirements`].
    LeastTension,
}

impl Objective {
    /// The name the command line and the JSON use.
    pub fn name(&self) -> &'static str {
        match self {
            Objective::StiffnessAlong(_) => "stiffness-along",
            Objective::ComplianceAlong(_) => "compliance-along",
            Objective::MinStiffness => "min-stiffness",
            Objective::Volume => "volume",
            Objective::LeastTension => "least-tension",
        }
    }
}

/// Constraints of every plan, besides exact equilibrium (by construction) and the tension
/// limits (always).
#[derive(Debug, Clone, PartialEq)]
pub struct Requirements {
    /// Stability margin `λ_min(K_q + K_W) ≥ margin`, N m/rad (> 0: the arm must be stable).
    pub margin: f64,
    /// Total tension `Σ f ≤ budget`, N.
    pub budget: Option<f64>,
    /// `λ_min(K_fd) ≥ k_min`, N/m.
    pub k_min: Option<f64>,
    /// `K_fd ⪰ K_des` (symmetric positive definite), N/m.
    pub k_des: Option<Matrix3<f64>>,
    /// Per-joint budgets `(joint, B)`: the tensions of the cables that drive `joint`
    /// (0-based, [`sinew_routing::Routing::cables_of_joint`]) sum to at most `B`, N.
    pub joint_budgets: Vec<(usize, f64)>,
    /// Joints held at a given tension level `(joint, s)`, `s ∈ [0, 1]` (the paper's levels: the
    /// closed form, decoupled model only: there a joint's own tensions at a level do not depend
    /// on the others).
    pub fixed_levels: Vec<(usize, f64)>,
}

impl Default for Requirements {
    fn default() -> Self {
        Requirements {
            margin: DEFAULT_MARGIN,
            budget: None,
            k_min: None,
            k_des: None,
            joint_budgets: Vec::new(),
            fixed_levels: Vec::new(),
        }
    }
}

/// The default stability margin, N m/rad.
pub const DEFAULT_MARGIN: f64 = 1e-3;

/// The default relative gap at which a plan stops.
pub const DEFAULT_GAP: f64 = 1e-6;

/// The method of a plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// The primal–dual interior-point method on the plan's matrix inequalities (`sdp.rs`,
    /// `ipm.rs`): the default.
    #[default]
    InteriorPoint,
    /// The level bundle method on clarabel LPs and QPs (`bundle.rs`): a second, independent
    /// method for tests and benchmarks.
    Bundle,
}

/// How a plan stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanSettings {
    /// Stop when the certified gap is at most this fraction of the value.
    pub relative_gap: f64,
    /// Give up (with [`PlanError::NotConverged`]) after this many iterations.
    pub max_iterations: usize,
    /// The method.
    pub method: Method,
}

impl Default for PlanSettings {
    fn default() -> Self {
        PlanSettings { relative_gap: DEFAULT_GAP, max_iterations: 2000, method: Method::default() }
    }
}

/// A certified answer.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The objective.
    pub objective: Objective,
    /// Its value at the answer: `uᵀ K_fd u` (N/m), `uᵀ C_x u` (m/N), `λ_min(K_fd)` (N/m),
    /// `log det K_fd` (ln of (N/m)³) or `Σ f` (N), as the stiffness pipeline evaluates it at
    /// `tensions` (as are `k_fd`, `c_x` and `min_eigenvalue`).
    pub value: f64,
    /// The certificate: the true optimum is at most `gap` better than `value` (same unit).
    pub gap: f64,
    /// The coordinates `λ` of the tensions in the equilibrium set.
    pub lambda: Vec<f64>,
    /// The tensions (m, N, routing order): balance to rounding, limits exact.
    pub tensions: Vec<f64>,
    /// `Σ f`, N.
    pub total_tension: f64,
    /// The paper's tension levels of these tensions (one per joint, in `[0, 1]`), where the
    /// closed form applies (three cables per universal joint).
    pub levels: Option<Vec<f64>>,
    /// `K_fd` at the answer, N/m (`None` when `J_x` has rank < 6).
    pub k_fd: Option<Matrix3<f64>>,
    /// `C_x` at the answer (6 × 6).
    pub c_x: nalgebra::Matrix6<f64>,
    /// `λ_min(K_q + K_W)` at the answer (its symmetric part), N m/rad: the pipeline's
    /// matrices, the eigenvalue bracketed by Cholesky trials to `1e-10 max |a_ij|` (the value
    /// itself a Rayleigh quotient, agreeing with a full eigensolve to about `1e-14 max |a_ij|`).
    pub min_eigenvalue: f64,
    /// Iterations of the method (both phases).
    pub iterations: usize,
}

pub(crate) fn check_inputs(
    f0: &Vector6<f64>,
    objective: Objective,
    requirements: &Requirements,
    settings: &PlanSettings,
) -> Result<(), PlanError> {
    let bad = |what, problem| Err(PlanError::InvalidInput { what, problem });
    if !f0.iter().all(|v| v.is_finite()) {
        return bad("wrench", InputProblem::NonFiniteComponent);
    }
    if f0[3] != 0.0 || f0[4] != 0.0 || f0[5] != 0.0 {
        return Err(PlanError::NonConservativeLoad { moment: [f0[3], f0[4], f0[5]] });
    }
    if let Objective::StiffnessAlong(u) | Objective::ComplianceAlong(u) = objective {
        let n = u.norm();
        if !(n.is_finite() && (n - 1.0).abs() <= 1e-9) {
            return bad("direction", InputProblem::NotUnitDirection);
        }
    }
    if !(requirements.margin.is_finite() && requirements.margin > 0.0) {
        return bad(
            "margin",
            InputProblem::NotPositive { unit: " N m/rad", reason: " (the arm must be stable)" },
        );
    }
    if let Some(b) = requirements.budget
        && !(b.is_finite() && b >= 0.0)
    {
        return bad("budget", InputProblem::Negative { unit: " N" });
    }
    if let Some(k) = requirements.k_min
        && !k.is_finite()
    {
        return bad("k_min", InputProblem::NotFinite);
    }
    if requirements.joint_budgets.iter().any(|(_, b)| !(b.is_finite() && *b >= 0.0)) {
        return bad("joint_budget", InputProblem::Negative { unit: " N" });
    }
    if let Some(k) = requirements.k_des {
        let symmetric = (k - k.transpose()).abs().max() <= 1e-9 * k.abs().max().max(1.0);
        if !(k.iter().all(|v| v.is_finite()) && symmetric && k.cholesky().is_some()) {
            return bad("k_des", InputProblem::NotSymmetricPositiveDefinite);
        }
    }
    if !(settings.relative_gap.is_finite() && settings.relative_gap > 0.0) {
        return bad("gap", InputProblem::NotPositive { unit: "", reason: "" });
    }
    Ok(())
}
