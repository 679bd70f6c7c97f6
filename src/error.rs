//! One error type for the facade: every crate's error, normalised to one path each, with its
//! [`ErrorKind`] (each crate classifies its own) and the input at fault ([`InputAtFault`]).

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

    /// The one input the error is about, when it names one: what the `sinew` command turns
    /// into its option (`--q`, `--levels`, `--joint 3`, …) and Python into its parameter
    /// (`q`, `levels`, `joint 2`, …). `None` for an error that names no single input (a file,
    /// an infeasible load, a numerical failure, …: its message says what is at fault).
    ///
    /// Read from the variant [`From`] puts each error in (one path per underlying error).
    pub fn input_at_fault(&self) -> Option<InputAtFault> {
        match self {
            Error::Robot(
                RobotError::OutOfLimits { joint, .. } | RobotError::NonFiniteAngle { joint, .. },
            ) => Some(InputAtFault::JointAngle { joint: joint.clone() }),
            Error::Statics(e) => match **e {
                StaticsError::InvalidLevel { joint, .. } => Some(InputAtFault::Levels { joint }),
                StaticsError::NonFiniteWrench { .. } => Some(InputAtFault::Wrench),
                StaticsError::NonFiniteTorque { joint, .. } => Some(InputAtFault::Torque { joint }),
                _ => None,
            },
            Error::Planner(e) => match **e {
                PlanError::NonConservativeLoad { .. } => Some(InputAtFault::Wrench),
                PlanError::InvalidInput { what, .. } => {
                    Some(InputAtFault::PlannerArgument { name: what })
                }
                _ => None,
            },
            Error::Indicators(e) => match *e {
                IndicatorError::NoSuchJoint { joint, .. }
                | IndicatorError::NotThreeCables { joint, .. }
                | IndicatorError::NotUniversal { joint, .. } => Some(InputAtFault::Joint { joint }),
                IndicatorError::GridTooSmall { points, .. } => {
                    Some(InputAtFault::GridPoints { points })
                }
                IndicatorError::GridRange { .. } => Some(InputAtFault::JointLimits),
                _ => None,
            },
            _ => None,
        }
    }

    /// The message the `sinew` command and the Python bindings report: an infeasible load says
    /// so first (`infeasible load: …`, or `infeasible: …` when no tensions meet a plan's
    /// requirements); an error about one input ([`Error::input_at_fault`]) starts with that
    /// input as `name` spells it (`--q: …` on the command line, `q: …` in Python); any other
    /// error is its message alone.
    pub fn message_naming(&self, name: impl FnOnce(&InputAtFault) -> String) -> String {
        match (self.kind(), self.input_at_fault()) {
            (ErrorKind::Infeasible, _) if matches!(self, Error::Planner(_)) => {
                format!("infeasible: {self}")
            }
            (ErrorKind::Infeasible, _) => format!("infeasible load: {self}"),
            (_, Some(input)) => format!("{}: {self}", name(&input)),
            (_, None) => self.to_string(),
        }
    }
}

/// The one input an [`Error`] is about ([`Error::input_at_fault`]): what the caller passed
/// and should change. Joints are 0-based, as everywhere in the library.
///
/// Not `#[non_exhaustive]`: the command line and Python each name every input with one
/// exhaustive match, so an input added here must be named there too.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum InputAtFault {
    /// The joint angles `Q`: the angle of revolute joint `joint` (its name) is outside its
    /// limits or not finite.
    JointAngle {
        /// The revolute joint's name.
        joint: String,
    },
    /// The tension levels: the level of universal joint `joint` is outside `[0, 1]`.
    Levels {
        /// The universal joint.
        joint: usize,
    },
    /// The load wrench `F0`: not finite, or with a moment where the planner takes forces only.
    Wrench,
    /// The joint torque: universal joint `joint`'s is not finite.
    Torque {
        /// The universal joint.
        joint: usize,
    },
    /// The joint chosen: universal joint `joint` does not exist or the single-joint model
    /// cannot take it.
    Joint {
        /// The universal joint.
        joint: usize,
    },
    /// The chosen joint's angle limits, which span the sweep's range: empty or not finite.
    JointLimits,
    /// The sweep grid's points per axis: too few.
    GridPoints {
        /// The points per axis asked for.
        points: usize,
    },
    /// A planner argument, by its name in the library (`direction`, `budget`, `margin`,
    /// `k_des`, …; snake case).
    PlannerArgument {
        /// The argument's name.
        name: &'static str,
    },
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
