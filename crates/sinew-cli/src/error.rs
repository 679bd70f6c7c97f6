//! The command's errors: one line on standard error and an exit code.

use std::fmt;

/// Exit code for bad input: options, counts, joint numbers, angles outside the limits, robot
/// files (clap's own usage errors exit with 2 as well).
pub const EXIT_INPUT: u8 = 2;
/// Exit code when the input is valid but the model has no answer: an infeasible load, lost
/// force closure, a degenerate geometry, a numerical failure.
pub const EXIT_MODEL: u8 = 1;

/// An error of the command, printed as `sinew: <message>`.
#[derive(Debug)]
pub enum CliError {
    /// Bad input (exit 2).
    Input(String),
    /// The model has no answer (exit 1).
    Model(String),
}

impl CliError {
    /// Bad input, from anything printable.
    pub fn input(message: impl fmt::Display) -> CliError {
        CliError::Input(message.to_string())
    }

    /// No answer from the model, from anything printable.
    pub fn model(message: impl fmt::Display) -> CliError {
        CliError::Model(message.to_string())
    }

    /// The process exit code.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Input(_) => EXIT_INPUT,
            CliError::Model(_) => EXIT_MODEL,
        }
    }

    /// The message on one line (library messages may quote a multi-line parser report).
    pub fn one_line(&self) -> String {
        let message = match self {
            CliError::Input(m) | CliError::Model(m) => m,
        };
        one_line(message)
    }
}

/// A library error met while computing (exit 1); an infeasible load says so first.
pub fn model_error(e: impl Into<sinew::Error>) -> CliError {
    let e: sinew::Error = e.into();
    let infeasible = match &e {
        sinew::Error::Statics(s) => is_infeasible(s),
        sinew::Error::Stiffness(s) => {
            matches!(&**s, sinew::stiffness::StiffnessError::Statics(s) if is_infeasible(s))
        }
        sinew::Error::Indicators(sinew::indicators::IndicatorError::Statics(s)) => is_infeasible(s),
        _ => false,
    };
    if infeasible {
        CliError::Model(format!("infeasible load: {e}"))
    } else {
        CliError::Model(e.to_string())
    }
}

fn is_infeasible(e: &sinew::statics::StaticsError) -> bool {
    matches!(e, sinew::statics::StaticsError::Infeasible { .. })
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
