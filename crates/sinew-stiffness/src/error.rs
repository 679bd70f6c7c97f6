//! The one error type of this crate.

use sinew_robot::{Compact, ErrorKind};
use sinew_statics::StaticsError;

/// Everything that can go wrong computing a stiffness. Each underlying error arrives by one
/// path: robot and routing errors as [`StiffnessError::Robot`] and [`StiffnessError::Routing`]
/// (also when the statics met them: the `From<StaticsError>` conversion unwraps them), the
/// statics' own errors as [`StiffnessError::Statics`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StiffnessError {
    /// `K_q + K_W` is not positive definite: the equilibrium is unstable, and no end stiffness
    /// exists. `min_eigenvalue` is the smallest eigenvalue of its symmetric part (N m/rad).
    #[error(
        "unstable equilibrium: K_q + K_W is not positive definite (smallest eigenvalue {} N m/rad)",
        Compact(*.min_eigenvalue)
    )]
    Unstable {
        /// Smallest eigenvalue of the symmetric part of `K_q + K_W`.
        min_eigenvalue: f64,
    },
    /// The end-effector Jacobian has rank < 6: `C_x` is singular and `K_x` does not exist.
    #[error(
        "the end-effector Jacobian has rank < 6 (smallest/largest pivot of C_x = {}); K_x does not exist, C_x does",
        Compact(*.pivot_ratio)
    )]
    RankDeficient {
        /// Smallest over largest pivot magnitude of `C_x`'s LU factorisation.
        pivot_ratio: f64,
    },
    /// A matrix with NaN or infinite entries.
    #[error("{what} has a non-finite entry")]
    NonFinite {
        /// Which matrix.
        what: &'static str,
    },
    /// A zero or non-finite direction for a directional stiffness.
    #[error(
        "direction [{}, {}, {}] is not a non-zero finite vector",
        Compact(.direction[0]), Compact(.direction[1]), Compact(.direction[2])
    )]
    InvalidDirection {
        /// The direction passed.
        direction: [f64; 3],
    },
    /// A zero or non-finite wrench direction (a stick load limit's).
    #[error(
        "wrench direction [{}, {}, {}, {}, {}, {}] is not a non-zero finite vector",
        Compact(.direction[0]), Compact(.direction[1]), Compact(.direction[2]),
        Compact(.direction[3]), Compact(.direction[4]), Compact(.direction[5])
    )]
    InvalidWrenchDirection {
        /// The direction passed (force, then moment).
        direction: [f64; 6],
    },
    /// The directional response's active-set passes found no consistent set of sliding holes
    /// (they cycled), or a sliding set made the increment's system singular.
    #[error("no consistent set of sliding holes for this direction (after {passes} passes)")]
    NoConsistentSliding {
        /// Passes taken (0: the system of one set was singular).
        passes: usize,
    },
    /// The holes that slide under an increment leave a joint stiffness that is not positive
    /// definite: that sliding combination is itself unstable.
    #[error(
        "the arm is unstable with its {holes} sliding holes free (smallest eigenvalue {} N m/rad)",
        Compact(*.min_eigenvalue)
    )]
    UnstableSliding {
        /// How many holes slide.
        holes: usize,
        /// Smallest eigenvalue of the symmetric part of that joint stiffness.
        min_eigenvalue: f64,
    },
    /// A stage of the pipeline asked for before the stage it needs: tensions before a pose
    /// ([`crate::ArmStiffness::set_pose`]), the end before tensions
    /// ([`crate::ArmStiffness::set_tensions`]).
    #[error("{needs} first: the workspace has no {missing} yet")]
    StageMissing {
        /// The call that must come first.
        needs: &'static str,
        /// What the workspace lacks.
        missing: &'static str,
    },
    /// The eigen-decomposition did not converge.
    #[error("the eigen-decomposition of K_q + K_W did not converge")]
    Eigen,
    /// An input of the wrong size.
    #[error("{what}: expected {expected} rows/columns, got {got}")]
    DimensionMismatch {
        /// What was passed.
        what: &'static str,
        /// The size needed.
        expected: usize,
        /// The size passed.
        got: usize,
    },
    /// An [`crate::ArmStiffnessData`] made for another arm (Pinocchio's `model.check(data)`).
    #[error(
        "the workspace was made for another arm ({workspace_dof} DOF, {workspace_cables} cables, or other blocks of K_q); this arm has {dof} DOF and {cables} cables: make it with ArmStiffnessData::new(&arm)"
    )]
    WorkspaceMismatch {
        /// DOFs of the arm.
        dof: usize,
        /// Cables of the arm.
        cables: usize,
        /// DOFs of the arm the workspace was made for.
        workspace_dof: usize,
        /// Cables of the arm the workspace was made for.
        workspace_cables: usize,
    },
    /// The stick regime asked of a cable without friction (μ = 0): it has no band, so it
    /// cannot stick (spec §9).
    #[error("the stick regime needs friction: cable {cable} has μ = 0 (no band to stick in)")]
    StickWithoutFriction {
        /// The cable (0-based).
        cable: usize,
    },
    /// The friction workspace holds the capstan weights of another slip regime, or none.
    #[error(
        "the friction workspace holds the capstan weights of {computed:?}, not of {needs:?}: run compute_capstan_weights for {needs:?} first"
    )]
    WrongCapstanWeights {
        /// The regime needed.
        needs: sinew_routing::Slip,
        /// The regime whose weights it holds (`None`: none).
        computed: Option<sinew_routing::Slip>,
    },
    /// An error of the statics itself (tensions, torques, unsupported routing).
    #[error(transparent)]
    Statics(StaticsError),
    /// An error of the robot model.
    #[error(transparent)]
    Robot(#[from] sinew_robot::RobotError),
    /// An error of the cable geometry.
    #[error(transparent)]
    Routing(#[from] sinew_routing::RoutingError),
}

impl StiffnessError {
    /// The kind of failure: an unstable equilibrium ([`ErrorKind::Unstable`]), a rank-deficient
    /// end-effector Jacobian ([`ErrorKind::RankDeficient`]), an input of the wrong size
    /// ([`ErrorKind::Input`]) or a computation that failed ([`ErrorKind::Numerical`], which
    /// includes a workspace made for another arm); the errors of the crates below say their
    /// own kind.
    pub fn kind(&self) -> ErrorKind {
        // No wildcard: a new variant must be classified here.
        match self {
            StiffnessError::Unstable { .. } | StiffnessError::UnstableSliding { .. } => {
                ErrorKind::Unstable
            }
            StiffnessError::RankDeficient { .. } => ErrorKind::RankDeficient,
            StiffnessError::NonFinite { .. }
            | StiffnessError::Eigen
            | StiffnessError::NoConsistentSliding { .. }
            | StiffnessError::WorkspaceMismatch { .. } => ErrorKind::Numerical,
            StiffnessError::DimensionMismatch { .. }
            | StiffnessError::InvalidDirection { .. }
            | StiffnessError::InvalidWrenchDirection { .. }
            | StiffnessError::StageMissing { .. }
            | StiffnessError::StickWithoutFriction { .. }
            | StiffnessError::WrongCapstanWeights { .. } => ErrorKind::Input,
            StiffnessError::Statics(e) => e.kind(),
            StiffnessError::Robot(e) => e.kind(),
            StiffnessError::Routing(e) => e.kind(),
        }
    }
}

impl From<StaticsError> for StiffnessError {
    /// The statics' robot and routing errors become [`StiffnessError::Robot`] and
    /// [`StiffnessError::Routing`] (one path per underlying error); the rest
    /// [`StiffnessError::Statics`].
    fn from(e: StaticsError) -> StiffnessError {
        match e {
            StaticsError::Robot(e) => StiffnessError::Robot(e),
            StaticsError::Routing(e) => StiffnessError::Routing(e),
            e => StiffnessError::Statics(e),
        }
    }
}
