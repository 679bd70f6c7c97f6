//! The one error type of this crate.

use sinew_robot::{Compact, ErrorKind, RobotError};
use sinew_routing::RoutingError;
use sinew_statics::StaticsError;
use sinew_stiffness::StiffnessError;

/// Everything that can go wrong computing an indicator.
///
/// **One path per underlying error.** The errors of the crates below nest (a
/// `StiffnessError::Statics` carries a `StaticsError`, which may carry a `RoutingError`, which
/// may carry a `RobotError`). The `From` conversions unwrap that nesting, so an error always
/// arrives in the variant of the crate that raised it: a robot error (e.g. an angle outside
/// the limits) is always [`IndicatorError::Robot`], an infeasible load always
/// [`IndicatorError::Statics`], never a `Stiffness(Statics(..))`.
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
    /// The joint does not have exactly three cables of its own, consecutive in the routing:
    /// the single-joint model (eq. 22–23) cannot take it.
    #[error(
        "joint {} has {cables} cables of its own; the single-joint model needs exactly three, consecutive in the routing, with the common tension limits (any cable set: `sinew arm --policy`)",
        .joint + 1
    )]
    NotThreeCables {
        /// The joint (0-based).
        joint: usize,
        /// How many cables drive it.
        cables: usize,
    },
    /// The single-joint model (eq. 20–23) is for the universal joints of a universal arm.
    #[error(
        "joint {} has {dofs} revolute joint(s); the single-joint model needs an arm of universal joints (any arm: `sinew arm --policy`)",
        .joint + 1
    )]
    NotUniversal {
        /// The joint (0-based).
        joint: usize,
        /// Its revolute joints.
        dofs: usize,
    },
    /// A sweep grid of fewer than [`crate::AngleGrid::MIN_POINTS`] points per axis.
    #[error("sweep grid of {points} points per axis: need at least {min}")]
    GridTooSmall {
        /// Points per axis asked for.
        points: usize,
        /// The least accepted.
        min: usize,
    },
    /// A sweep grid whose angle range is empty or not finite.
    #[error(
        "sweep grid range [{}, {}] rad is empty or not finite",
        Compact(*.lower), Compact(*.upper)
    )]
    GridRange {
        /// First angle, rad.
        lower: f64,
        /// Last angle, rad.
        upper: f64,
    },
    /// A statics error (an infeasible tension interval among them), never one of its
    /// wrapping variants (boxed: it is large).
    #[error(transparent)]
    Statics(Box<StaticsError>),
    /// A stiffness error, never one of its wrapping variants (boxed: it is large and rare).
    #[error(transparent)]
    Stiffness(Box<StiffnessError>),
    /// A cable geometry error, never its `Robot` variant.
    #[error(transparent)]
    Routing(RoutingError),
    /// A robot model error (e.g. angles outside the limits).
    #[error(transparent)]
    Robot(RobotError),
}

impl IndicatorError {
    /// The kind of failure: a non-finite stiffness matrix is [`ErrorKind::Numerical`]; joints,
    /// grids and routings the probe cannot take are the caller's input
    /// ([`ErrorKind::Input`]); the errors of the crates below say their own kind.
    pub fn kind(&self) -> ErrorKind {
        // No wildcard: a new variant must be classified here.
        match self {
            IndicatorError::NoSuchJoint { .. }
            | IndicatorError::NotThreeCables { .. }
            | IndicatorError::NotUniversal { .. }
            | IndicatorError::GridTooSmall { .. }
            | IndicatorError::GridRange { .. } => ErrorKind::Input,
            IndicatorError::Statics(e) => e.kind(),
            IndicatorError::Stiffness(e) => e.kind(),
            IndicatorError::Routing(e) => e.kind(),
            IndicatorError::Robot(e) => e.kind(),
        }
    }

    /// Whether this is an infeasible load (the torque cannot be held within the limits; with
    /// friction, also a cable whose segments no actuator tension keeps within them).
    pub fn is_infeasible(&self) -> bool {
        matches!(self, IndicatorError::Statics(e)
            if matches!(**e, StaticsError::Infeasible { .. }
                | StaticsError::LevelsInfeasible(_)
                | StaticsError::EmptyActuatorInterval { .. }))
    }
}

impl From<RobotError> for IndicatorError {
    fn from(e: RobotError) -> Self {
        IndicatorError::Robot(e)
    }
}

impl From<RoutingError> for IndicatorError {
    fn from(e: RoutingError) -> Self {
        match e {
            RoutingError::Robot(e) => e.into(),
            e => IndicatorError::Routing(e),
        }
    }
}

impl From<StaticsError> for IndicatorError {
    fn from(e: StaticsError) -> Self {
        match e {
            StaticsError::Robot(e) => e.into(),
            StaticsError::Routing(e) => e.into(),
            e => IndicatorError::Statics(Box::new(e)),
        }
    }
}

impl From<StiffnessError> for IndicatorError {
    fn from(e: StiffnessError) -> Self {
        match e {
            StiffnessError::Statics(e) => e.into(),
            StiffnessError::Robot(e) => e.into(),
            StiffnessError::Routing(e) => e.into(),
            e => IndicatorError::Stiffness(Box::new(e)),
        }
    }
}
