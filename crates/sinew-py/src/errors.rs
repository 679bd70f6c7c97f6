//! Sinew's errors as Python exceptions: `SinewError` and one subclass per
//! [`sinew::ErrorKind`], each carrying the message the `sinew` command prints, with the Python
//! parameter's name where the command names its option (`q: …` for `--q: …`).

use pyo3::PyErr;
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use sinew::ErrorKind;
use sinew::indicators::IndicatorError;
use sinew::planner::PlanError;
use sinew::robot::RobotError;
use sinew::statics::StaticsError;

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

/// The kind and message of a library error, as `sinew`'s `library_error` words it
/// (crates/sinew-cli/src/error.rs), the option replaced by the Python parameter.
pub fn message(e: impl Into<sinew::Error>) -> (ErrorKind, String) {
    let e: sinew::Error = e.into();
    let kind = e.kind();
    let message = match (kind, parameter_of(&e)) {
        (ErrorKind::Infeasible, _) if matches!(e, sinew::Error::Planner(_)) => {
            format!("infeasible: {e}")
        }
        (ErrorKind::Infeasible, _) => format!("infeasible load: {e}"),
        (_, Some(parameter)) => format!("{parameter}: {e}"),
        (_, None) => e.to_string(),
    };
    (kind, message)
}

fn parameter_of(e: &sinew::Error) -> Option<String> {
    match e {
        sinew::Error::Robot(RobotError::OutOfLimits { .. } | RobotError::NonFiniteAngle { .. }) => {
            Some("q".to_owned())
        }
        sinew::Error::Statics(s) => match &**s {
            StaticsError::InvalidLevel { .. } => Some("levels".to_owned()),
            StaticsError::NonFiniteWrench { .. } => Some("wrench".to_owned()),
            StaticsError::NonFiniteTorque { .. } => Some("torque".to_owned()),
            _ => None,
        },
        sinew::Error::Planner(p) => match &**p {
            PlanError::NonConservativeLoad { .. } => Some("wrench".to_owned()),
            PlanError::InvalidInput { what, .. } => Some((*what).to_string()),
            _ => None,
        },
        sinew::Error::Indicators(i) => match i {
            IndicatorError::NoSuchJoint { joint, .. }
            | IndicatorError::NotThreeCables { joint, .. }
            | IndicatorError::NotUniversal { joint, .. } => Some(format!("joint {joint}")),
            IndicatorError::GridTooSmall { points, .. } => Some(format!("points {points}")),
            IndicatorError::GridRange { .. } => Some("joint (its angle limits)".to_owned()),
            _ => None,
        },
        _ => None,
    }
}
