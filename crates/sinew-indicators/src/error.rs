//! The one error type of this crate.

/// Everything that can go wrong computing an indicator.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IndicatorError {
    /// The joint index is not a universal joint of the robot.
    #[error("joint {} does not exist: the robot has {joints} universal joints", .joint + 1)]
    NoSuchJoint {
        /// The index passed (0-based).
        joint: usize,
        /// How many universal joints there are.
        joints: usize,
    },
    /// A stiffness matrix with a NaN or infinite entry.
    #[error("{what} has a non-finite entry")]
    NonFinite {
        /// Which matrix.
        what: &'static str,
    },
    /// A zero or non-finite direction for a directional stiffness.
    #[error("direction {direction:?} is not a non-zero finite vector")]
    InvalidDirection {
        /// The direction passed.
        direction: [f64; 3],
    },
    /// A sweep grid of fewer than 2 points per axis, or an empty or non-finite range.
    #[error("invalid sweep grid: {reason}")]
    InvalidGrid {
        /// What is wrong.
        reason: String,
    },
    /// An infeasible tension interval or another statics error (boxed: it is large).
    #[error(transparent)]
    Statics(Box<sinew_statics::StaticsError>),
    /// A stiffness error (boxed: it is large and rare).
    #[error(transparent)]
    Stiffness(Box<sinew_stiffness::StiffnessError>),
    /// A cable geometry error.
    #[error(transparent)]
    Routing(#[from] sinew_routing::RoutingError),
    /// A robot model error (e.g. angles outside the limits).
    #[error(transparent)]
    Robot(#[from] sinew_robot::RobotError),
}

impl From<sinew_stiffness::StiffnessError> for IndicatorError {
    fn from(e: sinew_stiffness::StiffnessError) -> Self {
        IndicatorError::Stiffness(Box::new(e))
    }
}

impl From<sinew_statics::StaticsError> for IndicatorError {
    fn from(e: sinew_statics::StaticsError) -> Self {
        IndicatorError::Statics(Box::new(e))
    }
}
