//! One error type for the facade: every crate's error, and messages of the report tools.

/// Any error of the Sinew crates.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Robot model or robot files.
    #[error(transparent)]
    Robot(#[from] crate::robot::RobotError),
    /// Cable routing.
    #[error(transparent)]
    Routing(#[from] crate::routing::RoutingError),
    /// Statics (infeasible tensions among them). Boxed, as it is large.
    #[error(transparent)]
    Statics(Box<crate::statics::StaticsError>),
    /// Stiffness (unstable equilibria among them). Boxed, as it is large.
    #[error(transparent)]
    Stiffness(Box<crate::stiffness::StiffnessError>),
    /// Indicators and sweeps.
    #[error(transparent)]
    Indicators(#[from] crate::indicators::IndicatorError),
    /// Anything else, with its message (e.g. a URDF read for a report).
    #[error("{message}")]
    Other {
        /// What went wrong.
        message: String,
    },
}

impl From<crate::statics::StaticsError> for Error {
    fn from(e: crate::statics::StaticsError) -> Self {
        Error::Statics(Box::new(e))
    }
}

impl From<crate::stiffness::StiffnessError> for Error {
    fn from(e: crate::stiffness::StiffnessError) -> Self {
        Error::Stiffness(Box::new(e))
    }
}
