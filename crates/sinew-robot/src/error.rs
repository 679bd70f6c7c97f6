//! The one error type of this crate.

use std::path::PathBuf;

use crate::Compact;
use crate::ErrorKind;

/// Everything that can go wrong while loading a robot or evaluating it at a configuration.
///
/// Every variant names the file, element or joint at fault, so that a message read on its own
/// says what to fix; numbers print through [`Compact`] (at most 5 significant digits,
/// scientific when huge or tiny).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RobotError {
    /// A file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
    /// The URDF text is not valid XML or not a URDF document.
    #[error("{source_name}: not a valid URDF: {message}")]
    InvalidUrdf {
        /// The file (or `<string>`) the text came from.
        source_name: String,
        /// What the URDF parser said.
        message: String,
    },
    /// The robot description file (`robot.toml`) is malformed.
    #[error("{path}: invalid robot description: {message}")]
    InvalidDescription {
        /// The description file.
        path: PathBuf,
        /// What the TOML parser said.
        message: String,
    },
    /// Two links share a name.
    #[error("{source_name}: link `{link}` is defined twice")]
    DuplicateLink {
        /// The file.
        source_name: String,
        /// The repeated name.
        link: String,
    },
    /// Two joints share a name.
    #[error("{source_name}: joint `{joint}` is defined twice")]
    DuplicateJoint {
        /// The file.
        source_name: String,
        /// The repeated name.
        joint: String,
    },
    /// A joint names a parent or child link that the file does not define.
    #[error("{source_name}: joint `{joint}` refers to unknown link `{link}`")]
    UnknownLink {
        /// The file.
        source_name: String,
        /// The joint that refers to it.
        joint: String,
        /// The missing link.
        link: String,
    },
    /// The links do not form a tree: a link is the child of two joints, or the joints form a cycle.
    #[error("{source_name}: kinematic loop through link `{link}`")]
    KinematicLoop {
        /// The file.
        source_name: String,
        /// A link on the loop (or with two parents).
        link: String,
    },
    /// More than one link has no parent joint: the description is not one connected chain.
    #[error("{source_name}: links `{first}` and `{second}` both have no parent; expected one root")]
    MultipleRoots {
        /// The file.
        source_name: String,
        /// One root.
        first: String,
        /// Another root.
        second: String,
    },
    /// The movable joints branch: Sinew models serial chains only.
    #[error(
        "{source_name}: link `{link}` has more than one child chain with movable joints; only serial chains are supported"
    )]
    BranchingChain {
        /// The file.
        source_name: String,
        /// The link where the chain branches.
        link: String,
    },
    /// A joint type other than revolute, continuous or fixed.
    #[error(
        "{source_name}: joint `{joint}` is {kind}; only revolute, continuous and fixed joints are supported"
    )]
    UnsupportedJoint {
        /// The file.
        source_name: String,
        /// The joint.
        joint: String,
        /// Its URDF type.
        kind: String,
    },
    /// A revolute joint whose axis has zero length.
    #[error("{source_name}: joint `{joint}` has a zero axis")]
    ZeroAxis {
        /// The file.
        source_name: String,
        /// The joint.
        joint: String,
    },
    /// A revolute joint whose lower limit is not below its upper limit.
    #[error(
        "{source_name}: joint `{joint}` has limits [{}, {}]; lower must be below upper",
        Compact(*.lower), Compact(*.upper)
    )]
    InvalidLimits {
        /// The file.
        source_name: String,
        /// The joint.
        joint: String,
        /// The lower limit, rad.
        lower: f64,
        /// The upper limit, rad.
        upper: f64,
    },
    /// A link with a negative, non-finite or absurd (> 1e9 kg) mass.
    #[error(
        "{source_name}: link `{link}` has mass {} kg; mass must be finite, non-negative and at most 1e9 kg",
        Compact(*.mass)
    )]
    InvalidMass {
        /// The file.
        source_name: String,
        /// The link.
        link: String,
        /// Its mass, kg.
        mass: f64,
    },
    /// A number in the description is NaN, infinite or beyond ±1e9 where a finite value is
    /// needed.
    #[error("{source_name}: {element}: `{field}` is not finite (or beyond ±1e9)")]
    NonFinite {
        /// The file.
        source_name: String,
        /// The element (e.g. `joint joint1_x`, `link link1`).
        element: String,
        /// The attribute.
        field: String,
    },
    /// The chain has no movable joint.
    #[error("{source_name}: the chain has no revolute joint")]
    NoJoints {
        /// The file.
        source_name: String,
    },
    /// A link name that the robot does not have (e.g. the tip link, or a hole's link).
    #[error("robot `{robot}` has no link `{link}`")]
    NoSuchLink {
        /// The robot.
        robot: String,
        /// The name asked for.
        link: String,
    },
    /// The gravity vector in the description is not finite.
    #[error(
        "{path}: gravity [{}, {}, {}] is not a finite vector",
        Compact(.gravity[0]), Compact(.gravity[1]), Compact(.gravity[2])
    )]
    InvalidGravity {
        /// The description file.
        path: PathBuf,
        /// The value read.
        gravity: [f64; 3],
    },
    /// An input vector or matrix has the wrong size.
    #[error("{what}: expected {expected} entries, got {got}")]
    DimensionMismatch {
        /// What was passed.
        what: &'static str,
        /// The size the robot needs.
        expected: usize,
        /// The size passed.
        got: usize,
    },
    /// A joint angle is NaN or infinite.
    #[error("joint `{joint}`: angle {} is not finite", Compact(*.value))]
    NonFiniteAngle {
        /// The joint.
        joint: String,
        /// The value passed.
        value: f64,
    },
    /// A joint angle outside its limits.
    #[error(
        "joint `{joint}`: angle {} rad is outside its limits [{}, {}] rad",
        Compact(*.position), Compact(*.lower), Compact(*.upper)
    )]
    OutOfLimits {
        /// The joint.
        joint: String,
        /// The angle passed, rad.
        position: f64,
        /// Lower limit, rad.
        lower: f64,
        /// Upper limit, rad.
        upper: f64,
    },
    /// A point index that the robot does not have.
    #[error("body index {body} is out of range: the robot has {bodies} bodies")]
    NoSuchBody {
        /// The index passed.
        body: usize,
        /// How many bodies there are.
        bodies: usize,
    },
    /// A workspace built for another robot.
    #[error("workspace was built for a robot with {data_dof} joints, this robot has {robot_dof}")]
    WorkspaceMismatch {
        /// Joints of the robot the workspace was made for.
        data_dof: usize,
        /// Joints of this robot.
        robot_dof: usize,
    },
}

impl RobotError {
    /// The kind of failure: every robot error is about the files or what the caller passed
    /// ([`ErrorKind::Input`]).
    pub fn kind(&self) -> ErrorKind {
        // No wildcard: a new variant must be classified here.
        match self {
            RobotError::Io { .. }
            | RobotError::InvalidUrdf { .. }
            | RobotError::InvalidDescription { .. }
            | RobotError::DuplicateLink { .. }
            | RobotError::DuplicateJoint { .. }
            | RobotError::UnknownLink { .. }
            | RobotError::KinematicLoop { .. }
            | RobotError::MultipleRoots { .. }
            | RobotError::BranchingChain { .. }
            | RobotError::UnsupportedJoint { .. }
            | RobotError::ZeroAxis { .. }
            | RobotError::InvalidLimits { .. }
            | RobotError::InvalidMass { .. }
            | RobotError::NonFinite { .. }
            | RobotError::NoJoints { .. }
            | RobotError::NoSuchLink { .. }
            | RobotError::InvalidGravity { .. }
            | RobotError::DimensionMismatch { .. }
            | RobotError::NonFiniteAngle { .. }
            | RobotError::OutOfLimits { .. }
            | RobotError::NoSuchBody { .. }
            | RobotError::WorkspaceMismatch { .. } => ErrorKind::Input,
        }
    }
}

/// Result with [`RobotError`].
pub type Result<T, E = RobotError> = std::result::Result<T, E>;
