//! The one error type of this crate.

use sinew_robot::Compact;

/// Why a joint's cables cannot hold its torque.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum InfeasibleReason {
    /// The joint's cable Jacobian block has rank < 2: the cables cannot produce some torque.
    RankDeficient,
    /// The null space of `J_cᵀ` has no strictly positive direction: the cables cannot all be
    /// tensioned together without unbalancing the joint (lost force closure). `null` is the
    /// unit null direction found.
    NoForceClosure {
        /// Unit null direction of `J_cᵀ`.
        null: [f64; 3],
    },
    /// Every balancing tension vector leaves some cable outside `[f_min, f_max]`: the limits
    /// would need `λ ≥ lambda_min` and `λ ≤ lambda_max` with `lambda_min > lambda_max`.
    OutsideLimits {
        /// Least `λ` that keeps every cable at or above `f_min`.
        lambda_min: f64,
        /// Greatest `λ` that keeps every cable at or below `f_max`.
        lambda_max: f64,
    },
}

impl std::fmt::Display for InfeasibleReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            InfeasibleReason::RankDeficient => write!(f, "its cable Jacobian has rank < 2"),
            InfeasibleReason::NoForceClosure { null } => write!(
                f,
                "its cables have lost force closure (null direction [{}, {}, {}] is not positive)",
                Compact(null[0]),
                Compact(null[1]),
                Compact(null[2])
            ),
            InfeasibleReason::OutsideLimits { lambda_min, lambda_max } => write!(
                f,
                "no tensions within the limits hold the torque (λ ≥ {} and λ ≤ {})",
                Compact(*lambda_min),
                Compact(*lambda_max)
            ),
        }
    }
}

/// Why a routing does not fit the closed-form statics: three cables per universal joint, in
/// joint order, none changing length with a joint beyond its own.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum UnsupportedRouting {
    /// An odd number of revolute joints: not a chain of 2-DOF universal joints.
    OddDof {
        /// The number of revolute joints.
        dof: usize,
    },
    /// Not three cables per joint.
    CableCount {
        /// The number of cables.
        cables: usize,
        /// The number of universal joints.
        joints: usize,
    },
    /// A joint that does not own exactly three cables, consecutive in the routing.
    JointCables {
        /// Universal joint index (0-based).
        joint: usize,
        /// The number of cables that drive it.
        cables: usize,
    },
    /// A cable out of joint order.
    CableOrder {
        /// The cable.
        cable: String,
        /// The joint it drives (0-based).
        joint: usize,
    },
    /// A cable whose length changes with a joint beyond the one it drives.
    BeyondOwnJoint {
        /// The cable.
        cable: String,
        /// The joint it drives (0-based).
        joint: usize,
    },
}

impl std::fmt::Display for UnsupportedRouting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            UnsupportedRouting::OddDof { dof } => {
                write!(f, "{dof} DOF is not a chain of 2-DOF universal joints")
            }
            UnsupportedRouting::CableCount { cables, joints } => write!(
                f,
                "{cables} cables for {joints} joints; the closed-form solver needs 3 per joint"
            ),
            UnsupportedRouting::JointCables { joint, cables } => write!(
                f,
                "joint {} has {cables} cables; the single-joint model needs its own three",
                joint + 1
            ),
            UnsupportedRouting::CableOrder { cable, joint } => write!(
                f,
                "cable `{cable}` drives joint {}; expected 3 cables per joint, in joint order",
                joint + 1
            ),
            UnsupportedRouting::BeyondOwnJoint { cable, joint } => write!(
                f,
                "cable `{cable}` of joint {} changes length with joints beyond its own",
                joint + 1
            ),
        }
    }
}

/// Everything that can go wrong in the statics.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StaticsError {
    /// A joint's cables cannot hold its torque within the tension limits: the typed outcome of
    /// an infeasible load.
    #[error("joint {} cannot hold torque [{}, {}] N m with tensions in [{}, {}] N: {reason}", .joint + 1, Compact(.torque[0]), Compact(.torque[1]), Compact(.limits[0]), Compact(.limits[1]))]
    Infeasible {
        /// Universal joint index (0-based; the message counts from 1, as the paper does).
        joint: usize,
        /// The torque the joint's own cables must hold, N m.
        torque: [f64; 2],
        /// `[f_min, f_max]`, N.
        limits: [f64; 2],
        /// Why.
        reason: InfeasibleReason,
    },
    /// A torque with a NaN or infinite component.
    #[error("joint {}: torque [{}, {}] is not finite", .joint + 1, Compact(.torque[0]), Compact(.torque[1]))]
    NonFiniteTorque {
        /// Universal joint index (0-based).
        joint: usize,
        /// The torque.
        torque: [f64; 2],
    },
    /// A tension level outside `[0, 1]` (or NaN).
    #[error("joint {}: tension level {} is outside [0, 1]", .joint + 1, Compact(*.level))]
    InvalidLevel {
        /// Universal joint index (0-based).
        joint: usize,
        /// The level passed.
        level: f64,
    },
    /// A routing that is not three cables per universal joint (each cable driving one joint).
    #[error("unsupported routing: {0}")]
    UnsupportedRouting(UnsupportedRouting),
    /// A joint index beyond the arm's universal joints.
    #[error("joint {} does not exist: the arm has {joints} universal joints", .joint + 1)]
    NoSuchJoint {
        /// The joint asked for (0-based; the message counts from 1).
        joint: usize,
        /// The number of universal joints.
        joints: usize,
    },
    /// An input of the wrong size.
    #[error("{what}: expected {expected} entries, got {got}")]
    DimensionMismatch {
        /// What was passed.
        what: &'static str,
        /// The size needed.
        expected: usize,
        /// The size passed.
        got: usize,
    },
    /// A wrench with a NaN or infinite component.
    #[error("wrench {wrench:?} is not finite")]
    NonFiniteWrench {
        /// The wrench.
        wrench: [f64; 6],
    },
    /// An error of the robot model (sizes, workspace).
    #[error(transparent)]
    Robot(#[from] sinew_robot::RobotError),
    /// An error of the cable geometry.
    #[error(transparent)]
    Routing(#[from] sinew_routing::RoutingError),
}
