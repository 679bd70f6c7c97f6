//! The one error type of this crate.

use sinew_robot::{Compact, ErrorKind, RobotError};
use sinew_routing::RoutingError;

/// Everything that can go wrong while writing a model.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MjcfError {
    /// The pose is not one of the robot's: wrong length, non-finite, or outside the limits.
    #[error(transparent)]
    Robot(#[from] RobotError),
    /// The routing does not belong to the robot, or a segment degenerates at the pose.
    #[error(transparent)]
    Routing(#[from] RoutingError),
    /// The tension vector does not have one entry per cable.
    #[error("tensions: expected {expected} (one per cable, routing order), got {got}")]
    TensionCount {
        /// The routing's cable count.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// The segment tensions do not have one entry per routing segment.
    #[error("segment tensions: expected {expected} (one per segment, routing order), got {got}")]
    SegmentTensionCount {
        /// The routing's segment count.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// A tension is not finite, or lies outside the cable's limits.
    #[error(
        "cable `{cable}`: tension {} N is outside its limits [{}, {}] N",
        Compact(*tension),
        Compact(limits[0]),
        Compact(limits[1])
    )]
    Tension {
        /// The cable's name.
        cable: String,
        /// The tension given, N.
        tension: f64,
        /// The cable's `[f_min, f_max]`, N.
        limits: [f64; 2],
    },
    /// The wrench has a non-finite component.
    #[error("wrench: component {index} is {}, not a finite number", Compact(*value))]
    Wrench {
        /// 0-based component.
        index: usize,
        /// The value.
        value: f64,
    },
    /// An option is out of its range or does not go with another.
    #[error("{option}: {reason}")]
    Option {
        /// The option (`damping`, `timestep`, `split`).
        option: &'static str,
        /// Why it is refused.
        reason: String,
    },
}

impl MjcfError {
    /// What kind of failure this is (every variant is bad input except what the robot or
    /// routing classify otherwise, e.g. a degenerate segment: numerical).
    pub fn kind(&self) -> ErrorKind {
        match self {
            MjcfError::Robot(e) => e.kind(),
            MjcfError::Routing(e) => e.kind(),
            MjcfError::TensionCount { .. }
            | MjcfError::SegmentTensionCount { .. }
            | MjcfError::Tension { .. }
            | MjcfError::Wrench { .. }
            | MjcfError::Option { .. } => ErrorKind::Input,
        }
    }
}

/// This crate's result.
pub type Result<T> = std::result::Result<T, MjcfError>;
