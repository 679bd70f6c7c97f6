//! Sinew's errors as Python exceptions: `SinewError` and one subclass per
//! [`sinew::ErrorKind`], each carrying the message the `sinew` command prints, with the Python
//! parameter's name where the command names its option (`q: …` for `--q: …`).

use pyo3::PyErr;
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use sinew::{ErrorKind, InputAtFault};

create_exception!(sinew, SinewError, PyException, "Base class of every error Sinew raises.");
create_exception!(
    sinew,
    InputError,
    SinewError,
    "The input is wrong: a file, a shape, a non-finite number, an angle outside its limits, an unknown joint or policy."
);
create_exception!(
    sinew,
    InfeasibleError,
    SinewError,
    "The cables cannot hold the load within their tension limits (eq. 22-23), or no tensions meet a plan's requirements."
);
create_exception!(
    sinew,
    UnstableError,
    SinewError,
    "K_q + K_W is not positive definite: no end stiffness exists (eq. 19)."
);
create_exception!(
    sinew,
    RankDeficientError,
    SinewError,
    "J_x has rank < 6: C_x exists, K_x does not (eq. 19)."
);
create_exception!(
    sinew,
    NumericalError,
    SinewError,
    "The computation failed (non-finite matrix, no convergence, a degenerate cable segment)."
);

/// The exception of `kind` with `message`.
pub fn exception(kind: ErrorKind, message: String) -> PyErr {
    match kind {
        ErrorKind::Input => InputError::new_err(message),
        ErrorKind::Infeasible => InfeasibleError::new_err(message),
        ErrorKind::Unstable => UnstableError::new_err(message),
        ErrorKind::RankDeficient => RankDeficientError::new_err(message),
        _ => NumericalError::new_err(message),
    }
}

/// An input error.
pub fn input(message: impl std::fmt::Display) -> PyErr {
    InputError::new_err(message.to_string())
}

/// A library error: its kind and the command line's message (see [`message`]).
pub fn library(e: impl Into<sinew::Error>) -> PyErr {
    let (kind, message) = message(e);
    exception(kind, message)
}

/// The kind and message of a library error, as the `sinew` command words it
/// ([`sinew::Error::message_naming`]), with the Python parameter where the command names its
/// option.
pub fn message(e: impl Into<sinew::Error>) -> (ErrorKind, String) {
    let e: sinew::Error = e.into();
    (e.kind(), e.message_naming(parameter))
}

/// The Python parameter an input at fault came from (joints 0-based, as in Python).
fn parameter(input: &InputAtFault) -> String {
    match input {
        InputAtFault::JointAngle { .. } => "q".to_owned(),
        InputAtFault::Levels { .. } => "levels".to_owned(),
        InputAtFault::Wrench => "wrench".to_owned(),
        InputAtFault::Torque { .. } => "torque".to_owned(),
        InputAtFault::Joint { joint } => format!("joint {joint}"),
        InputAtFault::JointLimits => "joint (its angle limits)".to_owned(),
        InputAtFault::GridPoints { points } => format!("points {points}"),
        InputAtFault::PlannerArgument { name } => (*name).to_owned(),
    }
}
