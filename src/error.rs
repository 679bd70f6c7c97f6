//! One error type for the facade: every crate's error, normalised to one path each, and its
//! [`ErrorKind`].

use crate::indicators::IndicatorError;
use crate::planner::PlanError;
use crate::robot::RobotError;
use crate::routing::RoutingError;
use crate::statics::StaticsError;
use crate::stiffness::StiffnessError;

/// Any error of the Sinew crates.
///
/// **One path per underlying error.** The crates' errors nest (a `StiffnessError` may carry a
/// `StaticsError` that carries a `RoutingError` that carries a `RobotError`); the `From`
/// conversions unwrap that nesting, so each error arrives in exactly one variant: a
/// [`RobotError`] is always [`Error::Robot`], a routing's own error always [`Error::Routing`],
/// an infeasible load always [`Error::Statics`], and so on. [`Error::Statics`],
/// [`Error::Stiffness`] and [`Error::Indicators`] built through `From` never hold one of their
/// crate's wrapping variants. Match on [`Error::kind`] for what to do about it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Robot model or robot files.
    #[error(transparent)]
    Robot(RobotError),
    /// Cable routing (the routing's own errors; its robot errors are [`Error::Robot`]).
    #[error(transparent)]
    Routing(RoutingError),
    /// Statics (infeasible tensions among them). Boxed, as it is large.
    #[error(transparent)]
    Statics(Box<StaticsError>),
    /// Stiffness (unstable equilibria among them). Boxed, as it is large.
    #[error(transparent)]
    Stiffness(Box<StiffnessError>),
    /// Indicators and sweeps (their own errors; the errors of the crates below arrive in their
    /// own variants).
    #[error(transparent)]
    Indicators(IndicatorError),
    /// The tension planner (its own errors; the errors of the crates below arrive in their own
    /// variants). Boxed, as it is large.
    #[error(transparent)]
    Planner(Box<PlanError>),
    /// Anything else, with its message (e.g. a URDF read for a report).
    #[error("{message}")]
    Other {
        /// What went wrong.
        message: String,
    },
}

/// What kind of failure an [`Error`] is: what a caller (or the `sinew` command's exit code)
/// does about it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The input is wrong: a file that cannot be read or is malformed, an unsupported robot or
    /// routing, a joint or cable that does not exist, an angle outside the joint limits, a
    /// tension level outside `[0, 1]`, a non-finite torque or wrench, a buffer or workspace of
    /// the wrong size. Fix the input and try again.
    Input,
    /// The input is valid but a joint's cables cannot hold its torque within the tension
    /// limits, or have lost force closure (eq. 22–23: an empty feasible tension interval).
    Infeasible,
    /// The equilibrium is unstable: `K_q + K_W` is not positive definite, so no end stiffness
    /// exists (eq. 19).
    Unstable,
    /// The end-effector Jacobian has rank < 6: `C_x` exists, `K_x = C_x⁻¹` does not (eq. 19).
    RankDeficient,
    /// The computation failed: a non-finite matrix, an eigen-decomposition that did not
    /// converge, a cable segment of (near-)zero length at this configuration.
    Numerical,
}

impl std::fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ErrorKind::Input => "input",
            ErrorKind::Infeasible => "infeasible",
            ErrorKind::Unstable => "unstable",
            ErrorKind::RankDeficient => "rank-deficient",
            ErrorKind::Numerical => "numerical",
        })
    }
}

impl Error {
    /// The kind of failure (see [`ErrorKind`] for what each one covers).
    ///
    /// Every variant of every crate's error maps to one kind; a variant added to a crate later
    /// is [`ErrorKind::Numerical`] until it is classified here.
    pub fn kind(&self) -> ErrorKind {
        match self {
            Error::Robot(e) => robot_kind(e),
            Error::Routing(e) => routing_kind(e),
            Error::Statics(e) => statics_kind(e),
            Error::Stiffness(e) => stiffness_kind(e),
            Error::Indicators(e) => indicator_kind(e),
            Error::Planner(e) => planner_kind(e),
            Error::Other { .. } => ErrorKind::Input,
        }
    }

    /// Whether this is an infeasible load ([`ErrorKind::Infeasible`]).
    pub fn is_infeasible(&self) -> bool {
        self.kind() == ErrorKind::Infeasible
    }
}

/// Every robot error is about the files or what the caller passed.
fn robot_kind(_: &RobotError) -> ErrorKind {
    ErrorKind::Input
}

fn routing_kind(e: &RoutingError) -> ErrorKind {
    match e {
        RoutingError::Robot(e) => robot_kind(e),
        RoutingError::DegenerateSegment { .. } | RoutingError::Serialize { .. } => {
            ErrorKind::Numerical
        }
        // Files, specs, sizes, indices, evaluation order: the caller's input.
        _ => ErrorKind::Input,
    }
}

fn statics_kind(e: &StaticsError) -> ErrorKind {
    match e {
        // Whatever the reason: a rank-deficient joint block, lost force closure, or limits.
        StaticsError::Infeasible { .. }
        | StaticsError::NoEquilibrium(_)
        | StaticsError::LevelsInfeasible(_) => ErrorKind::Infeasible,
        StaticsError::NonFiniteTorque { .. }
        | StaticsError::LevelsUnavailable(_)
        | StaticsError::NotBalanced(_)
        | StaticsError::NoPose
        | StaticsError::NoSuchJoint { .. }
        | StaticsError::InvalidLevel { .. }
        | StaticsError::UnsupportedRouting { .. }
        | StaticsError::DimensionMismatch { .. }
        | StaticsError::NonFiniteWrench { .. } => ErrorKind::Input,
        StaticsError::Robot(e) => robot_kind(e),
        StaticsError::Routing(e) => routing_kind(e),
        // NonFiniteInput, Numerical, Solver and any later numerical variant.
        _ => ErrorKind::Numerical,
    }
}

fn stiffness_kind(e: &StiffnessError) -> ErrorKind {
    match e {
        StiffnessError::Unstable { .. } => ErrorKind::Unstable,
        StiffnessError::RankDeficient { .. } => ErrorKind::RankDeficient,
        StiffnessError::NonFinite { .. } | StiffnessError::Eigen => ErrorKind::Numerical,
        StiffnessError::DimensionMismatch { .. }
        | StiffnessError::InvalidDirection { .. }
        | StiffnessError::StageMissing { .. } => ErrorKind::Input,
        StiffnessError::Statics(e) => statics_kind(e),
        StiffnessError::Robot(e) => robot_kind(e),
        StiffnessError::Routing(e) => routing_kind(e),
        _ => ErrorKind::Numerical,
    }
}

fn indicator_kind(e: &IndicatorError) -> ErrorKind {
    match e {
        IndicatorError::Statics(e) => statics_kind(e),
        IndicatorError::Stiffness(e) => stiffness_kind(e),
        IndicatorError::Routing(e) => routing_kind(e),
        IndicatorError::Robot(e) => robot_kind(e),
        // Joints, grids, routings the probe cannot take: the caller's input.
        _ => ErrorKind::Input,
    }
}

fn planner_kind(e: &PlanError) -> ErrorKind {
    match e {
        // No tensions meet what was asked: an answer of the model, like an infeasible load.
        PlanError::NoStableTensions { .. }
        | PlanError::RequirementUnreachable { .. }
        | PlanError::BudgetTooSmall { .. }
        | PlanError::BudgetsInfeasible => ErrorKind::Infeasible,
        PlanError::NoEndStiffness => ErrorKind::RankDeficient,
        PlanError::NonConservativeLoad { .. } | PlanError::InvalidInput { .. } => ErrorKind::Input,
        PlanError::Statics(e) => statics_kind(e),
        PlanError::Stiffness(e) => stiffness_kind(e),
        PlanError::Routing(e) => routing_kind(e),
        _ => ErrorKind::Numerical,
    }
}

impl From<PlanError> for Error {
    fn from(e: PlanError) -> Self {
        match e {
            PlanError::Statics(e) => (*e).into(),
            PlanError::Stiffness(e) => (*e).into(),
            PlanError::Routing(e) => (*e).into(),
            e => Error::Planner(Box::new(e)),
        }
    }
}

impl From<RobotError> for Error {
    fn from(e: RobotError) -> Self {
        Error::Robot(e)
    }
}

impl From<RoutingError> for Error {
    fn from(e: RoutingError) -> Self {
        match e {
            RoutingError::Robot(e) => Error::Robot(e),
            e => Error::Routing(e),
        }
    }
}

impl From<StaticsError> for Error {
    fn from(e: StaticsError) -> Self {
        match e {
            StaticsError::Robot(e) => e.into(),
            StaticsError::Routing(e) => e.into(),
            e => Error::Statics(Box::new(e)),
        }
    }
}

impl From<StiffnessError> for Error {
    fn from(e: StiffnessError) -> Self {
        match e {
            StiffnessError::Statics(e) => e.into(),
            StiffnessError::Robot(e) => e.into(),
            StiffnessError::Routing(e) => e.into(),
            e => Error::Stiffness(Box::new(e)),
        }
    }
}

impl From<IndicatorError> for Error {
    fn from(e: IndicatorError) -> Self {
        match e {
            IndicatorError::Statics(e) => (*e).into(),
            IndicatorError::Stiffness(e) => (*e).into(),
            IndicatorError::Routing(e) => e.into(),
            IndicatorError::Robot(e) => e.into(),
            e => Error::Indicators(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::statics::InfeasibleReason;

    fn robot_error() -> RobotError {
        RobotError::OutOfLimits { joint: "joint1_x".into(), position: 1.0, lower: -0.5, upper: 0.5 }
    }

    fn infeasible() -> StaticsError {
        StaticsError::Infeasible {
            joint: 0,
            torque: [50.0, 0.0],
            limits: [20.0, 600.0],
            reason: InfeasibleReason::OutsideLimits { lambda_min: 2.0, lambda_max: 1.0 },
        }
    }

    #[test]
    fn input_errors_are_input_from_every_crate() {
        let cases: Vec<Error> = vec![
            robot_error().into(),
            RoutingError::NoSuchCable { cable: 9, cables: 3 }.into(),
            StaticsError::InvalidLevel { joint: 0, level: 1.5 }.into(),
            StaticsError::NonFiniteWrench { wrench: [f64::NAN; 6] }.into(),
            StiffnessError::DimensionMismatch { what: "K_q", expected: 10, got: 9 }.into(),
            IndicatorError::NoSuchJoint { joint: 9, joints: 5 }.into(),
            IndicatorError::GridTooSmall { points: 1, min: 2 }.into(),
            IndicatorError::GridRange { lower: 0.0, upper: 0.0 }.into(),
            IndicatorError::NotThreeCables { joint: 0, cables: 2 }.into(),
            StiffnessError::InvalidDirection { direction: [0.0; 3] }.into(),
            Error::Other { message: "x.urdf: cannot read".into() },
        ];
        for e in cases {
            assert_eq!(e.kind(), ErrorKind::Input, "{e}");
        }
    }

    #[test]
    fn outcomes_have_their_own_kinds() {
        let e: Error = infeasible().into();
        assert_eq!(e.kind(), ErrorKind::Infeasible);
        assert!(e.is_infeasible());
        for reason in [
            InfeasibleReason::RankDeficient,
            InfeasibleReason::NoForceClosure { null: [1.0, -1.0, 0.0] },
        ] {
            let e: Error = StaticsError::Infeasible {
                joint: 1,
                torque: [0.0; 2],
                limits: [20.0, 600.0],
                reason,
            }
            .into();
            assert_eq!(e.kind(), ErrorKind::Infeasible, "{e}");
        }
        let e: Error = StiffnessError::Unstable { min_eigenvalue: -1.0 }.into();
        assert_eq!(e.kind(), ErrorKind::Unstable);
        let e: Error = StiffnessError::RankDeficient { pivot_ratio: 1e-17 }.into();
        assert_eq!(e.kind(), ErrorKind::RankDeficient);
    }

    #[test]
    fn numerical_failures_are_numerical() {
        let cases: Vec<Error> = vec![
            StiffnessError::NonFinite { what: "K_q" }.into(),
            StiffnessError::Eigen.into(),
            RoutingError::DegenerateSegment {
                cable: "j1c1".into(),
                segment: 0,
                length: 0.0,
                min: 1e-9,
            }
            .into(),
        ];
        for e in cases {
            assert_eq!(e.kind(), ErrorKind::Numerical, "{e}");
        }
    }

    #[test]
    fn nested_errors_arrive_by_one_path() {
        // However deep the nesting, the error lands in the variant of the crate that raised it.
        let deep =
            StiffnessError::Statics(StaticsError::Routing(RoutingError::Robot(robot_error())));
        assert!(matches!(Error::from(deep), Error::Robot(RobotError::OutOfLimits { .. })));
        let e = Error::from(IndicatorError::from(StiffnessError::Statics(infeasible())));
        assert!(matches!(&e, Error::Statics(s) if matches!(**s, StaticsError::Infeasible { .. })));
        let e = Error::from(IndicatorError::Robot(robot_error()));
        assert!(matches!(e, Error::Robot(_)));
        let e =
            Error::from(StiffnessError::Routing(RoutingError::NoSuchCable { cable: 1, cables: 0 }));
        assert!(matches!(e, Error::Routing(RoutingError::NoSuchCable { .. })));
        let e =
            Error::from(IndicatorError::from(StiffnessError::Unstable { min_eigenvalue: -1.0 }));
        assert!(
            matches!(&e, Error::Stiffness(s) if matches!(**s, StiffnessError::Unstable { .. }))
        );
        assert_eq!(e.kind(), ErrorKind::Unstable);
        // Built by hand around the normalisation, the kind is still found.
        let e = Error::Stiffness(Box::new(StiffnessError::Statics(infeasible())));
        assert_eq!(e.kind(), ErrorKind::Infeasible);
    }

    #[test]
    fn kinds_print_their_names() {
        assert_eq!(ErrorKind::RankDeficient.to_string(), "rank-deficient");
        assert_eq!(ErrorKind::Input.to_string(), "input");
    }
}
