//! The command's errors: one line on standard error and an exit code from the error's kind.

use std::fmt;

use sinew::{ErrorKind, InputAtFault};

/// Exit code for bad input: options, counts, joint numbers, angles outside the limits, robot
/// files ([`ErrorKind::Input`]; clap's own usage errors exit with 2 as well).
pub const EXIT_INPUT: u8 = 2;
/// Exit code when the input is valid but the model has no answer: an infeasible load, lost
/// force closure ([`ErrorKind::Infeasible`]), an unstable or rank-deficient end where no
/// result can stand in for it ([`ErrorKind::Unstable`], [`ErrorKind::RankDeficient`]), a
/// degenerate geometry or a numerical failure ([`ErrorKind::Numerical`]).
pub const EXIT_MODEL: u8 = 1;

/// The exit code of an error of this kind: [`EXIT_INPUT`] for input, [`EXIT_MODEL`] for the
/// rest.
pub fn exit_code(kind: ErrorKind) -> u8 {
    match kind {
        ErrorKind::Input => EXIT_INPUT,
        _ => EXIT_MODEL,
    }
}

/// An error of the command, printed as `sinew: <message>`.
#[derive(Debug)]
pub struct CliError {
    /// What kind of failure (gives the exit code).
    pub kind: ErrorKind,
    /// The message, possibly multi-line (printed on one line).
    pub message: String,
}

impl CliError {
    /// Bad input, from anything printable.
    pub fn input(message: impl fmt::Display) -> CliError {
        CliError { kind: ErrorKind::Input, message: message.to_string() }
    }

    /// No answer from the model (a numerical failure), from anything printable.
    pub fn model(message: impl fmt::Display) -> CliError {
        CliError { kind: ErrorKind::Numerical, message: message.to_string() }
    }

    /// The process exit code.
    pub fn exit_code(&self) -> u8 {
        exit_code(self.kind)
    }

    /// The message on one line (library messages may quote a multi-line parser report).
    pub fn one_line(&self) -> String {
        one_line(&self.message)
    }
}

/// A library error: its kind gives the exit code; the message is the library's, prefixed by
/// the option the faulty value came from when the error says which (`--q`, `--levels`,
/// `--joint N`, `--grid N`), and an infeasible load says so first
/// ([`sinew::Error::message_naming`]).
pub fn library_error(e: impl Into<sinew::Error>) -> CliError {
    let e: sinew::Error = e.into();
    CliError { kind: e.kind(), message: e.message_naming(option) }
}

/// The command-line option an input at fault came from (joints counted from 1, as the
/// command does).
fn option(input: &InputAtFault) -> String {
    match input {
        InputAtFault::JointAngle { .. } => "--q".to_owned(),
        InputAtFault::Levels { .. } => "--levels".to_owned(),
        InputAtFault::Wrench => "--wrench".to_owned(),
        InputAtFault::Torque { .. } => "--torque".to_owned(),
        InputAtFault::Joint { joint } => format!("--joint {}", joint + 1),
        InputAtFault::JointLimits => "--joint (its angle limits)".to_owned(),
        InputAtFault::GridPoints { points } => format!("--grid {points}"),
        InputAtFault::PlannerArgument { name } => format!("--{}", name.replace('_', "-")),
    }
}

/// Collapse a message to one line: the lines trimmed and joined with ` | `, dropping empty
/// ones and the gutter lines of a parser's source excerpt (only `|`, `^`, digits, spaces).
pub fn one_line(message: &str) -> String {
    message
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .filter(|l| !l.chars().all(|c| c == '|' || c == '^' || c == ' '))
        .collect::<Vec<_>>()
        .join(" | ")
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.one_line())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sinew::indicators::IndicatorError;
    use sinew::planner::PlanError;
    use sinew::robot::RobotError;
    use sinew::statics::StaticsError;

    #[test]
    fn kinds_map_to_the_documented_exit_codes() {
        assert_eq!(exit_code(ErrorKind::Input), 2);
        for kind in [
            ErrorKind::Infeasible,
            ErrorKind::Unstable,
            ErrorKind::RankDeficient,
            ErrorKind::Numerical,
        ] {
            assert_eq!(exit_code(kind), 1, "{kind}");
        }
    }

    #[test]
    fn library_input_errors_name_the_option() {
        let e = library_error(StaticsError::InvalidLevel { joint: 2, level: 1.5 });
        assert_eq!(e.kind, ErrorKind::Input);
        assert!(e.message.starts_with("--levels: joint 3"), "{}", e.message);
        let e = library_error(IndicatorError::NoSuchJoint { joint: 8, joints: 5 });
        assert!(e.message.starts_with("--joint 9: "), "{}", e.message);
    }

    /// Every prefix the command puts before a library message, pinned word for word: the
    /// option at fault, the infeasible load, or none.
    #[test]
    fn every_prefix_is_pinned() {
        let out_of_limits = || RobotError::OutOfLimits {
            joint: "joint2_y".into(),
            position: 1.0,
            lower: -0.5,
            upper: 0.5,
        };
        let infeasible = || StaticsError::Infeasible {
            joint: 0,
            torque: [50.0, 0.0],
            limits: [20.0, 600.0],
            reason: sinew::statics::InfeasibleReason::RankDeficient,
        };
        let cases: Vec<(sinew::Error, &str)> = vec![
            (out_of_limits().into(), "--q: "),
            (
                RobotError::NonFiniteAngle { joint: "joint1_x".into(), value: f64::NAN }.into(),
                "--q: ",
            ),
            (StaticsError::InvalidLevel { joint: 4, level: -0.5 }.into(), "--levels: "),
            (StaticsError::NonFiniteWrench { wrench: [f64::NAN; 6] }.into(), "--wrench: "),
            (
                StaticsError::NonFiniteTorque { joint: 0, torque: [f64::NAN, 0.0] }.into(),
                "--torque: ",
            ),
            (PlanError::NonConservativeLoad { moment: [0.0, 1.0, 0.0] }.into(), "--wrench: "),
            (
                PlanError::InvalidInput {
                    what: "k_des",
                    problem: sinew::planner::InputProblem::NotSymmetricPositiveDefinite,
                }
                .into(),
                "--k-des: ",
            ),
            (
                PlanError::InvalidInput {
                    what: "budget",
                    problem: sinew::planner::InputProblem::Negative { unit: " N" },
                }
                .into(),
                "--budget: ",
            ),
            (IndicatorError::NoSuchJoint { joint: 5, joints: 5 }.into(), "--joint 6: "),
            (IndicatorError::NotThreeCables { joint: 1, cables: 2 }.into(), "--joint 2: "),
            (IndicatorError::NotUniversal { joint: 0, dofs: 1 }.into(), "--joint 1: "),
            (IndicatorError::GridTooSmall { points: 1, min: 2 }.into(), "--grid 1: "),
            (
                IndicatorError::GridRange { lower: 0.0, upper: 0.0 }.into(),
                "--joint (its angle limits): ",
            ),
            (infeasible().into(), "infeasible load: "),
            (PlanError::from(infeasible()).into(), "infeasible load: "),
            (PlanError::BudgetsInfeasible.into(), "infeasible: "),
            (StaticsError::NoSuchJoint { joint: 7, joints: 5 }.into(), ""),
            (sinew::stiffness::StiffnessError::InvalidDirection { direction: [0.0; 3] }.into(), ""),
            (sinew::routing::RoutingError::NoSuchCable { cable: 9, cables: 3 }.into(), ""),
            (sinew::stiffness::StiffnessError::Unstable { min_eigenvalue: -1.0 }.into(), ""),
            (PlanError::NoEndStiffness.into(), ""),
            (sinew::Error::Other { message: "x.urdf: cannot read".into() }, ""),
        ];
        for (e, prefix) in cases {
            let expected = format!("{prefix}{e}");
            let kind = e.kind();
            let got = library_error(e);
            assert_eq!(got.message, expected);
            assert_eq!(got.kind, kind, "{expected}");
        }
    }
}
