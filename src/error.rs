//! One error type for the facade: every crate's error, normalised to one path each, with its
//! [`ErrorKind`] (each crate classifies its own).

pub use crate::robot::ErrorKind;

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

impl Error {
    /// The kind of failure (see [`ErrorKind`] for what each one covers), as the crate that
    /// raised the error classifies it (each crate's error has its own exhaustive `kind()`,
    /// e.g. [`StaticsError::kind`]); [`Error::Other`] is [`ErrorKind::Input`].
    pub fn kind(&self) -> ErrorKind {
        match self {
            Error::Robot(e) => e.kind(),
            Error::Routing(e) => e.kind(),
            Error::Statics(e) => e.kind(),
            Error::Stiffness(e) => e.kind(),
            Error::Indicators(e) => e.kind(),
            Error::Planner(e) => e.kind(),
            Error::Other { .. } => ErrorKind::Input,
        }
    }

    /// Whether this is an infeasible load ([`ErrorKind::Infeasible`]).
    pub fn is_infeasible(&self) -> bool {
        self.kind() == ErrorKind::Infeasible
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
