//! What kind of failure an error is: defined here, on the lowest floor with an error, so that
//! every crate's error enum can say its own kind (`kind()`, beside the enum in its `error.rs`).

/// What kind of failure an error is: what a caller (or the `sinew` command's exit code) does
/// about it. Every crate's error says its own with `kind()` ([`crate::RobotError::kind`] here);
/// the facade re-exports this type as `sinew::ErrorKind`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The input is wrong: a file that cannot be read or is malformed, an unsupported robot or
    /// routing, a joint or cable that does not exist, an angle outside the joint limits, a
    /// tension level outside `[0, 1]`, a non-finite torque or wrench, a buffer or workspace of
    /// the wrong size. Fix the input and try again.
    Input,
    /// The input is valid but a joint's cables cannot hold its torque within the tension
    /// limits, or have lost force closure (eq. 22–23: an empty feasible tension interval).
    Infeasible,
    /// The equilibrium is unstable: `K_q + K_W` is not positive definite, so no end stiffness
    /// exists (eq. 19).
    Unstable,
    /// The end-effector Jacobian has rank < 6: `C_x` exists, `K_x = C_x⁻¹` does not (eq. 19).
    RankDeficient,
    /// The computation failed: a non-finite matrix, an eigen-decomposition that did not
    /// converge, a cable segment of (near-)zero length at this configuration.
    Numerical,
}

impl std::fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ErrorKind::Input => "input",
            ErrorKind::Infeasible => "infeasible",
            ErrorKind::Unstable => "unstable",
            ErrorKind::RankDeficient => "rank-deficient",
            ErrorKind::Numerical => "numerical",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::ErrorKind;

    #[test]
    fn kinds_print_their_names() {
        assert_eq!(ErrorKind::RankDeficient.to_string(), "rank-deficient");
        assert_eq!(ErrorKind::Input.to_string(), "input");
    }
}
