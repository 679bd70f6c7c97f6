//! The one error type of this crate.

/// Everything that can go wrong computing a stiffness.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StiffnessError {
    /// `K_q + K_W` is not positive definite: the equilibrium is unstable, and no end stiffness
    /// exists. `min_eigenvalue` is the smallest eigenvalue of its symmetric part (N m/rad).
    #[error(
        "unstable equilibrium: K_q + K_W is not positive definite (smallest eigenvalue {min_eigenvalue:.6e} N m/rad)"
    )]
    Unstable {
        /// Smallest eigenvalue of the symmetric part of `K_q + K_W`.
        min_eigenvalue: f64,
    },
    /// The end-effector Jacobian has rank < 6: `C_x` is singular and `K_x` does not exist.
    #[error(
        "the end-effector Jacobian has rank < 6 (smallest/largest pivot of C_x = {pivot_ratio:.3e}); K_x does not exist, C_x does"
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
    /// An error of the statics (tensions, torques).
    #[error(transparent)]
    Statics(#[from] sinew_statics::StaticsError),
    /// An error of the robot model.
    #[error(transparent)]
    Robot(#[from] sinew_robot::RobotError),
    /// An error of the cable geometry.
    #[error(transparent)]
    Routing(#[from] sinew_routing::RoutingError),
}
