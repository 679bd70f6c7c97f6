//! The one error type of this crate.

use sinew_robot::{Compact, ErrorKind};

/// Everything a plan can end in besides an answer.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlanError {
    /// A moment in the load: `K_W` is then not symmetric, `K_x` is not concave in the
    /// tensions, and a local optimum need not be the global one. Refused.
    #[error(
        "the load has a moment [{}, {}, {}] N m: with a moment K_W is not symmetric and the end stiffness is not concave in the tensions, so no optimum can be certified; plan under forces only",
        Compact(.moment[0]), Compact(.moment[1]), Compact(.moment[2])
    )]
    NonConservativeLoad {
        /// The moment part of `F0`, N m.
        moment: [f64; 3],
    },
    /// A bad argument: a zero or non-finite direction, a negative budget or margin, a `K_des`
    /// that is not symmetric positive definite, a NaN.
    #[error("{what}: {problem}")]
    InvalidInput {
        /// The argument.
        what: &'static str,
        /// What is wrong with it.
        problem: InputProblem,
    },
    /// No tensions within the limits (and the budget) keep the arm stable with the margin
    /// asked for; `best` bounds every reachable margin from above.
    #[error(
        "no tensions within the limits{} keep the arm stable with margin {} N m/rad: the best reachable margin is at most {} N m/rad",
        if *.budget { " and the budget" } else { "" }, Compact(*.margin), Compact(*.best)
    )]
    NoStableTensions {
        /// The margin asked for, N m/rad.
        margin: f64,
        /// An upper bound of the best reachable margin, N m/rad.
        best: f64,
        /// Whether a tension budget was part of the constraints.
        budget: bool,
    },
    /// The tension budget is below the least total tension that balances the load.
    #[error(
        "the tension budget {} N is below the least total tension that balances the load, {} N",
        Compact(*.budget), Compact(*.least)
    )]
    BudgetTooSmall {
        /// The budget, N.
        budget: f64,
        /// The least total tension, N.
        least: f64,
    },
    /// No tensions within the limits meet the per-joint budgets (and the total budget).
    #[error("no tensions within the limits that balance the load meet the per-joint budgets")]
    BudgetsInfeasible,
    /// Along a trajectory, no tensions within the limits (and the budgets) that balance the
    /// load are within the rate limit of the previous step's tensions.
    #[error(
        "no tensions that balance the load within the limits are within the rate limit of the previous step's tensions: raise the rate or shorten the step"
    )]
    RateLimitInfeasible,
    /// The required stiffness cannot be reached within the constraints.
    #[error(
        "the required {what} {} exceeds the best reachable, at most {} (the tension limits, budget and margin allow no more)",
        Compact(*.required), Compact(*.best)
    )]
    RequirementUnreachable {
        /// Which requirement.
        what: &'static str,
        /// The value asked for.
        required: f64,
        /// An upper bound of the best reachable value.
        best: f64,
    },
    /// The objective needs `K_x`, which does not exist: `J_x` has rank < 6 (e.g. a planar arm).
    #[error(
        "the end stiffness K_x does not exist at this pose (J_x has rank < 6): choose the compliance objective"
    )]
    NoEndStiffness,
    /// The method stopped before its gap closed.
    #[error(
        "no certified optimum after {iterations} iterations: gap {} above the tolerance {}",
        Compact(*.gap), Compact(*.tolerance)
    )]
    NotConverged {
        /// Iterations run.
        iterations: usize,
        /// The gap reached.
        gap: f64,
        /// The gap asked for.
        tolerance: f64,
    },
    /// The convex solver (clarabel) stopped without an answer or a certificate.
    #[error("the convex solver stopped without an answer: {stop}")]
    Solver {
        /// Why it stopped.
        stop: sinew_statics::SolverStop,
    },
    /// A dense factorisation of the planner's own failed to converge.
    #[error("the {what} did not converge")]
    Numerical {
        /// Which (e.g. the eigendecomposition of `K_q + K_W`).
        what: &'static str,
    },
    /// The statics (infeasible loads among them). Boxed, as it is large.
    #[error(transparent)]
    Statics(Box<sinew_statics::StaticsError>),
    /// The stiffness pipeline.
    #[error(transparent)]
    Stiffness(Box<sinew_stiffness::StiffnessError>),
    /// The cable geometry.
    #[error(transparent)]
    Routing(Box<sinew_routing::RoutingError>),
}

impl PlanError {
    /// The kind of failure: no tensions meet what was asked ([`ErrorKind::Infeasible`], an
    /// answer of the model like an infeasible load), no end stiffness at this pose
    /// ([`ErrorKind::RankDeficient`]), a bad argument or a moment in the load
    /// ([`ErrorKind::Input`]), a method that stopped without a certified answer
    /// ([`ErrorKind::Numerical`]); the errors of the crates below say their own kind.
    pub fn kind(&self) -> ErrorKind {
        // No wildcard: a new variant must be classified here.
        match self {
            PlanError::NoStableTensions { .. }
            | PlanError::RequirementUnreachable { .. }
            | PlanError::BudgetTooSmall { .. }
            | PlanError::BudgetsInfeasible
            | PlanError::RateLimitInfeasible => ErrorKind::Infeasible,
            PlanError::NoEndStiffness => ErrorKind::RankDeficient,
            PlanError::NonConservativeLoad { .. } | PlanError::InvalidInput { .. } => {
                ErrorKind::Input
            }
            PlanError::NotConverged { .. }
            | PlanError::Solver { .. }
            | PlanError::Numerical { .. } => ErrorKind::Numerical,
            PlanError::Statics(e) => e.kind(),
            PlanError::Stiffness(e) => e.kind(),
            PlanError::Routing(e) => e.kind(),
        }
    }
}

impl From<sinew_statics::StaticsError> for PlanError {
    fn from(e: sinew_statics::StaticsError) -> Self {
        PlanError::Statics(Box::new(e))
    }
}

impl From<sinew_stiffness::StiffnessError> for PlanError {
    fn from(e: sinew_stiffness::StiffnessError) -> Self {
        // An infeasible load reaches the stiffness pipeline through its statics: keep one path.
        match e {
            sinew_stiffness::StiffnessError::Statics(s) => PlanError::Statics(Box::new(s)),
            e => PlanError::Stiffness(Box::new(e)),
        }
    }
}

impl From<sinew_routing::RoutingError> for PlanError {
    fn from(e: sinew_routing::RoutingError) -> Self {
        PlanError::Routing(Box::new(e))
    }
}

/// What is wrong with an argument of a plan ([`PlanError::InvalidInput`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum InputProblem {
    /// A vector with a NaN or infinite component.
    NonFiniteComponent,
    /// A direction that is not a finite unit vector.
    NotUnitDirection,
    /// A number that must be finite and positive.
    NotPositive {
        /// Its unit, with a leading space (or empty).
        unit: &'static str,
        /// Why, with a leading space (or empty).
        reason: &'static str,
    },
    /// A number that must be finite and non-negative.
    Negative {
        /// Its unit, with a leading space (or empty).
        unit: &'static str,
    },
    /// A number that must be finite.
    NotFinite,
    /// A matrix that must be symmetric positive definite.
    NotSymmetricPositiveDefinite,
    /// A joint the arm does not have (0-based; said from 1).
    NoSuchJoint {
        /// The joint asked for.
        joint: usize,
        /// The arm's joints.
        joints: usize,
    },
    /// A held level of a joint the arm does not have, or outside `[0, 1]`.
    BadFixedLevel {
        /// The joint asked for (0-based; said from 1).
        joint: usize,
        /// The level asked for.
        level: f64,
        /// The arm's joints.
        joints: usize,
    },
    /// Held levels on a routing without the decoupled closed form.
    FixedLevelsNeedDecoupled,
    /// An option the stick regime's planner does not offer (held levels, the bundle method).
    NotInStick,
}

impl std::fmt::Display for InputProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            InputProblem::NonFiniteComponent => write!(f, "has a NaN or infinite component"),
            InputProblem::NotUnitDirection => write!(f, "must be a finite unit vector"),
            InputProblem::NotPositive { unit, reason } => {
                write!(f, "must be finite and > 0{unit}{reason}")
            }
            InputProblem::Negative { unit } => write!(f, "must be finite and ≥ 0{unit}"),
            InputProblem::NotFinite => write!(f, "must be finite"),
            InputProblem::NotSymmetricPositiveDefinite => {
                write!(f, "must be symmetric positive definite")
            }
            InputProblem::NoSuchJoint { joint, joints } => {
                write!(f, "joint {} does not exist: the arm has {joints} joints", joint + 1)
            }
            InputProblem::BadFixedLevel { joint, level, joints } => write!(
                f,
                "joint {} at level {level}: joints are 1 to {joints}, levels in [0, 1]",
                joint + 1
            ),
            InputProblem::NotInStick => write!(
                f,
                "is not offered when planning in the stick regime (the interior-point method, budgets and floors are)"
            ),
            InputProblem::FixedLevelsNeedDecoupled => write!(
                f,
                "fixed tension levels need the paper's closed form in the decoupled model (three cables per universal joint, each crossing only its joint)"
            ),
        }
    }
}
