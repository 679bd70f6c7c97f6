//! The one error type of this crate.

use std::path::PathBuf;

use sinew_robot::{Compact, ErrorKind, RobotError};

/// Everything that can go wrong while loading a routing or evaluating it at a configuration.
///
/// Load-time variants name the routing file (`file`, `<string>` or `<generated …>` when not read
/// from disk), the cable at fault (its name) and the field at fault, spelled as in the file
/// (`cable[2].holes[1].link`, `pattern.distal_discs[3]`, `material.diameter`), so that a message
/// read on its own says what to fix.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RoutingError {
    /// A file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
    /// The text is not valid TOML, or does not have the routing file's shape (unknown key,
    /// missing key, wrong type). The message comes from the TOML parser and gives the line.
    #[error("{file}: invalid routing file: {message}")]
    Parse {
        /// The routing file.
        file: String,
        /// What the TOML parser said.
        message: String,
    },
    /// The file gives both a `[pattern]` and `[[cable]]` entries, or neither.
    #[error("{file}: {message}")]
    CableForm {
        /// The routing file.
        file: String,
        /// What is wrong.
        message: &'static str,
    },
    /// The `[pattern]` form on a robot whose joints are not all universal
    /// ([`sinew_robot::Robot::joint_groups`]).
    #[error(
        "{file}: robot `{robot}` ({dof} revolute joints) has joints that are not universal; the [pattern] form needs universal joints: give the cables as [[cable]] entries"
    )]
    NotUniversal {
        /// The routing file.
        file: String,
        /// The robot.
        robot: String,
        /// Its number of revolute joints.
        dof: usize,
    },
    /// A hole (or disc) names a link that the robot does not have.
    #[error("{file}: cable `{cable}`: {field} = `{link}`: the robot has no such link")]
    UnknownLink {
        /// The routing file.
        file: String,
        /// The cable.
        cable: String,
        /// The field naming the link.
        field: String,
        /// The missing link.
        link: String,
    },
    /// A hole lies on a link that is not on the cable's chain: the bodies from the base to the
    /// cable's anchor (its last hole). A cable cannot pass beyond the disc that it ends on.
    #[error(
        "{file}: cable `{cable}`: {field} = `{link}` (body {body}) is not on the cable's chain, the bodies 0..={anchor_body} from the base to its anchor"
    )]
    HoleOffChain {
        /// The routing file.
        file: String,
        /// The cable.
        cable: String,
        /// The field naming the link.
        field: String,
        /// The link.
        link: String,
        /// Its body.
        body: usize,
        /// The body of the cable's anchor.
        anchor_body: usize,
    },
    /// A cable with fewer than two holes has no segment.
    #[error("{file}: cable `{cable}`: {field} has {holes} hole(s); a cable needs at least 2")]
    TooFewHoles {
        /// The routing file.
        file: String,
        /// The cable.
        cable: String,
        /// The field listing the holes.
        field: String,
        /// How many holes it has.
        holes: usize,
    },
    /// Two cables share a name.
    #[error("{file}: cable `{cable}` is defined twice ({field})")]
    DuplicateCable {
        /// The routing file.
        file: String,
        /// The repeated name.
        cable: String,
        /// The second definition.
        field: String,
    },
    /// A cable's `joint` is not a universal joint of the robot, or its anchor does not sit on
    /// the distal side of that joint, or none of its holes lies proximal to it.
    #[error("{file}: cable `{cable}`: {field}: {problem}")]
    WrongJoint {
        /// The routing file.
        file: String,
        /// The cable.
        cable: String,
        /// The field at fault (`cable[i].joint`, the anchor's link or `cable[i].holes`).
        field: String,
        /// What is wrong, with the numbers.
        problem: JointProblem,
    },
    /// A segment between two consecutive holes has (near-)zero or non-finite length at Q = 0:
    /// its direction, and so its derivatives, would be undefined.
    #[error(
        "{file}: cable `{cable}`: segment {segment} ({from} → {to}) has length {} m at Q = 0; need a finite length ≥ {} m",
        Compact(*.length), Compact(*.min)
    )]
    ZeroLengthSegment {
        /// The routing file.
        file: String,
        /// The cable.
        cable: String,
        /// Segment index within the cable (segment `s` joins holes `s` and `s + 1`).
        segment: usize,
        /// The field of its first hole.
        from: String,
        /// The field of its second hole.
        to: String,
        /// Its length at Q = 0, m.
        length: f64,
        /// The least length accepted, m ([`crate::MIN_SEGMENT_LENGTH`]).
        min: f64,
    },
    /// The cable material is not physical: a non-positive or non-finite Young's modulus,
    /// diameter or area (or neither/both of diameter and area). It applies to every cable.
    #[error("{file}: {field} = {}: {message} (applies to every cable)", Compact(*.value))]
    InvalidMaterial {
        /// The routing file.
        file: String,
        /// The field (`material.youngs_modulus`, `material.diameter`, `material.area`).
        field: &'static str,
        /// The value read (NaN when absent).
        value: f64,
        /// What is wrong.
        message: &'static str,
    },
    /// The tension limits `[f_min, f_max]` do not satisfy `0 ≤ f_min < f_max` (finite).
    #[error(
        "{file}: tension_limits = [{}, {}] N: need finite 0 ≤ f_min < f_max (applies to every cable)",
        Compact(*.f_min), Compact(*.f_max)
    )]
    InvalidTensionLimits {
        /// The routing file.
        file: String,
        /// Lower limit read, N.
        f_min: f64,
        /// Upper limit read, N.
        f_max: f64,
    },
    /// A number in the file is out of its range (a NaN coordinate, a negative free length, a
    /// zero radius …). `cable` is empty when the field is not a cable's own.
    #[error("{file}: {}{field} = {}: {expected}", cable_prefix(.cable), Compact(*.value))]
    InvalidValue {
        /// The routing file.
        file: String,
        /// The cable, or empty when the field concerns several cables.
        cable: String,
        /// The field.
        field: String,
        /// The value read.
        value: f64,
        /// What the value must be.
        expected: &'static str,
    },
    /// A friction coefficient μ that is negative or not finite (spec §9). `cable` is empty for
    /// the file's `friction_coefficient`, which applies to every cable without its own.
    #[error(
        "{file}: {}{field} = {}: the friction coefficient μ must be finite and ≥ 0{}",
        cable_prefix(.cable), Compact(*.value),
        if .cable.is_empty() { " (applies to every cable without its own)" } else { "" }
    )]
    InvalidFrictionCoefficient {
        /// The routing file (or what set μ).
        file: String,
        /// The cable, or empty for the routing-wide value.
        cable: String,
        /// The field (`friction_coefficient`, `cable[2].friction_coefficient`,
        /// `pattern.cable.j1c2.friction_coefficient`).
        field: String,
        /// The value read.
        value: f64,
    },
    /// A cable's entry direction (the free length's direction at its first hole) of zero length
    /// or with a non-finite coordinate: it gives no direction.
    #[error(
        "{file}: cable `{cable}`: {field} = [{}, {}, {}]: the entry direction must be finite and of non-zero length",
        Compact(.direction[0]), Compact(.direction[1]), Compact(.direction[2])
    )]
    InvalidEntryDirection {
        /// The routing file.
        file: String,
        /// The cable.
        cable: String,
        /// The field (`cable[0].entry_direction`, `pattern.cable.j1c1.entry_direction`).
        field: String,
        /// The vector read, in the first hole's link frame.
        direction: [f64; 3],
    },
    /// A per-cable table of the pattern form (`[pattern.cable.NAME]`) names a cable the pattern
    /// does not make.
    #[error(
        "{file}: {field}: the pattern has no cable `{cable}` (its cables are j1c1 … j{joints}c3)"
    )]
    UnknownCable {
        /// The routing file.
        file: String,
        /// The table (`pattern.cable.NAME`).
        field: String,
        /// The name given.
        cable: String,
        /// The pattern's number of universal joints.
        joints: usize,
    },
    /// A per-joint list of the pattern (discs, radii, free lengths) whose length is not the
    /// number of universal joints.
    #[error("{file}: {field} has {got} entries; the robot has {expected} universal joints")]
    PatternSize {
        /// The routing file.
        file: String,
        /// The list.
        field: String,
        /// Number of universal joints.
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// At a configuration, a segment became (nearly) zero-length: the cable's direction there is
    /// undefined. Never a NaN: this error instead.
    #[error(
        "cable `{cable}`: segment {segment} has length {} m at this configuration (< {} m); its direction is undefined",
        Compact(*.length), Compact(*.min)
    )]
    DegenerateSegment {
        /// The cable.
        cable: String,
        /// Segment index within the cable.
        segment: usize,
        /// Its length, m.
        length: f64,
        /// The least length accepted, m.
        min: f64,
    },
    /// The routing was built for another robot (or the robot workspace for another robot).
    #[error(
        "routing was built for robot `{routing_robot}` ({routing_dof} joints), not for `{robot}` ({dof} joints)"
    )]
    RobotMismatch {
        /// The robot the routing was built for.
        routing_robot: String,
        /// Its joints.
        routing_dof: usize,
        /// The robot passed.
        robot: String,
        /// Its joints.
        dof: usize,
    },
    /// A workspace ([`crate::RoutingData`] or `RobotData`) sized for another routing or robot.
    #[error("{what} was sized for {got}, the routing needs {expected}")]
    WorkspaceMismatch {
        /// Which workspace and which size.
        what: &'static str,
        /// The size the routing needs.
        expected: usize,
        /// The size it has.
        got: usize,
    },
    /// A caller's buffer has the wrong size.
    #[error("{what}: expected {expected} entries, got {got}")]
    DimensionMismatch {
        /// What was passed.
        what: &'static str,
        /// The size needed.
        expected: usize,
        /// The size passed.
        got: usize,
    },
    /// A cable index out of range.
    #[error("cable index {cable} is out of range: the routing has {cables} cables")]
    NoSuchCable {
        /// The index passed.
        cable: usize,
        /// How many cables there are.
        cables: usize,
    },
    /// A quantity was asked for that the last evaluation did not compute (e.g. Hessians after
    /// an evaluation with [`crate::Order::Jacobian`]).
    #[error("{what} not computed: evaluate with at least Order::{needed:?}")]
    NotComputed {
        /// What was asked for.
        what: &'static str,
        /// The evaluation order that computes it.
        needed: crate::Order,
    },
    /// A friction quantity was asked for before the call that computes it.
    #[error("{what} not computed: call {call} first")]
    FrictionNotComputed {
        /// What was asked for.
        what: &'static str,
        /// The function that computes it.
        call: &'static str,
    },
    /// Serializing the expanded routing failed.
    #[error("cannot serialize the routing: {message}")]
    Serialize {
        /// What the serializer said.
        message: String,
    },
    /// An error of the robot model (kinematics, workspace, configuration).
    #[error(transparent)]
    Robot(#[from] RobotError),
}

impl RoutingError {
    /// The kind of failure: a segment degenerate at a configuration and a failed serialization
    /// are [`ErrorKind::Numerical`]; files, specs, sizes, indices and the evaluation order are
    /// the caller's input ([`ErrorKind::Input`]); a robot error says its own kind.
    pub fn kind(&self) -> ErrorKind {
        // No wildcard: a new variant must be classified here.
        match self {
            RoutingError::Robot(e) => e.kind(),
            RoutingError::DegenerateSegment { .. } | RoutingError::Serialize { .. } => {
                ErrorKind::Numerical
            }
            RoutingError::Io { .. }
            | RoutingError::Parse { .. }
            | RoutingError::CableForm { .. }
            | RoutingError::NotUniversal { .. }
            | RoutingError::UnknownLink { .. }
            | RoutingError::HoleOffChain { .. }
            | RoutingError::TooFewHoles { .. }
            | RoutingError::DuplicateCable { .. }
            | RoutingError::WrongJoint { .. }
            | RoutingError::ZeroLengthSegment { .. }
            | RoutingError::InvalidMaterial { .. }
            | RoutingError::InvalidTensionLimits { .. }
            | RoutingError::InvalidValue { .. }
            | RoutingError::InvalidFrictionCoefficient { .. }
            | RoutingError::InvalidEntryDirection { .. }
            | RoutingError::UnknownCable { .. }
            | RoutingError::PatternSize { .. }
            | RoutingError::RobotMismatch { .. }
            | RoutingError::WorkspaceMismatch { .. }
            | RoutingError::DimensionMismatch { .. }
            | RoutingError::NoSuchCable { .. }
            | RoutingError::NotComputed { .. }
            | RoutingError::FrictionNotComputed { .. } => ErrorKind::Input,
        }
    }
}

/// Why a cable does not fit the joint it drives ([`RoutingError::WrongJoint`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum JointProblem {
    /// The cable's `joint` is not a universal joint of the robot (0-based, as in the file).
    NoSuchJoint {
        /// The joint named.
        joint: usize,
        /// How many universal joints the robot has.
        joints: usize,
    },
    /// The anchor (last hole) is not on a body that the driven joint moves and no further
    /// joint does (bodies `first..=last`; `2·joint + 1`, `2·joint + 2` on a universal arm).
    AnchorElsewhere {
        /// The joint driven (0-based).
        joint: usize,
        /// The anchor's body.
        anchor_body: usize,
        /// The first body the joint moves and no further joint does.
        first: usize,
        /// The last such body.
        last: usize,
    },
    /// The anchor is on the base body: the cable drives no joint.
    AnchorOnBase,
    /// No hole lies proximal to the driven joint (on a body ≤ `proximal`, the body before
    /// the joint's first revolute joint: `2·joint` on a universal arm).
    NotCrossing {
        /// The joint driven (0-based).
        joint: usize,
        /// The last body proximal to the joint.
        proximal: usize,
    },
}

impl std::fmt::Display for JointProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            JointProblem::NoSuchJoint { joint, joints } => {
                write!(f, "joint {joint} does not exist: the robot has joints 0..{joints}")
            }
            JointProblem::AnchorElsewhere { joint, anchor_body, first, last } => write!(
                f,
                "the anchor is on body {anchor_body}, but a cable driving joint {joint} must end on a body in {first}..={last} (moved by joint {joint} and no further joint)"
            ),
            JointProblem::AnchorOnBase => {
                f.write_str("the anchor is on the base body: the cable drives no joint")
            }
            JointProblem::NotCrossing { joint, proximal } => write!(
                f,
                "no hole lies proximal to joint {joint} (on a body ≤ {proximal}): the cable does not cross the joint it drives"
            ),
        }
    }
}

fn cable_prefix(cable: &str) -> String {
    if cable.is_empty() { String::new() } else { format!("cable `{cable}`: ") }
}

/// Result with [`RoutingError`].
pub type Result<T, E = RoutingError> = std::result::Result<T, E>;
