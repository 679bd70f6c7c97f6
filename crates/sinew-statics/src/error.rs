//! The one error type of this crate.

use sinew_robot::{Compact, ErrorKind};

use crate::refusal::{InfeasibleReason, LevelsInfeasible, NotBalanced};

/// Why a convex solve (clarabel's, in the tension policies, the force-closure LP and the
/// planner's bundle subproblems) ended without an answer that can be used: one variant per
/// way, so that callers match on it rather than on a message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum SolverStop {
    /// The solver refused the program at setup (sizes, a non-finite entry).
    Setup,
    /// It reached only reduced accuracy where a bound must be exact (an LP bound).
    ReducedAccuracy,
    /// It reported a program infeasible that has a feasible point by construction.
    FalseInfeasibility,
    /// It reported the program unbounded (dual infeasible).
    Unbounded,
    /// Its bound lies below a value already found feasible: the answer is not to be trusted.
    InconsistentBound,
    /// It ran out of iterations.
    MaxIterations,
    /// It ran out of time.
    MaxTime,
    /// It met a numerical error (a failed factorisation).
    NumericalError,
    /// It stopped making progress.
    InsufficientProgress,
    /// It did not run (unsolved, or stopped by a callback).
    NotRun,
}

impl SolverStop {
    /// The stop for a clarabel status that is neither solved nor primal infeasible (those are
    /// answers, not stops; given one, the closest stop: reduced accuracy or a false
    /// infeasibility).
    #[must_use]
    pub fn from_status(status: clarabel::solver::SolverStatus) -> Self {
        use clarabel::solver::SolverStatus as S;
        match status {
            S::Solved | S::AlmostSolved => SolverStop::ReducedAccuracy,
            S::PrimalInfeasible | S::AlmostPrimalInfeasible => SolverStop::FalseInfeasibility,
            S::DualInfeasible | S::AlmostDualInfeasible => SolverStop::Unbounded,
            S::MaxIterations => SolverStop::MaxIterations,
            S::MaxTime => SolverStop::MaxTime,
            S::NumericalError => SolverStop::NumericalError,
            S::InsufficientProgress => SolverStop::InsufficientProgress,
            S::Unsolved | S::CallbackTerminated => SolverStop::NotRun,
        }
    }
}

impl std::fmt::Display for SolverStop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SolverStop::Setup => "the program was refused at setup",
            SolverStop::ReducedAccuracy => "solved only to reduced accuracy",
            SolverStop::FalseInfeasibility => "reported infeasible a program that has a point",
            SolverStop::Unbounded => "reported the program unbounded",
            SolverStop::InconsistentBound => "a bound below a feasible value",
            SolverStop::MaxIterations => "iteration limit reached",
            SolverStop::MaxTime => "time limit reached",
            SolverStop::NumericalError => "numerical error",
            SolverStop::InsufficientProgress => "insufficient progress",
            SolverStop::NotRun => "did not run",
        })
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
    /// A joint that is not a 2-DOF universal joint.
    NotUniversal {
        /// The joint (0-based).
        joint: usize,
        /// Its number of revolute joints.
        dofs: usize,
    },
    /// A cable with limits of its own.
    CableLimits {
        /// The cable.
        cable: String,
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
            UnsupportedRouting::NotUniversal { joint, dofs } => {
                write!(f, "joint {} has {dofs} revolute joint(s), not 2", joint + 1)
            }
            UnsupportedRouting::CableLimits { cable } => {
                write!(f, "cable `{cable}` has tension limits of its own")
            }
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
    /// No tensions within the limits balance the load (any cable set): the typed outcome of
    /// an infeasible load on the general path, with the joint motion along which the cables
    /// fall short.
    #[error("{0}")]
    NoEquilibrium(Box<NoEquilibrium>),
    /// Tension levels asked of a routing the closed form does not take.
    #[error(
        "tension levels need three cables per universal joint with common limits ({0}); choose a tension policy instead (least-total, least-norm, safest)"
    )]
    LevelsUnavailable(UnsupportedRouting),
    /// Given tensions that do not balance the load or leave their limits.
    #[error("the given tensions {0}")]
    NotBalanced(NotBalanced),
    /// A tension stage asked of a workspace that has had no pose stage
    /// ([`crate::ArmStatics::set_pose`]).
    #[error("no pose: set the pose and the load before choosing tensions")]
    NoPose,
    /// The tension levels could not be met, because the distal joints' levels (whose tensions
    /// the routed closed form fixes first) overloaded a proximal joint, while tensions within
    /// the limits do balance the load (a policy holds it).
    #[error("{0}")]
    LevelsInfeasible(Box<LevelsInfeasible>),
    /// A NaN or infinite entry in a computed input (the cable Jacobian, `T0`).
    #[error("{what} has a NaN or infinite entry")]
    NonFiniteInput {
        /// What.
        what: &'static str,
    },
    /// A factorisation failed to converge.
    #[error("{what} did not converge")]
    Numerical {
        /// Which.
        what: &'static str,
    },
    /// The convex solver (clarabel) stopped without an answer or a certificate.
    #[error("the tension solver stopped without an answer: {stop}")]
    Solver {
        /// Why it stopped.
        stop: SolverStop,
    },
    /// In a slip regime with friction, no actuator tension keeps every segment of the cable
    /// within its limits: the capstan ratio `max_s w_s / min_s w_s` along it exceeds
    /// `f_max / f_min` ([`crate::actuator_limits`]).
    #[error(
        "cable {cable}: no actuator tension keeps every segment within [{}, {}] N: the capstan ratio along it is {}",
        Compact(.limits[0]), Compact(.limits[1]), Compact(*.ratio)
    )]
    EmptyActuatorInterval {
        /// The cable (0-based).
        cable: usize,
        /// Its `[f_min, f_max]`, N.
        limits: [f64; 2],
        /// `max_s w_s / min_s w_s`.
        ratio: f64,
    },
    /// An error of the robot model (sizes, workspace).
    #[error(transparent)]
    Robot(#[from] sinew_robot::RobotError),
    /// An error of the cable geometry.
    #[error(transparent)]
    Routing(#[from] sinew_routing::RoutingError),
}

impl StaticsError {
    /// The kind of failure: an infeasible load ([`ErrorKind::Infeasible`], whatever the reason:
    /// a rank-deficient joint block, lost force closure or the limits), a bad input
    /// ([`ErrorKind::Input`]), or a computation that failed ([`ErrorKind::Numerical`]); robot
    /// and routing errors say their own kind.
    pub fn kind(&self) -> ErrorKind {
        // No wildcard: a new variant must be classified here.
        match self {
            StaticsError::Infeasible { .. }
            | StaticsError::NoEquilibrium(_)
            | StaticsError::LevelsInfeasible(_)
            | StaticsError::EmptyActuatorInterval { .. } => ErrorKind::Infeasible,
            StaticsError::NonFiniteTorque { .. }
            | StaticsError::LevelsUnavailable(_)
            | StaticsError::NotBalanced(_)
            | StaticsError::NoPose
            | StaticsError::NoSuchJoint { .. }
            | StaticsError::InvalidLevel { .. }
            | StaticsError::UnsupportedRouting { .. }
            | StaticsError::DimensionMismatch { .. }
            | StaticsError::NonFiniteWrench { .. } => ErrorKind::Input,
            StaticsError::NonFiniteInput { .. }
            | StaticsError::Numerical { .. }
            | StaticsError::Solver { .. } => ErrorKind::Numerical,
            StaticsError::Robot(e) => e.kind(),
            StaticsError::Routing(e) => e.kind(),
        }
    }
}

/// Why no tensions within the limits balance the load (any cable set,
/// [`StaticsError::NoEquilibrium`]).
#[derive(Debug, Clone, PartialEq)]
pub struct NoEquilibrium {
    /// The joints concerned (0-based): those that move along the certificate's joint motion.
    pub joints: Vec<usize>,
    /// The reason, with its numbers.
    pub cause: NoEquilibriumCause,
}

/// The two ways a load can have no balancing tensions.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum NoEquilibriumCause {
    /// `T0` has a component no tensions produce: along the joint motion `direction` (unit,
    /// dof) the cables exert no torque, and the load needs `torque` (N m).
    Unreachable {
        /// The joint motion the cables cannot resist.
        direction: Vec<f64>,
        /// The torque the load needs along it, N m.
        torque: f64,
    },
    /// The cables could balance the load, but not within their limits. Along the joint motion
    /// `direction` (largest component 1) every balancing tension vector gives the same cable
    /// torque `needed = T0 · direction` (N m; the cables' torque is `τ = −J_cᵀ f`), while
    /// tensions within the limits give only `range` (N m): the solver's certificate of
    /// infeasibility. Reaching `needed` would take the cables
    /// `at_max` beyond `f_max` or the cables `at_min` below `f_min`.
    Limits {
        /// The joint motion (largest component 1).
        direction: Vec<f64>,
        /// The torque the load needs along it, N m.
        needed: f64,
        /// `[least, greatest]` torque along it with tensions within the limits, N m.
        range: [f64; 2],
        /// The cables that pull as hard as they may along it.
        at_max: Vec<String>,
        /// The cables that are as slack as they may be along it.
        at_min: Vec<String>,
    },
}

impl std::fmt::Display for NoEquilibrium {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let joints: Vec<String> = self.joints.iter().map(|j| (j + 1).to_string()).collect();
        let joints = match joints.len() {
            0 => String::from("the arm"),
            1 => format!("joint {}", joints[0]),
            _ => format!("joints {}", joints.join(", ")),
        };
        let vector =
            |v: &[f64]| v.iter().map(|x| Compact(*x).to_string()).collect::<Vec<_>>().join(", ");
        match &self.cause {
            NoEquilibriumCause::Unreachable { direction, torque } => write!(
                f,
                "no cable tensions balance the load at {joints}: the cables exert no torque along the joint motion [{}], where the load needs {} N m",
                vector(direction),
                Compact(*torque)
            ),
            NoEquilibriumCause::Limits { direction, needed, range, at_max, at_min } => {
                write!(
                    f,
                    "no tensions within the limits balance the load at {joints}: along the joint motion [{}] the load needs {} N m from the cables, which give only [{}, {}] N m within their limits",
                    vector(direction),
                    Compact(*needed),
                    Compact(range[0]),
                    Compact(range[1])
                )?;
                if !at_max.is_empty() {
                    write!(f, "; {} at f_max", at_max.join(", "))?;
                }
                if !at_min.is_empty() {
                    write!(f, "; {} at f_min", at_min.join(", "))?;
                }
                write!(f, " (raise those limits or lighten the load)")
            }
        }
    }
}
